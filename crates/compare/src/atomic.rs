//! Atomic file output: bytes go to a temporary file in the destination's directory, which is
//! renamed over the destination only once complete. A failed or interrupted write therefore
//! never leaves a truncated file under the requested name.

use std::io::Write;
use std::path::Path;

use crate::error::{CompareError, Result};

/// Writes `bytes` to `path` atomically (same-directory temp file + rename).
///
/// The temp file is named `.<file name>.<random>.tmp` so a leftover from a killed process is
/// recognisable; on any error it is removed before returning.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| CompareError::io(path, std::io::Error::other("path has no file name")))?
        .to_string_lossy()
        .into_owned();
    if !dir.is_dir() {
        let msg = format!("directory {} does not exist", dir.display());
        return Err(CompareError::io(path, std::io::Error::new(std::io::ErrorKind::NotFound, msg)));
    }
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(|e| CompareError::io(path, e))?;
    // Temp files are created 0600; an image or report is for everyone who can read the folder.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let _ = tmp.as_file().set_permissions(std::fs::Permissions::from_mode(0o644));
    }
    tmp.write_all(bytes).map_err(|e| CompareError::io(path, e))?;
    tmp.as_file().sync_all().map_err(|e| CompareError::io(path, e))?;
    // On failure `PersistError` hands the temp file back; dropping it deletes it.
    tmp.persist(path).map_err(|e| CompareError::io(path, e.error))?;
    Ok(())
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
