//! Checkpoints of `spectra truth` (issue 31): the running per-pixel sums of a render
//! ([`truth::Accumulator`]), written atomically beside `--out` as `<out>.checkpoint` every
//! `--checkpoint-every` seconds once a render has run that long, and read back by `--resume`,
//! which continues to a result bit-identical to the uninterrupted render. The file carries the
//! render's record (the `spectra.*` attributes of its outputs) and is signed; a checkpoint of
//! another render, or a damaged one, is refused naming the file and what differs.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use truth::{Accumulator, Settings};

const MAGIC: &[u8] = b"spectra-truth-checkpoint 1\n";

/// Where the checkpoint of a render to `out` goes.
pub fn path_for(out: &Path) -> PathBuf {
    let mut name = out.file_name().unwrap_or_default().to_os_string();
    name.push(".checkpoint");
    out.with_file_name(name)
}

/// Exclusive use of one `--out`'s checkpoint by one `truth` process: two renders to the same
/// output shared its checkpoint, each overwrote the other's, and the first to finish deleted
/// it — a later kill of the other lost every sample. An advisory `flock(2)` on the hidden file
/// `.<out's name>.lock` beside it (the kernel lets it go when the process ends, however it
/// ends); the file is removed when the guard is dropped.
pub struct OutLock {
    file: std::fs::File,
    path: PathBuf,
}

impl OutLock {
    /// Takes the lock for `out`, or says that another render holds it.
    pub fn take(out: &Path) -> anyhow::Result<OutLock> {
        use std::os::unix::fs::MetadataExt;
        use std::os::unix::io::AsRawFd;
        let mut name = std::ffi::OsString::from(".");
        name.push(out.file_name().unwrap_or_default());
        name.push(".lock");
        let path = out.with_file_name(name);
        // A lock file removed by its holder between our open and our lock is not the path's
        // file any more: take the new one instead.
        for _ in 0..100 {
            let file =
                std::fs::OpenOptions::new().create(true).truncate(false).write(true).open(&path).map_err(
                    |e| anyhow::anyhow!("{}: cannot create the render's lock file: {e}", path.display()),
                )?;
            // SAFETY: flock(2) on a descriptor this function owns.
            if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
                anyhow::bail!(
                    "--out {}: another `spectra truth` is rendering to it (it holds {}); wait for it to end, or \
                     choose another --out",
                    out.display(),
                    path.display()
                );
            }
            let same = match (file.metadata(), std::fs::metadata(&path)) {
                (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
                _ => false,
            };
            if same {
                return Ok(OutLock { file, path });
            }
        }
        anyhow::bail!("{}: the render's lock file keeps changing", path.display())
    }
}

impl Drop for OutLock {
    fn drop(&mut self) {
        // Removed while still held, so no other process takes the lock of a file about to go.
        let _ = std::fs::remove_file(&self.path);
        let _ = &self.file;
    }
}

#[derive(Serialize, Deserialize)]
struct Header {
    record: Vec<(String, String)>,
    window: [u32; 4],
    spp: u32,
    done: u32,
    dropped: u64,
    bands: usize,
}

fn window(st: &Settings) -> [u32; 4] {
    let w = st.window();
    [w.x, w.y, w.width, w.height]
}

/// Writes `acc` (of the render `st` with `record`) to `path` atomically.
pub fn write(path: &Path, record: &[(String, String)], st: &Settings, acc: &Accumulator) -> Result<()> {
    let bands = if acc.xyz.is_empty() { 0 } else { acc.bins.len() / acc.xyz.len() };
    let header = Header {
        record: record.to_vec(),
        window: window(st),
        spp: st.spp,
        done: acc.done,
        dropped: acc.dropped,
        bands,
    };
    let json = serde_json::to_vec(&header)?;
    let mut out = Vec::with_capacity(MAGIC.len() + 8 + json.len() + 8 * (acc.xyz.len() * 3 + acc.bins.len()));
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(json.len() as u64).to_le_bytes());
    out.extend_from_slice(&json);
    for v in acc.xyz.iter().flatten().chain(&acc.bins) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    color::outfile::write_atomic(path, &color::signature::sign(out))
        .with_context(|| format!("writing the checkpoint {}", path.display()))
}

/// The accumulator in the checkpoint at `path`, if it is one of this render (`record`, `st`).
pub fn read(path: &Path, record: &[(String, String)], st: &Settings) -> Result<Accumulator> {
    let bad = |why: String| anyhow::anyhow!("--resume: the checkpoint {}: {why}", path.display());
    let check = |there: &[(String, String)], spp: u32, done: u32| -> Result<()> {
        if let Some((k, there, here)) = super::truth::record_difference(there, record) {
            bail!(
                "--resume: the checkpoint {} is of a different render: {k} is {there} there and {here} here; remove it to start over",
                path.display()
            );
        }
        if spp != st.spp || done > st.spp {
            bail!(
                "--resume: the checkpoint {} is of a different render: {spp} spp there, {} here",
                path.display(),
                st.spp
            );
        }
        Ok(())
    };
    read_sums(path, st, &bad, "remove it to start over", &check)
}

/// Spectral bands per pixel of a render's accumulator.
fn bands_of(acc: &Accumulator) -> usize {
    if acc.xyz.is_empty() { 0 } else { acc.bins.len() / acc.xyz.len() }
}

/// What separates a stored header's pixels or bands from this render's.
fn differs(h: &Header, st: &Settings, fresh: &Accumulator) -> String {
    if h.window != window(st) {
        return format!(
            "it holds the pixels {:?} (x, y, width, height), this render {:?}",
            h.window,
            window(st)
        );
    }
    let here = bands_of(fresh);
    format!(
        "it holds {} spectral bands, this render {here}: give the interrupted run's --spectral-out and \
         --spectral-bin (or none, if it had none)",
        h.bands
    )
}

/// The header of a file too large to read whole, unchecked (its signature covers the whole
/// file): only to say why it does not fit, never to resume from.
fn read_header(path: &Path) -> Option<Header> {
    use std::io::Read;
    let mut head = Vec::new();
    std::fs::File::open(path).ok()?.take((MAGIC.len() + 8 + (1 << 20)) as u64).read_to_end(&mut head).ok()?;
    let body = head.strip_prefix(MAGIC)?;
    let len = u64::from_le_bytes(body.get(..8)?.try_into().ok()?) as usize;
    serde_json::from_slice(body.get(8..8usize.checked_add(len)?)?).ok()
}

/// Accepts a stored record, the samples of the render it was written for and the samples done.
pub type CheckStored<'a> = dyn Fn(&[(String, String)], u32, u32) -> Result<()> + 'a;

/// The sums in the file at `path` (a checkpoint, or a truth-cache entry) for the render `st`:
/// `check` accepts the record, the samples of the render it was written for and the samples
/// done (or says why not), before the pixel window and bands are checked against `st`'s;
/// `bad` says what is wrong with the file, `fix` what to do about a damaged one.
pub fn read_sums(
    path: &Path,
    st: &Settings,
    bad: &dyn Fn(String) -> anyhow::Error,
    fix: &str,
    check: &CheckStored<'_>,
) -> Result<Accumulator> {
    let fresh = Accumulator::new(st)?;
    let floats = fresh.xyz.len() * 3 + fresh.bins.len();
    let cap = (MAGIC.len() + 8 + (1 << 20) + 8 * floats + color::signature::LEN) as u64;
    let bytes = match color::input::read_regular(path, cap) {
        Ok(b) => b,
        Err(e) => {
            // Larger than this render's: from its header, say which setting made it so (the
            // usual one: spectral bands that this render was not asked for).
            if let Some(h) = read_header(path) {
                check(&h.record, h.spp, h.done)?;
                if h.window != window(st) || h.bands != bands_of(&fresh) {
                    return Err(bad(differs(&h, st, &fresh)));
                }
            }
            return Err(bad(format!("cannot read it: {e}")));
        }
    };
    let damaged = || bad(format!("truncated or damaged (its signature does not match); {fix}"));
    let signed = color::signature::payload(&bytes, bytes.len().saturating_sub(color::signature::LEN))
        .ok_or_else(damaged)?;
    let body = signed.strip_prefix(MAGIC).ok_or_else(|| bad("not a spectra truth checkpoint".into()))?;
    let len = body.get(..8).map(|b| u64::from_le_bytes(b.try_into().unwrap()) as usize).unwrap_or(usize::MAX);
    let json = body.get(8..8usize.saturating_add(len)).filter(|_| len <= 1 << 20).ok_or_else(damaged)?;
    let header: Header = serde_json::from_slice(json).map_err(|e| bad(format!("unreadable header: {e}")))?;
    check(&header.record, header.spp, header.done)?;
    if header.window != window(st) || header.bands != bands_of(&fresh) {
        return Err(bad(differs(&header, st, &fresh)));
    }
    let sums = &body[8 + len..];
    if sums.len() != 8 * floats {
        return Err(damaged());
    }
    let mut vals = sums.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().unwrap()));
    let mut acc = fresh;
    for p in &mut acc.xyz {
        for c in p.iter_mut() {
            *c = vals.next().unwrap_or(0.0);
        }
    }
    for b in &mut acc.bins {
        *b = vals.next().unwrap_or(0.0);
    }
    acc.done = header.done;
    acc.dropped = header.dropped;
    Ok(acc)
}
