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

use crate::colorspace::RgbColorSpace;
use crate::error::{ColorError, Result};
use crate::upsample::table::CoeffTable;

/// Resolution of the tables the renderer and the path tracer use.
pub const TABLE_RES: usize = 64;

/// Bumped whenever the fitter changes its output, so stale caches are not reused.
pub const TABLE_VERSION: u32 = 8;

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

/// Most mean round-trip ΔE2000 a cached table may show on 32 random colours. Fitted tables are
/// below it (2.7 even at 8³, the coarsest the tests fit; far less at 64³); a well-formed but
/// wrong table is above it (all zeros, every colour the same grey: 24.6).
const MAX_CACHED_MEAN_DE: f64 = 10.0;

/// The `.coeff` bytes of `t` with this cache's signature appended.
fn signed_bytes(t: &CoeffTable) -> Vec<u8> {
    crate::signature::sign(t.to_bytes())
}

/// Writes a table to the cache atomically, signed.
fn write_cached(t: &CoeffTable, path: &std::path::Path) -> Result<()> {
    t.validate(&path.display().to_string())?;
    crate::upsample::table::write_atomic(path, &signed_bytes(t))
}

/// The table cached at `path`, if it is one this cache wrote for `space` at resolution `res`:
/// its signature matches its payload and a round trip of a few colours is accurate. Anything
/// else (missing, truncated, damaged, unsigned, or well-formed but wrong) is `None`, to be
/// refitted.
pub fn read_cached(path: &std::path::Path, space: &RgbColorSpace, res: usize) -> Option<CoeffTable> {
    let cap = (CoeffTable::file_len(res) + crate::upsample::table::CHROMA_TAG.len() + 4 * res) as u64 + 64;
    let bytes = crate::input::read_regular(path, cap).ok()?;
    let t = CoeffTable::from_bytes(&bytes, &path.display().to_string()).ok()?;
    if t.res != res {
        return None;
    }
    crate::signature::payload(&bytes, t.encoded_len())?;
    check_usable(&t, space).ok()?;
    Some(t)
}

/// Whether `t` upsamples `space`'s colours at all: the mean round-trip ΔE2000 of 32 random
/// colours at most [`MAX_CACHED_MEAN_DE`] (a res-2 table, 48–66, rendered black; a table for
/// another colour space fails too). The error gives the figure. For the cache and `--table`.
pub fn check_usable(t: &CoeffTable, space: &RgbColorSpace) -> Result<()> {
    let rt = crate::upsample::roundtrip::roundtrip_table(t, space, 32, 1)?;
    if rt.stats.mean.is_finite() && rt.stats.mean <= MAX_CACHED_MEAN_DE {
        return Ok(());
    }
    Err(ColorError::Table(format!(
        "a round trip of 32 {} colours through this {}³ table has mean ΔE2000 {:.1} (a usable table is below \
         {MAX_CACHED_MEAN_DE}): too coarse, damaged, or fitted for another colour space",
        space.name, t.res, rt.stats.mean
    )))
}

/// The table cached at `path` if it loads and has resolution `res`; otherwise a fresh
/// [`crate::upsample::fit_default_res`] fit, written atomically to `path` (a failed write is
/// not an error: the table is still good, it only costs a refit next time).
pub fn load_or_fit(path: &std::path::Path, space: &RgbColorSpace, res: usize) -> Result<CoeffTable> {
    if let Some(t) = read_cached(path, space, res) {
        return Ok(t);
    }
    let pb = crate::progress::reporter(&format!(
        "fitting the {} spectral table (once; cached in {})",
        space.name,
        path.display()
    ));
    let t = crate::upsample::fit_default_res(space, res, pb.as_ref())?;
    if let Some(dir) = path.parent() {
        let _ = std::fs::create_dir_all(dir);
    }
    let _ = write_cached(&t, path);
    Ok(t)
}

static MEMO: Mutex<Option<HashMap<String, Arc<CoeffTable>>>> = Mutex::new(None);

/// The default table of the colour space called `space_name` (see [`RgbColorSpace::by_name`]).
pub fn table(space_name: &str) -> Result<Arc<CoeffTable>> {
    table_for(&RgbColorSpace::by_name(space_name)?)
}

/// The default table of `space`: from this process's memory, else the cache file, else
/// fitted (reporting through [`crate::progress::reporter`]) and cached. Ctrl-C during the fit (once
/// the program installed a handler that calls [`crate::cancel::cancel`]) returns an error and writes nothing.
pub fn table_for(space: &RgbColorSpace) -> Result<Arc<CoeffTable>> {
    if let Some(t) = MEMO.lock().ok().and_then(|m| m.as_ref().and_then(|m| m.get(&space.name).cloned())) {
        return Ok(t);
    }
    let path = cache_path(space)?;
    let table = match read_cached(&path, space, TABLE_RES) {
        Some(t) => t,
        None => {
            let pb = crate::progress::reporter(&format!(
                "fitting the {} spectral table (once; cached in {})",
                space.name,
                path.display()
            ));
            let t = crate::upsample::fit_default(space, pb.as_ref())?;
            if let Some(dir) = path.parent() {
                let _ = std::fs::create_dir_all(dir);
            }
            // A read-only cache only means fitting again next time; the table is still good.
            let _ = write_cached(&t, &path);
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

    #[test]
    fn a_well_formed_but_wrong_cached_table_is_refitted() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("srgb-8.coeff");
        let space = RgbColorSpace::srgb();
        let fitted = load_or_fit(&path, &space, 8).unwrap();
        let good = std::fs::read(&path).unwrap();
        assert!(read_cached(&path, &space, 8).is_some());
        let zeros = CoeffTable {
            res: 8,
            scale: fitted.scale.clone(),
            chroma: fitted.chroma.clone(),
            data: vec![0.0; fitted.data.len()],
        };
        // All zeros, plainly written (as the old cache did, or another tool): no signature.
        zeros.write(&path).unwrap();
        assert!(read_cached(&path, &space, 8).is_none());
        assert_eq!(load_or_fit(&path, &space, 8).unwrap(), fitted);
        assert_eq!(std::fs::read(&path).unwrap(), good);
        // All zeros with a valid signature: the round trip catches it.
        write_cached(&zeros, &path).unwrap();
        assert!(read_cached(&path, &space, 8).is_none());
        // One flipped bit in the payload: the signature catches it.
        let mut flipped = good.clone();
        flipped[1000] ^= 0x10;
        std::fs::write(&path, &flipped).unwrap();
        assert!(read_cached(&path, &space, 8).is_none());
        assert_eq!(load_or_fit(&path, &space, 8).unwrap(), fitted);
        assert_eq!(std::fs::read(&path).unwrap(), good);
    }
}
