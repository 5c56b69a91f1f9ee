//! Atomic file output: bytes go to a temporary file in the destination's directory, which is
//! renamed over the destination only once complete. A failed or interrupted write therefore
//! never leaves a truncated file under the requested name. A command with several outputs
//! [`stage`]s each and puts them in place together with [`color::outfile::commit_all`], so that
//! a failure on one leaves every other as it was too.

use std::path::Path;

pub use color::outfile::{CommitError, Staged, commit_all};

use crate::error::{CompareError, Result};

/// Writes `bytes` to `path` atomically (same-directory `O_EXCL` temp file + rename; the mode of
/// an existing file kept; leftovers of killed writers removed): [`color::outfile::write_atomic`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    color::outfile::write_atomic(path, bytes).map_err(|e| CompareError::io(path, e))
}

/// Writes `bytes` beside `path` under a temporary name, complete and flushed, for a later
/// [`commit_all`] with the command's other outputs ([`color::outfile::stage`]); the error names
/// the file, as [`write_atomic`]'s does.
pub fn stage(path: &Path, bytes: &[u8]) -> Result<Staged> {
    color::outfile::stage(path, bytes).map_err(|e| CompareError::io(path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn writes_and_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.bin");
        write_atomic(&p, b"first").unwrap();
        write_atomic(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert_eq!(entries(dir.path()), vec!["a.bin"]);
    }

    #[test]
    fn failed_rename_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        // A non-empty directory cannot be replaced by a file: the rename fails after the
        // bytes were written to the temp file.
        let target = dir.path().join("out.png");
        std::fs::create_dir(&target).unwrap();
        std::fs::write(target.join("keep"), b"x").unwrap();
        let e = write_atomic(&target, b"data").unwrap_err().to_string();
        assert!(e.contains("out.png"), "{e}");
        assert_eq!(entries(dir.path()), vec!["out.png"]);
        assert!(target.is_dir());
    }

    #[test]
    fn staged_outputs_appear_together() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.csv"));
        write_atomic(&a, b"old").unwrap();
        let first = stage(&a, b"new").unwrap();
        let e = stage(&dir.path().join("no/b.csv"), b"x").unwrap_err().to_string();
        assert!(e.contains("b.csv") && e.contains("does not exist"), "{e}");
        drop(first);
        assert_eq!(entries(dir.path()), vec!["a.png"]);
        assert_eq!(std::fs::read(&a).unwrap(), b"old");
        commit_all(vec![stage(&a, b"new").unwrap(), stage(&b, b"rows").unwrap()]).unwrap();
        assert_eq!(entries(dir.path()), vec!["a.png", "b.csv"]);
        assert_eq!(std::fs::read(&a).unwrap(), b"new");
    }

    #[test]
    fn missing_directory_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("no/such/dir/x.exr");
        let e = write_atomic(&p, b"data").unwrap_err().to_string();
        assert!(e.contains("x.exr") && e.contains("does not exist"), "{e}");
    }
}
