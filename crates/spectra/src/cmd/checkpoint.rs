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
    let bytes = color::input::read_regular(path, cap).map_err(|e| bad(format!("cannot read it: {e}")))?;
    let damaged = || bad(format!("truncated or damaged (its signature does not match); {fix}"));
    let signed = color::signature::payload(&bytes, bytes.len().saturating_sub(color::signature::LEN))
        .ok_or_else(damaged)?;
    let body = signed.strip_prefix(MAGIC).ok_or_else(|| bad("not a spectra truth checkpoint".into()))?;
    let len = body.get(..8).map(|b| u64::from_le_bytes(b.try_into().unwrap()) as usize).unwrap_or(usize::MAX);
    let json = body.get(8..8usize.saturating_add(len)).filter(|_| len <= 1 << 20).ok_or_else(damaged)?;
    let header: Header = serde_json::from_slice(json).map_err(|e| bad(format!("unreadable header: {e}")))?;
    check(&header.record, header.spp, header.done)?;
    if header.window != window(st) {
        return Err(bad(format!(
            "it holds the pixels {:?} (x, y, width, height), this render {:?}",
            header.window,
            window(st)
        )));
    }
    let expect_bands = if fresh.xyz.is_empty() { 0 } else { fresh.bins.len() / fresh.xyz.len() };
    if header.bands != expect_bands {
        return Err(bad(format!("it holds {} bands, this render {expect_bands}", header.bands)));
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
