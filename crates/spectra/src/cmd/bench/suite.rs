//! `spectra bench --suite`: one fixed set of configurations, the command to run on a real GPU
//! (docs/benchmark.md, "Suite").
//!
//! Scenes ([`scenes`]): the Cornell box with its punctual lights only (`--env none`), the Cornell
//! box + the default environment, a textured glTF asset given with `--suite-asset` + the
//! default environment (skipped, with a line saying so, without one: the assets are not in the
//! repository), and the built-in `underwater` scene with the underwater pass's default
//! (light-field) model. Each at every `--suite-sizes` size (default [`SIZES`]), RGB once and
//! spectral (prefiltered quadrature) at every `--wavelengths` N (default [`WAVELENGTHS`]).
//!
//! Each row is measured as the normal benchmark measures ([`super::measure`]). A scene that
//! does not load, a size the device refuses or a row that fails is reported and skipped; the run
//! fails only when no row was measured, or on Ctrl-C (nothing written).

use super::{Args, Measured, Row, bench_media, cpu_device, load_average, load_report, measure};
use super::{parse_counts_for, progress_bar, timing_of};
use crate::cmd::setup::{EnvArgs, SceneArgs, parse_size};
use anyhow::{Context, Result, bail};
use color::Quadrature;
use render::timing::PASSES;
use render::{Mode, RenderSettings};
use std::fmt::Write as _;
use std::path::Path;

/// The suite's default `--suite-sizes`.
pub const SIZES: &str = "1280x720,1920x1080";
/// The suite's default `--wavelengths`.
pub const WAVELENGTHS: &str = "1,4,8,16,32";

/// One scene of the suite.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SuiteScene {
    /// Its name in the tables: `cornell`, `cornell+env`, `<asset file stem>+env`, `underwater`.
    pub label: String,
    /// A built-in scene name or the asset's path, as a scene argument.
    pub scene: String,
    /// Its `--env`: `none`, `default`, or `None` for the scene's own choice.
    pub env: Option<&'static str>,
}

/// The suite's scenes in order, and (without `asset`) the line saying how to include the
/// skipped asset row.
pub fn scenes(asset: Option<&Path>) -> (Vec<SuiteScene>, Option<String>) {
    let builtin =
        |label: &str, scene: &str, env| SuiteScene { label: label.into(), scene: scene.into(), env };
    let mut out =
        vec![builtin("cornell", "cornell", Some("none")), builtin("cornell+env", "cornell", Some("default"))];
    let note = match asset {
        Some(p) => {
            let stem = p.file_stem().map_or("asset".into(), |s| s.to_string_lossy().into_owned());
            out.push(SuiteScene {
                label: format!("{stem}+env"),
                scene: p.to_string_lossy().into_owned(),
                env: Some("default"),
            });
            None
        }
        None => Some(
            "skipping the textured-asset scene: give one with --suite-asset FILE.gltf (e.g. \
             DamagedHelmet.gltf from the Khronos glTF sample models; they are not in this repository)"
                .to_string(),
        ),
    };
    out.push(builtin("underwater", "underwater", None));
    (out, note)
}

/// The configurations of each scene and size: RGB, then spectral (prefiltered) at each N.
pub fn configs(counts: &[usize]) -> Vec<(Mode, Option<Quadrature>, Option<usize>)> {
    let mut out = vec![(Mode::Rgb, None, None)];
    out.extend(counts.iter().map(|&n| (Mode::Spectral, Some(Quadrature::Prefiltered), Some(n))));
    out
}

/// Parses `1280x720,1920x1080` (each as `--size` takes it), duplicates dropped, at least one; an
/// empty item is refused as the other lists refuse it (`16x12,,16x12` ran one size silently).
pub fn parse_sizes(s: &str) -> Result<Vec<(u32, u32)>> {
    let mut out = Vec::new();
    for part in super::list_items("--suite-sizes", s)? {
        let size = parse_size(part).with_context(|| format!("--suite-sizes '{s}'"))?;
        if !out.contains(&size) {
            out.push(size);
        }
    }
    if out.is_empty() {
        bail!("--suite-sizes '{s}': give at least one size, e.g. 1280x720");
    }
    Ok(out)
}

/// One measured row of the suite.
#[derive(Clone, Debug)]
pub struct SuiteRow {
    /// [`SuiteScene::label`].
    pub scene: String,
    pub size: (u32, u32),
    pub row: Row,
}

impl SuiteRow {
    pub fn size_name(&self) -> String {
        format!("{}x{}", self.size.0, self.size.1)
    }

    /// This row's time over its scene and size's RGB row's (GPU medians when measured, else
    /// CPU); `None` without that RGB row.
    pub fn ratio(&self, rows: &[SuiteRow]) -> Option<f64> {
        let rgb = rows.iter().find(|r| {
            r.scene == self.scene && r.size == self.size && r.row.mode == Mode::Rgb && !r.row.reference
        })?;
        Some(self.row.primary() / rgb.row.primary())
    }
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() }
}

/// A Markdown table cell: `|` escaped, line breaks as spaces.
fn md_cell(s: &str) -> String {
    s.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// `v` with `digits` decimals, or `empty` when not measured.
fn num(v: Option<f64>, digits: usize, empty: &str) -> String {
    v.map(|v| format!("{v:.digits$}")).unwrap_or_else(|| empty.to_string())
}

/// The cells of one row, in the order of the CSV's columns after scene and size: mode, N, GPU
/// median/p10/p90, CPU median/p10/p90, ratio to RGB, then each pass's GPU median.
fn cells(r: &SuiteRow, rows: &[SuiteRow], digits: usize, empty: &str) -> Vec<String> {
    let g = r.row.gpu;
    let mut c = vec![
        r.row.name(),
        r.row.n.map(|n| n.to_string()).unwrap_or_else(|| empty.to_string()),
        num(g.map(|g| g.median), digits, empty),
        num(g.map(|g| g.p10), digits, empty),
        num(g.map(|g| g.p90), digits, empty),
        num(Some(r.row.cpu.median), digits, empty),
        num(Some(r.row.cpu.p10), digits, empty),
        num(Some(r.row.cpu.p90), digits, empty),
        num(r.ratio(rows), digits, empty),
    ];
    c.extend(PASSES.iter().map(|p| num(r.row.pass(p), digits, empty)));
    c
}

/// The suite's CSV: one line per row, times in milliseconds, empty where not measured, the
/// adapter in the last column.
pub fn csv(rows: &[SuiteRow], adapter: &str) -> String {
    let mut s = String::from(
        "scene,size,mode,wavelengths,gpu_median_ms,gpu_p10_ms,gpu_p90_ms,cpu_median_ms,cpu_p10_ms,cpu_p90_ms,ratio_to_rgb",
    );
    for p in PASSES {
        let _ = write!(s, ",{p}_gpu_median_ms");
    }
    s.push_str(",adapter\n");
    for r in rows {
        let mut line = vec![csv_field(&r.scene), r.size_name()];
        line.extend(cells(r, rows, 4, "").iter().map(|c| csv_field(c)));
        line.push(csv_field(adapter));
        s += &line.join(",");
        s.push('\n');
    }
    s
}

/// The column headings of the table and the Markdown table.
fn headings() -> Vec<String> {
    let mut h: Vec<String> =
        ["scene", "size", "mode", "N", "GPU med", "p10", "p90", "CPU med", "p10", "p90", "×RGB"]
            .map(String::from)
            .to_vec();
    h.extend(PASSES.iter().map(|p| p.to_string()));
    h
}

/// The suite's Markdown: a line naming the adapter and the measurement, the table (ms), and the
/// list of what was skipped.
pub fn markdown(rows: &[SuiteRow], header: &str, skipped: &[String]) -> String {
    let mut s = format!("{}\n\n", md_cell(header));
    let h = headings();
    let _ = writeln!(s, "| {} |", h.join(" | "));
    // Text columns left-aligned, numbers right-aligned.
    let align: Vec<&str> = (0..h.len()).map(|i| if i < 3 { "---" } else { "---:" }).collect();
    let _ = writeln!(s, "|{}|", align.join("|"));
    for r in rows {
        let mut c = vec![md_cell(&r.scene), r.size_name()];
        c.extend(cells(r, rows, 2, "–").iter().map(|c| md_cell(c)));
        let _ = writeln!(s, "| {} |", c.join(" | "));
    }
    if !skipped.is_empty() {
        s += "\nSkipped:\n\n";
        for k in skipped {
            let _ = writeln!(s, "- {}", md_cell(k));
        }
    }
    s
}

/// The table printed on stdout (ms).
pub fn table(rows: &[SuiteRow]) -> String {
    let mut body: Vec<Vec<String>> = vec![headings()];
    for r in rows {
        let mut c = vec![r.scene.clone(), r.size_name()];
        c.extend(cells(r, rows, 2, "–"));
        body.push(c);
    }
    let cols = body[0].len();
    let width: Vec<usize> =
        (0..cols).map(|i| body.iter().map(|line| line[i].chars().count()).max().unwrap_or(0)).collect();
    let mut s = String::new();
    for line in &body {
        let mut out = String::new();
        for (i, cell) in line.iter().enumerate() {
            let pad = " ".repeat(width[i] - cell.chars().count());
            if i > 0 {
                out.push_str("  ");
            }
            if i < 3 {
                out += &format!("{cell}{pad}");
            } else {
                out += &format!("{pad}{cell}");
            }
        }
        s += out.trim_end();
        s.push('\n');
    }
    s
}

/// Loads `sc` with the suite's environment choice, and its custom shader.
fn load(
    args: &Args,
    sc: &SuiteScene,
    table: &color::upsample::CoeffTable,
) -> Result<(scene::Scene, Option<render::CustomShader>, String)> {
    let env = EnvArgs { env: sc.env.map(String::from), ..Default::default() };
    let scene = SceneArgs { scene: sc.scene.clone(), files: args.files.clone(), env }.load(None)?;
    let (custom, under) = bench_media(&scene, None, table)?;
    Ok((scene, custom, under))
}

pub fn run(args: Args) -> Result<()> {
    let sizes = parse_sizes(args.suite_sizes.as_deref().unwrap_or(SIZES))?;
    let counts = parse_counts_for("--wavelengths", args.wavelengths.as_deref().unwrap_or(WAVELENGTHS))?;
    if let Some(path) = &args.csv {
        crate::cmd::check_output("--csv", path)?;
    }
    if let Some(path) = &args.markdown {
        crate::cmd::check_output("--markdown", path)?;
    }
    let mut inputs = args.table.input_files();
    if let Some(asset) = &args.suite_asset {
        // The asset and every file it references (buffers, textures, its environment), so
        // that no table is written over one of them; loaded again, with its warnings, when
        // its turn comes. One that does not load is skipped then, as the suite skips any
        // scene that fails, and only its own path is guarded.
        let files = match args.files.load(&asset.to_string_lossy()) {
            Ok(scene) => scene.inputs,
            Err(_) => vec![asset.clone()],
        };
        inputs.extend(files.iter().enumerate().map(|(i, p)| {
            let what = if i == 0 {
                "--suite-asset".to_string()
            } else {
                format!("file --suite-asset references ({})", p.display())
            };
            (what, p.clone())
        }));
    }
    crate::cmd::check_outputs(
        &[("--csv", args.csv.as_deref()), ("--markdown", args.markdown.as_deref())],
        &inputs,
    )?;
    let (scenes, note) = scenes(args.suite_asset.as_deref());
    let coeffs = args.table.load()?;
    let (mut r, adapter) = super::bench_renderer(coeffs.clone(), args.shading_stage)?;
    let (has_ts, timing) = timing_of(&r);
    let configs = configs(&counts);
    let size_list = sizes.iter().map(|(w, h)| format!("{w}×{h}")).collect::<Vec<_>>().join(", ");
    let header = format!(
        "spectra bench --suite on {adapter}: {} frames after {} warm-up per row; time: {timing}; ms",
        args.frames, args.warmup
    );
    eprintln!(
        "suite: {} scenes × sizes {size_list} × {} configurations (rgb, spectral/prefiltered N = {}); \
         {} frames after {} warm-up; time: {timing}",
        scenes.len(),
        configs.len(),
        counts.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(","),
        args.frames,
        args.warmup,
    );
    let mut skipped: Vec<String> = note.into_iter().collect();
    if let Some(n) = skipped.first() {
        eprintln!("{n}");
    }
    let load_before = load_average();
    let per = (args.warmup + args.frames) as u64;
    let per_scene = per * (configs.len() * sizes.len()) as u64;
    let bar = progress_bar(per_scene * scenes.len() as u64);
    // A failure is reported and skipped, except after Ctrl-C: then nothing is written.
    let skip = |what: String, e: anyhow::Error, skipped: &mut Vec<String>| -> Result<()> {
        if color::cancel::is_cancelled() {
            bar.abandon();
            return Err(e);
        }
        let line = format!("{what}: {e:#}");
        bar.suspend(|| eprintln!("skipping {line}"));
        skipped.push(line);
        Ok(())
    };
    let mut rows: Vec<SuiteRow> = Vec::new();
    let mut custom_set = false;
    for (si, sc) in scenes.iter().enumerate() {
        let done = |k: u64| per_scene * si as u64 + k;
        let loaded = bar.suspend(|| load(&args, sc, &coeffs));
        let set = loaded.and_then(|(scene, custom, under)| {
            r.set_scene(&scene)?;
            // The previous scene's hooks go when this one has none.
            if custom.is_some() || custom_set {
                custom_set = custom.is_some();
                r.set_custom_shader(custom.unwrap_or_default())?;
            }
            Ok((scene, under))
        });
        let (scene, under) = match set {
            Ok(s) => s,
            Err(e) => {
                skip(format!("scene {} ({})", sc.label, sc.scene), e, &mut skipped)?;
                bar.set_position(done(per_scene));
                continue;
            }
        };
        if !under.is_empty() {
            bar.suspend(|| eprintln!("{}{under}", sc.label));
        }
        for (zi, &(w, h)) in sizes.iter().enumerate() {
            let block = per * (configs.len() * zi) as u64;
            if let Err(e) = r.resize(w, h) {
                skip(format!("{} at {w}x{h}", sc.label), e.into(), &mut skipped)?;
                bar.set_position(done(block + per * configs.len() as u64));
                continue;
            }
            for (ci, &(mode, quadrature, n)) in configs.iter().enumerate() {
                let start = done(block + per * ci as u64);
                let row_name = |n: Option<usize>| {
                    format!(
                        "{} {w}×{h} {} N={}",
                        sc.label,
                        mode.name(),
                        n.map_or("–".into(), |n| n.to_string())
                    )
                };
                bar.set_message(row_name(n));
                let settings = RenderSettings {
                    mode,
                    wavelengths: n.unwrap_or(RenderSettings::default().wavelengths),
                    quadrature: quadrature.unwrap_or_default(),
                    timestamps: has_ts,
                    ..Default::default()
                };
                match measure(&mut r, &scene.camera, &settings, (args.warmup, args.frames), &bar) {
                    Ok(Measured { gpu, shading, passes, cpu }) => rows.push(SuiteRow {
                        scene: sc.label.clone(),
                        size: (w, h),
                        row: Row { mode, quadrature, reference: false, n, gpu, shading, passes, cpu },
                    }),
                    Err(e) => {
                        skip(format!("row {}", row_name(n)), e, &mut skipped)?;
                        bar.set_position(start + per);
                    }
                }
            }
        }
    }
    bar.finish_and_clear();
    if rows.is_empty() {
        bail!("no row of the suite could be measured (see the lines above); nothing written");
    }
    print!("{}", table(&rows));
    for k in &skipped {
        println!("skipped: {k}");
    }
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    if let Some(line) = load_report(load_before, load_average(), cores, cpu_device(&r)) {
        println!("{line}");
    }
    let mut tables = Vec::new();
    if let Some(path) = &args.csv {
        tables.push((path.as_path(), csv(&rows, &adapter)));
    }
    if let Some(path) = &args.markdown {
        tables.push((path.as_path(), markdown(&rows, &header, &skipped)));
    }
    super::write_tables(&tables)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cmd::bench::stats::Summary;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn parse(a: &[&str]) -> std::result::Result<Args, clap::Error> {
        Cli::try_parse_from(std::iter::once("bench").chain(a.iter().copied())).map(|c| c.args)
    }

    #[test]
    fn suite_definition() {
        let (s, note) = scenes(None);
        let labels: Vec<&str> = s.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(labels, ["cornell", "cornell+env", "underwater"]);
        assert_eq!(s.iter().map(|s| s.env).collect::<Vec<_>>(), [Some("none"), Some("default"), None]);
        let note = note.unwrap();
        assert!(note.contains("--suite-asset") && note.contains("DamagedHelmet"), "{note}");
        let (s, note) = scenes(Some(Path::new("/m/DamagedHelmet/DamagedHelmet.gltf")));
        assert_eq!(note, None);
        assert_eq!(s.len(), 4);
        assert_eq!(
            s[2],
            SuiteScene {
                label: "DamagedHelmet+env".into(),
                scene: "/m/DamagedHelmet/DamagedHelmet.gltf".into(),
                env: Some("default")
            }
        );
        assert_eq!(s[3].scene, "underwater");
        let c = configs(&parse_counts_for("--wavelengths", WAVELENGTHS).unwrap());
        assert_eq!(c.len(), 6);
        assert_eq!(c[0], (Mode::Rgb, None, None));
        assert!(c[1..].iter().all(|&(m, q, _)| m == Mode::Spectral && q == Some(Quadrature::Prefiltered)));
        assert_eq!(c.iter().filter_map(|c| c.2).collect::<Vec<_>>(), [1, 4, 8, 16, 32]);
        assert_eq!(parse_sizes(SIZES).unwrap(), [(1280, 720), (1920, 1080)]);
        assert_eq!(parse_sizes(" 64x48, 64X48 ,32*24").unwrap(), [(64, 48), (32, 24)]);
        assert!(parse_sizes("64x0").unwrap_err().to_string().contains("--suite-sizes"));
        assert!(parse_sizes(",").unwrap_err().to_string().contains("at least one"));
        assert!(parse_sizes("16x12,,16x12").unwrap_err().to_string().contains("empty item"));
    }

    #[test]
    fn suite_flags() {
        let a = parse(&["--suite"]).unwrap();
        assert!(a.suite && a.scene.is_none() && a.suite_asset.is_none());
        assert_eq!((a.suite_sizes.as_deref(), a.wavelengths.as_deref()), (None, None));
        a.check_suite_flags().unwrap();
        let a = parse(&["--suite", "--suite-asset", "h.gltf", "--markdown", "s.md", "--wavelengths", "4"])
            .unwrap();
        assert_eq!(a.suite_asset.as_deref(), Some(Path::new("h.gltf")));
        assert_eq!(a.wavelengths.as_deref(), Some("4"));
        // A scene or the normal run's flags do not go with the suite, nor its flags without it.
        for bad in [
            &["--suite", "cornell"][..],
            &["--suite", "--size", "64x64"],
            &["--suite", "--naive"],
            &["--suite", "--env", "none"],
            &["--suite", "--quadrature", "midpoint"],
            &[],
        ] {
            assert!(parse(bad).is_err(), "{bad:?} parsed");
        }
        parse(&["cornell"]).unwrap().check_suite_flags().unwrap();
        for (flag, value) in [("--suite-asset", "h.gltf"), ("--markdown", "s.md"), ("--suite-sizes", "64x64")]
        {
            let e = parse(&["cornell", flag, value]).unwrap().check_suite_flags().unwrap_err().to_string();
            assert!(e.contains(flag) && e.contains("goes with --suite"), "{e}");
        }
    }

    fn s(m: f64) -> Summary {
        Summary { median: m, p10: m - 1.0, p90: m + 1.0 }
    }

    fn rows() -> Vec<SuiteRow> {
        let row = |scene: &str, size, mode, n: Option<usize>, ms: f64| SuiteRow {
            scene: scene.into(),
            size,
            row: Row {
                mode,
                quadrature: n.map(|_| Quadrature::Prefiltered),
                reference: false,
                n,
                gpu: Some(s(ms)),
                shading: Some(s(ms / 2.0)),
                passes: Some([1.0, 2.0, ms / 2.0, 0.0, 0.5, 0.25]),
                cpu: s(ms + 2.0),
            },
        };
        vec![
            row("cornell", (64, 48), Mode::Rgb, None, 10.0),
            row("cornell", (64, 48), Mode::Spectral, Some(4), 15.0),
            row("cornell", (128, 96), Mode::Rgb, None, 40.0),
            row("cornell", (128, 96), Mode::Spectral, Some(4), 50.0),
            // Its RGB row failed: no ratio.
            row("a,b+env", (64, 48), Mode::Spectral, Some(4), 30.0),
        ]
    }

    #[test]
    fn suite_csv() {
        let text = csv(&rows(), "GPU (Vulkan, DiscreteGpu)");
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 6);
        assert_eq!(
            lines[0],
            "scene,size,mode,wavelengths,gpu_median_ms,gpu_p10_ms,gpu_p90_ms,cpu_median_ms,cpu_p10_ms,\
             cpu_p90_ms,ratio_to_rgb,shadow_gpu_median_ms,gbuffer_gpu_median_ms,shading_gpu_median_ms,\
             custom_gpu_median_ms,post_gpu_median_ms,occlusion_gpu_median_ms,adapter"
        );
        assert_eq!(
            lines[1],
            "cornell,64x48,rgb,,10.0000,9.0000,11.0000,12.0000,11.0000,13.0000,1.0000,\
             1.0000,2.0000,5.0000,0.0000,0.5000,0.2500,\"GPU (Vulkan, DiscreteGpu)\""
        );
        // The ratio is to the same scene and size's RGB row: 50 / 40.
        assert!(lines[4].starts_with("cornell,128x96,spectral/prefiltered,4,50.0000,"), "{}", lines[4]);
        assert!(lines[4].contains(",1.2500,1.0000,2.0000,25.0000,"), "{}", lines[4]);
        // A label with a comma is quoted; no RGB row, no ratio.
        assert!(lines[5].starts_with("\"a,b+env\",64x48,spectral/prefiltered,4,30.0000,"), "{}", lines[5]);
        assert!(lines[5].contains(",29.0000,31.0000,32.0000,31.0000,33.0000,,1.0000,"), "{}", lines[5]);
        // Every line has the header's number of fields (outside quotes).
        let fields = |l: &str| l.split('"').step_by(2).map(|p| p.matches(',').count()).sum::<usize>();
        assert!(lines.iter().all(|l| fields(l) == fields(lines[0])), "{text}");
        // Without timestamps the GPU and pass cells are empty.
        let mut r = rows();
        r.truncate(1);
        r[0].row.gpu = None;
        r[0].row.passes = None;
        let text = csv(&r, "cpu");
        assert_eq!(
            text.lines().nth(1).unwrap(),
            "cornell,64x48,rgb,,,,,12.0000,11.0000,13.0000,1.0000,,,,,,,cpu"
        );
    }

    #[test]
    fn suite_markdown_and_table() {
        let skipped = vec!["scene x (y.gltf): loading | failed".to_string()];
        let md = markdown(&rows(), "spectra bench --suite on GPU", &skipped);
        let lines: Vec<&str> = md.lines().collect();
        assert_eq!(lines[0], "spectra bench --suite on GPU");
        assert_eq!(
            lines[2],
            "| scene | size | mode | N | GPU med | p10 | p90 | CPU med | p10 | p90 | ×RGB | shadow | gbuffer | shading | custom | post | occlusion |"
        );
        assert_eq!(
            lines[3],
            "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        );
        assert_eq!(
            lines[4],
            "| cornell | 64x48 | rgb | – | 10.00 | 9.00 | 11.00 | 12.00 | 11.00 | 13.00 | 1.00 | 1.00 | 2.00 | 5.00 | 0.00 | 0.50 | 0.25 |"
        );
        assert!(
            lines[5].contains("| spectral/prefiltered | 4 | 15.00 |") && lines[5].contains("| 1.50 |"),
            "{md}"
        );
        assert!(lines[8].contains("| 30.00 |") && lines[8].contains("| – |"), "{md}");
        let cols = |l: &str| l.replace("\\|", "").matches('|').count();
        assert!(lines[2..9].iter().all(|l| cols(l) == 18), "{md}");
        assert!(md.contains("Skipped:\n\n- scene x (y.gltf): loading \\| failed\n"), "{md}");
        assert!(!markdown(&rows(), "h", &[]).contains("Skipped"));

        let t = table(&rows());
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines.len(), 6);
        assert!(lines[0].starts_with("scene    size    mode "), "{t}");
        assert!(lines[0].ends_with("shadow  gbuffer  shading  custom  post  occlusion"), "{t}");
        // Right-aligned numbers: every row ends at the same column.
        let width = lines[0].chars().count();
        assert!(lines.iter().all(|l| l.chars().count() == width), "{t}");
        assert!(lines[4].contains(" 50.00 ") && lines[4].contains(" 1.25 "), "{t}");
    }
}
