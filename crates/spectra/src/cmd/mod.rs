//! Subcommands, one file each.

pub mod bench;
pub mod checkpoint;
pub mod demo;
pub mod diff;
pub mod eval;
pub mod lut;
pub mod merge;
pub mod observers;
pub mod render;
pub mod sequence;
pub mod setup;
pub mod truth;
pub mod truth_cache;
pub mod upsample;
#[cfg(feature = "viewer")]
pub mod view;

/// What an interrupted command kept (a truth checkpoint): main prints it instead of "no output
/// written".
#[derive(Debug)]
pub struct KeptOnInterrupt(pub String);

impl std::fmt::Display for KeptOnInterrupt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for KeptOnInterrupt {}

/// Checks before the work that the output `path` given with `flag` can be written (its
/// directory exists and takes new files), so a long render never ends in "directory does not
/// exist".
pub fn check_output(flag: &str, path: &std::path::Path) -> anyhow::Result<()> {
    color::outfile::check_writable(path).map_err(|e| anyhow::anyhow!("{flag} {}: {e}", path.display()))
}

/// Stages the output `bytes` for `path` (`compare::atomic::stage`): complete on disk, not yet in
/// place. The error reads as a failed write did, "writing PATH: PATH: cause".
pub fn stage_output(path: &std::path::Path, bytes: &[u8]) -> anyhow::Result<compare::atomic::Staged> {
    use anyhow::Context;
    compare::atomic::stage(path, bytes).with_context(|| format!("writing {}", path.display()))
}

/// Puts a command's staged outputs in place together, once all are written
/// (`color::outfile::commit_all`): a command with several outputs stages every one first, so a
/// full disk on one leaves the others as they were rather than a new file beside an old one.
pub fn commit_outputs(staged: Vec<compare::atomic::Staged>) -> anyhow::Result<()> {
    compare::atomic::commit_all(staged).map_err(|e| {
        let what = format!("writing {}", e.path.display());
        anyhow::Error::new(e).context(what)
    })
}

/// Refuses, before the work, a command's outputs (flag, path; `None` for one not asked for) that
/// are not regular files, are the same file as one of `inputs` (what, path) or as each other:
/// one guard for every command (`color::outfile::check_distinct`).
pub fn check_outputs(
    outputs: &[(&str, Option<&std::path::Path>)],
    inputs: &[(String, std::path::PathBuf)],
) -> anyhow::Result<()> {
    let outs: Vec<(&str, &std::path::Path)> =
        outputs.iter().filter_map(|(f, p)| p.map(|p| (*f, p))).collect();
    let ins: Vec<(&str, &std::path::Path)> = inputs.iter().map(|(w, p)| (w.as_str(), p.as_path())).collect();
    color::outfile::check_distinct(&outs, &ins).map_err(anyhow::Error::msg)
}
