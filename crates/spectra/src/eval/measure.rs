//! The measurements: ground truth (twice, for the noise floor), the three real-time modes,
//! their errors against truth (whole image and with an edge mask), frame time against N, and
//! jittered accumulation against equal spacing.

use anyhow::{Context, Result, bail};
use color::WavelengthRange;
use color::metrics::Stats;
use compare::{DiffMaps, DiffOptions, Image};
use render::{Mode, RenderSettings, Renderer};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Error statistics of one image against ground truth.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Errors {
    pub delta_e2000: Stats,
    pub mae_linear: Stats,
    /// ΔE2000 over the pixels outside the edge mask only.
    pub delta_e2000_masked: Stats,
    pub mae_linear_masked: Stats,
}

impl Errors {
    pub fn of(maps: &DiffMaps, mask: &[bool]) -> Result<Errors> {
        let keep =
            |v: &[f64]| -> Vec<f64> { v.iter().zip(mask).filter(|(_, m)| !**m).map(|(x, _)| *x).collect() };
        let st = |v: &[f64]| Stats::of(v).context("no pixels left to measure (mask covers the whole image)");
        Ok(Errors {
            delta_e2000: st(&maps.delta_e2000)?,
            mae_linear: st(&maps.abs_linear)?,
            delta_e2000_masked: st(&keep(&maps.delta_e2000))?,
            mae_linear_masked: st(&keep(&maps.abs_linear))?,
        })
    }
}

/// What a ground-truth render needs besides the scene.
#[derive(Clone, Copy, Debug)]
pub struct TruthJob {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub seed: u64,
    pub range: WavelengthRange,
}

/// The scene's water as the renderer and the tracer need it, if it has any.
pub fn water(scene: &scene::Scene) -> Result<Option<scene::water::WaterMedium>> {
    crate::cmd::setup::water_medium(scene, None, None)
}

/// Where a ground truth's samples came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TruthSource {
    /// Samples read from the truth cache (0 without one or on a miss).
    pub cached: u32,
    /// Samples rendered now.
    pub rendered: u32,
}

/// The tracer's settings of a case's ground truth: direct lighting only (full transport under
/// water), the scene's white.
pub fn truth_settings(scene: &scene::Scene, job: TruthJob) -> Result<truth::Settings> {
    let mut st = truth::Settings::new(job.width, job.height, job.spp)?;
    st.seed = job.seed;
    st.direct_only = true;
    st.range = job.range;
    if let Some(w) = water(scene)? {
        // Full transport under water: the real-time model's Kd stands for multiple scattering.
        st.direct_only = false;
        st.medium = Some(truth::water::medium(&w, scene.camera.position()));
    }
    st.white = color::illuminant::by_name(scene.spectral.white_name())?;
    st.observer = observer_of(scene)?;
    Ok(st)
}

/// The observer a case is evaluated for: its scene's (`spectra eval --observer` sets it on
/// every case, `Config::case`), else CIE 1931.
pub fn observer_of(scene: &scene::Scene) -> Result<color::Observer> {
    let name = scene.spectral.observer.as_deref().unwrap_or("cie1931");
    color::Observer::by_name(name).with_context(|| format!("observer {name}"))
}

/// How the evaluation shows an observer: a camera through its ColorChecker fit to XYZ and sRGB
/// (`--camera-to-display`), so that ΔE2000 measures colours a person sees and the rgb mode's
/// sRGB is comparable; CIE observers as they are.
pub fn view_of(observer: &color::Observer) -> color::film::CameraView {
    match observer.kind() {
        color::observer::ObserverKind::CieXyz => color::film::CameraView::Balanced,
        _ => color::film::CameraView::Display,
    }
}

/// The sums of samples `first` … `first + samples − 1` of a case's ground truth (the same
/// per-pixel sample sequence as [`truth`] renders): a piece of it that another process may
/// render (`spectra.distributed.eval`); pieces add up to the sums of the whole.
pub fn truth_piece(
    scene: &scene::Scene,
    table: &color::upsample::CoeffTable,
    job: TruthJob,
    first: u32,
    samples: u32,
    cancel: &AtomicBool,
) -> Result<truth::Accumulator> {
    let mut st = truth_settings(scene, TruthJob { spp: samples, ..job })?;
    st.sample_offset = u64::from(first);
    let world = truth::World::new(scene, table, &st.white, st.range, st.medium.as_ref())?;
    let mut acc = truth::Accumulator::new(&st)?;
    match truth::render_pass(&world, &st, cancel, &mut acc, samples, &|_| {}) {
        Err(truth::TruthError::Cancelled) => bail!("interrupted"),
        r => r?,
    }
    Ok(acc)
}

/// Stores the sums of all of a case's ground-truth samples (`acc.done == job.spp`, the pieces of
/// [`truth_piece`] added up) in `cache` as [`truth`] stores its own, so that [`truth`] then
/// renders nothing.
pub fn store_truth(
    scene: &scene::Scene,
    table: &color::upsample::CoeffTable,
    job: TruthJob,
    acc: &truth::Accumulator,
    cache: &crate::cmd::truth_cache::TruthCache,
) -> Result<()> {
    let st = truth_settings(scene, job)?;
    if acc.done != st.spp || acc.xyz.len() != st.width as usize * st.height as usize {
        bail!(
            "the sums hold {} samples of {} pixels; the truth has {} samples of {}×{} pixels",
            acc.done,
            acc.xyz.len(),
            st.spp,
            st.width,
            st.height
        );
    }
    let fields = crate::cmd::truth::sum_fields(scene, &st, table, &[], false)?;
    cache.store(&fields, &st, acc).map(|_| ())
}

/// How many samples of a case's ground truth `cache` already holds from the first one (what
/// [`truth`] would not render).
pub fn cached_samples(
    scene: &scene::Scene,
    table: &color::upsample::CoeffTable,
    job: TruthJob,
    cache: &crate::cmd::truth_cache::TruthCache,
) -> Result<u32> {
    let st = truth_settings(scene, job)?;
    let fields = crate::cmd::truth::sum_fields(scene, &st, table, &[], false)?;
    Ok(cache.start(&fields, &st)?.acc.done)
}

/// Ground truth of a scene: direct lighting only (full transport under water), linear sRGB.
/// With `cache`, starts from the cache's samples of the same render and stores the result
/// (`crate::cmd::truth_cache`).
pub fn truth(
    scene: &scene::Scene,
    table: &color::upsample::CoeffTable,
    job: TruthJob,
    cache: Option<&crate::cmd::truth_cache::TruthCache>,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<(Image, TruthSource)> {
    let (width, height) = (job.width, job.height);
    let st = truth_settings(scene, job)?;
    let world = truth::World::new(scene, table, &st.white, st.range, st.medium.as_ref())?;
    let fields = match cache {
        Some(_) => crate::cmd::truth::sum_fields(scene, &st, table, &[], false)?,
        None => Vec::new(),
    };
    let (mut acc, cached) = match cache {
        Some(c) => {
            let start = c.start(&fields, &st)?;
            for n in &start.notes {
                eprintln!("{n}");
            }
            let done = start.acc.done;
            (start.acc, done)
        }
        None => (truth::Accumulator::new(&st)?, 0),
    };
    let rendered = st.spp - cached;
    if rendered > 0 {
        match truth::render_pass(&world, &st, cancel, &mut acc, rendered, progress) {
            Err(truth::TruthError::Cancelled) => bail!("interrupted"),
            r => r?,
        }
        if cancel.load(Ordering::Relaxed) {
            bail!("interrupted");
        }
        // As `spectra truth`: a cache that cannot take the samples does not stop the run.
        if let Some(Err(e)) = cache.map(|c| c.store(&fields, &st, &acc)) {
            eprintln!("warning: {e:#}: the samples are not cached");
        }
    }
    let img = acc.finish(&st);
    let rgb = img.to_display(&st, view_of(&st.observer))?;
    Ok((Image::new(width, height, rgb)?, TruthSource { cached, rendered }))
}

/// The real-time renderer's linear HDR image of the scene's camera.
pub fn realtime(r: &mut Renderer, scene: &scene::Scene, settings: &RenderSettings) -> Result<Image> {
    r.render(&scene.camera, settings)?;
    let (w, h) = r.size().context("renderer has no size")?;
    let data = r.read_hdr()?.iter().map(|p| [p[0], p[1], p[2]]).collect();
    Ok(Image::new(w, h, data)?)
}

/// Settings for a mode at N over `range`, everything else default (no tone map, shadows on).
pub fn settings(mode: Mode, n: usize, range: WavelengthRange) -> RenderSettings {
    RenderSettings { mode, wavelengths: n, range, ..RenderSettings::default() }
}

/// [`settings`] for `scene`'s case: its observer ([`observer_of`]) shown as [`view_of`] says.
pub fn settings_for(
    scene: &scene::Scene,
    mode: Mode,
    n: usize,
    range: WavelengthRange,
) -> Result<RenderSettings> {
    let observer = observer_of(scene)?;
    Ok(RenderSettings {
        camera_view: view_of(&observer),
        observer: observer.name,
        ..settings(mode, n, range)
    })
}

/// Pixels near an edge of the ground-truth image: the 3×3 neighbourhood's luminance varies by
/// more than [`EDGE_CONTRAST`] of its maximum. Depends on truth only, so it removes the same
/// pixels from every mode (shadow-map and silhouette mismatches, but also texture edges).
pub fn edge_mask(truth: &Image) -> Vec<bool> {
    let (w, h) = (truth.width as i64, truth.height as i64);
    let srgb = color::colorspace::RgbColorSpace::srgb();
    let y: Vec<f32> = truth.data.iter().map(|p| srgb.luminance(p.map(f64::from)) as f32).collect();
    let mut mask = vec![false; y.len()];
    for py in 0..h {
        for px in 0..w {
            let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (x, yy) = ((px + dx).clamp(0, w - 1), (py + dy).clamp(0, h - 1));
                    let v = y[(yy * w + x) as usize];
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            }
            mask[(py * w + px) as usize] = hi - lo > EDGE_CONTRAST * hi.max(0.02);
        }
    }
    mask
}

/// Relative 3×3 luminance variation above which a pixel is masked.
pub const EDGE_CONTRAST: f32 = 0.25;

/// Median CPU wall time (ms) of `frames` frames: submit, then wait for the HDR read-back.
/// Includes the read-back, which is the same for every mode.
pub fn frame_ms(r: &mut Renderer, scene: &scene::Scene, s: &RenderSettings, frames: usize) -> Result<f64> {
    for _ in 0..2 {
        realtime(r, scene, s)?;
    }
    let mut t = Vec::with_capacity(frames);
    for _ in 0..frames {
        let t0 = Instant::now();
        r.render(&scene.camera, s)?;
        r.read_hdr()?;
        t.push(t0.elapsed().as_secs_f64() * 1e3);
    }
    t.sort_by(f64::total_cmp);
    Ok(t[t.len() / 2])
}

/// SplitMix64: a tiny deterministic generator for the jitter offsets (reproducible runs).
pub struct SplitMix(pub u64);

impl SplitMix {
    pub fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Stratified jittered offsets for `frames` frames: frame k's offset lies in [k/K, (k+1)/K).
pub fn jitter_offsets(frames: usize, seed: u64) -> Vec<f64> {
    let mut g = SplitMix(seed);
    (0..frames).map(|k| (k as f64 + g.next_f64()) / frames as f64).collect()
}

/// Average of `frames` frames with N wavelengths each at stratified jittered offsets: frame k
/// puts sample i at `range.min + (i + u_k)·Δ` (`RenderSettings::jitter`), which also makes the
/// renderer normalise with dense integrals over `range`, so the average converges to the
/// continuous integral instead of to the bias of N-sample ratio estimates.
pub fn accumulate(
    r: &mut Renderer,
    scene: &scene::Scene,
    n: usize,
    range: WavelengthRange,
    frames: usize,
    seed: u64,
) -> Result<Image> {
    let mut sum: Option<Image> = None;
    for u in jitter_offsets(frames, seed) {
        let s = RenderSettings {
            jitter: Some((u as f32).min(1.0 - f32::EPSILON)),
            ..settings(Mode::Spectral, n, range)
        };
        let img = realtime(r, scene, &s)?;
        match &mut sum {
            None => sum = Some(img),
            Some(s) => s.data.iter_mut().zip(&img.data).for_each(|(a, b)| (0..3).for_each(|k| a[k] += b[k])),
        }
    }
    let mut s = sum.context("no frames")?;
    let k = 1.0 / frames as f32;
    s.data.iter_mut().for_each(|p| p.iter_mut().for_each(|c| *c *= k));
    Ok(s)
}

/// ΔE2000/MAE maps of `test` against `reference` (CIELAB white Y = 1).
pub fn diff(reference: &Image, test: &Image) -> Result<DiffMaps> {
    Ok(DiffMaps::compute(reference, test, DiffOptions::default())?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jitter_is_stratified() {
        let u = jitter_offsets(8, 3);
        for (k, v) in u.iter().enumerate() {
            assert!(*v >= k as f64 / 8.0 && *v < (k + 1) as f64 / 8.0);
            // The renderer takes the offset as f32 and refuses 1.0.
            assert!((*v as f32) < 1.0);
        }
    }

    #[test]
    fn edge_mask_marks_a_step_only() {
        let img = Image::from_fn(8, 4, |x, _| if x < 4 { [0.1; 3] } else { [0.9; 3] }).unwrap();
        let m = edge_mask(&img);
        assert!(m[3] && m[4] && !m[0] && !m[7]);
    }
}
