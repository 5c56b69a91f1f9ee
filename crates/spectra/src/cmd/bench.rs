//! `spectra bench`: frame time of the real-time renderer in RGB mode and in spectral mode at
//! N = 1, 2, 4, …, 64 wavelengths, with the spectral/RGB ratio and the least-squares cost per
//! wavelength.
//!
//! Each frame is timed twice: GPU time (sum of the per-pass timestamp queries, when the
//! adapter supports them) and CPU wall time from submission until the frame has finished
//! (the timestamp read-back, or a device poll, waits for it). Warm-up frames absorb pipeline
//! and buffer creation. Frames are rendered back to back at a fixed camera; nothing is
//! presented, so there is no v-sync in the numbers.
//!
//! The spectral rows run once per `--quadrature` (the rules differ only in the weights uploaded,
//! so their cost should be the same; the benchmark shows it). `--reference` adds a row that
//! replaces the shading pass by a minimal single-light Lambert + GGX shader, the floor an RGB
//! deferred pass cannot go below, and prints the RGB shading pass against it.
//!
//! A scene with water (the built-in `underwater`) is drawn with the underwater pass and its
//! default (light-field) model, as `spectra render` draws it. `--suite` runs the fixed set of
//! scenes, sizes and wavelength counts of [`suite`] instead of one scene.

pub mod stats;
pub mod suite;

use super::setup::{EnvArgs, RgbMediumArgs, SceneArgs, SceneFileArgs, TableArgs, parse_size};
use anyhow::{Context, Result, anyhow, bail};
use clap::Args as ClapArgs;
use color::Quadrature;
use indicatif::{ProgressBar, ProgressStyle};
use render::passes::underwater;
use render::timing::PASSES;
use render::{CustomShader, Mode, PassTimings, RenderSettings, Renderer};
use stats::{LineFit, Summary, fit_line, percentile};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// The normal run's `--wavelengths`.
pub const WAVELENGTHS: &str = "1,2,4,8,16,32,64";

/// Most measured (and most warm-up) frames per configuration.
pub const MAX_FRAMES: usize = 10_000;

#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Built-in scene name (cornell, colorchecker, metamerism, iridescence, glass, clearcoat, specular, sheen, anisotropy, translucent, underwater, fog, tinted-fog) or a
    /// .gltf/.glb file. Not with --suite, which runs its own scenes.
    #[arg(required_unless_present = "suite")]
    pub scene: Option<String>,
    #[command(flatten)]
    pub files: SceneFileArgs,
    #[command(flatten)]
    pub env: EnvArgs,
    // Drawn with the RGB medium pass's default march steps (16).
    #[command(flatten)]
    pub rgb_medium: RgbMediumArgs,
    /// Frame size WIDTHxHEIGHT (or WIDTHXHEIGHT, WIDTH*HEIGHT).
    #[arg(long, default_value = "1280x720")]
    pub size: String,
    /// Measured frames per configuration (1–10000).
    #[arg(long, default_value_t = 60)]
    pub frames: usize,
    /// Unmeasured frames before each configuration (0–10000).
    #[arg(long, default_value_t = 10)]
    pub warmup: usize,
    /// Wavelength counts to measure, comma-separated (default 1,2,4,8,16,32,64; with --suite
    /// 1,4,8,16,32).
    #[arg(long, value_name = "N,N,…")]
    pub wavelengths: Option<String>,
    /// Also measure naive (box-upsampled) spectral rendering at every N.
    #[arg(long)]
    pub naive: bool,
    /// Write the table as CSV to this file (atomically).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    #[command(flatten)]
    pub table: TableArgs,
    /// Quadrature rules to measure the spectral rows with, comma-separated (midpoint,
    /// prefiltered).
    #[arg(long, default_value = "prefiltered")]
    pub quadrature: String,
    /// Also time the minimal reference shading pass (one light, Lambert + GGX, RGB) and print
    /// the RGB shading pass against it.
    #[arg(long)]
    pub reference: bool,
    /// Run the fixed benchmark suite (docs/benchmark.md, "Suite"): Cornell box with punctual
    /// lights, Cornell box + default environment, a textured glTF asset (--suite-asset) +
    /// default environment, and underwater; RGB and spectral (prefiltered) at each
    /// --wavelengths and each --suite-sizes.
    #[arg(long, conflicts_with_all = [
        "scene", "size", "naive", "reference", "quadrature", "env", "env_intensity", "env_rotation",
        "rgb_medium",
    ])]
    pub suite: bool,
    /// With --suite: the textured glTF asset of its third scene (e.g. DamagedHelmet.gltf from
    /// the Khronos glTF sample models); without it that scene is skipped.
    #[arg(long, value_name = "FILE")]
    pub suite_asset: Option<PathBuf>,
    /// With --suite: frame sizes, comma-separated [default: 1280x720,1920x1080].
    #[arg(long, value_name = "WxH,WxH,…")]
    pub suite_sizes: Option<String>,
    /// With --suite: also write the table as Markdown to this file (atomically).
    #[arg(long, value_name = "FILE")]
    pub markdown: Option<PathBuf>,
    /// Where the shading pass runs: `compute` (a compute pass over the screen) or `fragment`
    /// (a fullscreen triangle). Default: $SPECTRA_SHADING_STAGE, else compute on a GPU and
    /// fragment on a CPU driver (the images are the same; docs/benchmark.md, "Shading in a
    /// compute pass").
    #[arg(long, value_name = "STAGE", value_parser = parse_stage)]
    pub shading_stage: Option<render::ShadingStage>,
}

fn parse_stage(s: &str) -> std::result::Result<render::ShadingStage, String> {
    render::ShadingStage::parse(s).ok_or_else(|| format!("expected compute or fragment, got {s:?}"))
}

/// A renderer for the benchmark with the shading in `stage` (or the adapter's default), and the
/// line that names the adapter and the stage, printed first and written with the tables.
pub(crate) fn bench_renderer(
    coeffs: std::sync::Arc<color::upsample::CoeffTable>,
    stage: Option<render::ShadingStage>,
) -> Result<(Renderer, String)> {
    let mut r = Renderer::with_table(coeffs)?;
    if let Some(stage) = stage {
        r.set_shading_stage(stage)?;
    }
    let adapter = format!("{}; shading pass: {}", r.gpu().describe(), r.shading_stage().name());
    println!("adapter: {adapter}");
    Ok((r, adapter))
}

impl Args {
    /// The suite's own flags are refused without `--suite` (clap's `requires` cannot name a
    /// flag that is always set, to false or true).
    pub fn check_suite_flags(&self) -> Result<()> {
        // The frame times are kept for the medians: 4294967295 frames aborted allocating them.
        if !(1..=MAX_FRAMES).contains(&self.frames) {
            bail!("--frames {}: measure 1 to {MAX_FRAMES} frames", self.frames);
        }
        if self.warmup > MAX_FRAMES {
            bail!("--warmup {}: at most {MAX_FRAMES} frames", self.warmup);
        }
        if !self.suite {
            for (flag, given) in [
                ("--suite-asset", self.suite_asset.is_some()),
                ("--suite-sizes", self.suite_sizes.is_some()),
                ("--markdown", self.markdown.is_some()),
            ] {
                if given {
                    bail!("{flag} goes with --suite (the normal run measures one scene at --size)");
                }
            }
        }
        Ok(())
    }
}

/// The items of a comma list given with `flag`, trimmed; an empty one (`1,,2`, `1,`) is refused
/// rather than skipped, as a typo may hide there. None for a list of nothing (blank or commas).
pub(crate) fn list_items<'a>(flag: &str, s: &'a str) -> Result<Vec<&'a str>> {
    let items: Vec<&str> = s.split(',').map(str::trim).collect();
    if items.iter().all(|i| i.is_empty()) {
        return Ok(Vec::new());
    }
    if items.iter().any(|i| i.is_empty()) {
        bail!("{flag} '{s}': an empty item in the list");
    }
    Ok(items)
}

/// Parses `midpoint,prefiltered` into rules.
pub fn parse_rules(s: &str) -> Result<Vec<Quadrature>> {
    let mut out = Vec::new();
    for part in list_items("--quadrature", s)? {
        let q = Quadrature::parse(part).map_err(|e| anyhow!("--quadrature '{s}': {e}"))?;
        if !out.contains(&q) {
            out.push(q);
        }
    }
    if out.is_empty() {
        bail!("--quadrature '{s}': give at least one of midpoint, prefiltered");
    }
    Ok(out)
}

/// Parses `1,2,4` into wavelength counts, each within the renderer's limit.
pub fn parse_counts(s: &str) -> Result<Vec<usize>> {
    parse_counts_for("--wavelengths", s)
}

/// Parses a comma list of wavelength counts given with `flag` (named in the errors): each within
/// 1..=MAX_WAVELENGTHS, duplicates dropped, at least one, in the order given.
pub fn parse_counts_for(flag: &str, s: &str) -> Result<Vec<usize>> {
    let max = render::settings::MAX_WAVELENGTHS;
    let mut out = Vec::new();
    for part in list_items(flag, s)? {
        let n: usize = part.parse().map_err(|_| anyhow!("{flag} '{s}': '{part}' is not a whole number"))?;
        if n == 0 || n > max {
            bail!("{flag} '{s}': {n} is outside 1..={max}");
        }
        if !out.contains(&n) {
            out.push(n);
        }
    }
    if out.is_empty() {
        bail!("{flag} '{s}': give at least one count, e.g. 1,2,4,8");
    }
    Ok(out)
}

/// One measured configuration.
#[derive(Clone, Debug)]
pub struct Row {
    pub mode: Mode,
    /// The spectral rows' rule; `None` for RGB.
    pub quadrature: Option<Quadrature>,
    /// The minimal reference shading pass instead of the real one (RGB mode).
    pub reference: bool,
    /// `None` for RGB (its cost does not depend on N).
    pub n: Option<usize>,
    pub gpu: Option<Summary>,
    /// GPU time of the shading pass alone.
    pub shading: Option<Summary>,
    /// Median GPU time of each pass, in [`PASSES`] order.
    pub passes: Option<[f64; PASSES.len()]>,
    pub cpu: Summary,
}

impl Row {
    /// `rgb`, `reference`, or the spectral mode with its rule (`spectral/prefiltered`).
    pub fn name(&self) -> String {
        match (self.reference, self.quadrature) {
            (true, _) => "reference".into(),
            (false, Some(q)) => format!("{}/{}", self.mode.name(), q.name()),
            (false, None) => self.mode.name().into(),
        }
    }

    /// The time the comparisons use: GPU when measured, else CPU wall time.
    pub fn primary(&self) -> f64 {
        self.gpu.map(|g| g.median).unwrap_or(self.cpu.median)
    }

    /// The median GPU time of pass `pass` (a name in [`PASSES`]).
    pub fn pass(&self, pass: &str) -> Option<f64> {
        let i = PASSES.iter().position(|p| *p == pass)?;
        self.passes.map(|p| p[i])
    }
}

/// The per-pass columns the normal CSV appends after its original ones (the shading pass has
/// its column there already).
const EXTRA_PASSES: [&str; 5] = ["shadow", "gbuffer", "custom", "post", "occlusion"];

/// The least-squares ms-per-wavelength line of one mode's rows under one rule.
pub fn slope(rows: &[Row], mode: Mode, rule: Quadrature) -> Option<LineFit> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.mode == mode && r.quadrature == Some(rule))
        .filter_map(|r| Some((r.n? as f64, r.primary())))
        .collect();
    fit_line(&pts)
}

/// The baseline the ratios divide by: the real RGB row.
fn rgb_row(rows: &[Row]) -> Option<&Row> {
    rows.iter().find(|r| r.mode == Mode::Rgb && !r.reference)
}

/// The CSV text: one line per configuration, times in milliseconds, empty where not measured.
pub fn csv(rows: &[Row]) -> String {
    let rgb = rgb_row(rows).map(Row::primary);
    let mut s = String::from(
        "mode,wavelengths,gpu_median_ms,gpu_p10_ms,gpu_p90_ms,shading_gpu_median_ms,cpu_median_ms,cpu_p10_ms,cpu_p90_ms,ratio_to_rgb",
    );
    for p in EXTRA_PASSES {
        let _ = write!(s, ",{p}_gpu_median_ms");
    }
    s.push('\n');
    for r in rows {
        let g = |f: fn(&Summary) -> f64| r.gpu.as_ref().map(|g| format!("{:.4}", f(g))).unwrap_or_default();
        let ratio = rgb.map(|b| format!("{:.4}", r.primary() / b)).unwrap_or_default();
        let _ = write!(
            s,
            "{},{},{},{},{},{},{:.4},{:.4},{:.4},{}",
            r.name(),
            r.n.map(|n| n.to_string()).unwrap_or_default(),
            g(|s| s.median),
            g(|s| s.p10),
            g(|s| s.p90),
            r.shading.map(|s| format!("{:.4}", s.median)).unwrap_or_default(),
            r.cpu.median,
            r.cpu.p10,
            r.cpu.p90,
            ratio
        );
        for p in EXTRA_PASSES {
            let _ = write!(s, ",{}", r.pass(p).map(|v| format!("{v:.4}")).unwrap_or_default());
        }
        s.push('\n');
    }
    s
}

/// The human-readable table plus the per-wavelength fit lines.
pub fn table(rows: &[Row]) -> String {
    let rgb = rgb_row(rows).map(Row::primary);
    let mut s = format!(
        "{:<21} {:>3}  {:>9} {:>8} {:>8} {:>9}  {:>9} {:>8} {:>8}  {:>7}\n",
        "mode", "N", "GPU med", "p10", "p90", "shading", "CPU med", "p10", "p90", "×RGB"
    );
    let opt = |v: Option<f64>| v.map(|v| format!("{v:.2}")).unwrap_or_else(|| "–".into());
    for r in rows {
        let _ = writeln!(
            s,
            "{:<21} {:>3}  {:>9} {:>8} {:>8} {:>9}  {:>9.2} {:>8.2} {:>8.2}  {:>7}",
            r.name(),
            r.n.map(|n| n.to_string()).unwrap_or_else(|| "–".into()),
            opt(r.gpu.map(|g| g.median)),
            opt(r.gpu.map(|g| g.p10)),
            opt(r.gpu.map(|g| g.p90)),
            opt(r.shading.map(|g| g.median)),
            r.cpu.median,
            r.cpu.p10,
            r.cpu.p90,
            rgb.map(|b| format!("{:.2}", r.primary() / b)).unwrap_or_else(|| "–".into()),
        );
    }
    for mode in [Mode::Spectral, Mode::Naive] {
        for rule in Quadrature::ALL {
            if let Some(f) = slope(rows, mode, rule) {
                // Through two points a line always fits: no R² to report.
                let points = rows
                    .iter()
                    .filter(|r| r.mode == mode && r.quadrature == Some(rule) && r.n.is_some())
                    .count();
                let fit = if points > 2 {
                    format!("least squares over N, R² = {:.4}", f.r2)
                } else {
                    "the line through two N; a third N tests whether it is one".into()
                };
                let _ = writeln!(
                    s,
                    "{}/{}: {:.3} ms per wavelength + {:.2} ms ({fit})",
                    mode.name(),
                    rule.name(),
                    f.slope,
                    f.intercept
                );
            }
        }
    }
    // The rules upload different weights to the same shader: their cost should match.
    for n in rows.iter().filter_map(|r| r.n) {
        let at =
            |q| rows.iter().find(|r| r.mode == Mode::Spectral && r.n == Some(n) && r.quadrature == Some(q));
        if let (Some(m), Some(p)) = (at(Quadrature::Midpoint), at(Quadrature::Prefiltered))
            && !s.contains(&format!("N = {n}: prefiltered"))
        {
            let _ = writeln!(s, "N = {n}: prefiltered / midpoint = {:.3}", p.primary() / m.primary());
        }
    }
    let shading = |r: Option<&Row>| r.and_then(|r| r.shading).map(|s| s.median);
    if let (Some(real), Some(floor)) = (shading(rgb_row(rows)), shading(rows.iter().find(|r| r.reference))) {
        let _ = writeln!(
            s,
            "RGB shading pass {real:.2} ms vs the minimal reference {floor:.2} ms: {:.2}×",
            real / floor
        );
    }
    s
}

/// The 1-minute load average (Linux), to flag runs where other processes shared the CPU.
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

/// The load line printed after the table, and whether other processes competed for the CPU:
/// the load before the run should be well under the core count, and after it (this
/// benchmark keeps up to every core busy on a CPU driver) under 1.5× the cores.
pub fn load_report(
    before: Option<f64>,
    after: Option<f64>,
    cores: usize,
    cpu_device: bool,
) -> Option<String> {
    let (b, a) = (before?, after?);
    let busy = b > 0.5 * cores as f64 || a > 1.5 * cores as f64;
    let mut s = format!("load average {b:.1} before, {a:.1} after, on {cores} cores");
    if busy {
        s += "; other processes were competing for the CPU";
        if cpu_device {
            s += ", which runs this adapter: the times are inflated";
        }
    }
    Some(s)
}

/// The time of each frame of one configuration, summarised.
#[derive(Clone, Debug)]
pub struct Measured {
    pub gpu: Option<Summary>,
    pub shading: Option<Summary>,
    pub passes: Option<[f64; PASSES.len()]>,
    pub cpu: Summary,
}

/// The median of each pass over `frames`; `None` without frames.
pub fn pass_medians(frames: &[PassTimings]) -> Option<[f64; PASSES.len()]> {
    let mut out = [0.0; PASSES.len()];
    for (i, m) in out.iter_mut().enumerate() {
        *m = percentile(&frames.iter().map(|t| t.ms[i]).collect::<Vec<_>>(), 50.0)?;
    }
    Some(out)
}

/// Renders `warmup` unmeasured then `frames` measured frames with `settings` (one tick of
/// `bar` each) and summarises their times. Stops with an error once Ctrl-C was pressed.
pub fn measure(
    r: &mut Renderer,
    camera: &scene::Camera,
    settings: &RenderSettings,
    (warmup, frames): (usize, usize),
    bar: &ProgressBar,
) -> Result<Measured> {
    let mut timings = Vec::with_capacity(frames);
    let mut cpu_ms = Vec::with_capacity(frames);
    for i in 0..warmup + frames {
        if color::cancel::is_cancelled() {
            bail!("interrupted: nothing written");
        }
        let t0 = Instant::now();
        r.render(camera, settings)?;
        // Reading the timestamps waits for the frame; without them, wait explicitly.
        let t = r.read_timings()?;
        if t.is_none() {
            r.wait()?;
        }
        let wall = t0.elapsed().as_secs_f64() * 1e3;
        if i >= warmup {
            cpu_ms.push(wall);
            timings.extend(t);
        }
        bar.inc(1);
    }
    let gpu_ms: Vec<f64> = timings.iter().map(PassTimings::total_ms).collect();
    let shading_ms: Vec<f64> = timings.iter().filter_map(|t| t.get("shading")).collect();
    Ok(Measured {
        gpu: Summary::of(&gpu_ms),
        shading: Summary::of(&shading_ms),
        passes: pass_medians(&timings),
        cpu: Summary::of(&cpu_ms).context("no frame times")?,
    })
}

/// The custom shader a benchmark draws `scene` with, and a phrase for the header: the
/// underwater pass with its default (light-field) model when the scene has water, else the RGB
/// medium's hooks (`--rgb-medium` or the scene's), else none.
pub fn bench_media(
    scene: &scene::Scene,
    rgb_medium: Option<&str>,
    table: &color::upsample::CoeffTable,
) -> Result<(Option<CustomShader>, String)> {
    let water = super::setup::water_medium(scene, None, None)?;
    let rgb = super::setup::realtime_medium(scene, rgb_medium, water.is_some(), table, Default::default())?;
    Ok(match water {
        Some(m) => {
            let ty = m.water_type.map_or("custom".to_string(), |t| t.to_string());
            let shader = underwater::shader_with(&m, &underwater::Options::default())
                .with_context(|| format!("the underwater pass of {}", scene.source))?;
            (Some(shader), format!(", under water {ty} at {} m (light-field model)", m.depth))
        }
        None => {
            let what = if rgb.is_some() { ", in an RGB medium" } else { "" };
            (rgb, what.to_string())
        }
    })
}

/// The frame-count progress bar every benchmark shows.
pub fn progress_bar(frames: u64) -> ProgressBar {
    ProgressBar::new(frames).with_style(
        ProgressStyle::with_template("{msg:>14} [{bar:40}] {pos}/{len} frames, {eta} left")
            .expect("static template")
            .progress_chars("=> "),
    )
}

/// Whether the adapter has timestamp queries, and the header's phrase for how frames are timed.
pub fn timing_of(r: &Renderer) -> (bool, &'static str) {
    let has_ts = r.gpu().features.contains(wgpu::Features::TIMESTAMP_QUERY);
    (has_ts, if has_ts { "GPU timestamps + CPU wall" } else { "CPU wall only (no timestamp queries)" })
}

/// Whether the adapter is a CPU rasteriser (its times are CPU milliseconds).
pub fn cpu_device(r: &Renderer) -> bool {
    r.gpu().adapter.get_info().device_type == wgpu::DeviceType::Cpu
}

pub fn run(args: Args) -> Result<()> {
    args.check_suite_flags()?;
    if args.suite {
        return suite::run(args);
    }
    let (width, height) = parse_size(&args.size)?;
    let counts = parse_counts(args.wavelengths.as_deref().unwrap_or(WAVELENGTHS))?;
    if let Some(path) = &args.csv {
        super::check_output("--csv", path)?;
    }
    let name = args.scene.clone().context("give a scene, or --suite")?;
    let scene_args = SceneArgs { scene: name, files: args.files.clone(), env: args.env.clone() };
    let scene = scene_args.load(None)?;
    let mut inputs = scene_args.input_files(&scene);
    inputs.extend(args.table.input_files());
    inputs.extend(args.rgb_medium.input_files());
    super::check_outputs(&[("--csv", args.csv.as_deref())], &inputs)?;
    let coeffs = args.table.load()?;
    let (custom, under) = bench_media(&scene, args.rgb_medium.arg(), &coeffs)?;
    let (mut r, _) = bench_renderer(coeffs, args.shading_stage)?;
    r.set_scene(&scene)?;
    if let Some(c) = custom {
        r.set_custom_shader(c)?;
    }
    r.resize(width, height).map_err(|e| anyhow::anyhow!("--size {width}x{height}: {e}"))?;
    let load_before = load_average();
    let (has_ts, timing) = timing_of(&r);
    eprintln!(
        "{}{under} {width}×{height}; {} frames after {} warm-up; time: {timing}",
        scene.source, args.frames, args.warmup,
    );

    let rules = parse_rules(&args.quadrature)?;
    // (mode, rule, reference, N)
    let mut configs: Vec<(Mode, Option<Quadrature>, bool, Option<usize>)> =
        vec![(Mode::Rgb, None, false, None)];
    if args.reference {
        configs.push((Mode::Rgb, None, true, None));
    }
    for &q in &rules {
        configs.extend(counts.iter().map(|&n| (Mode::Spectral, Some(q), false, Some(n))));
        if args.naive {
            configs.extend(counts.iter().map(|&n| (Mode::Naive, Some(q), false, Some(n))));
        }
    }
    let per = (args.warmup + args.frames) as u64;
    let bar = progress_bar(per * configs.len() as u64);
    let mut rows = Vec::new();
    for (mode, quadrature, reference, n) in configs {
        bar.set_message(format!("{} N={}", mode.name(), n.map(|n| n.to_string()).unwrap_or("–".into())));
        let settings = RenderSettings {
            mode,
            wavelengths: n.unwrap_or(RenderSettings::default().wavelengths),
            quadrature: quadrature.unwrap_or_default(),
            timestamps: has_ts,
            ..Default::default()
        };
        r.set_reference_shading(reference)?;
        let m = match measure(&mut r, &scene.camera, &settings, (args.warmup, args.frames), &bar) {
            Ok(m) => m,
            Err(e) => {
                bar.abandon();
                return Err(e);
            }
        };
        rows.push(Row {
            mode,
            quadrature,
            reference,
            n,
            gpu: m.gpu,
            shading: m.shading,
            passes: m.passes,
            cpu: m.cpu,
        });
    }
    bar.finish_and_clear();
    r.set_reference_shading(false)?;
    print!("{}", table(&rows));
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    if let Some(line) = load_report(load_before, load_average(), cores, cpu_device(&r)) {
        println!("{line}");
    }
    if let Some(path) = &args.csv {
        write_tables(&[(path, csv(&rows))])?;
    }
    Ok(())
}

/// Writes tables (CSV, markdown) together or not at all, each atomically, and says so: staged
/// first, then put in place, so a full disk on the second does not leave the first replaced
/// beside the second's old version.
pub(crate) fn write_tables(tables: &[(&std::path::Path, String)]) -> Result<()> {
    let staged = tables
        .iter()
        .map(|(path, text)| super::stage_output(path, text.as_bytes()))
        .collect::<Result<Vec<_>>>()?;
    super::commit_outputs(staged)?;
    for (path, _) in tables {
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    #[test]
    fn defaults_and_counts() {
        let a = Cli::try_parse_from(["bench", "cornell"]).unwrap().args;
        assert_eq!((a.size.as_str(), a.frames, a.warmup), ("1280x720", 60, 10));
        assert_eq!(a.wavelengths, None);
        assert_eq!(parse_counts(WAVELENGTHS).unwrap(), vec![1, 2, 4, 8, 16, 32, 64]);
        assert_eq!(parse_counts(" 4, 4,8 ").unwrap(), vec![4, 8]);
        assert!(parse_counts("0").unwrap_err().to_string().contains("outside"));
        assert!(parse_counts("4,x").unwrap_err().to_string().contains("'x'"));
        for s in [" ", ",", " , "] {
            assert!(parse_counts(s).unwrap_err().to_string().contains("at least one"), "{s}");
        }
        // An empty item is a typo's place, not skipped (1,,2 ran 1 and 2).
        for s in ["1,,2", "1,2,", ",4"] {
            assert!(parse_counts(s).unwrap_err().to_string().contains("empty item"), "{s}");
        }
        assert!(parse_rules("midpoint,,prefiltered").unwrap_err().to_string().contains("--quadrature"));
        assert!(Cli::try_parse_from(["bench", "cornell", "--frames", "-3"]).is_err());
    }

    fn summary(m: f64) -> Summary {
        Summary { median: m, p10: m - 1.0, p90: m + 1.0 }
    }

    fn rows() -> Vec<Row> {
        let row = |mode, quadrature, n: Option<usize>, ms: f64| Row {
            mode,
            quadrature,
            reference: false,
            n,
            gpu: Some(summary(ms)),
            shading: Some(summary(ms / 2.0)),
            passes: Some([ms / 8.0, ms / 4.0, ms / 2.0, 0.0, ms / 8.0, ms / 16.0]),
            cpu: summary(ms + 5.0),
        };
        let mut rows = vec![row(Mode::Rgb, None, None, 20.0)];
        for n in [1, 2, 4, 8] {
            rows.push(row(Mode::Spectral, Some(Quadrature::Prefiltered), Some(n), 20.0 + 2.5 * n as f64));
        }
        rows
    }

    #[test]
    fn slope_ratio_and_csv() {
        let rows = rows();
        let f = slope(&rows, Mode::Spectral, Quadrature::Prefiltered).unwrap();
        assert!((f.slope - 2.5).abs() < 1e-12 && (f.intercept - 20.0).abs() < 1e-12);
        assert!(slope(&rows, Mode::Naive, Quadrature::Prefiltered).is_none());
        assert!(slope(&rows, Mode::Spectral, Quadrature::Midpoint).is_none());
        let text = csv(&rows);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 6);
        assert!(lines[0].starts_with("mode,wavelengths,gpu_median_ms,"), "{}", lines[0]);
        assert!(
            lines[0].ends_with(
                ",ratio_to_rgb,shadow_gpu_median_ms,gbuffer_gpu_median_ms,custom_gpu_median_ms,post_gpu_median_ms,\
                 occlusion_gpu_median_ms"
            ),
            "{}",
            lines[0]
        );
        assert_eq!(
            lines[1],
            "rgb,,20.0000,19.0000,21.0000,10.0000,25.0000,24.0000,26.0000,1.0000,2.5000,5.0000,0.0000,2.5000,1.2500"
        );
        // N = 8: 40 ms / 20 ms.
        assert_eq!(
            lines[5],
            "spectral/prefiltered,8,40.0000,39.0000,41.0000,20.0000,45.0000,44.0000,46.0000,2.0000,5.0000,10.0000,0.0000,5.0000,2.5000"
        );
        assert!(table(&rows).contains("spectral/prefiltered: 2.500 ms per wavelength + 20.00 ms"));
        assert_eq!(parse_rules(" midpoint,prefiltered,midpoint").unwrap(), Quadrature::ALL.to_vec());
        assert!(parse_rules("gauss").unwrap_err().to_string().contains("gauss"));
    }

    #[test]
    fn load_report_flags_busy_runs() {
        assert_eq!(load_report(None, Some(1.0), 2, true), None);
        let quiet = load_report(Some(0.2), Some(2.1), 2, true).unwrap();
        assert_eq!(quiet, "load average 0.2 before, 2.1 after, on 2 cores");
        let busy = load_report(Some(4.2), Some(7.3), 2, true).unwrap();
        assert!(busy.contains("competing") && busy.contains("inflated"), "{busy}");
        let late = load_report(Some(0.1), Some(3.5), 2, false).unwrap();
        assert!(late.contains("competing") && !late.contains("inflated"), "{late}");
    }

    #[test]
    fn cpu_time_is_used_without_timestamps() {
        let mut rows = rows();
        for r in &mut rows {
            r.gpu = None;
            r.shading = None;
            r.passes = None;
        }
        let lines: Vec<String> = csv(&rows).lines().map(String::from).collect();
        // 45 ms / 25 ms, and no GPU columns.
        assert_eq!(lines[5], "spectral/prefiltered,8,,,,,45.0000,44.0000,46.0000,1.8000,,,,,");
    }

    #[test]
    fn pass_medians_per_pass() {
        let t = |k: f64| PassTimings { ms: [k, 2.0 * k, 3.0 * k, 0.0, 1.0, 0.5 * k] };
        assert_eq!(pass_medians(&[]), None);
        assert_eq!(pass_medians(&[t(1.0), t(9.0), t(2.0)]), Some([2.0, 4.0, 6.0, 0.0, 1.0, 1.0]));
        let row = Row {
            mode: Mode::Rgb,
            quadrature: None,
            reference: false,
            n: None,
            gpu: None,
            shading: None,
            passes: pass_medians(&[t(1.0)]),
            cpu: summary(3.0),
        };
        assert_eq!((row.pass("gbuffer"), row.pass("post"), row.pass("nope")), (Some(2.0), Some(1.0), None));
        assert_eq!(row.pass("occlusion"), Some(0.5));
    }
}
