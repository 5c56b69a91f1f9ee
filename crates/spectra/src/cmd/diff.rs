//! `spectra diff REFERENCE TEST`: how far a render is from a reference, in CIEDE2000 and MAE.
//!
//! A measurement, not a test: it exits 0 whatever the difference, and non-zero only when it
//! cannot measure (unreadable file, size mismatch, non-finite pixel, bad option).

use color::error::show as short;
use std::path::PathBuf;

use anyhow::{Context, bail};
use compare::{ColorMap, DiffMaps, DiffOptions, DiffSummary, Heatmap, HeatmapOptions, Image};

#[derive(clap::Args)]
pub struct Args {
    /// Reference image (.exr linear, or .png sRGB-encoded), e.g. the ground-truth render.
    reference: PathBuf,
    /// Image to measure against the reference, same size.
    test: PathBuf,
    /// Write a ΔE2000 heat map with a labelled colour bar to this PNG.
    #[arg(long, value_name = "FILE.png")]
    heatmap: Option<PathBuf>,
    /// Top of the heat-map scale in ΔE00 (default: the largest ΔE rounded up to 1/2/2.5/5×10ᵏ).
    #[arg(long, value_name = "X", requires = "heatmap", allow_negative_numbers = true)]
    max_de: Option<f64>,
    /// Heat-map colour map: viridis, magma or inferno.
    #[arg(long, default_value = "viridis", requires = "heatmap")]
    colormap: String,
    /// Luminance Y (image units) of the CIELAB reference white, D65 chromaticity. With 1,
    /// an image value of (1, 1, 1) is L* = 100.
    #[arg(long, value_name = "Y", default_value_t = 1.0, allow_negative_numbers = true)]
    white_y: f64,
    /// Print the results as JSON (for scripts) instead of a table.
    #[arg(long)]
    json: bool,
    /// Write per-pixel values (x, y, ΔE2000, |Δ| linear, |Δ| sRGB) to this CSV file.
    #[arg(long, value_name = "FILE.csv")]
    per_pixel_out: Option<PathBuf>,
    /// Average both images over N×N pixel blocks before measuring (partial edge blocks are
    /// dropped): against a noisy Monte-Carlo reference this cuts its noise by N.
    #[arg(long, value_name = "N", default_value_t = 1)]
    block: u32,
    /// Observer integrating a spectral EXR input (one with S0.<λ>nm or T.<λ>nm channels, e.g.
    /// from `truth --spectral-out`, pbrt-v4 or Mitsuba): cie1931 (default), cie1964, a camera
    /// (nikon_d5100, canon_eos_r5, …, `spectra observers`; white balanced and shown as linear
    /// RGB) or any other `--observer` name or file spectra takes.
    #[arg(long)]
    observer: Option<String>,
    /// White of a spectral input: normalises radiance (a radiance equal to it has Y = 1) and
    /// lights reflectance. Default: the file's `spectra.white` attribute, else D65.
    #[arg(long)]
    white: Option<String>,
    /// Show a camera observer through its least-squares matrix to CIE XYZ (the ColorChecker
    /// under the white) and sRGB instead of its balanced channels (as render and truth do).
    #[arg(long)]
    camera_to_display: bool,
    /// An extra metric beside ΔE2000 and MAE: `flip` (NVIDIA's perceptual difference, computed
    /// by its reference C++ code, FLIP 1.7; LDR- or HDR-FLIP, see --flip).
    #[arg(long, value_name = "NAME")]
    metric: Option<String>,
    /// Which FLIP: `ldr` (the sRGB-encoded images clipped to [0, 1], what a display shows),
    /// `hdr` (HDR-FLIP: the linear images over a range of exposures, tone mapped), or `auto`:
    /// HDR-FLIP when both inputs are EXR (linear, possibly above 1), LDR-FLIP otherwise.
    #[arg(long, value_name = "MODE", default_value = "auto", requires = "metric")]
    flip: String,
    /// HDR-FLIP's first exposure in stops (default, as FLIP's tool: from the reference's
    /// brightest pixel).
    #[arg(long, value_name = "EV", allow_negative_numbers = true, requires = "metric")]
    flip_start_exposure: Option<f32>,
    /// HDR-FLIP's last exposure in stops (default, as FLIP's tool: from the reference's median
    /// luminance).
    #[arg(long, value_name = "EV", allow_negative_numbers = true, requires = "metric")]
    flip_stop_exposure: Option<f32>,
    /// HDR-FLIP's number of exposures (default, as FLIP's tool: ⌈stop − start⌉, at least 2).
    #[arg(long, value_name = "N", requires = "metric")]
    flip_exposures: Option<u32>,
    /// HDR-FLIP's tone mapper: aces (default, as FLIP's tool), reinhard or hable.
    #[arg(long, value_name = "NAME", default_value = "aces", requires = "metric")]
    flip_tone_mapper: String,
    /// Write the FLIP error map (magma colours, 0 black to 1 white-yellow) to this PNG.
    #[arg(long, value_name = "FILE.png")]
    flip_map: Option<PathBuf>,
    /// FLIP's viewing condition in pixels per degree (67: a 0.7 m wide 4K screen at 0.7 m).
    #[arg(long, value_name = "PPD", default_value_t = compare::flip::DEFAULT_PIXELS_PER_DEGREE)]
    flip_ppd: f32,
}

/// Reads an input with the command's options.
fn load(
    path: &std::path::Path,
    what: &str,
    args: &Args,
) -> anyhow::Result<(Image, compare::Placement, Option<String>)> {
    read_input(path, what, args.observer.as_deref(), args.white.as_deref(), args.camera_to_display)
}

/// Reads an input as `spectra diff` does (the Python package's `diff` of two files reads them
/// through here, so both read a file alike): an EXR or PNG as it is, a spectral EXR integrated
/// to linear sRGB with `observer` (default CIE 1931) against `white` (default the file's, else
/// D65). Returns where its pixels lie in its frame ([`compare::align`]), and a note saying how a
/// spectral input was integrated; `what` names the input in errors.
pub fn read_input(
    path: &std::path::Path,
    what: &str,
    observer: Option<&str>,
    white: Option<&str>,
    camera_to_display: bool,
) -> anyhow::Result<(Image, compare::Placement, Option<String>)> {
    let bytes = color::input::read_regular(path, compare::io::MAX_INPUT_BYTES)
        .with_context(|| format!("reading the {what} image {}", path.display()))?;
    let is_exr = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if !(is_exr && compare::spectral::is_spectral_exr(&bytes)) {
        let (img, placed) = compare::decode_image_placed(path, &bytes)
            .with_context(|| format!("reading the {what} image"))?;
        return Ok((img, placed, None));
    }
    let (spec, placed) = compare::spectral::decode_spectral_exr_placed(path, &bytes)
        .with_context(|| format!("reading the {what} image"))?;
    let obs_name = observer.unwrap_or("cie1931");
    let observer = color::Observer::by_name(obs_name).context("--observer")?;
    let white_name = white.map(str::to_string).or(spec.white.clone()).unwrap_or_else(|| "D65".into());
    let white = color::illuminant::by_name(&white_name).with_context(|| format!("white {white_name}"))?;
    let img = spec
        .to_display(&observer, &white, color::film::CameraView::from_flag(camera_to_display))
        .with_context(|| format!("integrating the {what} image {}", path.display()))?;
    let edges = &spec.edges;
    let note = format!(
        "spectral, {} bands {:.1}–{:.1} nm, integrated with {} against {white_name}",
        spec.bands(),
        edges[0],
        edges[edges.len() - 1],
        observer.name
    );
    Ok((img, placed, Some(note)))
}

pub fn run(args: Args) -> anyhow::Result<()> {
    // Check cheap things before reading possibly large images.
    let flip = match args.metric.as_deref() {
        None => false,
        Some(m) if m.eq_ignore_ascii_case("flip") => true,
        Some(m) => bail!("--metric {m}: the extra metric can be: flip (ΔE2000 and MAE are always measured)"),
    };
    if args.flip_map.is_some() && !flip {
        bail!("--flip-map needs --metric flip");
    }
    let both_exr = [&args.reference, &args.test]
        .iter()
        .all(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")));
    let hdr_flip = match args.flip.to_ascii_lowercase().as_str() {
        "auto" => both_exr,
        "hdr" => true,
        "ldr" => false,
        other => bail!("--flip {other}: FLIP can be ldr, hdr or auto (hdr when both inputs are EXR)"),
    };
    let hdr_opts = compare::flip::HdrOptions {
        start_exposure: args.flip_start_exposure,
        stop_exposure: args.flip_stop_exposure,
        exposures: args.flip_exposures,
        tone_mapper: compare::flip::ToneMapper::by_name(&args.flip_tone_mapper)
            .context("--flip-tone-mapper")?,
    };
    let hdr_only = args.flip_start_exposure.is_some()
        || args.flip_stop_exposure.is_some()
        || args.flip_exposures.is_some()
        || !args.flip_tone_mapper.eq_ignore_ascii_case("aces");
    if flip && !hdr_flip && hdr_only {
        bail!(
            "the --flip-*exposure*/--flip-tone-mapper options set HDR-FLIP, and LDR-FLIP was chosen (--flip)"
        );
    }
    if let Some(p) = &args.flip_map
        && !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        bail!("{}: the FLIP map is written as PNG; give it a .png name", p.display());
    }
    let (lo, hi) = compare::flip::PPD_RANGE;
    if !(lo..=hi).contains(&args.flip_ppd) {
        bail!("--flip-ppd {}: pixels per degree must be between {lo} and {hi}", args.flip_ppd);
    }
    let (lo, hi) = compare::flip::EXPOSURE_RANGE;
    for (flag, v) in [
        ("--flip-start-exposure", args.flip_start_exposure),
        ("--flip-stop-exposure", args.flip_stop_exposure),
    ] {
        if let Some(v) = v
            && !(lo..=hi).contains(&v)
        {
            bail!("{flag} {v}: an exposure must lie within {lo}…{hi} stops");
        }
    }
    if let (Some(a), Some(b)) = (args.flip_start_exposure, args.flip_stop_exposure)
        && b - a > compare::flip::MAX_EXPOSURE_SPAN
    {
        bail!(
            "--flip-start-exposure {a} --flip-stop-exposure {b}: the span must be at most {} stops",
            compare::flip::MAX_EXPOSURE_SPAN
        );
    }
    let colormap = ColorMap::by_name(&args.colormap)?;
    let (lo, hi) = (compare::diff::MIN_WHITE_LUMINANCE, compare::diff::MAX_WHITE_LUMINANCE);
    if !(lo..=hi).contains(&args.white_y) {
        anyhow::bail!(
            "--white-y {}: the white luminance must be between {} and {}",
            short(args.white_y),
            short(lo),
            short(hi)
        );
    }
    if let Some(h) = &args.heatmap
        && !h.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        bail!("{}: the heat map is written as PNG; give it a .png name", h.display());
    }
    if let Some(m) = args.max_de
        && !(compare::heatmap::MIN_SCALE..=compare::heatmap::MAX_SCALE).contains(&m)
    {
        bail!(
            "--max-de must be a ΔE00 from {} to {}, got {}",
            short(compare::heatmap::MIN_SCALE),
            short(compare::heatmap::MAX_SCALE),
            short(m)
        );
    }

    // Before the (possibly long) comparison: every output writable, none an input or another.
    let outputs = [
        ("--heatmap", args.heatmap.as_deref()),
        ("--per-pixel-out", args.per_pixel_out.as_deref()),
        ("--flip-map", args.flip_map.as_deref()),
    ];
    let mut inputs = vec![
        ("reference".to_string(), args.reference.clone()),
        ("test image".to_string(), args.test.clone()),
    ];
    inputs.extend(super::setup::observer_input(args.observer.as_deref()));
    super::check_outputs(&outputs, &inputs)?;
    for (flag, p) in outputs {
        if let Some(p) = p {
            super::check_output(flag, p)?;
        }
    }
    let (reference, ref_placed, ref_note) = load(&args.reference, "reference", &args)?;
    let (test, test_placed, test_note) = load(&args.test, "test", &args)?;
    if (args.observer.is_some() || args.white.is_some()) && ref_note.is_none() && test_note.is_none() {
        bail!("--observer and --white integrate spectral EXR inputs, and neither input is one");
    }
    // The same pixel of the frame with itself: an EXR's data window may be a crop of its frame
    // (two crops of one size at different places were compared pixel for pixel).
    let (mut reference, mut test, region) = compare::align(reference, ref_placed, test, test_placed)
        .with_context(|| format!("comparing {} with {}", args.reference.display(), args.test.display()))?;
    if args.block != 1 {
        // Blocks of two different sizes could coincide: compare sizes first.
        if reference.size() != test.size() {
            bail!("image sizes differ: reference is {:?}, test is {:?}", reference.size(), test.size());
        }
        reference = reference.block_mean(args.block).context("--block")?;
        test = test.block_mean(args.block).context("--block")?;
    }
    let maps = DiffMaps::compute(&reference, &test, DiffOptions { white_luminance: args.white_y })
        .with_context(|| format!("comparing {} with {}", args.reference.display(), args.test.display()))?;
    let summary = maps.summary();
    // Every output is staged, complete on disk, and all are put in place only at the end: one
    // after the other, a failure on the CSV (a full disk) left a new heat map and FLIP map
    // beside the old CSV.
    let mut staged = Vec::new();
    let flip_stats = if flip {
        let map = if hdr_flip {
            compare::flip::hdr_flip(&reference, &test, args.flip_ppd, &hdr_opts).context("HDR-FLIP")?
        } else {
            // A 16-bit PNG's own codes (block means are display codes of no file: 8 bits).
            let depth = |p: &std::path::Path| {
                if args.block == 1 { compare::io::png_bit_depth(p).unwrap_or(8) } else { 8 }
            };
            let bits = (depth(&args.reference), depth(&args.test));
            compare::flip::ldr_flip_at_depths(&reference, &test, args.flip_ppd, bits).context("LDR-FLIP")?
        };
        if let Some(p) = &args.flip_map {
            let png = map.to_png(p).context("writing the FLIP map")?;
            staged.push(compare::atomic::stage(p, &png).context("writing the FLIP map")?);
        }
        let v: Vec<f64> = map.values.iter().map(|&x| f64::from(x)).collect();
        // The mean as FLIP's own tool computes and prints it.
        color::metrics::Stats::of(&v)
            .map(|st| (color::metrics::Stats { mean: map.mean(), ..st }, map.exposures))
    } else {
        None
    };

    let heatmap = match &args.heatmap {
        Some(path) => {
            let opts = HeatmapOptions { max: args.max_de, colormap, ..Default::default() };
            let h = Heatmap::of_delta_e(&maps, &opts)?;
            let png = h.to_png().context("writing the heat map")?;
            staged.push(compare::atomic::stage(path, &png).context("writing the heat map")?);
            Some((path, h.max))
        }
        None => None,
    };
    if let Some(path) = &args.per_pixel_out {
        staged.push(
            compare::atomic::stage(path, maps.to_csv().as_bytes()).context("writing per-pixel values")?,
        );
    }
    super::commit_outputs(staged)?;

    if args.json {
        let mut v = serde_json::to_value(summary)?;
        let o = v.as_object_mut().expect("a struct serialises to an object");
        o.insert("reference".into(), args.reference.display().to_string().into());
        o.insert("test".into(), args.test.display().to_string().into());
        o.insert("reference_spectral".into(), ref_note.clone().into());
        if let Some((f, exposures)) = &flip_stats {
            o.insert("flip".into(), serde_json::to_value(f)?);
            o.insert("flip_kind".into(), if exposures.is_some() { "hdr" } else { "ldr" }.into());
            o.insert("flip_exposures".into(), serde_json::to_value(exposures)?);
            o.insert("flip_ppd".into(), args.flip_ppd.into());
            o.insert("flip_map".into(), args.flip_map.as_ref().map(|p| p.display().to_string()).into());
        }
        o.insert("test_spectral".into(), test_note.clone().into());
        o.insert(
            "heatmap".into(),
            match heatmap {
                Some((p, max)) => serde_json::json!({ "path": p.display().to_string(), "max_delta_e": max }),
                None => serde_json::Value::Null,
            },
        );
        o.insert("per_pixel_out".into(), args.per_pixel_out.as_ref().map(|p| p.display().to_string()).into());
        o.insert("region".into(), region_json(region.as_ref()));
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        print_table(&args, &summary, heatmap, [&ref_note, &test_note], flip_stats.as_ref(), region);
    }
    Ok(())
}

fn print_table(
    args: &Args,
    s: &DiffSummary,
    heatmap: Option<(&PathBuf, f64)>,
    notes: [&Option<String>; 2],
    flip: Option<&(color::metrics::Stats, Option<compare::flip::Exposures>)>,
    region: Option<compare::Region>,
) {
    let note = |n: &Option<String>| n.as_ref().map(|n| format!(" ({n})")).unwrap_or_default();
    println!("reference  {}{}", args.reference.display(), note(notes[0]));
    println!("test       {}{}", args.test.display(), note(notes[1]));
    println!(
        "size       {}×{} ({} pixels); CIELAB white: D65, Y = {}",
        s.width,
        s.height,
        u64::from(s.width) * u64::from(s.height),
        s.white_luminance
    );
    if let Some(r) = region {
        println!(
            "region     {}×{} at ({}, {}) of the {}×{} frame: the pixels both images hold (data windows); \
             the maps' and per-pixel x, y count from it",
            r.size.0, r.size.1, r.origin.0, r.origin.1, r.frame.0, r.frame.1
        );
    }
    println!();
    println!(
        "{:<22}{:>12}{:>12}{:>12}{:>12}{:>12}",
        "per-pixel metric", "mean", "median", "p95", "p99", "max"
    );
    let row = |name: &str, st: &color::metrics::Stats, prec: usize| {
        let cells: String =
            [st.mean, st.median, st.p95, st.p99, st.max].map(|v| table_cell(v, prec)).concat();
        println!("{name:<22}{cells}");
    };
    row("ΔE2000", &s.delta_e2000, 4);
    row("MAE linear RGB", &s.mae_linear, 6);
    row("MAE sRGB-encoded", &s.mae_srgb, 6);
    match flip {
        Some((f, None)) => row(&format!("LDR-FLIP ({:.0} ppd)", args.flip_ppd), f, 6),
        Some((f, Some(_))) => row(&format!("HDR-FLIP ({:.0} ppd)", args.flip_ppd), f, 6),
        None => {}
    }
    if let Some((p, max)) = heatmap {
        println!();
        println!("heat map   {} (ΔE00 scale 0 to {max})", p.display());
    }
    if let Some(p) = &args.per_pixel_out {
        println!("per-pixel  {}", p.display());
    }
    if let Some((_, Some(e))) = flip {
        println!(
            "HDR-FLIP   exposures {:+.4} to {:+.4} EV, {} of them, {} tone mapping",
            e.start, e.stop, e.count, e.tone_mapper
        );
    }
    if let Some(p) = &args.flip_map {
        println!("FLIP map   {}", p.display());
    }
}

/// One column of the statistics table: 12 characters, at least one a space, so that columns
/// never run together; values of a million or more in scientific notation (the MAE of a 3e38
/// pixel filled 40 digits and joined the next column).
fn table_cell(v: f64, prec: usize) -> String {
    let s = if v.is_finite() && v.abs() >= 1e6 { format!("{v:.4e}") } else { format!("{v:.prec$}") };
    format!(" {s:>11}")
}

/// The compared region as `--json` and Python's `diff` report it: `{"frame": [W, H], "x", "y",
/// "width", "height"}`, or null where both images hold the same pixels.
pub fn region_json(region: Option<&compare::Region>) -> serde_json::Value {
    match region {
        Some(r) => serde_json::json!({
            "frame": [r.frame.0, r.frame.1],
            "x": r.origin.0,
            "y": r.origin.1,
            "width": r.size.0,
            "height": r.size.1,
        }),
        None => serde_json::Value::Null,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_cells_keep_their_columns() {
        assert_eq!(table_cell(0.25, 6), "    0.250000");
        assert_eq!(table_cell(133.33333, 4), "    133.3333");
        assert_eq!(table_cell(3e38, 6), "   3.0000e38");
        assert_eq!(table_cell(-2.5e6, 6), "   -2.5000e6");
        assert_eq!(table_cell(f64::NAN, 6), "         NaN");
        assert!(table_cell(123456.789, 6).starts_with(' '));
    }

    fn args(extra: &[&str]) -> Args {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            a: Args,
        }
        Cli::parse_from(["diff"].iter().chain(extra)).a
    }

    fn run_with(extra: &[&str]) -> anyhow::Result<()> {
        run(args(extra))
    }

    /// A spectral input is integrated (and a wrong observer changes the result); the options
    /// that only make sense with spectral inputs or FLIP are refused otherwise.
    #[test]
    fn spectral_inputs_and_flip_options() {
        let dir = tempfile::tempdir().unwrap();
        let p = |n: &str| dir.path().join(n).display().to_string();
        let edges = color::WavelengthRange::VISIBLE.bin_edges(5.0).unwrap();
        let n = edges.len() - 1;
        // A D65-coloured emitter at half the white: sRGB (0.5, 0.5, 0.5) for CIE 1931.
        let d65 = color::illuminant::by_name("D65").unwrap();
        let wl = color::SampledWavelengths::from_edges(&edges).unwrap();
        let image = |f: &dyn Fn(f64) -> f64| compare::SpectralImage {
            width: 4,
            height: 3,
            kind: compare::SpectralKind::Emissive,
            edges: edges.clone(),
            data: (0..12).flat_map(|_| wl.lambda.iter().map(|&l| f(l) as f32)).collect(),
            white: Some("D65".into()),
            centres: None,
        };
        let spec = image(&|l| 0.5 * d65.eval(l));
        compare::write_spectral_exr(p("s.exr"), &spec, None).unwrap();
        // An orange emitter, which the 2° and 10° observers see differently.
        let orange = image(&|l| 50.0 * (-((l - 600.0) / 30.0).powi(2)).exp());
        compare::write_spectral_exr(p("o.exr"), &orange, None).unwrap();
        let grey = Image::filled(4, 3, [0.5; 3]).unwrap();
        compare::write_image(p("g.exr"), &grey, Default::default()).unwrap();
        assert_eq!(spec.bands(), n);
        let pixel = |file: &str, obs: &str| {
            let a = args(&[&p("g.exr"), &p(file), "--observer", obs]);
            let (img, _, note) = load(std::path::Path::new(&p(file)), "test", &a).unwrap();
            assert!(note.unwrap().contains(obs), "the note names the observer");
            img.data[5]
        };
        // D65 is the white an RGB (1, 1, 1) light emits, which every observer's display is
        // balanced to (`color::film`): grey for the 2° and 10° observers and a camera alike.
        for obs in ["cie1931", "cie1964", "nikon_d5100"] {
            let grey = pixel("s.exr", obs);
            assert!(grey.iter().all(|v| (v - 0.5).abs() < 1e-6), "{obs}: {grey:?}");
        }
        // Any other colour depends on the observer.
        let (c31, c64) = (pixel("o.exr", "cie1931"), pixel("o.exr", "cie1964"));
        assert!(c64.iter().zip(c31).any(|(a, b)| (a - b).abs() > 5e-3), "{c64:?} vs {c31:?}");
        run_with(&[&p("g.exr"), &p("s.exr"), "--metric", "flip", "--flip-map", &p("f.png")]).unwrap();
        assert!(dir.path().join("f.png").exists());
        run_with(&[&p("g.exr"), &p("s.exr"), "--metric", "flip", "--flip", "ldr"]).unwrap();
        let (g, sp) = (p("g.exr"), p("s.exr"));
        let ev = ["--flip-start-exposure", "-1", "--flip-stop-exposure", "1"];
        run_with(&[&[g.as_str(), &sp, "--metric", "flip"][..], &ev].concat()).unwrap();
        run_with(&[&p("s.exr"), &p("g.exr"), "--observer", "nikon", "--json"]).unwrap();
        let e = |x: &[&str]| format!("{:#}", run_with(x).unwrap_err());
        assert!(e(&[&p("g.exr"), &p("g.exr"), "--observer", "cie1964"]).contains("neither input"));
        assert!(e(&[&p("g.exr"), &p("s.exr"), "--observer", "martian"]).contains("martian"));
        assert!(e(&[&p("g.exr"), &p("g.exr"), "--metric", "ssim"]).contains("flip"));
        assert!(e(&[&p("g.exr"), &p("g.exr"), "--flip-map", &p("x.png")]).contains("--metric flip"));
        assert!(
            e(&[&p("g.exr"), &p("g.exr"), "--metric", "flip", "--flip-map", &p("x.jpg")]).contains(".png")
        );
        assert!(!dir.path().join("x.png").exists());
        assert!(
            e(&[&p("g.exr"), &p("g.exr"), "--metric", "flip", "--flip", "hd"]).contains("ldr, hdr or auto")
        );
        let ldr_ev = [&[g.as_str(), &g, "--metric", "flip", "--flip", "ldr"][..], &ev].concat();
        assert!(e(&ldr_ev).contains("HDR-FLIP"));
        let backwards = ["--flip-start-exposure", "2", "--flip-stop-exposure", "1"];
        assert!(e(&[&[g.as_str(), &sp, "--metric", "flip"][..], &backwards].concat()).contains("start"));
        assert!(
            e(&[&p("g.exr"), &p("g.exr"), "--metric", "flip", "--flip-tone-mapper", "filmic"])
                .contains("filmic")
        );
    }
}
