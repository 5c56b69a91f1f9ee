//! Reading files a user or a scene names, safely: only regular files, and never more than a cap.
//!
//! Every input of the workspace (glTF/GLB scenes and their buffers and images, CSV spectra,
//! `.coeff` tables, `--medium` JSON, environment maps, the images `diff` compares) is read through
//! [`read_regular`]. It lives in this bottom crate so that `scene`, `compare` and the binary share
//! one implementation. Why each step:
//!
//! * `/dev/zero` or `/dev/urandom` would be read until memory runs out, a FIFO would block
//!   forever, a directory gives a confusing error: anything but a regular file is refused.
//! * Opening a FIFO blocks until a writer appears, so the path is `stat`ed first and then opened
//!   with `O_NONBLOCK` (which also covers a file swapped for a FIFO between the two calls); the
//!   opened handle is checked again, since that is the file actually read.
//! * A regular file can still be huge (or growing): reading stops one byte past the cap, so the
//!   memory used is bounded by the cap whatever the file claims.

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// Bytes in one mebibyte, for writing caps.
pub const MIB: u64 = 1 << 20;

fn not_regular(meta: &std::fs::Metadata) -> io::Error {
    let ft = meta.file_type();
    let what = if ft.is_dir() {
        "a directory"
    } else {
        #[cfg(unix)]
        {
            use std::os::unix::fs::FileTypeExt;
            if ft.is_fifo() {
                "a FIFO (named pipe)"
            } else if ft.is_char_device() || ft.is_block_device() {
                "a device"
            } else if ft.is_socket() {
                "a socket"
            } else {
                "not a regular file"
            }
        }
        #[cfg(not(unix))]
        {
            "not a regular file"
        }
    };
    io::Error::new(io::ErrorKind::InvalidInput, format!("{what}; only regular files are read"))
}

/// Opens `path` for reading only if it is a regular file (after following symlinks), without
/// ever blocking on a FIFO.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    let mut opts = std::fs::OpenOptions::new();
    opts.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        opts.custom_flags(libc::O_NONBLOCK);
    }
    let file = opts.open(path)?;
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    Ok(file)
}

/// What tells a file's contents apart on disk without reading them: its device and inode, its
/// length and its modification time. A file replaced (an exporter's rename over it) or rewritten
/// gets another stamp. The scene loader stamps every file as it takes it, so that a record's
/// content hash, read afterwards, can be checked to be of the bytes that were loaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FileStamp {
    dev: u64,
    ino: u64,
    len: u64,
    modified: Option<std::time::SystemTime>,
}

/// The [`FileStamp`] of the file at `path` now, `None` if it cannot be read.
pub fn stamp(path: &Path) -> Option<FileStamp> {
    let m = std::fs::metadata(path).ok()?;
    #[cfg(unix)]
    let (dev, ino) = {
        use std::os::unix::fs::MetadataExt;
        (m.dev(), m.ino())
    };
    #[cfg(not(unix))]
    let (dev, ino) = (0, 0);
    Some(FileStamp { dev, ino, len: m.len(), modified: m.modified().ok() })
}

/// The whole content of the regular file at `path`, refused (without reading further) once it
/// exceeds `max_bytes`. Errors are `io::Error`s whose message says what was wrong, for the
/// caller to prefix with the file name.
pub fn read_regular(path: &Path, max_bytes: u64) -> io::Result<Vec<u8>> {
    let file = open_regular(path)?;
    let len = file.metadata()?.len();
    if len > max_bytes {
        return Err(too_big(len, max_bytes));
    }
    // The length may change under us; `take` bounds what is read whatever happens.
    let mut out = Vec::with_capacity(len as usize);
    file.take(max_bytes.saturating_add(1)).read_to_end(&mut out)?;
    if out.len() as u64 > max_bytes {
        return Err(too_big(out.len() as u64, max_bytes));
    }
    Ok(out)
}

/// [`read_regular`] as UTF-8 text.
pub fn read_regular_string(path: &Path, max_bytes: u64) -> io::Result<String> {
    String::from_utf8(read_regular(path, max_bytes)?)
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidData, "not valid UTF-8 text"))
}

/// A JSON document a user wrote (an observer, a medium), as serde_json's value, refusing what
/// serde_json would take silently: an object that names one key twice (the value map keeps the
/// last, so a pasted duplicate row replaced the first without a word). A leading byte-order mark
/// (Windows Notepad writes one) is skipped. The error is serde_json's, with its line and column.
pub fn json_value(text: &str) -> Result<serde_json::Value, serde_json::Error> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut de = serde_json::Deserializer::from_str(text);
    serde::de::DeserializeSeed::deserialize(NoDuplicateKeys, &mut de)?;
    de.end()?;
    serde_json::from_str(text)
}

/// Walks a JSON document and fails on the first object with a repeated key.
struct NoDuplicateKeys;

impl<'de> serde::de::DeserializeSeed<'de> for NoDuplicateKeys {
    type Value = ();
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for NoDuplicateKeys {
    type Value = ();
    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        while seq.next_element_seed(NoDuplicateKeys)?.is_some() {}
        Ok(())
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            if !seen.insert(key.clone()) {
                return Err(serde::de::Error::custom(format!(
                    "the key \"{key}\" is given twice in one object"
                )));
            }
            map.next_value_seed(NoDuplicateKeys)?;
        }
        Ok(())
    }
}

fn too_big(len: u64, max: u64) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("the file is larger than the {max} bytes accepted for it (at least {len} bytes)"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_refuses_repeated_keys_at_any_depth_and_skips_a_bom() {
        let v = json_value(
            "\u{feff}{\"a\": {\"400\": [1, 2], \"410\": [3, 4]}, \"b\": [{\"x\": 1}, {\"x\": 2}]}",
        )
        .unwrap();
        assert_eq!(v["a"]["410"][1], 4);
        for (doc, key) in [
            ("{\"a\": 1, \"a\": 2}", "\"a\""),
            ("{\"d\": {\"m\": {\"400\": [9], \"400\": [1]}}}", "\"400\""),
            ("[{\"x\": 1, \"y\": 2, \"x\": 3}]", "\"x\""),
        ] {
            let e = json_value(doc).unwrap_err().to_string();
            assert!(e.contains(key) && e.contains("twice") && e.contains("line 1"), "{doc}: {e}");
        }
        assert!(json_value("{\"a\": 1} x").is_err(), "trailing characters");
        assert!(json_value("{\"a\": ").is_err());
    }
    use std::time::{Duration, Instant};

    #[test]
    fn reads_a_regular_file_within_the_cap() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        std::fs::write(&p, b"hello").unwrap();
        assert_eq!(read_regular(&p, 5).unwrap(), b"hello");
        let e = read_regular(&p, 4).unwrap_err().to_string();
        assert!(e.contains("larger than the 4 bytes"), "{e}");
    }

    #[test]
    fn refuses_directories_and_devices() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_regular(dir.path(), 1 << 30).unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
        #[cfg(unix)]
        for dev in ["/dev/zero", "/dev/urandom"] {
            let e = read_regular(Path::new(dev), 1 << 30).unwrap_err().to_string();
            assert!(e.contains("a device"), "{dev}: {e}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("pipe");
        let c = std::ffi::CString::new(p.as_os_str().as_encoded_bytes()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let t = Instant::now();
        let e = read_regular(&p, 1 << 30).unwrap_err().to_string();
        assert!(e.contains("FIFO"), "{e}");
        assert!(t.elapsed() < Duration::from_secs(2));
        // Opening with O_NONBLOCK is what saves us if the stat is raced: even a direct open
        // returns at once (and the handle check then refuses it).
        let t = Instant::now();
        let mut opts = std::fs::OpenOptions::new();
        std::os::unix::fs::OpenOptionsExt::custom_flags(opts.read(true), libc::O_NONBLOCK);
        let f = opts.open(&p).unwrap();
        assert!(!f.metadata().unwrap().is_file());
        assert!(t.elapsed() < Duration::from_secs(2));
    }
}
