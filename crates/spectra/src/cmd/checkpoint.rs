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
    let fresh = Accumulator::new(st)?;
    let floats = fresh.xyz.len() * 3 + fresh.bins.len();
    let cap = (MAGIC.len() + 8 + (1 << 20) + 8 * floats + color::signature::LEN) as u64;
    let bad = |why: String| anyhow::anyhow!("--resume: the checkpoint {}: {why}", path.display());
    let bytes = color::input::read_regular(path, cap).map_err(|e| bad(format!("cannot read it: {e}")))?;
    let body = bytes.strip_prefix(MAGIC).ok_or_else(|| bad("not a spectra truth checkpoint".into()))?;
    let len = body.get(..8).map(|b| u64::from_le_bytes(b.try_into().unwrap()) as usize).unwrap_or(usize::MAX);
    let payload_len = MAGIC.len() + 8 + len.min(1 << 20) + 8 * floats;
    if len > 1 << 20 || color::signature::payload(&bytes, payload_len).is_none() {
        return Err(bad(
            "truncated or damaged (its signature does not match); remove it to start over".into()
        ));
    }
    let header: Header =
        serde_json::from_slice(&body[8..8 + len]).map_err(|e| bad(format!("unreadable header: {e}")))?;
    if let Some((k, there, here)) = super::truth::record_difference(&header.record, record) {
        bail!(
            "--resume: the checkpoint {} is of a different render: {k} is {there} there and {here} here; remove it to start over",
            path.display()
        );
    }
    if header.window != window(st) || header.spp != st.spp || header.done > st.spp {
        bail!(
            "--resume: the checkpoint {} is of a different render: window {:?} at {} spp there, {:?} at {} spp here",
            path.display(),
            header.window,
            header.spp,
            window(st),
            st.spp
        );
    }
    let expect_bands = if fresh.xyz.is_empty() { 0 } else { fresh.bins.len() / fresh.xyz.len() };
    if header.bands != expect_bands {
        bail!(
            "--resume: the checkpoint {} holds {} bands, this render {expect_bands}",
            path.display(),
            header.bands
        );
    }
    let mut vals = body[8 + len..8 + len + 8 * floats]
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap()));
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
