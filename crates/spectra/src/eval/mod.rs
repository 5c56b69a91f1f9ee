//! `spectra eval`: the paper's evaluation in one command.
//!
//! For every case of the suite ([`suite`]): a direct-lighting ground truth from the CPU path
//! tracer (twice, with different seeds, so the report states its own noise floor), the three
//! real-time modes (`spectral` = ours, `naive`, `rgb`) at the same size and camera, and their
//! ΔE2000 / MAE against truth, over the whole image and outside an edge mask, plus a sweep of
//! ours and naive over N in both quadratures against the same truth. Then frame time against N
//! (paper Fig. 4), the error-vs-frame-time curve that a user picks N from and, beyond the
//! paper, stratified jittered wavelengths accumulated over frames against equal spacing.
//! Everything lands in `--out`: PNGs, heat maps, `results.json`, `results.csv`, SVG charts and
//! `index.html` ([`report`]).

pub mod measure;
pub mod plot;
pub mod report;
pub mod suite;

#[cfg(test)]
mod conventions_tests;

use anyhow::{Context, Result};
use color::{Quadrature, WavelengthRange};
use compare::{Heatmap, HeatmapOptions, Image, WriteOptions};
use indicatif::{ProgressBar, ProgressStyle};
use measure::Errors;
use render::{Mode, RenderSettings, Renderer};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::Instant;

/// The three real-time modes, in report order, with their report names.
pub const MODES: &[(Mode, &str)] = &[(Mode::Spectral, "ours"), (Mode::Naive, "naive"), (Mode::Rgb, "rgb")];

/// The modes whose result depends on N and on the quadrature: the first two of [`MODES`].
pub const SPECTRAL_MODES: &[(Mode, &str)] = &[(Mode::Spectral, "ours"), (Mode::Naive, "naive")];

/// The headline modes' quadrature: the renderer's default, i.e. what a user gets.
pub fn headline_quadrature() -> Quadrature {
    RenderSettings::default().quadrature
}

/// What a run needs.
pub struct Config {
    pub out: PathBuf,
    pub quick: bool,
    pub budget: suite::Budget,
    pub ids: Vec<String>,
    pub notes: Vec<String>,
    pub table: Option<PathBuf>,
    /// Keep the ground truths here and start from the ones kept (`--truth-cache`).
    pub truth_cache: Option<PathBuf>,
    /// Evaluate for this observer instead of CIE 1931 (`--observer`): a camera is shown through
    /// its fitted matrix (`measure::view_of`).
    pub observer: Option<String>,
}

impl Config {
    /// The case `id` as this evaluation renders it (its observer set on the scene).
    pub fn case(&self, id: &str) -> Result<suite::Case> {
        let mut c = suite::case(id)?;
        if let Some(o) = &self.observer {
            c.scene.spectral.observer = Some(o.clone());
        }
        Ok(c)
    }
}

/// One mode's result in one case.
#[derive(serde::Serialize)]
pub struct ModeResult {
    pub mode: String,
    pub wavelengths: Option<usize>,
    /// `None` for rgb, which has no wavelength nodes.
    pub quadrature: Option<String>,
    pub image: String,
    pub heatmap: String,
    pub errors: Errors,
    /// Mean LDR-FLIP against the truth (sRGB-encoded, clipped; 67 pixels per degree) and its
    /// error map (magma PNG).
    pub flip_mean: f64,
    pub flip_map: String,
    /// Mean HDR-FLIP against the truth (the linear images, FLIP's default exposure range taken
    /// from the truth, ACES tone mapping): what LDR-FLIP misses above 1 (highlights, lights).
    pub flip_hdr_mean: f64,
}

/// One case's results.
#[derive(serde::Serialize)]
pub struct CaseResult {
    pub id: String,
    pub title: String,
    pub truth_image: String,
    /// Image size and truth samples per pixel of this case (underwater cases have their own).
    pub width: u32,
    pub height: u32,
    pub truth_spp: u32,
    /// Ground-truth transport: "direct" (direct lighting, the rasteriser's punctual lights) or
    /// "volumetric" (full path tracing of the water; no edge mask is applied then).
    pub transport: String,
    /// ΔE2000/MAE between two truth renders with different seeds: differences below this are noise.
    pub noise_floor: Errors,
    pub masked_fraction: f64,
    pub modes: Vec<ModeResult>,
    /// Ours and naive at every N of the sweep in both quadratures, against the same truth as
    /// `modes` (seed 1).
    pub sweep: Vec<SweepPoint>,
}

/// One (mode, quadrature, N) of the sweep: its errors against the case's truth. Only the means
/// are kept; the sweep writes no images.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SweepPoint {
    pub mode: String,
    pub quadrature: String,
    pub wavelengths: usize,
    pub delta_e2000_mean: f64,
    /// Outside the edge mask; equal to the whole-image mean for volumetric cases (no mask).
    pub delta_e2000_masked_mean: f64,
    pub mae_linear_mean: f64,
}

impl CaseResult {
    /// The sweep's point for a mode, quadrature and N, if it was measured.
    pub fn sweep_point(&self, mode: &str, quadrature: &str, n: usize) -> Option<&SweepPoint> {
        self.sweep.iter().find(|p| p.mode == mode && p.quadrature == quadrature && p.wavelengths == n)
    }
}

/// A point of the error-vs-frame-time curve: the frame time of a configuration on the
/// frame-time scene beside its mean error in that scene's case.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TradeoffPoint {
    pub mode: String,
    /// `None` for rgb.
    pub quadrature: Option<String>,
    pub wavelengths: Option<usize>,
    pub median_ms: f64,
    pub delta_e2000_mean: f64,
}

#[derive(serde::Serialize)]
pub struct FrameTime {
    pub mode: String,
    pub wavelengths: Option<usize>,
    /// `None` for rgb.
    pub quadrature: Option<String>,
    pub median_ms: f64,
}

#[derive(serde::Serialize)]
pub struct JitterPoint {
    /// Wavelengths per pixel summed over the accumulated frames.
    pub total_wavelengths: usize,
    pub frames: usize,
    pub equal_spacing_delta_e: f64,
    pub jittered_delta_e: f64,
}

#[derive(serde::Serialize)]
pub struct Results {
    pub quick: bool,
    pub budget: suite::Budget,
    pub adapter: String,
    /// The observer every case was rendered for (`--observer`; a camera shown through its
    /// ColorChecker fit to XYZ).
    pub observer: String,
    pub machine: String,
    pub seconds: f64,
    pub notes: Vec<String>,
    pub edge_contrast: f32,
    pub cases: Vec<CaseResult>,
    pub frame_time_scene: String,
    pub frame_times: Vec<FrameTime>,
    /// Frame time (at the frame-time size) against mean ΔE2000 (at the case's size) of the
    /// frame-time scene's case, for N both swept and timed, plus rgb.
    pub tradeoff: Vec<TradeoffPoint>,
    pub jitter_scene: String,
    pub jitter_range: [f64; 2],
    pub jitter_quadrature: String,
    pub jitter: Vec<JitterPoint>,
}

/// What the truth cache gave the renders of a case, for the log: each render's samples per
/// pixel from the cache and rendered now.
fn describe_source(s: &[measure::TruthSource]) -> String {
    let one = |t: &measure::TruthSource| match (t.cached, t.rendered) {
        (c, 0) => format!("{c} spp from the cache"),
        (0, r) => format!("{r} spp rendered"),
        (c, r) => format!("{c} spp from the cache + {r} rendered"),
    };
    let all: Vec<String> = s.iter().map(one).collect();
    let nothing = if s.iter().all(|t| t.rendered == 0) { "; nothing rendered" } else { "" };
    format!("{}{nothing}", all.join(", "))
}

fn bar(len: u64, what: &str) -> ProgressBar {
    let pb = ProgressBar::new(len);
    if let Ok(st) = ProgressStyle::with_template("{prefix:>14} [{bar:30}] {pos}/{len} {msg} ({elapsed})") {
        pb.set_style(st.progress_chars("=> "));
    }
    pb.set_prefix(what.to_string());
    pb
}

/// One ground truth a run renders: the case (by id), its seed and its job.
#[derive(Clone, Debug)]
pub struct PlannedTruth {
    pub case: String,
    pub seed: u64,
    pub job: measure::TruthJob,
}

/// The ground truths [`run`] renders for `cfg`, in its order: per case seeds 1 and 2 (the
/// noise floor), then the jittered-accumulation truth (seed 3) of the first case. With them in
/// the truth cache ([`measure::store_truth`]) a run renders no truth.
pub fn truth_plan(cfg: &Config) -> Result<Vec<PlannedTruth>> {
    let mut plan = Vec::new();
    for id in &cfg.ids {
        let c = cfg.case(id)?;
        let range = scene_range(&c.scene)?;
        let (width, height, spp) = cfg.budget.for_case(&c);
        for seed in [1, 2] {
            plan.push(PlannedTruth {
                case: id.clone(),
                seed,
                job: measure::TruthJob { width, height, spp, seed, range },
            });
        }
    }
    let first = plan.first().cloned().context("no scenes to evaluate")?;
    plan.push(PlannedTruth { seed: 3, job: measure::TruthJob { seed: 3, ..first.job }, ..first });
    Ok(plan)
}

/// Runs the suite into `cfg.out` (a new or empty-able directory). Ctrl-C stops it with an
/// error; files already finished stay, `results.json` and `index.html` are written last, so a
/// directory without them is an interrupted run.
pub fn run(cfg: Config) -> Result<Results> {
    let out = cfg.out.clone();
    let made = std::fs::symlink_metadata(&out).is_err();
    let r = run_into(cfg);
    // A run refused before it wrote anything (a size the GPU cannot make, a bad table) leaves
    // no empty folder behind; an interrupted run keeps what it finished.
    if r.is_err() && made && std::fs::read_dir(&out).is_ok_and(|mut d| d.next().is_none()) {
        let _ = std::fs::remove_dir(&out);
    }
    r
}

/// The files of an earlier evaluation in `out` (its results.json, index.html and results.csv),
/// which a new run replaces; an error for a file of one of those names that an evaluation did
/// not write.
fn earlier_results(out: &Path) -> Result<Vec<PathBuf>> {
    let ours = |name: &str, text: &str| match name {
        "results.json" => serde_json::from_str::<serde_json::Value>(text)
            .is_ok_and(|v| ["cases", "budget", "frame_times"].iter().all(|k| v.get(k).is_some())),
        "index.html" => text.contains(report::HTML_TITLE),
        _ => text.starts_with(report::CSV_HEADER),
    };
    let mut found = Vec::new();
    for name in ["results.json", "index.html", "results.csv"] {
        let p = out.join(name);
        if std::fs::symlink_metadata(&p).is_err() {
            continue;
        }
        let text = std::fs::read(&p).map(|b| String::from_utf8_lossy(&b).into_owned()).unwrap_or_default();
        if !p.is_file() || !ours(name, &text) {
            anyhow::bail!(
                "{}: exists and is not an earlier `spectra eval`'s output, which a run would replace; \
                 choose another --out, or move the file",
                p.display()
            );
        }
        found.push(p);
    }
    Ok(found)
}

fn run_into(cfg: Config) -> Result<Results> {
    let t_start = Instant::now();
    // The run writes many files into --out (the report, its charts, every case's images): an
    // input kept there could be one of them (a --table named mae.svg was replaced by the chart;
    // every other command refuses an output that is an input).
    if let (Some(t), Ok(out)) = (cfg.table.as_deref(), cfg.out.canonicalize())
        && t.canonicalize().is_ok_and(|t| t.starts_with(&out))
    {
        anyhow::bail!(
            "--table {} lies in --out {}, whose files an evaluation writes; move the table or choose another --out",
            t.display(),
            cfg.out.display()
        );
    }
    std::fs::create_dir_all(&cfg.out).with_context(|| format!("creating {}", cfg.out.display()))?;
    // An earlier run's results are replaced, but only once this run's inputs are all read, and
    // never a file of that name that an evaluation did not write (an --out pointed at a
    // project's folder).
    let stale = earlier_results(&cfg.out)?;
    let table = crate::cmd::setup::load_table(cfg.table.as_deref())?;
    let cancel = color::upsample::interrupt_flag();
    let check = || -> Result<()> {
        if cancel.load(Ordering::Relaxed) {
            anyhow::bail!("interrupted; results.json and index.html not written");
        }
        Ok(())
    };
    let probe = Renderer::with_table(table.clone())?;
    let adapter = probe.gpu().describe();
    let cache = cfg.truth_cache.as_deref().map(crate::cmd::truth_cache::TruthCache::open).transpose()?;
    let cache = cache.as_ref();
    let b = &cfg.budget;
    let job = |c: &suite::Case, seed: u64, range: WavelengthRange| {
        let (width, height, spp) = b.for_case(c);
        measure::TruthJob { width, height, spp, seed, range }
    };
    let cases: Vec<suite::Case> = cfg.ids.iter().map(|id| cfg.case(id)).collect::<Result<_>>()?;
    // Every case's inputs are checked before an earlier run's results go or any work starts: a
    // size either renderer refuses, a range, water settings (`underwater-XX`) failed only when
    // their case came, after the earlier results were removed and the cases before it rendered.
    for c in &cases {
        let (width, height, spp) = b.for_case(c);
        let at = |e: String| anyhow::anyhow!("{}: --size {width}x{height}: {e}", c.id);
        probe.check_size(width, height).map_err(|e| at(e.to_string()))?;
        truth::render::check_size(width, height).map_err(|e| at(e.to_string()))?;
        anyhow::ensure!(spp > 0, "{}: --spp must be at least 1", c.id);
        scene_range(&c.scene).with_context(|| c.id.clone())?;
        measure::water(&c.scene)?;
    }
    drop(probe);
    for p in stale {
        std::fs::remove_file(&p).with_context(|| format!("removing an earlier run's {}", p.display()))?;
    }

    let mut results = Vec::new();
    for c in &cases {
        check()?;
        let range = scene_range(&c.scene)?;
        let n = c.scene.spectral.wavelengths.map(|n| n as usize).unwrap_or(16);
        let (width, height, spp) = b.for_case(c);
        let pb = bar(2 * height as u64, &c.id);
        pb.set_message("ground truth");
        let pbr = &pb;
        let rows = |base: u64| move |k: u64| pbr.set_position(base + k);
        let (t0, s0) = measure::truth(&c.scene, &table, job(c, 1, range), cache, cancel, &rows(0))?;
        let (t1, s1) =
            measure::truth(&c.scene, &table, job(c, 2, range), cache, cancel, &rows(height as u64))?;
        pb.finish_and_clear();
        if cache.is_some() {
            eprintln!("{:<18} ground truth: {}", c.id, describe_source(&[s0, s1]));
        }
        check()?;
        // Volumetric truth is too noisy for a luminance-edge mask (it would mask everything).
        let water = measure::water(&c.scene)?;
        let mask = if water.is_some() { vec![false; t0.data.len()] } else { measure::edge_mask(&t0) };
        if mask.iter().all(|&m| m) {
            anyhow::bail!(
                "{}: at {width}×{height} every pixel lies on an edge of the truth, leaving none to measure; \
                 use a larger --size",
                c.id
            );
        }
        let noise = Errors::of(&measure::diff(&t0, &t1)?, &mask)?;
        let truth_png = format!("{}_truth.png", c.id);
        save_png(&cfg.out.join(&truth_png), &t0)?;
        write_exr(&cfg.out.join(format!("{}_truth.exr", c.id)), &t0)?;

        let mut r = renderer_for(c, &table, water.as_ref())?;
        r.resize(width, height)?;
        let mut maps = Vec::new();
        for (mode, name) in MODES {
            let img =
                measure::realtime(&mut r, &c.scene, &measure::settings_for(&c.scene, *mode, n, range)?)?;
            let png = format!("{}_{}.png", c.id, name);
            save_png(&cfg.out.join(&png), &img)?;
            // The measured image itself (the PNG is 8-bit sRGB): `spectra diff ID_truth.exr
            // ID_MODE.exr` gives the report's numbers.
            write_exr(&cfg.out.join(format!("{}_{}.exr", c.id, name)), &img)?;
            let ppd = compare::flip::DEFAULT_PIXELS_PER_DEGREE;
            let flip = compare::flip::ldr_flip(&t0, &img, ppd)?;
            let flip_hdr = compare::flip::hdr_flip(&t0, &img, ppd, &Default::default())?.mean();
            maps.push((*mode, *name, png, measure::diff(&t0, &img)?, (flip, flip_hdr)));
        }
        // One heat-map scale per case so the three modes are comparable at a glance.
        let scale = compare::heatmap::nice_ceil(
            maps.iter().map(|m| m.3.summary().delta_e2000.p99).fold(1.0, f64::max),
        );
        let mut modes = Vec::new();
        for (mode, name, png, m, (flip, flip_hdr_mean)) in maps {
            let hm = format!("{}_{}_heat.png", c.id, name);
            Heatmap::of_delta_e(&m, &HeatmapOptions { max: Some(scale), ..Default::default() })?
                .save_png(cfg.out.join(&hm))?;
            let flip_map = format!("{}_{}_flip.png", c.id, name);
            flip.save_png(&cfg.out.join(&flip_map))?;
            modes.push(ModeResult {
                mode: name.into(),
                wavelengths: (mode != Mode::Rgb).then_some(n),
                quadrature: (mode != Mode::Rgb).then(|| headline_quadrature().name().to_string()),
                image: png,
                heatmap: hm,
                errors: Errors::of(&m, &mask)?,
                flip_mean: flip.mean(),
                flip_map,
                flip_hdr_mean,
            });
        }
        eprintln!(
            "{:<18} ΔE00 mean at N = {n}, {}: ours {:.3}  naive {:.3}  rgb {:.3}  (truth noise {:.3})",
            c.id,
            headline_quadrature(),
            modes[0].errors.delta_e2000.mean,
            modes[1].errors.delta_e2000.mean,
            modes[2].errors.delta_e2000.mean,
            noise.delta_e2000.mean
        );
        let sweep = sweep(&mut r, c, &t0, &mask, range, &b.sweep_counts, &check)?;
        results.push(CaseResult {
            id: c.id.clone(),
            title: c.title.clone(),
            truth_image: truth_png,
            width,
            height,
            truth_spp: spp,
            transport: if water.is_some() { "volumetric" } else { "direct" }.into(),
            noise_floor: noise,
            masked_fraction: mask.iter().filter(|m| **m).count() as f64 / mask.len() as f64,
            modes,
            sweep,
        });
    }

    // Frame time against N on the first case's scene.
    let ft_case = cases.first().context("no scenes to evaluate")?;
    let range = scene_range(&ft_case.scene)?;
    let mut r = renderer_for(ft_case, &table, measure::water(&ft_case.scene)?.as_ref())?;
    r.resize(b.bench_width, b.bench_height)?;
    let configs = (SPECTRAL_MODES.len() * Quadrature::ALL.len() * b.bench_counts.len()) as u64;
    let pb = bar(1 + configs, "frame time");
    let mut frame_times = Vec::new();
    let ms = measure::frame_ms(
        &mut r,
        &ft_case.scene,
        &measure::settings_for(&ft_case.scene, Mode::Rgb, 1, range)?,
        b.bench_frames,
    )?;
    frame_times.push(FrameTime { mode: "rgb".into(), wavelengths: None, quadrature: None, median_ms: ms });
    pb.inc(1);
    for &n in &b.bench_counts {
        for (mode, name) in SPECTRAL_MODES {
            for q in Quadrature::ALL {
                check()?;
                let s = RenderSettings {
                    quadrature: q,
                    ..measure::settings_for(&ft_case.scene, *mode, n, range)?
                };
                let ms = measure::frame_ms(&mut r, &ft_case.scene, &s, b.bench_frames)?;
                frame_times.push(FrameTime {
                    mode: (*name).into(),
                    wavelengths: Some(n),
                    quadrature: Some(q.name().into()),
                    median_ms: ms,
                });
                pb.inc(1);
            }
        }
    }
    pb.finish_and_clear();
    let tradeoff = tradeoff(&results[0], &frame_times);

    // Jittered accumulation vs equal spacing, on the first case's scene and range (jitter
    // moves the samples inside the range; the range itself stays put).
    let jrange = range;
    let (jw, jh, _) = b.for_case(ft_case);
    let pb = bar(jh as u64, "jitter truth");
    let (jt, js) = measure::truth(&ft_case.scene, &table, job(ft_case, 3, jrange), cache, cancel, &|k| {
        pb.set_position(k)
    })?;
    pb.finish_and_clear();
    if cache.is_some() {
        eprintln!("{:<18} jitter truth: {}", ft_case.id, describe_source(&[js]));
    }
    check()?;
    r.resize(jw, jh)?;
    let mut jitter = Vec::new();
    for &k in &b.jitter_frames {
        check()?;
        let total = k * b.jitter_per_frame;
        let eq = measure::realtime(
            &mut r,
            &ft_case.scene,
            &measure::settings_for(&ft_case.scene, Mode::Spectral, total, jrange)?,
        )?;
        let acc = measure::accumulate(&mut r, &ft_case.scene, b.jitter_per_frame, jrange, k, 17)?;
        jitter.push(JitterPoint {
            total_wavelengths: total,
            frames: k,
            equal_spacing_delta_e: measure::diff(&jt, &eq)?.summary().delta_e2000.mean,
            jittered_delta_e: measure::diff(&jt, &acc)?.summary().delta_e2000.mean,
        });
    }

    let res = Results {
        quick: cfg.quick,
        budget: cfg.budget.clone(),
        adapter,
        observer: cfg.observer.clone().unwrap_or_else(|| "cie1931".into()),
        machine: machine(),
        seconds: t_start.elapsed().as_secs_f64(),
        notes: cfg.notes.clone(),
        edge_contrast: measure::EDGE_CONTRAST,
        cases: results,
        frame_time_scene: ft_case.id.clone(),
        frame_times,
        tradeoff,
        jitter_scene: ft_case.id.clone(),
        jitter_range: [jrange.min, jrange.max],
        jitter_quadrature: headline_quadrature().name().into(),
        jitter,
    };
    check()?;
    report::write_all(&cfg.out, &res)?;
    Ok(res)
}

/// Ours and naive at every N of `counts` in both quadratures, against the case's truth `t0`
/// (the renderer is already at the case's size).
fn sweep(
    r: &mut Renderer,
    c: &suite::Case,
    t0: &Image,
    mask: &[bool],
    range: WavelengthRange,
    counts: &[usize],
    check: &dyn Fn() -> Result<()>,
) -> Result<Vec<SweepPoint>> {
    let pb = bar((SPECTRAL_MODES.len() * Quadrature::ALL.len() * counts.len()) as u64, &c.id);
    pb.set_message("N sweep");
    let mut out = Vec::new();
    for (mode, name) in SPECTRAL_MODES {
        for q in Quadrature::ALL {
            for &n in counts {
                check()?;
                let s = RenderSettings { quadrature: q, ..measure::settings_for(&c.scene, *mode, n, range)? };
                let img = measure::realtime(r, &c.scene, &s)?;
                let e = Errors::of(&measure::diff(t0, &img)?, mask)?;
                out.push(SweepPoint {
                    mode: (*name).into(),
                    quadrature: q.name().into(),
                    wavelengths: n,
                    delta_e2000_mean: e.delta_e2000.mean,
                    delta_e2000_masked_mean: e.delta_e2000_masked.mean,
                    mae_linear_mean: e.mae_linear.mean,
                });
                pb.inc(1);
            }
        }
    }
    pb.finish_and_clear();
    Ok(out)
}

/// Pairs each timed configuration with the error the sweep measured for it in `case`; N values
/// that were timed but not swept (or the reverse) have no point. rgb's error is the headline's.
pub fn tradeoff(case: &CaseResult, frame_times: &[FrameTime]) -> Vec<TradeoffPoint> {
    frame_times
        .iter()
        .filter_map(|f| {
            let de = match (&f.quadrature, f.wavelengths) {
                (Some(q), Some(n)) => case.sweep_point(&f.mode, q, n)?.delta_e2000_mean,
                _ => case.modes.iter().find(|m| m.mode == f.mode)?.errors.delta_e2000.mean,
            };
            Some(TradeoffPoint {
                mode: f.mode.clone(),
                quadrature: f.quadrature.clone(),
                wavelengths: f.wavelengths,
                median_ms: f.median_ms,
                delta_e2000_mean: de,
            })
        })
        .collect()
}

/// A fresh renderer for a case's scene, with the underwater hooks when it has water (they are
/// per-renderer custom passes, so no case inherits another's).
fn renderer_for(
    c: &suite::Case,
    table: &std::sync::Arc<color::upsample::CoeffTable>,
    water: Option<&scene::water::WaterMedium>,
) -> Result<Renderer> {
    let mut r = Renderer::with_table(table.clone())?;
    r.set_scene(&c.scene)?;
    if let Some(w) = water {
        r.set_custom_shader(render::passes::underwater::shader(w)?)?;
    }
    Ok(r)
}

fn scene_range(s: &scene::Scene) -> Result<WavelengthRange> {
    Ok(match s.spectral.range {
        Some((a, b)) => WavelengthRange::new(a as f64, b as f64)?,
        None => WavelengthRange::VISIBLE,
    })
}

fn save_png(path: &Path, img: &Image) -> Result<()> {
    compare::io::write_image(path, img, WriteOptions::default())
        .with_context(|| format!("writing {}", path.display()))
}

fn write_exr(path: &Path, img: &Image) -> Result<()> {
    save_png(path, img)
}

/// CPU model, core count and memory, from /proc where available.
fn machine() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0);
    let mem = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            s.lines().next().and_then(|l| l.split_whitespace().nth(1)).and_then(|k| k.parse::<f64>().ok())
        })
        .map(|kb| format!(", {:.0} GiB RAM", kb / 1048576.0))
        .unwrap_or_default();
    format!("{cpu}, {cores} threads{mem}, {} {}", std::env::consts::OS, std::env::consts::ARCH)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn errors(de: f64) -> Errors {
        let st = color::metrics::Stats::of(&[de]).unwrap();
        Errors { delta_e2000: st, mae_linear: st, delta_e2000_masked: st, mae_linear_masked: st }
    }

    fn point(mode: &str, q: &str, n: usize, de: f64) -> SweepPoint {
        SweepPoint {
            mode: mode.into(),
            quadrature: q.into(),
            wavelengths: n,
            delta_e2000_mean: de,
            delta_e2000_masked_mean: de,
            mae_linear_mean: de,
        }
    }

    #[test]
    fn tradeoff_pairs_only_swept_and_timed_configurations() {
        let mode = |m: &str, de: f64| ModeResult {
            mode: m.into(),
            wavelengths: None,
            quadrature: None,
            image: String::new(),
            heatmap: String::new(),
            errors: errors(de),
            flip_mean: 0.0,
            flip_map: String::new(),
            flip_hdr_mean: 0.0,
        };
        let case = CaseResult {
            id: "c".into(),
            title: String::new(),
            truth_image: String::new(),
            width: 1,
            height: 1,
            truth_spp: 1,
            transport: "direct".into(),
            noise_floor: errors(0.0),
            masked_fraction: 0.0,
            modes: vec![mode("ours", 9.0), mode("rgb", 2.5)],
            sweep: vec![
                point("ours", "midpoint", 4, 3.0),
                point("ours", "prefiltered", 4, 2.0),
                point("ours", "prefiltered", 8, 1.0),
            ],
        };
        let ft = |m: &str, q: Option<&str>, n: Option<usize>, ms: f64| FrameTime {
            mode: m.into(),
            wavelengths: n,
            quadrature: q.map(Into::into),
            median_ms: ms,
        };
        let times = [
            ft("rgb", None, None, 5.0),
            ft("ours", Some("prefiltered"), Some(1), 6.0),
            ft("ours", Some("prefiltered"), Some(4), 7.0),
            ft("ours", Some("midpoint"), Some(4), 7.5),
            ft("ours", Some("prefiltered"), Some(8), 8.0),
            ft("naive", Some("prefiltered"), Some(8), 8.5),
        ];
        let t = tradeoff(&case, &times);
        type Row<'a> = (&'a str, Option<&'a str>, Option<usize>, f64, f64);
        let got: Vec<Row> = t
            .iter()
            .map(|p| {
                (p.mode.as_str(), p.quadrature.as_deref(), p.wavelengths, p.median_ms, p.delta_e2000_mean)
            })
            .collect();
        assert_eq!(
            got,
            [
                ("rgb", None, None, 5.0, 2.5),
                ("ours", Some("prefiltered"), Some(4), 7.0, 2.0),
                ("ours", Some("midpoint"), Some(4), 7.5, 3.0),
                ("ours", Some("prefiltered"), Some(8), 8.0, 1.0),
            ]
        );
    }
}
