//! The truth cache (`--truth-cache DIR` of `spectra truth` and `spectra eval`; issue 31): the
//! per-pixel sums of finished ground-truth renders, kept by what they are a render of (every
//! setting that changes the sums, `super::truth::sum_fields`, with the first sample and the
//! pixel window) and by their sample count. A render finds the entry with the most samples
//! that it needs, renders only the samples after them, and stores what it ends with as a new
//! entry: asked again for the same, it renders nothing; asked for more, only the difference.
//! Because the sums of a render in passes are bit-identical to one pass (`truth::render_pass`),
//! an extended truth is the one a render of all its samples at once gives, bit for bit.
//!
//! An entry is `DIR/<key>-<spp>.truth`, in the checkpoint format (`super::checkpoint`: signed,
//! the record inside); written atomically, so processes can share a directory. An entry that
//! does not read back (damaged, another format) is reported, removed and rendered again.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use truth::{Accumulator, Settings};

/// A directory of stored truths.
pub struct TruthCache {
    dir: PathBuf,
    /// This run made the folder: it goes again if nothing was stored in it (an interrupted
    /// first run left an empty folder behind).
    made: bool,
}

impl Drop for TruthCache {
    fn drop(&mut self) {
        if self.made {
            // Only an empty folder can be removed, so nothing stored is lost.
            let _ = std::fs::remove_dir(&self.dir);
        }
    }
}

/// Where a render's sums start from.
pub struct Start {
    pub acc: Accumulator,
    /// The entry they came from, if any (`acc.done` of its samples).
    pub from: Option<PathBuf>,
    /// What the cache had to say that is not an error (an entry it could not use and removed).
    pub notes: Vec<String>,
}

const EXT: &str = "truth";

impl TruthCache {
    /// The cache in `dir`, created if missing.
    pub fn open(dir: &Path) -> Result<TruthCache> {
        if std::fs::metadata(dir).is_ok_and(|m| !m.is_dir()) {
            bail!("--truth-cache {}: not a directory", dir.display());
        }
        let made = std::fs::symlink_metadata(dir).is_err();
        std::fs::create_dir_all(dir)
            .with_context(|| format!("--truth-cache {}: cannot create it", dir.display()))?;
        Ok(TruthCache { dir: dir.to_path_buf(), made })
    }

    /// The entries' record: the sums' fields, the first sample and the pixel window.
    fn record(fields: &[(String, String)], st: &Settings) -> Vec<(String, String)> {
        let w = st.window();
        let mut r = fields.to_vec();
        r.push(("first_sample".into(), st.sample_offset.to_string()));
        r.push(("window".into(), format!("{},{},{},{}", w.x, w.y, w.width, w.height)));
        r
    }

    fn key(fields: &[(String, String)], st: &Settings) -> String {
        super::truth::fields_hash(&Self::record(fields, st))
    }

    fn entry(&self, key: &str, spp: u32) -> PathBuf {
        self.dir.join(format!("{key}-{spp}.{EXT}"))
    }

    /// The sample counts stored for `key`, most first.
    fn stored(&self, key: &str) -> Result<Vec<u32>> {
        let rd = std::fs::read_dir(&self.dir)
            .with_context(|| format!("--truth-cache {}: cannot list it", self.dir.display()))?;
        let prefix = format!("{key}-");
        let suffix = format!(".{EXT}");
        let mut v: Vec<u32> = rd
            .flatten()
            .filter_map(|e| {
                let name = e.file_name().into_string().ok()?;
                name.strip_prefix(&prefix)?.strip_suffix(&suffix)?.parse().ok()
            })
            .collect();
        v.sort_unstable_by(|a, b| b.cmp(a));
        Ok(v)
    }

    /// The sums a render of `st` (whose sums are described by `fields`) starts from: the stored
    /// entry with the most samples up to `st.spp`, else none.
    pub fn start(&self, fields: &[(String, String)], st: &Settings) -> Result<Start> {
        let key = Self::key(fields, st);
        let record = Self::record(fields, st);
        let mut notes = Vec::new();
        for spp in self.stored(&key)?.into_iter().filter(|&n| n <= st.spp) {
            let path = self.entry(&key, spp);
            let bad = |why: String| anyhow::anyhow!("the truth-cache entry {}: {why}", path.display());
            let check = |there: &[(String, String)], n: u32, done: u32| -> Result<()> {
                if let Some((k, there, here)) = super::truth::record_difference(there, &record) {
                    return Err(bad(format!(
                        "it is of a different render ({k} is {there} there and {here} here)"
                    )));
                }
                if n != spp || done != spp {
                    return Err(bad(format!("it holds {done} of {n} samples, its name says {spp}")));
                }
                Ok(())
            };
            match super::checkpoint::read_sums(&path, st, &bad, "it is rendered again", &check) {
                Ok(acc) => return Ok(Start { acc, from: Some(path), notes }),
                Err(e) => {
                    let removed = match std::fs::remove_file(&path) {
                        Ok(()) => "removed it".to_string(),
                        Err(re) => format!("could not remove it: {re}"),
                    };
                    notes.push(format!("warning: {e:#}; {removed}"));
                }
            }
        }
        Ok(Start { acc: Accumulator::new(st)?, from: None, notes })
    }

    /// Stores the finished sums `acc` (all of `st.spp`) of the render described by `fields`;
    /// returns the entry's path.
    pub fn store(&self, fields: &[(String, String)], st: &Settings, acc: &Accumulator) -> Result<PathBuf> {
        if acc.done != st.spp {
            bail!("internal: only a finished render is stored ({} of {} samples)", acc.done, st.spp);
        }
        let path = self.entry(&Self::key(fields, st), st.spp);
        let record = Self::record(fields, st);
        super::checkpoint::write(&path, &record, st, acc)
            .with_context(|| format!("--truth-cache {}", self.dir.display()))?;
        Ok(path)
    }
}
