//! `spectra merge`: sample chunks and crop tiles of one `spectra truth` render, combined into
//! one image — chunks weighted by their sample counts (so chunks 0…n−1 of `--chunk i/n` are the
//! render of all their samples), tiles stitched. Every input carries the record `truth` writes
//! (`spectra.*` EXR attributes: identity, settings, sample range; the data window in the
//! frame); anything that would not merge into a render of one setting is refused, naming the
//! file and the mismatch, before anything is written.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use compare::{ExrFrame, Image, SpectralImage};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The chunks and tiles: EXR files written by `spectra truth` (all --out files, or all
    /// --spectral-out files, of one scene and setting).
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    /// The merged image (.exr), with the record of what it holds.
    #[arg(long)]
    pub out: PathBuf,
}

/// Half-open sample ranges `a..b`, as `spectra.samples` lists them ("0..64,128..192").
fn parse_samples(path: &Path, s: &str) -> Result<Vec<(u64, u64)>> {
    s.split(',')
        .map(|r| {
            let (a, b) = r
                .split_once("..")
                .and_then(|(a, b)| Some((a.trim().parse().ok()?, b.trim().parse().ok()?)))
                .filter(|(a, b): &(u64, u64)| a < b)
                .with_context(|| {
                    format!("{}: spectra.samples '{s}' is not a list of ranges a..b", path.display())
                })?;
            Ok((a, b))
        })
        .collect()
}

/// `ranges` sorted and joined where they touch.
fn normalise(mut ranges: Vec<(u64, u64)>) -> Vec<(u64, u64)> {
    ranges.sort();
    let mut out: Vec<(u64, u64)> = Vec::new();
    for r in ranges {
        match out.last_mut() {
            Some(last) if last.1 == r.0 => last.1 = r.1,
            _ => out.push(r),
        }
    }
    out
}

fn show(ranges: &[(u64, u64)]) -> String {
    ranges.iter().map(|(a, b)| format!("{a}..{b}")).collect::<Vec<_>>().join(",")
}

/// One input: its record, window and sample ranges, from its headers (its pixels are read
/// one input at a time, when they are added: [`Pixels::of`]).
struct Piece {
    path: PathBuf,
    frame: ExrFrame,
    samples: Vec<(u64, u64)>,
    size: (u32, u32),
}

impl Piece {
    fn spp(&self) -> u64 {
        self.samples.iter().map(|(a, b)| b - a).sum()
    }
    fn rect(&self) -> (u32, u32, u32, u32) {
        (self.frame.origin.0, self.frame.origin.1, self.size.0, self.size.1)
    }
    fn spectral(&self) -> bool {
        self.frame.get("spectra.content") == Some("spectral")
    }
}

fn read_piece(path: &Path) -> Result<Piece> {
    let (frame, size) = compare::read_exr_frame_and_size(path)?;
    let version = frame.get("spectra.version").with_context(|| {
        format!(
            "{}: not a spectra truth render (no spectra.* record): only `spectra truth` EXR outputs merge",
            path.display()
        )
    })?;
    if version != super::truth::RECORD_VERSION {
        bail!(
            "{}: record version {version}; this spectra reads version {}",
            path.display(),
            super::truth::RECORD_VERSION
        );
    }
    let samples = parse_samples(path, frame.get("spectra.samples").unwrap_or(""))?;
    if frame.get("spectra.check") != Some(super::truth::record_check(&frame, size).as_str()) {
        bail!(
            "{}: its record (spectra.samples, the windows or spectra.content) does not match its \
             spectra.check: the header was edited or damaged; render the piece again",
            path.display()
        );
    }
    let fits = |o: u32, n: u32, d: u32| u64::from(o) + u64::from(n) <= u64::from(d);
    if !fits(frame.origin.0, size.0, frame.display.0) || !fits(frame.origin.1, size.1, frame.display.1) {
        bail!(
            "{}: its data window ({}×{} at {},{}) does not lie in its {}×{} frame",
            path.display(),
            size.0,
            size.1,
            frame.origin.0,
            frame.origin.1,
            frame.display.0,
            frame.display.1
        );
    }
    Ok(Piece { path: path.to_path_buf(), frame, samples, size })
}

/// An input's pixels: colour, and bands for a spectral file.
struct Pixels {
    rgb: Image,
    bands: Option<SpectralImage>,
}

impl Pixels {
    /// The pixels of `p`, checked against its headers and finite (a truth render drops
    /// non-finite samples, so a NaN is a damaged file, and would spread through the merge).
    fn of(p: &Piece) -> Result<Pixels> {
        let path = &p.path;
        let (rgb, bands) = if p.spectral() {
            (compare::io::read_spectral_exr_rgb(path)?, Some(compare::read_spectral_exr(path)?))
        } else {
            (compare::read_image(path)?, None)
        };
        if (rgb.width, rgb.height) != p.size {
            bail!("{}: changed while being merged", path.display());
        }
        let bad = |i: usize| {
            let w = p.size.0 as usize;
            anyhow::anyhow!("{}: pixel ({}, {}) is not finite: a damaged file", path.display(), i % w, i / w)
        };
        if let Some(i) = rgb.data.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
            return Err(bad(i));
        }
        if let Some(b) = &bands
            && let Some(i) = b.data.iter().position(|v| !v.is_finite())
        {
            return Err(bad(i / b.bands().max(1)));
        }
        Ok(Pixels { rgb, bands })
    }
}

/// Why `b` is not the same render as `a`: the first setting that differs.
fn mismatch(a: &Piece, b: &Piece) -> Option<String> {
    if a.frame.get("spectra.identity") == b.frame.get("spectra.identity") {
        return None;
    }
    let (k, there, here) = super::truth::record_difference(&a.frame.attributes, &b.frame.attributes)?;
    Some(format!(
        "{}: a different render from {}: {k} is {there} there and {here} here",
        b.path.display(),
        a.path.display()
    ))
}

pub fn run(a: Args) -> Result<()> {
    if !a.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
        bail!("--out {}: a merged render is an OpenEXR file; give it a .exr name", a.out.display());
    }
    super::check_output("--out", &a.out)?;
    let inputs: Vec<(String, PathBuf)> = a.inputs.iter().map(|p| ("input".to_string(), p.clone())).collect();
    super::check_outputs(&[("--out", Some(a.out.as_path()))], &inputs)?;
    let pieces: Vec<Piece> = a.inputs.iter().map(|p| read_piece(p)).collect::<Result<_>>()?;
    let first = &pieces[0];
    for p in &pieces[1..] {
        if let Some(m) = mismatch(first, p) {
            bail!(m);
        }
        if p.frame.display != first.frame.display {
            bail!(
                "{}: its frame is {}×{}, {}'s {}×{}",
                p.path.display(),
                p.frame.display.0,
                p.frame.display.1,
                first.path.display(),
                first.frame.display.0,
                first.frame.display.1
            );
        }
        if p.frame.get("spectra.content") != first.frame.get("spectra.content") {
            bail!(
                "{}: {} holds {} and {} holds {}: merge --out files and --spectral-out files separately",
                p.path.display(),
                p.path.display(),
                p.frame.get("spectra.content").unwrap_or("rgb"),
                first.path.display(),
                first.frame.get("spectra.content").unwrap_or("rgb")
            );
        }
    }
    // Tiles: the pieces of one window; within one, disjoint sample ranges.
    let mut tiles: Vec<Vec<&Piece>> = Vec::new();
    for p in &pieces {
        match tiles.iter_mut().find(|t| t[0].rect() == p.rect()) {
            Some(t) => t.push(p),
            None => tiles.push(vec![p]),
        }
    }
    let mut tile_samples = Vec::new();
    for t in &tiles {
        let mut all: Vec<(u64, u64, &Path)> =
            t.iter().flat_map(|p| p.samples.iter().map(|&(s, e)| (s, e, p.path.as_path()))).collect();
        all.sort();
        for w in all.windows(2) {
            if w[1].0 < w[0].1 {
                bail!(
                    "{}: samples {}..{} overlap {}..{} of {}: a sample may be counted once",
                    w[1].2.display(),
                    w[1].0,
                    w[1].1,
                    w[0].0,
                    w[0].1,
                    w[0].2.display()
                );
            }
        }
        tile_samples.push(normalise(all.iter().map(|&(s, e, _)| (s, e)).collect()));
    }
    for (t, s) in tiles.iter().zip(&tile_samples).skip(1) {
        if *s != tile_samples[0] {
            bail!(
                "{}: its tile holds samples {}, {}'s tile {}: every tile of a merge needs the same samples",
                t[0].path.display(),
                show(s),
                tiles[0][0].path.display(),
                show(&tile_samples[0])
            );
        }
    }
    let overlap = |a: (u32, u32, u32, u32), b: (u32, u32, u32, u32)| {
        a.0 < b.0 + b.2 && b.0 < a.0 + a.2 && a.1 < b.1 + b.3 && b.1 < a.1 + a.3
    };
    for (i, ti) in tiles.iter().enumerate() {
        for tj in &tiles[i + 1..] {
            if overlap(ti[0].rect(), tj[0].rect()) {
                let r = |p: &Piece| {
                    let (x, y, w, h) = p.rect();
                    format!("{w}×{h} at {x},{y}")
                };
                bail!(
                    "{}: its tile ({}) overlaps {}'s ({})",
                    tj[0].path.display(),
                    r(tj[0]),
                    ti[0].path.display(),
                    r(ti[0])
                );
            }
        }
    }
    let x0 = tiles.iter().map(|t| t[0].rect().0).min().unwrap_or(0);
    let y0 = tiles.iter().map(|t| t[0].rect().1).min().unwrap_or(0);
    let x1 = tiles.iter().map(|t| t[0].rect().0 + t[0].rect().2).max().unwrap_or(0);
    let y1 = tiles.iter().map(|t| t[0].rect().1 + t[0].rect().3).max().unwrap_or(0);
    let area: u64 = tiles.iter().map(|t| u64::from(t[0].size.0) * u64::from(t[0].size.1)).sum();
    if area != u64::from(x1 - x0) * u64::from(y1 - y0) {
        let names: Vec<String> = tiles.iter().take(3).map(|t| t[0].path.display().to_string()).collect();
        bail!(
            "the tiles ({}{}) do not cover a rectangle: they span {}×{} at {x0},{y0} with {} of its {} pixels missing",
            names.join(", "),
            if tiles.len() > 3 { format!(" and {} more", tiles.len() - 3) } else { String::new() },
            x1 - x0,
            y1 - y0,
            u64::from(x1 - x0) * u64::from(y1 - y0) - area,
            u64::from(x1 - x0) * u64::from(y1 - y0)
        );
    }
    let (w, h) = (x1 - x0, y1 - y0);
    // One input decoded at a time: the merge holds the sums and one input, whatever their number
    // (holding all of them, 64 chunks of a 1080p spectral render would have needed ~40 GB).
    let mut rgb = vec![[0.0f64; 3]; (w * h) as usize];
    let mut bands: Vec<f64> = Vec::new();
    let mut like: Option<(SpectralImage, &Path)> = None;
    for t in &tiles {
        let total: u64 = t.iter().map(|p| p.spp()).sum();
        for p in t {
            if color::cancel::is_cancelled() {
                bail!("interrupted");
            }
            let px_of = Pixels::of(p)?;
            let nb = match (&px_of.bands, &like) {
                (Some(b), None) => {
                    bands = vec![0.0f64; (w * h) as usize * b.bands()];
                    like = Some((SpectralImage { data: Vec::new(), ..b.clone() }, p.path.as_path()));
                    b.bands()
                }
                (Some(b), Some((l, from))) => {
                    if b.edges != l.edges {
                        bail!("{}: its bands are not {}'s", p.path.display(), from.display());
                    }
                    b.bands()
                }
                (None, _) => 0,
            };
            let k = p.spp() as f64 / total as f64;
            let (px, py, pw, ph) = p.rect();
            for y in 0..ph {
                for x in 0..pw {
                    let src = (y * pw + x) as usize;
                    let dst = ((py - y0 + y) * w + (px - x0 + x)) as usize;
                    for (acc, v) in rgb[dst].iter_mut().zip(px_of.rgb.data[src]) {
                        *acc += k * f64::from(v);
                    }
                    if let Some(b) = &px_of.bands {
                        for i in 0..nb {
                            bands[dst * nb + i] += k * f64::from(b.data[src * nb + i]);
                        }
                    }
                }
            }
        }
    }
    if color::cancel::is_cancelled() {
        bail!("interrupted");
    }
    let nb = like.as_ref().map_or(0, |(b, _)| b.bands());
    let image = Image::new(w, h, rgb.iter().map(|p| p.map(|v| v as f32)).collect())?;
    let samples = &tile_samples[0];
    let mut frame = ExrFrame {
        display: first.frame.display,
        origin: (x0, y0),
        attributes: first.frame.attributes.clone(),
    };
    for (k, v) in &mut frame.attributes {
        if k == "spectra.samples" {
            *v = show(samples);
        }
    }
    let frame = super::truth::sealed(frame, (w, h));
    match like {
        Some((b, _)) => {
            let spec =
                SpectralImage { width: w, height: h, data: bands.iter().map(|&v| v as f32).collect(), ..b };
            compare::write_spectral_exr_framed(&a.out, &spec, Some(&image), Some(&frame))
        }
        None => compare::write_exr_framed(&a.out, &image, &frame),
    }
    .with_context(|| format!("writing {}", a.out.display()))?;
    let spp: u64 = samples.iter().map(|(a, b)| b - a).sum();
    eprintln!(
        "{}: {} input{} ({} tile{}) merged: {w}×{h} at {x0},{y0} of the {}×{} frame, samples {} ({spp} spp){}",
        a.out.display(),
        pieces.len(),
        if pieces.len() == 1 { "" } else { "s" },
        tiles.len(),
        if tiles.len() == 1 { "" } else { "s" },
        first.frame.display.0,
        first.frame.display.1,
        show(samples),
        if nb > 0 { format!(", {nb} bands") } else { String::new() }
    );
    Ok(())
}
