//! `spectra truth`: the CPU spectral path tracer's ground-truth image of a scene.

use super::setup::{RgbMediumArgs, SceneArgs, SpectrumArgs, TableArgs, WaterArgs, parse_size};
use anyhow::{Context, Result, bail};
use clap::Args as ClapArgs;
use color::Observer;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::time::Instant;
use truth::{Medium, Settings, TruthError, World};

#[derive(ClapArgs, Debug, Clone)]
pub struct Args {
    // The scene, how it is loaded, and the environment light (--env, --env-intensity,
    // --env-rotation), shared with `render`; the environment is importance-sampled ∝ luminance
    // with MIS against the BRDF (truth::env_map).
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Samples (paths) per pixel; each path carries four wavelengths. With --sample-offset or
    /// --chunk, the samples of this chunk.
    #[arg(long, default_value_t = 64)]
    pub spp: u32,
    /// Render samples K … K+spp−1 of each pixel's sample sequence: chunks with disjoint ranges
    /// merge (`spectra merge`) into exactly the render of all their samples.
    #[arg(long, value_name = "K", conflicts_with = "chunk")]
    pub sample_offset: Option<u64>,
    /// Chunk i of n (from 0): `--spp 64 --chunk 2/4` renders samples 128 … 191, a quarter of a
    /// 256-sample render. The shorthand for --sample-offset i·spp.
    #[arg(long, value_name = "i/n")]
    pub chunk: Option<String>,
    /// Render only this pixel rectangle of the --size frame, X,Y,WIDTH,HEIGHT from the top-left:
    /// its pixels get exactly the samples of the full render (the EXR's data window inside the
    /// full display window); tiles merge with `spectra merge`.
    #[arg(long, value_name = "X,Y,W,H")]
    pub crop: Option<String>,
    /// Direct lighting only (one scattering vertex), to compare like for like with the
    /// real-time image.
    #[arg(long)]
    pub direct_only: bool,
    /// Random seed; the image depends on it alone (not on threads).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Image size WIDTHxHEIGHT (or WIDTHXHEIGHT, WIDTH*HEIGHT).
    #[arg(long, default_value = "256x256")]
    pub size: String,
    #[command(flatten)]
    pub spectrum: SpectrumArgs,
    /// Longest path, in scattering events (Russian roulette ends most paths long before).
    #[arg(long, default_value_t = 1024)]
    pub max_depth: u32,
    /// A homogeneous participating medium: a JSON file or inline JSON ('{…}'), keys sigma_a,
    /// sigma_s (per scene unit: a number or {"wavelengths": […], "values": […]}), phase
    /// ("isotropic" or {"hg": g}), box ({"min": [x, y, z], "max": […]}; without it the medium
    /// fills the scene): docs/ground-truth.md.
    #[arg(long, conflicts_with = "rgb_medium")]
    pub medium: Option<String>,
    #[command(flatten)]
    pub rgb_medium: RgbMediumArgs,
    #[command(flatten)]
    pub water: WaterArgs,
    /// Lambertian BRDF instead of glTF's (only for comparisons with Mitsuba's `diffuse`).
    #[arg(long)]
    pub lambert: bool,
    /// Write CIE XYZ into the EXR's three channels instead of linear sRGB: the tracer's own
    /// integral (Y = 1 for the white), before the display's balance onto sRGB's white
    /// (`--out` without this flag is XYZ scaled so that the white over --range lands on sRGB's
    /// white, then the sRGB matrix: docs/cameras.md).
    #[arg(long)]
    pub xyz: bool,
    #[command(flatten)]
    pub table: TableArgs,
    /// Also (or only, without --out) export the scene for Mitsuba 3 into this new directory.
    #[arg(long)]
    pub export_mitsuba: Option<PathBuf>,
    /// Output image: .exr (linear) or .png (sRGB-encoded, clipped).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write the radiance binned by wavelength as a spectral EXR (the OpenEXR layout of
    /// Fichet et al. 2021, as pbrt-v4 writes it: channels S0.<λ>nm, with R, G, B beside them),
    /// estimated from the same samples as --out, which it does not change.
    #[arg(long, value_name = "FILE.exr")]
    pub spectral_out: Option<PathBuf>,
    /// Width of the --spectral-out bins in nm, over the render range (the last bin is narrower
    /// when the width does not divide the range). Bins re-integrate to --out only up to their
    /// quadrature and noise: 0.5 nm with 4096 spp or more to get within 1e-4 per pixel
    /// (docs/spectral-exr.md).
    #[arg(
        long,
        value_name = "NM",
        default_value_t = 5.0,
        requires = "spectral_out",
        allow_negative_numbers = true
    )]
    pub spectral_bin: f64,
    /// Once the render has run this long, write its samples so far to `<out>.checkpoint`
    /// (atomically), again every such interval and on Ctrl-C; 0: never. A finished render
    /// removes it.
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0, allow_negative_numbers = true)]
    pub checkpoint_every: f64,
    /// Continue the render from `<out>.checkpoint` (the same command otherwise): the result is
    /// the uninterrupted render's, bit for bit.
    #[arg(long)]
    pub resume: bool,
    /// Render the glTF file's animation (`--animation`, default its first) as a sequence of
    /// frames, each a render of its own: START:END:STEP in seconds (END included when a step
    /// lands on it; `end`: the animation's last key), or a list T1,T2,…. `--out` (and
    /// `--spectral-out`) then hold a frame number, %d or %0Nd (e.g. `--out run_%04d.exr`).
    /// Ctrl-C keeps the frames finished and the current one's checkpoint; `--resume` skips the
    /// frames written and continues the checkpointed one.
    #[arg(long, value_name = "START:END:STEP|T1,T2,…", conflicts_with = "time")]
    pub times: Option<String>,
    /// Keep finished renders' samples in this directory (created) and start from them: the same
    /// render again renders nothing, one with more --spp only the samples it lacks (the result
    /// is the full render's, bit for bit). Shared with `spectra eval --truth-cache`.
    #[arg(long, value_name = "DIR")]
    pub truth_cache: Option<PathBuf>,
    /// Bin the radiance by wavelength (`--spectral-bin`) without a --spectral-out file: for
    /// callers of [`settings`] that keep the bands themselves (the Python package).
    #[arg(skip)]
    pub spectral_bands: bool,
}

/// Longest `--checkpoint-every`, seconds (a year).
pub const MAX_CHECKPOINT_SECONDS: f64 = 3.2e7;
/// Shortest `--checkpoint-every` but 0, seconds: below it the render spends its time writing
/// checkpoints (1e-30 ran 10× slower, a checkpoint after every one-sample pass).
pub const MIN_CHECKPOINT_SECONDS: f64 = 0.1;

/// The tracer's settings these flags ask for, the scene's own medium and water included: what
/// `spectra truth` renders, and what the Python package's `truth` renders with the same options.
pub fn settings(a: &Args, scene: &scene::Scene, table: &color::upsample::CoeffTable) -> Result<Settings> {
    let (width, height) = parse_size(&a.size)?;
    let mut s = Settings::new(width, height, a.spp)?;
    s.seed = a.seed;
    s.sample_offset = sample_offset(a)?;
    s.crop = a.crop.as_deref().map(parse_crop).transpose()?;
    s.direct_only = a.direct_only;
    s.max_depth = a.max_depth;
    s.lambert = a.lambert;
    let sp = a.spectrum.resolve(scene)?;
    s.range = sp.range;
    s.observer = Observer::by_name(&sp.observer)?;
    s.white = color::illuminant::by_name(&sp.white)?;
    if let Some(arg) = &a.medium {
        // Inline JSON as for --rgb-medium; anything else names a file (and so does a '{…}' that
        // is a file's name).
        let (m, origin) = if super::setup::inline_json(arg) {
            (Medium::from_json(arg, "--medium")?, "--medium".to_string())
        } else {
            (Medium::read(std::path::Path::new(arg))?, format!("medium {arg}"))
        };
        m.validate(s.range).with_context(|| origin)?;
        let mut m = m;
        // The box is in the scene file's frame; a recentred scene moved away from it.
        if let truth::medium::Region::Box { min, max } = &mut m.region {
            let o = scene.origin.as_vec3();
            *min -= o;
            *max -= o;
        }
        s.medium = Some(m);
    }
    // An explicit --medium / --rgb-medium replaces the scene's own RGB medium.
    let rgb = match (a.rgb_medium.arg(), &scene.medium) {
        (Some(arg), _) => Some((super::setup::rgb_medium_arg(arg)?, "--rgb-medium".to_string())),
        (None, Some(m)) if a.medium.is_none() => {
            Some((m.clone(), format!("{}: extras.medium", scene.source)))
        }
        _ => None,
    };
    if let Some((m, origin)) = &rgb {
        if let Some(w) = m.unlit_warning(scene) {
            eprintln!("{w}");
        }
        let m = Medium::from_rgb(m, table).with_context(|| origin.clone())?;
        m.validate(s.range).with_context(|| origin.clone())?;
        s.medium = Some(m);
    }
    if let Some(w) = a.water.medium(scene)? {
        if a.medium.is_some() || rgb.is_some() {
            bail!(
                "--medium / --rgb-medium / the scene's medium and water (from --water or the scene) cannot be combined: pick one medium"
            );
        }
        s.medium = Some(truth::water::medium(&w, scene.camera.position()));
    }
    if a.spectral_out.is_some() || a.spectral_bands {
        s.spectral_bands = Some(s.range.bin_edges(a.spectral_bin).context("--spectral-bin")?);
    }
    // Named by the flag that set what is wrong.
    s.validate().map_err(|e| match &e {
        truth::TruthError::TooLarge(..) | truth::TruthError::BadSize(..) => {
            anyhow::anyhow!("--size {}: {e}", a.size)
        }
        truth::TruthError::BadCrop(_) => anyhow::anyhow!("--crop: {e}"),
        truth::TruthError::BadSamples(_) => anyhow::anyhow!("--spp / --chunk / --sample-offset: {e}"),
        _ => anyhow::anyhow!(e),
    })?;
    Ok(s)
}

/// The first sample: `--sample-offset`, or i·spp for `--chunk i/n`.
fn sample_offset(a: &Args) -> Result<u64> {
    let Some(c) = &a.chunk else { return Ok(a.sample_offset.unwrap_or(0)) };
    let parsed = c
        .split_once('/')
        .and_then(|(i, n)| Some((i.trim().parse::<u64>().ok()?, n.trim().parse::<u64>().ok()?)));
    match parsed {
        Some((i, n)) if n >= 1 && i < n => i
            .checked_mul(u64::from(a.spp))
            .with_context(|| format!("--chunk {c}: the sample offset {i}·{} is too large", a.spp)),
        _ => bail!("--chunk '{c}' must be i/n with 0 ≤ i < n, e.g. 0/4 for the first of four chunks"),
    }
}

/// `--crop X,Y,W,H`.
fn parse_crop(s: &str) -> Result<truth::Crop> {
    let v: Vec<u32> = s.split(',').filter_map(|x| x.trim().parse().ok()).collect();
    match v[..] {
        [x, y, width, height] if s.split(',').count() == 4 => Ok(truth::Crop { x, y, width, height }),
        _ => bail!("--crop '{s}' must be X,Y,WIDTH,HEIGHT in pixels (whole numbers), e.g. 0,0,128,128"),
    }
}

/// What the output holds, for `spectra merge`: every setting that changes the image (resolved,
/// so two spellings of one setting agree), the contents of every input file (not their paths,
/// which differ between machines), the seed, the sample range and the crop.
/// `spectral`: the record of the --spectral-out file (its bands are part of what it holds; the
/// --out image is the same with or without them).
fn record(
    a: &Args,
    scene: &scene::Scene,
    st: &Settings,
    table: &color::upsample::CoeffTable,
    spectral: bool,
) -> Result<Vec<(String, String)>> {
    let mut fields = sum_fields(scene, st, table, &a.scene.input_files(scene), spectral)?;
    // What the colour channels hold (a camera's by the view `color::film` shows it in).
    let camera = st.observer.kind() != color::observer::ObserverKind::CieXyz;
    let channels = match (a.xyz, camera, a.spectrum.camera_to_display) {
        (true, false, _) => "CIE XYZ",
        (true, true, _) => "observer tristimulus",
        (false, false, _) => "linear sRGB",
        (false, true, false) => "white-balanced observer channels as linear display RGB",
        (false, true, true) => "linear sRGB (camera to display)",
    };
    fields.push(("channels".into(), channels.into()));
    Ok(wrap_record(fields, st, spectral))
}

/// A record's `spectra.*` attributes from its setting fields (`spectra.identity` is their hash).
fn wrap_record(fields: Vec<(String, String)>, st: &Settings, spectral: bool) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = vec![
        ("spectra.version".into(), RECORD_VERSION.into()),
        ("spectra.identity".into(), fields_hash(&fields)),
        ("spectra.samples".into(), format!("{}..{}", st.sample_offset, st.sample_offset + u64::from(st.spp))),
    ];
    if spectral {
        out.push(("spectra.content".into(), "spectral".into()));
    }
    out.extend(fields.into_iter().map(|(k, v)| (format!("spectra.setting.{k}"), v)));
    out
}

/// The hash of setting fields, as 16 hex digits.
pub fn fields_hash(fields: &[(String, String)]) -> String {
    let text: String = fields.iter().map(|(k, v)| format!("{k}={v}\n")).collect();
    format!("{:016x}", color::signature::fnv1a64(text.as_bytes()))
}

/// Every setting that changes a render's per-pixel sums (`truth::Accumulator`), whatever is
/// written from them: the scene (its input files' contents; a scene built in code, its
/// description), the tracer's settings, the coefficient table and the tracer's code
/// (`truth::render::CODE_HASH`). Not the samples or the crop, which a record holds beside
/// them. `inputs`: the files the scene was read from (`SceneArgs::input_files`); `spectral`:
/// the sums include the --spectral-out bands. Shared by `spectra truth`'s records and the
/// truth cache (`super::truth_cache`), which `spectra eval` uses too.
/// An observer as the record names it: a file by its name alone (its contents are hashed
/// beside it), so that chunks rendered where the file lies elsewhere merge.
fn observer_name(name: &str) -> String {
    if color::observer_file::is_file_name(name) {
        let p = std::path::Path::new(name.trim());
        if let Some(n) = p.file_name() {
            return n.to_string_lossy().into_owned();
        }
    }
    name.to_string()
}

pub fn sum_fields(
    scene: &scene::Scene,
    st: &Settings,
    table: &color::upsample::CoeffTable,
    inputs: &[(String, PathBuf)],
    spectral: bool,
) -> Result<Vec<(String, String)>> {
    use color::signature::fnv1a64;
    let hash = |s: &str| format!("{:016x}", fnv1a64(s.as_bytes()));
    let mut fields: Vec<(String, String)> = vec![
        ("size".into(), format!("{}x{}", st.width, st.height)),
        ("seed".into(), st.seed.to_string()),
        ("range".into(), format!("{}-{} nm", st.range.min, st.range.max)),
        (
            "observer".into(),
            format!("{} {}", observer_name(&st.observer.name), hash(&format!("{:?}", st.observer.bar))),
        ),
        ("white".into(), hash(&format!("{:?}", st.white))),
        ("direct_only".into(), st.direct_only.to_string()),
        ("max_depth".into(), st.max_depth.to_string()),
        ("lambert".into(), st.lambert.to_string()),
        ("medium".into(), st.medium.as_ref().map_or("none".into(), |m| hash(&format!("{m:?}")))),
        ("uniform_environment".into(), format!("{:?}", st.environment)),
        ("table".into(), format!("{:016x}", fnv1a64(&table.to_bytes()))),
        (
            "truth".into(),
            format!(
                "{} sampler {} code {}",
                env!("CARGO_PKG_VERSION"),
                truth::render::SAMPLER_VERSION,
                truth::render::CODE_HASH
            ),
        ),
    ];
    // A file's variant and animation moment: the same files drawn otherwise.
    fields.extend(scene.choices.iter().map(|(k, v)| (format!("scene.{k}"), v.clone())));
    if scene.inputs.is_empty() {
        // Built in code: its name, and what it holds (a built-in changes with the code).
        let s = scene;
        let described = format!(
            "{:?}{:?}{:?}{:?}{:?}{:?}{:?}{:?}",
            s.meshes, s.materials, s.textures, s.lights, s.camera, s.spectral, s.water, s.medium
        );
        fields.push(("scene".into(), format!("{} {}", scene.source, hash(&described))));
    }
    if spectral {
        fields.push(("content".into(), "spectral".into()));
        fields.push(("bands".into(), hash(&format!("{:?}", st.spectral_bands))));
    }
    if let Some(e) = &scene.environment {
        let name = std::path::Path::new(&e.source).file_name().map(|n| n.to_string_lossy().into_owned());
        let mut v = format!("{} × {} rotated {}", name.unwrap_or_default(), e.intensity, e.rotation);
        if !inputs.iter().any(|(_, p)| p.as_os_str() == e.source.as_str()) {
            // Made in code (the default sky): its texels, which no input file covers.
            let bytes: Vec<u8> =
                e.texels.iter().flat_map(|t| t.to_array()).flat_map(f32::to_le_bytes).collect();
            v.push_str(&format!(" {}x{} {:016x}", e.width, e.height, fnv1a64(&bytes)));
        }
        fields.push(("environment".into(), v));
    }
    for (i, (what, p)) in inputs.iter().enumerate() {
        let bytes = color::input::read_regular(p, scene::environment::MAX_INPUT_BYTES)
            .with_context(|| format!("{what} {}", p.display()))?;
        // The hash must be of what the scene was loaded from: a file replaced since (an
        // exporter's rename over it) recorded the other version — merge then accepted pieces of
        // two scenes and the truth cache kept samples under the wrong contents for good.
        let loaded = scene
            .inputs
            .iter()
            .position(|q| q == p)
            .and_then(|k| scene.input_stamps.get(k).copied().flatten());
        if let Some(then) = loaded
            && color::input::stamp(p) != Some(then)
        {
            let shown = p.display().to_string();
            let name = if what.contains(&shown) { what.clone() } else { format!("{what} {shown}") };
            bail!("{name} changed while the scene was being loaded: run the command again");
        }
        // Its name (without the folder) beside the hash, so that a refusal can say which file
        // changed.
        let name =
            p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned());
        fields.push((format!("input{i}"), format!("{name} {:016x}", fnv1a64(&bytes))));
    }
    Ok(fields)
}

/// Where two records (`spectra.*` attributes) differ: the first setting (`spectra.setting.*`)
/// that does, shown without its prefix, else the first other key — as (key, there, here). For
/// `spectra merge` and `--resume`, so both name the same setting the same way.
pub fn record_difference(
    there: &[(String, String)],
    here: &[(String, String)],
) -> Option<(String, String, String)> {
    let get = |r: &[(String, String)], k: &str| {
        r.iter().find(|(kk, _)| kk == k).map_or("(absent)".to_string(), |(_, v)| v.clone())
    };
    let keys: std::collections::BTreeSet<&String> = there.iter().chain(here).map(|(k, _)| k).collect();
    let differs = |k: &str| get(there, k) != get(here, k);
    let setting = keys.iter().find(|k| k.starts_with("spectra.setting.") && differs(k));
    let k = setting.or_else(|| keys.iter().find(|k| differs(k)))?;
    let name = k.trim_start_matches("spectra.setting.");
    // Hashes say only that something differs: name what it stands for.
    if name == "bands" {
        let said = |v: String| if v == "(absent)" { "none".to_string() } else { format!("some (bins {v})") };
        return Some(("spectral bands (--spectral-out)".into(), said(get(there, k)), said(get(here, k))));
    }
    if let Some(i) = name.strip_prefix("input") {
        // "DuckCM.png 0123…": the file's name, then its content hash.
        let (there, here) = (get(there, k), get(here, k));
        let split = |v: &str| {
            v.rsplit_once(' ').map_or((String::new(), v.to_string()), |(n, h)| (n.into(), h.into()))
        };
        let ((n0, h0), (n1, h1)) = (split(&there), split(&here));
        if h0 == h1 && n0 != n1 {
            // A renamed copy: the same contents under another name (which the record keeps, to
            // name a changed file); the hashes would read "x there and x here".
            return Some((format!("the name of input file {i} (its contents are the same)"), n0, n1));
        }
        let file = if n1.is_empty() { n0 } else { n1 };
        let what =
            if file.is_empty() { format!("input file {i} (") } else { format!("{file} (input file {i}; ") };
        return Some((format!("the contents of {what}content hash)"), h0, h1));
    }
    Some((name.to_string(), get(there, k), get(here, k)))
}

/// Version of the `spectra.*` attributes' meaning (2: `spectra.check`).
pub const RECORD_VERSION: &str = "2";

/// The check of what a record's identity does not cover — its sample ranges, its content and
/// its windows — so that a header edited or damaged there (a range that reads `4..7` for `4..8`
/// merged with the wrong weight) is refused, not merged. Not a defence against forgery, like
/// every signature here (`color::signature`).
pub fn record_check(frame: &compare::ExrFrame, size: (u32, u32)) -> String {
    let get = |k: &str| frame.get(k).unwrap_or("");
    let text = format!(
        "{}\n{}\n{}\n{} {} {} {}\n{} {}\n",
        get("spectra.identity"),
        get("spectra.samples"),
        get("spectra.content"),
        frame.origin.0,
        frame.origin.1,
        size.0,
        size.1,
        frame.display.0,
        frame.display.1
    );
    format!("{:016x}", color::signature::fnv1a64(text.as_bytes()))
}

/// `frame` with its `spectra.check` for data of `size` (replacing any).
pub fn sealed(mut frame: compare::ExrFrame, size: (u32, u32)) -> compare::ExrFrame {
    frame.attributes.retain(|(k, _)| k != "spectra.check");
    let check = record_check(&frame, size);
    frame.attributes.push(("spectra.check".into(), check));
    frame
}

pub fn run(a: Args) -> Result<()> {
    if let Some(arg) = a.times.clone() {
        return run_sequence(a, &arg);
    }
    if a.spectral_out.is_some() && a.out.is_none() {
        bail!("--spectral-out needs --out as well (its R, G, B are the --out image)");
    }
    if a.out.is_none() && a.export_mitsuba.is_none() {
        bail!("nothing to do: give --out FILE (.exr/.png) and/or --export-mitsuba DIR");
    }
    if a.spp == 0 {
        bail!(TruthError::NoSamples);
    }
    if let Some(out) = &a.out {
        let ext = out.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        if ext != "exr" && ext != "png" {
            bail!("--out {}: use a .exr (linear) or .png (sRGB) file name", out.display());
        }
        if a.xyz && ext != "exr" {
            bail!("--xyz needs an .exr output (PNG is display-encoded sRGB)");
        }
        super::check_output("--out", out)?;
    }
    if let Some(sp) = &a.spectral_out {
        if !sp.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
            bail!(
                "--spectral-out {}: a spectral image is an OpenEXR file; give it a .exr name",
                sp.display()
            );
        }
        if a.xyz {
            bail!("--spectral-out stores linear sRGB beside the bands; it cannot be combined with --xyz");
        }
        super::check_output("--spectral-out", sp)?;
    }
    if let Some(dir) = &a.export_mitsuba {
        if std::fs::symlink_metadata(dir).is_ok() {
            bail!("--export-mitsuba {}: already exists; remove it first", dir.display());
        }
        super::check_output("--export-mitsuba", dir)?;
    }
    let every = a.checkpoint_every;
    if !(every == 0.0
        || (every.is_finite() && (MIN_CHECKPOINT_SECONDS..=MAX_CHECKPOINT_SECONDS).contains(&every)))
    {
        bail!(
            "--checkpoint-every {every:.6}: give 0 (never) or seconds from {MIN_CHECKPOINT_SECONDS} to {MAX_CHECKPOINT_SECONDS:e}"
        );
    }
    if let Some(out) = &a.out {
        let ckpt = super::checkpoint::path_for(out);
        // A legal --out whose checkpoint's name is not (245–255 bytes): every checkpoint would
        // fail, and Ctrl-C lose every sample.
        let ckpt_len = ckpt.file_name().map_or(0, |n| n.len());
        if every != 0.0 && ckpt_len > color::outfile::NAME_MAX {
            bail!(
                "--out {}: its checkpoint's name (--out's + .checkpoint) would be {ckpt_len} bytes, past the {} \
                 file systems allow; shorten the name, or give --checkpoint-every 0",
                out.display(),
                color::outfile::NAME_MAX
            );
        }
        // The cache is a folder made on first use: the same path as an output or the checkpoint
        // would end a long render in "is a directory" (or leave a folder where the next run
        // looks for an interrupted render's checkpoint).
        if let Some(cache) = &a.truth_cache {
            let same = |p: &std::path::Path| std::path::absolute(p).ok() == std::path::absolute(cache).ok();
            for (flag, p) in [
                ("--out", Some(out.as_path())),
                ("--spectral-out", a.spectral_out.as_deref()),
                ("the checkpoint", Some(ckpt.as_path())),
            ] {
                if let Some(p) = p.filter(|p| same(p)) {
                    bail!("{flag} {} is the --truth-cache folder; give each a path of its own", p.display());
                }
            }
        }
        match std::fs::symlink_metadata(&ckpt) {
            Ok(m) if m.is_dir() => bail!(
                "{}: a folder is where this render keeps its checkpoint (--out's name + .checkpoint); move it, or choose another --out",
                ckpt.display()
            ),
            Ok(_) if !a.resume => bail!(
                "{}: the checkpoint of an interrupted render is there: add --resume to continue it, or remove it to start over",
                ckpt.display()
            ),
            _ => {}
        }
    }
    let scene = a.scene.load(a.water.water.as_deref())?;
    let mut inputs = a.scene.input_files(&scene);
    inputs.extend(a.table.input_files());
    inputs.extend(a.rgb_medium.input_files());
    inputs.extend(
        a.medium
            .iter()
            .filter(|m| !super::setup::inline_json(m))
            .map(|m| ("--medium file".to_string(), PathBuf::from(m))),
    );
    inputs.extend(super::setup::observer_input(a.spectrum.observer.as_deref()));
    let ckpt = a.out.as_deref().map(super::checkpoint::path_for);
    super::check_outputs(
        &[
            ("--out", a.out.as_deref()),
            ("--spectral-out", a.spectral_out.as_deref()),
            ("the checkpoint", ckpt.as_deref()),
        ],
        &inputs,
    )?;
    let table = a.table.load()?;
    let st = settings(&a, &scene, &table)?;
    let t0 = Instant::now();
    let mut world = World::new(&scene, table.as_ref(), &st.white, st.range, st.medium.as_ref())?;
    if let Some(env) = &st.environment {
        world = world.with_environment(env);
    }
    let prep = t0.elapsed();
    if let Some(dir) = &a.export_mitsuba {
        let skipped = truth::export_mitsuba::export(&world, st.width, st.height, dir, color::cancel::token())
            .with_context(|| format!("exporting to {}", dir.display()))?;
        eprintln!("exported {} for Mitsuba to {}", scene.source, dir.display());
        for s in skipped {
            eprintln!("  not exported: {s}");
        }
    }
    let Some(out) = &a.out else { return Ok(()) };

    // One render per --out while checkpoints are on (they share the checkpoint file).
    let _lock = (a.checkpoint_every != 0.0).then(|| super::checkpoint::OutLock::take(out)).transpose()?;
    let ckpt = super::checkpoint::path_for(out);
    let ckpt_record = record(&a, &scene, &st, &table, st.spectral_bands.is_some())?;
    let cache = a.truth_cache.as_deref().map(super::truth_cache::TruthCache::open).transpose()?;
    let fields = sum_fields(&scene, &st, &table, &a.scene.input_files(&scene), st.spectral_bands.is_some())?;
    let mut cached = 0;
    let mut acc = if a.resume {
        if std::fs::symlink_metadata(&ckpt).is_err() {
            bail!("--resume: there is no checkpoint {} to continue", ckpt.display());
        }
        super::checkpoint::read(&ckpt, &ckpt_record, &st)?
    } else if let Some(c) = &cache {
        let start = c.start(&fields, &st)?;
        for n in &start.notes {
            eprintln!("{n}");
        }
        cached = start.acc.done;
        match &start.from {
            Some(p) if cached == st.spp => {
                eprintln!("truth cache: all {} samples from {}; nothing to render", st.spp, p.display())
            }
            Some(p) => eprintln!(
                "truth cache: {cached} of {} samples from {}; rendering the other {}",
                st.spp,
                p.display(),
                st.spp - cached
            ),
            None => {
                eprintln!("truth cache: nothing stored for this render yet; rendering {} samples", st.spp)
            }
        }
        start.acc
    } else {
        truth::Accumulator::new(&st)?
    };
    let rows = u64::from(st.window().height);
    // Progress in pixel rows × samples, so resumed samples show as done.
    let pb = ProgressBar::new(rows * u64::from(st.spp));
    if let Ok(style) =
        ProgressStyle::with_template("truth [{bar:30}] {percent}% {msg}, {elapsed} (eta {eta})")
    {
        pb.set_style(style.progress_chars("=> "));
    }
    let t1 = Instant::now();
    let cancel = color::cancel::token();
    let interval = a.checkpoint_every;
    let mut last_write = t1;
    let mut per_sample: Option<f64> = None;
    let resumed = acc.done;
    while acc.done < st.spp {
        // Passes of at most half an interval (a first pass of one sample measures them), so a
        // checkpoint is at most one interval old, and no longer than all the passes before
        // them: they double from the first, so that Ctrl-C, which keeps the finished passes,
        // loses at most about half of what was rendered. Without checkpoints, one pass.
        let left = st.spp - acc.done;
        let n = match (interval > 0.0, per_sample) {
            (false, _) => left,
            (true, None) => 1,
            (true, Some(t)) => {
                let rendered = f64::from(acc.done - resumed) * t;
                let budget = (0.5 * interval).min(rendered.max(t));
                ((budget / t.max(1e-9)).floor().clamp(1.0, f64::from(left))) as u32
            }
        };
        let done = acc.done;
        // The samples this pass renders (the bar moves with its rows): "1/256" for a whole
        // render in one pass read as if it had stalled at the first sample.
        pb.set_message(format!("samples {}–{} of {}", done + 1, done + n, st.spp));
        let t = Instant::now();
        let r = truth::render_pass(&world, &st, cancel, &mut acc, n, &|r| {
            pb.set_position(rows * u64::from(done) + r * u64::from(n))
        });
        match r {
            Err(TruthError::Cancelled) => {
                pb.finish_and_clear();
                // Every finished pass is kept (only an interval's worth was, which threw away up
                // to a minute of rendering at the default interval).
                if interval > 0.0 && acc.done > resumed {
                    let _hold = color::cancel::hold();
                    super::checkpoint::write(&ckpt, &ckpt_record, &st, &acc)?;
                    return Err(super::KeptOnInterrupt(format!(
                        "{} of {} samples kept in {}: the same command with --resume continues",
                        acc.done,
                        st.spp,
                        ckpt.display()
                    ))
                    .into());
                }
                if a.resume && resumed > 0 {
                    // Nothing new kept, but the checkpoint this run resumed from is intact.
                    return Err(super::KeptOnInterrupt(format!(
                        "{resumed} of {} samples still kept in {}: the same command with --resume continues",
                        st.spp,
                        ckpt.display()
                    ))
                    .into());
                }
                bail!("interrupted; nothing written");
            }
            r => r?,
        }
        per_sample = Some(t.elapsed().as_secs_f64() / f64::from(n));
        if interval > 0.0 && acc.done < st.spp && last_write.elapsed().as_secs_f64() >= interval {
            // A checkpoint is a safety net: one that cannot be written (a full disk, a quota)
            // must not cost the samples it was to keep. Tried again an interval later.
            let _hold = color::cancel::hold();
            if let Err(e) = super::checkpoint::write(&ckpt, &ckpt_record, &st, &acc) {
                pb.suspend(|| eprintln!("warning: {e:#}; rendering on, trying again in {interval} s"));
            }
            last_write = Instant::now();
        }
    }
    pb.finish_and_clear();
    if let Some(c) = cache.as_ref().filter(|_| cached < st.spp) {
        // A cache that cannot take them does not cost the outputs.
        match c.store(&fields, &st, &acc) {
            Ok(p) => eprintln!("truth cache: stored {} samples in {}", st.spp, p.display()),
            Err(e) => eprintln!("warning: {e:#}: the samples are not cached"),
        }
    }
    let img = acc.finish(&st);
    let secs = t1.elapsed().as_secs_f64();
    // Every sample is rendered: an interrupt now (while the cache was stored, say) would throw
    // the whole render away to save the second its writing takes, so it is written, held
    // against the forced exit.
    let _hold = color::cancel::hold();
    let late = cancel.load(Ordering::Relaxed);
    let data = if a.xyz {
        img.xyz.clone()
    } else {
        img.to_display(&st, color::film::CameraView::from_flag(a.spectrum.camera_to_display))?
    };
    let image = compare::image::Image::new(img.width, img.height, data)?;
    let win = st.window();
    let frame = sealed(
        compare::ExrFrame {
            display: (st.width, st.height),
            origin: (win.x, win.y),
            attributes: record(&a, &scene, &st, &table, false)?,
        },
        (img.width, img.height),
    );
    // Both outputs are staged, complete on disk, before either is put in place: a failure on
    // the second (a full disk) left the first replaced beside the second's old version.
    let mut staged = Vec::new();
    if let (Some(sp), Some(bands)) = (&a.spectral_out, img.spectral.clone()) {
        let edges = st.spectral_bands.clone().expect("bands were asked for");
        let white = a.spectrum.resolve(&scene)?.white;
        let spec = compare::SpectralImage {
            width: img.width,
            height: img.height,
            kind: compare::SpectralKind::Emissive,
            edges,
            data: bands,
            white: Some(white),
            centres: None,
        };
        let spectral_frame = sealed(
            compare::ExrFrame { attributes: record(&a, &scene, &st, &table, true)?, ..frame.clone() },
            (img.width, img.height),
        );
        let bytes = compare::encode_spectral_exr_framed(sp, &spec, Some(&image), Some(&spectral_frame))
            .with_context(|| format!("writing {}", sp.display()))?;
        staged.push(super::stage_output(sp, &bytes)?);
    }
    let is_exr = out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    let bytes = if is_exr {
        compare::encode_exr_framed(out, &image, &frame)
    } else {
        compare::io::encode_image(out, &image, Default::default())
    }
    .with_context(|| format!("writing {}", out.display()))?;
    staged.push(super::stage_output(out, &bytes)?);
    super::commit_outputs(staged)?;
    // The outputs are complete: the samples are safe in them.
    if std::fs::symlink_metadata(&ckpt).is_ok()
        && let Err(e) = std::fs::remove_file(&ckpt)
    {
        eprintln!("warning: removing the checkpoint {}: {e} (the outputs are complete)", ckpt.display());
    }
    // This process's paths (a resumed render did the checkpoint's before).
    let paths = img.width as f64 * img.height as f64 * f64::from(st.spp - resumed);
    let y = img.mean()[1];
    let env = match &scene.environment {
        Some(e) => format!(", environment {} × {}", e.source, e.intensity + 0.0),
        None => String::new(),
    };
    eprintln!(
        "{}: {} {}×{}{} at {} spp{}, {:.0}–{:.0} nm{}{}{}; {:.2} s ({:.2} s setup), {} Mpaths/s, mean Y {:.5}{}",
        out.display(),
        scene.source,
        st.width,
        st.height,
        st.crop.map_or(String::new(), |c| format!(" (crop {}×{} at {},{})", c.width, c.height, c.x, c.y)),
        st.spp,
        if st.sample_offset > 0 || a.chunk.is_some() {
            format!(" (samples {}..{})", st.sample_offset, st.sample_offset + u64::from(st.spp))
        } else {
            String::new()
        },
        st.range.min,
        st.range.max,
        if st.direct_only { ", direct only" } else { "" },
        if st.lambert { ", Lambert" } else { "" },
        env,
        secs,
        prep.as_secs_f64(),
        if paths > 0.0 { format!("{:.3}", paths / secs / 1e6) } else { "–".into() },
        y,
        if img.dropped > 0 { format!(", {} non-finite samples dropped", img.dropped) } else { String::new() }
    );
    if a.resume && resumed > 0 {
        eprintln!("  resumed from {} with {resumed} of {} samples done", ckpt.display(), st.spp);
    }
    if late {
        eprintln!("  interrupted after the last sample: the finished render is written");
    }
    if let (Some(sp), Some(edges)) = (&a.spectral_out, &st.spectral_bands) {
        // The bands as written (a --spectral-bin wider than the range is one band of it; the
        // requested width was shown, 301 digits for 1e300).
        let width = (edges[edges.len() - 1] - edges[0]) / (edges.len() - 1) as f64;
        eprintln!(
            "{}: {} bands of {width:.4} nm, {:.0}–{:.0} nm (S0.<λ>nm channels, with R, G, B)",
            sp.display(),
            edges.len() - 1,
            st.range.min,
            st.range.max
        );
    }
    Ok(())
}

/// `truth --times`: each frame a render of its own (`run` with its moment and output names),
/// in order; `--resume` skips the frames whose output exists without a checkpoint beside it
/// and continues the one with a checkpoint.
fn run_sequence(a: Args, arg: &str) -> Result<()> {
    use super::sequence;
    sequence::require_gltf(arg, &a.scene.scene)?;
    if a.export_mitsuba.is_some() {
        bail!("--export-mitsuba exports one moment: give --time instead of --times");
    }
    let Some(out) = a.out.clone() else {
        bail!("--times needs --out with a frame number, e.g. --out run_%04d.exr");
    };
    let end = if sequence::needs_end(arg) {
        a.scene.load_at(a.water.water.as_deref(), sequence::start(arg)?, false)?.animation_end
    } else {
        None
    };
    let times = sequence::parse_times(arg, end)?;
    let n = times.len();
    let frame = |i: usize| -> Result<(std::path::PathBuf, Option<std::path::PathBuf>)> {
        Ok((
            sequence::frame_path("--out", &out, i)?,
            a.spectral_out.as_deref().map(|sp| sequence::frame_path("--spectral-out", sp, i)).transpose()?,
        ))
    };
    // Every name is checked before the first frame is rendered.
    for i in 0..n {
        frame(i)?;
    }
    let (mut done, mut kept) = (0usize, 0usize);
    for (i, &t) in times.iter().enumerate() {
        let (o, sp) = frame(i)?;
        let checkpoint = super::checkpoint::path_for(&o);
        let resume = a.resume && checkpoint.exists();
        if a.resume && !resume && o.is_file() && sp.as_deref().is_none_or(std::path::Path::is_file) {
            kept += 1;
            continue;
        }
        eprintln!("frame {}/{n} at {t} s: {}", i + 1, o.display());
        let mut f = a.clone();
        f.times = None;
        f.out = Some(o.clone());
        f.spectral_out = sp;
        f.scene.files.time = Some(t);
        f.resume = resume;
        match run(f) {
            Ok(()) => done += 1,
            Err(e) if color::cancel::is_cancelled() => {
                let this = match e.downcast_ref::<super::KeptOnInterrupt>() {
                    Some(k) => format!("; frame {i}: {k}"),
                    None => String::new(),
                };
                return Err(super::KeptOnInterrupt(format!(
                    "{} of {n} frames written{this}; the same command with --resume goes on",
                    done + kept
                ))
                .into());
            }
            Err(e) => {
                return Err(e.context(format!(
                    "frame {i} at {t} s ({} of {n} frames written before it)",
                    done + kept
                )));
            }
        }
    }
    eprintln!(
        "{}: {n} frames, {}–{} s{}",
        out.display(),
        times[0],
        times[n - 1],
        if kept > 0 { format!(" ({kept} already there kept, {done} rendered)") } else { String::new() }
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(extra: &[&str]) -> Args {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            a: Args,
        }
        Cli::parse_from(["truth", "cornell"].iter().chain(extra)).a
    }

    fn srgb_table() -> std::sync::Arc<color::upsample::CoeffTable> {
        color::upsample::table("srgb").expect("the sRGB table")
    }

    /// A scene file replaced after it was loaded (an exporter's rename over it, found by a
    /// sweep: 12–19 of 30 renders recorded the other version) is not hashed into a record as if
    /// it had been rendered: the hash is refused, naming the file.
    #[test]
    fn a_file_replaced_after_loading_is_not_recorded() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("box.gltf");
        scene::write_gltf(&scene::builtin("cornell").unwrap(), &file).unwrap();
        let a = args(&[]);
        let scene = scene::load(&file).unwrap();
        let tab = srgb_table();
        let st = settings(&a, &scene, &tab).unwrap();
        let inputs = vec![("scene file".to_string(), file.clone())];
        let before = sum_fields(&scene, &st, &tab, &inputs, false).unwrap();
        let copy = dir.path().join("new.gltf");
        std::fs::copy(&file, &copy).unwrap();
        std::fs::rename(&copy, &file).unwrap();
        let e = format!("{:#}", sum_fields(&scene, &st, &tab, &inputs, false).unwrap_err());
        assert!(e.contains("box.gltf") && e.contains("changed while the scene was being loaded"), "{e}");
        // Loaded again, it hashes as before (the same bytes).
        let again = scene::load(&file).unwrap();
        assert_eq!(sum_fields(&again, &st, &tab, &inputs, false).unwrap(), before);
    }

    /// `--rgb-medium` inline or from a file reaches the tracer as a medium filling the scene;
    /// bad input is an error naming the flag and the field; it cannot be combined with water or
    /// `--medium`.
    #[test]
    fn rgb_medium_flag() {
        let scene = scene::builtin("cornell").unwrap();
        let tab = srgb_table();
        let a = args(&[
            "--rgb-medium",
            r#"{"absorption": [0.5, 0.2, 0.1], "scattering": [0.1, 0.1, 0.1], "g": 0.5}"#,
        ]);
        let m = settings(&a, &scene, &tab).unwrap().medium.expect("a medium");
        assert_eq!(m.region, truth::Region::Everywhere);
        assert_eq!(m.phase, truth::Phase::HenyeyGreenstein { g: 0.5 });
        // Box upsampling of the extinction: the red channel's at 650 nm, the blue one's at 450 nm.
        let t = |l: f64| m.sigma_a.eval(l) + m.sigma_s.eval(l);
        assert!((t(650.0) - 0.6).abs() < 1e-9 && (t(450.0) - 0.2).abs() < 1e-9, "{} {}", t(650.0), t(450.0));
        let dir = std::env::temp_dir().join(format!("spectra-rgb-medium-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("fog.json");
        std::fs::write(
            &f,
            r#"{"attenuation_color": [0.5, 0.5, 0.5], "attenuation_distance": 2, "albedo": [1, 1, 1]}"#,
        )
        .unwrap();
        let m =
            settings(&args(&["--rgb-medium", f.to_str().unwrap()]), &scene, &tab).unwrap().medium.unwrap();
        assert_eq!(m.sigma_a, color::Spectrum::Constant(0.0));
        let e = |x: &[&str]| format!("{:#}", settings(&args(x), &scene, &tab).unwrap_err());
        let m = e(&["--rgb-medium", r#"{"absorption": [0.5, 0.2, 0.1], "g": 2}"#]);
        assert!(m.contains("--rgb-medium") && m.contains("g:") && m.contains("−1 and 1"), "{m}");
        let m = e(&["--rgb-medium", r#"{"absorption": [0.5, -0.2, 0.1]}"#]);
        assert!(m.contains("absorption") && m.contains("green"), "{m}");
        let m = e(&["--rgb-medium", "no-such-medium.json"]);
        assert!(m.contains("no-such-medium.json"), "{m}");
        let m = e(&["--rgb-medium", r#"{"absorption": [1, 1, 1]}"#, "--water", "II"]);
        assert!(m.contains("cannot be combined"), "{m}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn refuses_bad_requests_before_any_work() {
        let e = |x: &[&str]| format!("{:#}", run(args(x)).unwrap_err());
        assert!(e(&[]).contains("nothing to do"));
        assert!(e(&["--spp", "0", "--out", "x.exr"]).contains("at least 1"));
        assert!(e(&["--out", "x.bmp"]).contains(".exr"));
        assert!(e(&["--xyz", "--out", "x.png"]).contains("--xyz"));
        assert!(e(&["--spectral-out", "s.exr"]).contains("needs --out"));
        assert!(e(&["--out", "x.exr", "--spectral-out", "s.png"]).contains(".exr name"));
        assert!(e(&["--out", "x.exr", "--spectral-out", "s.exr", "--xyz"]).contains("--xyz"));
        let m = e(&["--out", "x.exr", "--spectral-out", "s.exr", "--spectral-bin", "-5"]);
        assert!(m.contains("--spectral-bin") && m.contains("positive"), "{m}");
        assert!(!std::path::Path::new("s.exr").exists());
        assert!(e(&["--size", "0x4", "--out", "x.exr"]).contains("positive"));
        let m = e(&["--size", "4294967295x1", "--out", "x.exr"]);
        assert!(m.contains("too large") && m.contains("4294967295"), "{m}");
        // The directory is checked before the render, not after it.
        let t = std::time::Instant::now();
        let m = e(&["--spp", "100000", "--out", "no-such-dir/x.exr"]);
        assert!(m.contains("--out") && m.contains("no-such-dir") && m.contains("does not exist"), "{m}");
        assert!(t.elapsed().as_secs() < 5);
        let m = e(&["--export-mitsuba", "no-such-dir/export"]);
        assert!(m.contains("--export-mitsuba") && m.contains("does not exist"), "{m}");
        assert!(!std::path::Path::new("x.exr").exists());
    }

    /// `--env FILE` that cannot be used is an error naming the file, before any work, and
    /// nothing is written.
    #[test]
    fn a_bad_environment_file_is_an_error_naming_it() {
        let dir = std::env::temp_dir().join(format!("spectra-truth-env-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("t.exr");
        let out_s = out.display().to_string();
        let missing = dir.join("missing-sky.hdr").display().to_string();
        let m = format!("{:#}", run(args(&["--env", &missing, "--out", &out_s])).unwrap_err());
        assert!(m.contains("missing-sky.hdr"), "{m}");
        let corrupt = dir.join("corrupt.exr");
        std::fs::write(&corrupt, b"not an exr").unwrap();
        let c = corrupt.display().to_string();
        let m = format!("{:#}", run(args(&["--env", &c, "--out", &out_s])).unwrap_err());
        assert!(m.contains("corrupt.exr"), "{m}");
        let m = format!(
            "{:#}",
            run(args(&["--env", "none", "--env-intensity", "2", "--out", &out_s])).unwrap_err()
        );
        assert!(m.contains("--env-intensity"), "{m}");
        assert!(!out.exists());
        std::fs::remove_dir_all(&dir).ok();
    }

    /// `--env default` on the Cornell box gives the tracer an environment map; `--env none`
    /// none; under water an environment map is refused by the tracer.
    #[test]
    fn env_flags_reach_the_tracer() {
        let up = truth::upsample::GreyOnly;
        for (flags, want) in
            [(&["--env", "default", "--env-rotation", "-30"][..], true), (&["--env", "none"][..], false)]
        {
            let a = args(flags);
            let mut scene = scene::builtin("cornell").unwrap();
            a.scene.env.apply(&mut scene, false).unwrap();
            let st = settings(&a, &scene, &srgb_table()).unwrap();
            let w = World::new(&scene, &up, &st.white, st.range, None).unwrap();
            assert_eq!(w.env_map.is_some(), want, "{flags:?}");
        }
        let mut a = args(&["--env", "default"]);
        a.scene.scene = "underwater".into();
        let mut scene = scene::builtin("underwater").unwrap();
        a.scene.env.apply(&mut scene, false).unwrap();
        let st = settings(&a, &scene, &srgb_table()).unwrap();
        let e = World::new(&scene, &up, &st.white, st.range, st.medium.as_ref()).err().unwrap();
        assert!(e.to_string().contains("environment map"), "{e}");
    }

    /// The underwater scene's truth has the water surface and, from the scene's sky stand-in,
    /// a sky; `--water` on it changes the type and keeps the sky.
    #[test]
    fn underwater_truth_sees_the_sky_through_the_surface() {
        let scene = scene::builtin("underwater").unwrap();
        for extra in [&[][..], &["--water", "II"][..]] {
            let mut a = args(extra);
            a.scene.scene = "underwater".into();
            let st = settings(&a, &scene, &srgb_table()).unwrap();
            let m = st.medium.as_ref().unwrap();
            assert_eq!(m.surface_ior, Some(scene::water::WATER_IOR as f32));
            let w = World::new(&scene, &truth::upsample::GreyOnly, &st.white, st.range, Some(m)).unwrap();
            let sky = w.surface.as_ref().and_then(|s| s.sky.as_ref()).expect("a sky");
            assert!(sky.eval(550.0) > 0.0);
        }
    }
}
