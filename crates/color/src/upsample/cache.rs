//! Getting a coefficient table to the renderer: fit once per machine, then load from a cache.
//!
//! Tables are not committed (9.4 MB of nearly incompressible floats per space and resolution)
//! and not built by `build.rs` (that would slow every clean build and run the fitter under the
//! build profile). Fitting a 64³ table takes a few seconds on two cores (see
//! `docs/upsampling.md`), so the first use fits it, writes it atomically to
//! `$SPECTRA_CACHE_DIR` (default: the platform cache directory + `spectra/`, e.g.
//! `~/.cache/spectra/`), and every later use reads it in milliseconds. A cache file that fails
//! to load (truncated, corrupted, an older format version) is refitted and replaced; a cache
//! directory that cannot be written only costs the refit next time.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use indicatif::{ProgressBar, ProgressStyle};

use crate::colorspace::RgbColorSpace;
use crate::error::{ColorError, Result};
use crate::upsample::table::CoeffTable;

/// Resolution of the tables the renderer and the path tracer use.
pub const TABLE_RES: usize = 64;

/// Bumped whenever the fitter changes its output, so stale caches are not reused.
pub const TABLE_VERSION: u32 = 4;

/// Environment variable overriding the cache directory.
pub const CACHE_ENV: &str = "SPECTRA_CACHE_DIR";

/// The cache directory: `$SPECTRA_CACHE_DIR`, else the platform cache dir + `spectra`.
pub fn cache_dir() -> Result<PathBuf> {
    if let Some(d) = std::env::var_os(CACHE_ENV).filter(|d| !d.is_empty()) {
        return Ok(PathBuf::from(d));
    }
    dirs::cache_dir()
        .map(|d| d.join("spectra"))
        .ok_or_else(|| ColorError::Table(format!("no cache directory on this platform; set {CACHE_ENV}")))
}

/// Cache file of `space`'s default table.
pub fn cache_path(space: &RgbColorSpace) -> Result<PathBuf> {
    Ok(cache_dir()?.join(format!("{}-{TABLE_RES}-v{TABLE_VERSION}.coeff", space.name)))
}

/// A progress bar on stderr (hidden automatically when stderr is not a terminal).
pub fn fit_progress(what: &str) -> ProgressBar {
    let pb = ProgressBar::new(0);
    if let Ok(style) =
        ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} rows, {elapsed} (eta {eta})")
    {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_message(what.to_string());
    pb
}

/// The table cached at `path` if it loads and has resolution `res`; otherwise a fresh
/// [`crate::upsample::fit_default_res`] fit, written atomically to `path` (a failed write is
/// not an error: the table is still good, it only costs a refit next time).
pub fn load_or_fit(path: &std::path::Path, space: &RgbColorSpace, res: usize) -> Result<CoeffTable> {
    if let Ok(t) = CoeffTable::read(path)
        && t.res == res
    {
        return Ok(t);
    }
    let pb = fit_progress(&format!(
        "fitting the {} spectral table (once; cached in {})",
        space.name,
        path.display()
    ));
    let t = crate::upsample::fit_default_res(space, res, &pb)?;
    if let Some(dir) = path.parent() {
        let _ = std::fs::create_dir_all(dir);
    }
    let _ = t.write(path);
    Ok(t)
}

static MEMO: Mutex<Option<HashMap<String, Arc<CoeffTable>>>> = Mutex::new(None);

/// The default table of the colour space called `space_name` (see [`RgbColorSpace::by_name`]).
pub fn table(space_name: &str) -> Result<Arc<CoeffTable>> {
    table_for(&RgbColorSpace::by_name(space_name)?)
}

/// The default table of `space`: from this process's memory, else the cache file, else
/// fitted (with a progress bar on stderr) and cached. Ctrl-C during the fit (once
/// [`crate::upsample::install_interrupt_handler`] ran) returns an error and writes nothing.
pub fn table_for(space: &RgbColorSpace) -> Result<Arc<CoeffTable>> {
    if let Some(t) = MEMO.lock().ok().and_then(|m| m.as_ref().and_then(|m| m.get(&space.name).cloned())) {
        return Ok(t);
    }
    let path = cache_path(space)?;
    let table = match CoeffTable::read(&path) {
        Ok(t) if t.res == TABLE_RES => t,
        _ => {
            let pb = fit_progress(&format!(
                "fitting the {} spectral table (once; cached in {})",
                space.name,
                path.display()
            ));
            let t = crate::upsample::fit_default(space, &pb)?;
            if let Some(dir) = path.parent() {
                let _ = std::fs::create_dir_all(dir);
            }
            // A read-only cache only means fitting again next time; the table is still good.
            let _ = t.write(&path);
            t
        }
    };
    let t = Arc::new(table);
    if let Ok(mut m) = MEMO.lock() {
        m.get_or_insert_with(HashMap::new).insert(space.name.clone(), t.clone());
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_once_then_loads_and_replaces_corrupt_files() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub").join("srgb-8.coeff");
        let space = RgbColorSpace::srgb();
        let fitted = load_or_fit(&path, &space, 8).unwrap();
        assert_eq!(CoeffTable::read(&path).unwrap(), fitted);
        // A truncated cache file is refitted and replaced, never returned.
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        assert_eq!(load_or_fit(&path, &space, 8).unwrap(), fitted);
        assert_eq!(std::fs::read(&path).unwrap(), bytes);
        assert_eq!(std::fs::read_dir(path.parent().unwrap()).unwrap().count(), 1);
    }
}
