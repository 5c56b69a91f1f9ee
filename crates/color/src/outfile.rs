//! Output files that appear complete or not at all, created safely.
//!
//! Every file the workspace writes goes through [`write_atomic`]: the bytes go to a temporary
//! file created with `O_EXCL` (the `tempfile` crate) in the destination's directory, which is
//! renamed over the destination only once complete. The temporary name is unpredictable (no
//! symlink can be planted for it), and carries the writer's process id, so that a leftover
//! from a process killed with `kill -9` is recognised and removed by the next write of the
//! same file ([`remove_stale_temps`]). An existing destination keeps its permission bits; a new
//! one gets `0666` minus the umask, like any file a shell redirection creates.
//!
//! A command with several outputs (an image and its spectral file, a heat map and a CSV) writes
//! them together or not at all: it [`stage`]s each, complete and on disk under its temporary
//! name, and only then renames them all into place ([`commit_all`]). One after the other, a full
//! disk on the second left the first replaced beside the second's old version.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The directory a file `path` goes in (`.` for a bare file name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Longest file name, in bytes, that Linux file systems accept (NAME_MAX: ext4, XFS, tmpfs).
pub const NAME_MAX: usize = 255;

fn file_name(path: &Path) -> io::Result<String> {
    // `out.exr/` names a folder: Path's file name ignores the separator, and the write failed
    // with "Not a directory" only after the render.
    let raw = path.as_os_str().to_string_lossy();
    if raw.ends_with('/') || (cfg!(windows) && raw.ends_with('\\')) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "ends with a path separator, which names a folder; give a file name",
        ));
    }
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path has no file name"))?;
    if path.file_name().map_or(0, |n| n.len()) > NAME_MAX {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("the file name is {} bytes long; file systems allow at most {NAME_MAX}", name.len()),
        ));
    }
    Ok(name)
}

/// The part of a temporary name that identifies the destination `name`: the name itself, or,
/// where `.<name>.<pid>.<random>.tmp` would pass [`NAME_MAX`] (a legal 244-byte output name
/// used to fail after the render), its first bytes and a hash of the whole.
fn temp_stem(name: &str) -> String {
    // "." + "." + a u32 pid + "." + tempfile's 6 random characters + ".tmp".
    const EXTRA: usize = 2 + 10 + 1 + 6 + 4;
    if name.len() + EXTRA <= NAME_MAX {
        return name.to_string();
    }
    let mut cut = 160;
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!("{}~{:016x}", &name[..cut], crate::signature::fnv1a64(name.as_bytes()))
}

/// Checks, before any long work, that `path` could be written: its directory exists and is a
/// directory we may create files in, and `path` itself is not a directory. Creates and removes
/// a temporary file to find out (the only reliable test of permission).
pub fn check_writable(path: &Path) -> io::Result<()> {
    let dir = parent_dir(path);
    file_name(path)?;
    if !dir.is_dir() {
        // Where the parent is a file, saying it does not exist sent users looking for it.
        let why = if dir.exists() { "is a file, not a directory" } else { "does not exist" };
        return Err(io::Error::new(io::ErrorKind::NotFound, format!("directory {} {why}", dir.display())));
    }
    if path.is_dir() {
        return Err(io::Error::new(io::ErrorKind::IsADirectory, "is a directory"));
    }
    tempfile::Builder::new()
        .prefix(".spectra-check.")
        .tempfile_in(dir)
        .map(drop)
        .map_err(|e| io::Error::new(e.kind(), format!("cannot create files in {}: {e}", dir.display())))
}

/// What a path names on disk, for telling whether two paths are the same file: the device and
/// inode where it exists (so symlinks and hard links compare equal), else the real path of its
/// directory joined with its name (two outputs that do not exist yet).
#[derive(Debug, PartialEq, Eq)]
enum FileId {
    #[cfg(unix)]
    Inode(u64, u64),
    Path(PathBuf),
}

fn file_id(path: &Path) -> FileId {
    #[cfg(unix)]
    if let Ok(m) = std::fs::metadata(path) {
        use std::os::unix::fs::MetadataExt;
        return FileId::Inode(m.dev(), m.ino());
    }
    if let Ok(real) = path.canonicalize() {
        return FileId::Path(real);
    }
    let dir = parent_dir(path);
    let dir = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    FileId::Path(path.file_name().map_or(dir.clone(), |n| dir.join(n)))
}

/// What kind of non-regular thing `path` is, if it exists and is not a regular file (or a
/// symlink to one): outputs are written by renaming a new file over the path, which would
/// replace a device or a FIFO with a regular file.
fn not_regular(path: &Path) -> Option<&'static str> {
    let m = std::fs::metadata(path).ok()?;
    let t = m.file_type();
    if t.is_file() {
        return None;
    }
    if t.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_char_device() {
            return Some("a character device");
        }
        if t.is_block_device() {
            return Some("a block device");
        }
        if t.is_fifo() {
            return Some("a FIFO");
        }
        if t.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a regular file")
}

/// Checks a command's outputs together, before any work, each named by its flag: every output
/// is a regular file or does not exist yet, and none is the same file as an input (the command
/// would destroy what it reads) or as another output (only the last would survive). The
/// message names both flags and the path.
pub fn check_distinct(outputs: &[(&str, &Path)], inputs: &[(&str, &Path)]) -> Result<(), String> {
    let ids: Vec<FileId> = outputs.iter().map(|(_, p)| file_id(p)).collect();
    for (i, (flag, path)) in outputs.iter().enumerate() {
        if let Some(kind) = not_regular(path) {
            return Err(format!("{flag} {}: is {kind}; outputs must be regular files", path.display()));
        }
        for (what, input) in inputs {
            if file_id(input) == ids[i] {
                return Err(format!(
                    "{flag} {}: is the {what} this command reads; an output must not overwrite an input",
                    path.display()
                ));
            }
        }
        if let Some(j) = (0..i).find(|&j| ids[j] == ids[i]) {
            return Err(format!(
                "{flag} {} and {} {}: the same file; each output needs a path of its own",
                path.display(),
                outputs[j].0,
                outputs[j].1.display()
            ));
        }
    }
    Ok(())
}

/// The process's umask: read from `/proc/self/status` (setting and restoring it with
/// `umask(2)` would race with other threads creating files). `0o022` where unknown.
pub fn umask() -> u32 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("Umask:"))
                .and_then(|v| u32::from_str_radix(v.trim(), 8).ok())
        })
        .unwrap_or(0o022)
}

/// Writes `bytes` to `path` atomically; see the module documentation.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes))
}

/// [`write_atomic`] with the content written by `fill` (for encoders that stream).
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut std::fs::File) -> io::Result<()>,
) -> io::Result<()> {
    stage_with(path, fill)?.commit()
}

/// A complete output waiting beside its destination under a temporary name: everything that
/// can run out of space (the bytes, their fsync) is done, and only a rename is left. A command
/// with several outputs stages them all before it puts any in place ([`commit_all`]), so that a
/// full disk on its second file cannot leave the first replaced beside the second's old
/// version. Dropped uncommitted (an error, a panic), it deletes its temporary file and the
/// destination is untouched.
#[derive(Debug)]
pub struct Staged {
    tmp: tempfile::NamedTempFile,
    path: PathBuf,
}

impl Staged {
    /// The destination it will be renamed to.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the temporary file over the destination.
    pub fn commit(self) -> io::Result<()> {
        // On failure `PersistError` hands the temp file back; dropping it deletes it.
        self.tmp.persist(&self.path).map_err(|e| e.error)?;
        Ok(())
    }
}

/// [`stage_with`] for bytes already in memory.
pub fn stage(path: &Path, bytes: &[u8]) -> io::Result<Staged> {
    stage_with(path, |f| f.write_all(bytes))
}

/// Writes the content `fill` makes to a temporary file beside `path` and flushes it to disk,
/// but leaves `path` alone until [`Staged::commit`]: the first half of [`write_atomic_with`],
/// with the same checks, temporary name, permissions and removal of dead writers' leftovers.
pub fn stage_with(
    path: &Path,
    fill: impl FnOnce(&mut std::fs::File) -> io::Result<()>,
) -> io::Result<Staged> {
    let dir = parent_dir(path);
    let name = file_name(path)?;
    if !dir.is_dir() {
        // Where the parent is a file, saying it does not exist sent users looking for it.
        let why = if dir.exists() { "is a file, not a directory" } else { "does not exist" };
        return Err(io::Error::new(io::ErrorKind::NotFound, format!("directory {} {why}", dir.display())));
    }
    remove_stale_temps(dir, &name);
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{}.{}.", temp_stem(&name), std::process::id());
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    let existing = std::fs::metadata(path).ok().filter(|m| m.is_file()).map(|m| m.permissions());
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        // Passed to open(2), so the umask applies, as for any newly created file.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir)?;
    // An existing file keeps its mode: replacing a private (0600) file must not publish it.
    #[cfg(unix)]
    if let Some(p) = existing {
        tmp.as_file().set_permissions(p)?;
    }
    fill(tmp.as_file_mut())?;
    tmp.as_file().sync_all()?;
    Ok(Staged { tmp, path: path.to_path_buf() })
}

/// A rename in [`commit_all`] that failed: which destination, and why. Its message names the
/// file, since the caller cannot tell which of its outputs it was.
#[derive(Debug)]
pub struct CommitError {
    pub path: PathBuf,
    pub error: io::Error,
}

impl std::fmt::Display for CommitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.error)
    }
}

// No `source`: the cause is in the message, and error chains would print it twice.
impl std::error::Error for CommitError {}

impl From<CommitError> for io::Error {
    fn from(e: CommitError) -> io::Error {
        io::Error::new(e.error.kind(), e.to_string())
    }
}

/// Puts a command's staged outputs in place, in order, once every one of them is complete on
/// disk: nothing under an output's name changes unless all of them were written. A rename
/// needs no space, so a full disk or a quota cannot stop it; what is left is a rename failing
/// in the middle (an I/O error, the file system remounted read-only, a destination replaced by
/// a directory meanwhile), which leaves the outputs before it replaced and the rest untouched,
/// their temporary files deleted.
pub fn commit_all(staged: Vec<Staged>) -> Result<(), CommitError> {
    for s in staged {
        let path = s.path.clone();
        s.commit().map_err(|error| CommitError { path, error })?;
    }
    Ok(())
}

/// The process id in a temporary name `.<name>.<pid>.<random>.tmp`, if it is one.
fn temp_owner(entry: &str, name: &str) -> Option<u32> {
    let rest = entry
        .strip_prefix('.')?
        .strip_prefix(temp_stem(name).as_str())?
        .strip_prefix('.')?
        .strip_suffix(".tmp")?;
    let (pid, random) = rest.split_once('.')?;
    (!random.is_empty()).then_some(())?;
    pid.parse().ok()
}

/// Removes temporary files of `name` in `dir` left by writers that no longer run (killed
/// with `kill -9` or by a power cut). A writer that still runs keeps its file. Where process
/// ids cannot be checked (no `/proc`), only leftovers older than a day are removed.
pub fn remove_stale_temps(dir: &Path, name: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    let proc = Path::new("/proc/self").exists();
    for e in entries.flatten() {
        let entry = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = temp_owner(&entry, name) else { continue };
        let stale = if proc {
            pid != std::process::id() && !Path::new("/proc").join(pid.to_string()).exists()
        } else {
            e.metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 86_400)
        };
        // Regular files, and directories of [`temp_dir_next_to`]; `file_type` does not
        // follow symlinks, so a link planted under such a name is never followed.
        match e.file_type() {
            Ok(t) if stale && t.is_file() => {
                let _ = std::fs::remove_file(e.path());
            }
            Ok(t) if stale && t.is_dir() => {
                let _ = std::fs::remove_dir_all(e.path());
            }
            _ => {}
        }
    }
}

/// A new private (0700) directory next to `target`, created atomically with an unpredictable
/// name (`mkdtemp`), for building a directory output that is renamed into place when
/// complete. Unlike `create_dir_all` on a predictable name, it cannot be redirected by a
/// planted symlink. Removed on drop unless [`persist_dir`] moved it.
pub fn temp_dir_next_to(target: &Path) -> io::Result<tempfile::TempDir> {
    let dir = parent_dir(target);
    let name = file_name(target)?;
    remove_stale_temps(dir, &name);
    let mut builder = tempfile::Builder::new();
    let prefix = format!(".{}.{}.", temp_stem(&name), std::process::id());
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o700));
    }
    builder.tempdir_in(dir)
}

/// Renames a directory made by [`temp_dir_next_to`] to `target` and gives it the mode a new
/// directory would have (0777 minus the umask). Fails, leaving `target` alone, if `target`
/// exists; the temporary directory is then removed.
pub fn persist_dir(tmp: tempfile::TempDir, target: &Path) -> io::Result<PathBuf> {
    if std::fs::symlink_metadata(target).is_ok() {
        return Err(io::Error::new(io::ErrorKind::AlreadyExists, "already exists; remove it first"));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(tmp.path(), std::fs::Permissions::from_mode(0o777 & !umask()))?;
    }
    std::fs::rename(tmp.path(), target)?;
    // Renamed away: nothing left for the guard to delete.
    let _ = tmp.keep();
    Ok(target.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_must_be_distinct_regular_files_and_not_inputs() {
        let d = tempfile::tempdir().unwrap();
        let (a, b) = (d.path().join("a.exr"), d.path().join("b.exr"));
        std::fs::write(&a, b"reference").unwrap();
        let p = |n: &str| d.path().join(n);
        // Distinct, new or existing regular files: fine.
        check_distinct(&[("--out", &p("x.exr")), ("--heatmap", &p("y.png"))], &[("reference", &a)]).unwrap();
        check_distinct(&[("--out", &b)], &[]).unwrap();
        // An output that is an input, also through another spelling, a symlink or a hard link.
        let e = check_distinct(&[("--per-pixel-out", &a)], &[("reference", &a)]).unwrap_err();
        assert!(e.contains("--per-pixel-out") && e.contains("reference") && e.contains("a.exr"), "{e}");
        let dotted = d.path().join(".").join("a.exr");
        assert!(check_distinct(&[("--out", &dotted)], &[("test", &a)]).is_err());
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&a, p("link.exr")).unwrap();
            assert!(check_distinct(&[("--out", &p("link.exr"))], &[("test", &a)]).is_err());
            std::fs::hard_link(&a, p("hard.exr")).unwrap();
            assert!(check_distinct(&[("--out", &p("hard.exr"))], &[("test", &a)]).is_err());
            // Not regular: a device, a FIFO.
            let e = check_distinct(&[("--out", Path::new("/dev/null"))], &[]).unwrap_err();
            assert!(e.contains("character device"), "{e}");
            let fifo = p("fifo");
            assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
            assert!(check_distinct(&[("--out", &fifo)], &[]).unwrap_err().contains("FIFO"));
        }
        assert!(check_distinct(&[("--out", d.path())], &[]).unwrap_err().contains("directory"));
        // A trailing separator names a folder, refused before the work (the write failed after it).
        let slash = PathBuf::from(format!("{}/", p("new.exr").display()));
        assert!(check_writable(&slash).unwrap_err().to_string().contains("path separator"));
        // Two outputs on one path, existing or not.
        let e = check_distinct(&[("--out", &p("n.exr")), ("--spectral-out", &p("n.exr"))], &[]).unwrap_err();
        assert!(e.contains("--out") && e.contains("--spectral-out") && e.contains("same file"), "{e}");
        assert!(check_distinct(&[("--heatmap", &b), ("--flip-map", &b)], &[]).is_err());
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[cfg(unix)]
    fn mode(p: &Path) -> u32 {
        use std::os::unix::fs::PermissionsExt;
        std::fs::metadata(p).unwrap().permissions().mode() & 0o777
    }

    /// Replacing a private file keeps it private (the old writer forced 0644).
    #[cfg(unix)]
    #[test]
    fn an_existing_files_mode_is_kept() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("secret.exr");
        std::fs::write(&p, b"old").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o600)).unwrap();
        write_atomic(&p, b"new").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        assert_eq!(mode(&p), 0o600);
        let q = dir.path().join("fresh.png");
        write_atomic(&q, b"x").unwrap();
        assert_eq!(mode(&q), 0o666 & !umask());
    }

    /// A temp file of a writer killed with -9 is removed by the next write of the same file;
    /// a live writer's (this process's) and other files' are kept.
    #[test]
    fn stale_temps_are_removed_on_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        // pid_max is at most 2^22 on Linux: this process cannot exist.
        let dead = dir.path().join(".out.png.4194305.AbC123.tmp");
        let live = dir.path().join(format!(".out.png.{}.XyZ789.tmp", std::process::id()));
        let other = dir.path().join(".other.png.4194305.AbC123.tmp");
        for f in [&dead, &live, &other] {
            std::fs::write(f, b"partial").unwrap();
        }
        write_atomic(&dir.path().join("out.png"), b"png").unwrap();
        let want = [
            ".other.png.4194305.AbC123.tmp".to_string(),
            live.file_name().unwrap().to_string_lossy().into(),
            "out.png".into(),
        ];
        let mut want = want.to_vec();
        want.sort();
        assert_eq!(entries(dir.path()), want);
    }

    /// A legal name near the limit writes (its temporary name is shortened, and still
    /// recognised as its leftover); a name over the limit is refused by the early check.
    #[test]
    fn names_near_the_length_limit() {
        let dir = tempfile::tempdir().unwrap();
        for len in [232, 244, NAME_MAX] {
            let name = format!("{}.exr", "é".repeat((len - 4) / 2) + &"a".repeat((len - 4) % 2));
            assert_eq!(name.len(), len);
            let p = dir.path().join(&name);
            check_writable(&p).unwrap();
            let dead = dir.path().join(format!(".{}.4194305.AbC123.tmp", temp_stem(&name)));
            std::fs::write(&dead, b"partial").unwrap();
            write_atomic(&p, b"x").unwrap();
            assert_eq!(std::fs::read(&p).unwrap(), b"x");
            assert!(!dead.exists(), "{len}: the dead writer's leftover is removed");
            std::fs::remove_file(&p).unwrap();
        }
        let long = dir.path().join(format!("{}.exr", "a".repeat(NAME_MAX - 3)));
        let e = check_writable(&long).unwrap_err().to_string();
        assert!(e.contains("256 bytes") && e.contains("255"), "{e}");
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn failed_writes_leave_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.bin");
        let e = write_atomic_with(&p, |_| Err(io::Error::other("encoder failed"))).unwrap_err();
        assert!(e.to_string().contains("encoder failed"));
        assert!(entries(dir.path()).is_empty());
        let e = check_writable(&dir.path().join("missing/x.bin")).unwrap_err();
        assert!(e.to_string().contains("does not exist"), "{e}");
        assert!(check_writable(&p).is_ok());
        assert!(entries(dir.path()).is_empty());
    }

    /// Outputs staged but not committed (the command failed on a later one) leave every
    /// destination as it was and no temporary file.
    #[test]
    fn staged_outputs_dropped_leave_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.exr"), dir.path().join("b.exr"));
        std::fs::write(&a, b"old a").unwrap();
        let staged = vec![stage(&a, b"new a").unwrap(), stage(&b, b"new b").unwrap()];
        assert_eq!(staged[1].path(), b);
        assert_eq!(entries(dir.path()).len(), 3, "two temporary files beside a.exr");
        assert_eq!(std::fs::read(&a).unwrap(), b"old a", "nothing in place before the commit");
        drop(staged);
        assert_eq!(entries(dir.path()), vec!["a.exr"]);
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
        // The second's content fails half way (a full disk): the first, staged, goes with it.
        let first = stage(&a, b"new a").unwrap();
        let e = stage_with(&b, |f| {
            f.write_all(b"half")?;
            Err(io::Error::from_raw_os_error(libc::ENOSPC))
        })
        .unwrap_err();
        assert_eq!(e.raw_os_error(), Some(libc::ENOSPC));
        drop(first);
        assert_eq!(entries(dir.path()), vec!["a.exr"]);
        assert_eq!(std::fs::read(&a).unwrap(), b"old a");
    }

    /// Committed together, every output is replaced and keeps its mode; a new one gets the
    /// umask's.
    #[cfg(unix)]
    #[test]
    fn commit_all_replaces_every_output() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = |n: &str| dir.path().join(n);
        for (n, mode) in [("a.exr", 0o600), ("b.png", 0o640)] {
            std::fs::write(p(n), b"old").unwrap();
            std::fs::set_permissions(p(n), std::fs::Permissions::from_mode(mode)).unwrap();
        }
        let staged: Vec<Staged> = [("a.exr", &b"A"[..]), ("b.png", b"B"), ("c.csv", b"C")]
            .iter()
            .map(|(n, bytes)| stage(&p(n), bytes).unwrap())
            .collect();
        commit_all(staged).unwrap();
        assert_eq!(entries(dir.path()), vec!["a.exr", "b.png", "c.csv"]);
        for (n, bytes, m) in
            [("a.exr", b"A", 0o600), ("b.png", b"B", 0o640), ("c.csv", b"C", 0o666 & !umask())]
        {
            assert_eq!(std::fs::read(p(n)).unwrap(), bytes, "{n}");
            assert_eq!(mode(&p(n)), m, "{n}");
        }
    }

    /// The window left: a rename that fails in the middle (here the destination became a
    /// non-empty directory after it was staged) is named, the outputs before it are in place
    /// and those after it untouched, and no temporary file stays.
    #[test]
    fn a_rename_failing_in_the_middle_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = |n: &str| dir.path().join(n);
        for n in ["a.exr", "c.csv"] {
            std::fs::write(p(n), b"old").unwrap();
        }
        let staged = vec![
            stage(&p("a.exr"), b"A").unwrap(),
            stage(&p("b.png"), b"B").unwrap(),
            stage(&p("c.csv"), b"C").unwrap(),
        ];
        std::fs::create_dir(p("b.png")).unwrap();
        std::fs::write(p("b.png").join("keep"), b"x").unwrap();
        let e = commit_all(staged).unwrap_err();
        assert_eq!(e.path, p("b.png"));
        assert!(e.to_string().starts_with(&format!("{}: ", p("b.png").display())), "{e}");
        assert_eq!(io::Error::from(e).to_string().matches("b.png").count(), 1);
        assert_eq!(entries(dir.path()), vec!["a.exr", "b.png", "c.csv"]);
        assert_eq!(std::fs::read(p("a.exr")).unwrap(), b"A");
        assert_eq!(std::fs::read(p("c.csv")).unwrap(), b"old");
    }

    /// A symlink planted where the old exporter's predictable temp directory went is not
    /// followed: the directory is built under an unpredictable name and renamed.
    #[cfg(unix)]
    #[test]
    fn directory_outputs_ignore_planted_symlinks() {
        let dir = tempfile::tempdir().unwrap();
        let elsewhere = tempfile::tempdir().unwrap();
        let target = dir.path().join("export");
        let planted = dir.path().join(format!(".export.tmp-{}", std::process::id()));
        std::os::unix::fs::symlink(elsewhere.path(), &planted).unwrap();
        // A dead writer's half-built export is removed; a link under such a name is not followed.
        let stale = dir.path().join(".export.4194305.AbC123.tmp");
        std::fs::create_dir(&stale).unwrap();
        std::fs::write(stale.join("texture_0.ppm"), b"P6").unwrap();
        std::fs::write(elsewhere.path().join("keep"), b"x").unwrap();
        std::os::unix::fs::symlink(elsewhere.path(), dir.path().join(".export.4194306.XyZ789.tmp")).unwrap();
        let tmp = temp_dir_next_to(&target).unwrap();
        assert_eq!(mode(tmp.path()), 0o700, "private while being built");
        std::fs::write(tmp.path().join("scene.xml"), b"<scene/>").unwrap();
        persist_dir(tmp, &target).unwrap();
        assert!(target.join("scene.xml").is_file());
        assert!(!stale.exists());
        assert_eq!(entries(elsewhere.path()), vec!["keep"]);
        assert_eq!(mode(&target), 0o777 & !umask());
        let tmp = temp_dir_next_to(&target).unwrap();
        let kept = tmp.path().to_path_buf();
        assert!(persist_dir(tmp, &target).is_err());
        assert!(!kept.exists());
    }
}
