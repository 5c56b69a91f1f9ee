//! Subcommands, one file each.

pub mod bench;
pub mod demo;
pub mod diff;
pub mod eval;
pub mod lut;
pub mod render;
pub mod setup;
pub mod truth;
pub mod upsample;
pub mod view;

/// Checks before the work that the output `path` given with `flag` can be written (its
/// directory exists and takes new files), so a long render never ends in "directory does not
/// exist".
pub fn check_output(flag: &str, path: &std::path::Path) -> anyhow::Result<()> {
    color::outfile::check_writable(path).map_err(|e| anyhow::anyhow!("{flag} {}: {e}", path.display()))
}
