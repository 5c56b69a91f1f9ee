//! Atomic file output: bytes go to a temporary file in the destination's directory, which is
//! renamed over the destination only once complete. A failed or interrupted write therefore
//! never leaves a truncated file under the requested name.

use std::path::Path;

use crate::error::{CompareError, Result};

/// Writes `bytes` to `path` atomically (same-directory `O_EXCL` temp file + rename; the mode of
/// an existing file kept; leftovers of killed writers removed): [`color::outfile::write_atomic`].
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    color::outfile::write_atomic(path, bytes).map_err(|e| CompareError::io(path, e))
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
    fn missing_directory_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("no/such/dir/x.exr");
        let e = write_atomic(&p, b"data").unwrap_err().to_string();
        assert!(e.contains("x.exr") && e.contains("does not exist"), "{e}");
    }
}
