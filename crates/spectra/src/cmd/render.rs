//! `spectra render`: one frame of the real-time renderer, headless, to PNG (tone-mapped) or
//! EXR (linear HDR × 2^EV).

use super::sequence;
use super::setup::{LookArgs, SceneArgs, parse_size};
use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use render::{Mode, RenderSettings, Renderer};
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    #[command(flatten)]
    pub look: LookArgs,
    /// Image size WIDTHxHEIGHT (or WIDTHXHEIGHT, WIDTH*HEIGHT).
    #[arg(long, default_value = "640x480")]
    pub size: String,
    /// Disable shadow maps (otherwise every light, up to 32, casts shadows through a map of its own).
    #[arg(long)]
    pub no_shadows: bool,
    /// Output file: .png (tone-mapped, sRGB) or .exr (linear HDR).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the radiance at the N wavelength nodes as a spectral EXR (the OpenEXR layout
    /// of Fichet et al. 2021, as `truth --spectral-out` writes it: channels S0.<λ>nm for the N
    /// equal bins around the nodes, with the linear R, G, B beside them). With --quadrature
    /// midpoint the bins integrate back (`spectra diff`) to the frame's own pixels, to f16
    /// rounding, at any N and range; with the default prefiltered rule they hold the radiance
    /// averaged around each node (docs/spectral-exr.md). Spectral or naive mode.
    #[arg(long, value_name = "FILE.exr")]
    pub spectral_out: Option<PathBuf>,
    /// Antialiasing: the mean of this many frames, each sampling the scene at another place in
    /// every pixel (a √K × √K grid when K is a square, else a Hammersley set), which is the
    /// image box-filtered over each pixel, as the path tracer's pixels are. 1 (the default)
    /// samples the pixel centres once; at most 256.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=MAX_SAMPLES as i64))]
    pub samples: u32,
    /// Render the glTF file's animation (`--animation`, default its first) as a sequence of
    /// frames: START:END:STEP in seconds (END included when a step lands on it; `end`: the
    /// animation's last key, e.g. 0:end:0.04), or a list of moments T1,T2,…. `--out` (and `--spectral-out`) then hold a frame number, %d or %0Nd,
    /// e.g. `--out fox_%04d.png` (frames numbered from 0, as ffmpeg reads them). Each frame is
    /// written when drawn; Ctrl-C keeps those finished. At most 100000 frames.
    #[arg(long, value_name = "START:END:STEP|T1,T2,…", conflicts_with = "time")]
    pub times: Option<String>,
    /// With `--times`: skip the frames whose files already exist (an interrupted sequence's
    /// rerun draws only the rest).
    #[arg(long, requires = "times")]
    pub resume: bool,
}

/// The most frames `--samples` averages.
pub const MAX_SAMPLES: u32 = 256;

/// Where sample `i` of `k` looks in its pixel, in pixels from the centre: the centres of a
/// √k × √k grid of equal cells when k is a square (the box filter's midpoint rule), else the
/// Hammersley set — x at the centres of k equal columns, y the base-2 radical inverse of i —
/// which covers the pixel evenly for any k and keeps the offsets' mean at the pixel centre
/// (exactly in x; within about log₂k / 2k in y), so the mean image is not shifted.
pub fn pixel_offset(i: u32, k: u32) -> [f32; 2] {
    let n = (f64::from(k).sqrt().round() as u32).max(1);
    if n * n == k {
        let cell = |j: u32| ((f64::from(j) + 0.5) / f64::from(n) - 0.5) as f32;
        return [cell(i % n), cell(i / n)];
    }
    let k = f64::from(k);
    let radical_inverse = f64::from(i.reverse_bits()) / 2f64.powi(32);
    [((f64::from(i) + 0.5) / k - 0.5) as f32, (radical_inverse + 0.5 / k - 0.5) as f32]
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum OutFormat {
    Png,
    Exr,
}

fn out_format(path: &Path) -> Result<OutFormat> {
    match path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("png") => Ok(OutFormat::Png),
        Some("exr") => Ok(OutFormat::Exr),
        other => bail!(
            "--out {}: unknown image extension {}; use .png (tone-mapped) or .exr (linear HDR)",
            path.display(),
            other.map(|e| format!("'.{e}'")).unwrap_or_else(|| "(none)".into())
        ),
    }
}

/// Draws the image: one frame at the pixel centres (`samples` = 1), or the mean of `samples`
/// frames at offsets spread over each pixel (`pixel_offset`), accumulated on the GPU in f32 —
/// post then tone-maps the mean for `read_ldr`. `interrupted` is asked before every frame.
pub fn draw(
    r: &mut Renderer,
    camera: &scene::Camera,
    settings: &RenderSettings,
    samples: u32,
    interrupted: &dyn Fn() -> Result<(), render::RenderError>,
) -> Result<(), render::RenderError> {
    if samples <= 1 {
        r.set_accumulation(false);
        return r.render(camera, settings);
    }
    r.set_accumulation(true);
    r.reset_accumulation();
    // Texture reads as fine as the samples are dense (`RenderSettings::texture_lod_bias`).
    let bias = settings.texture_lod_bias - 0.5 * (samples as f32).log2();
    for i in 0..samples {
        interrupted()?;
        let s = RenderSettings {
            pixel_offset: Some(pixel_offset(i, samples)),
            texture_lod_bias: bias,
            ..settings.clone()
        };
        r.render(camera, &s)?;
    }
    Ok(())
}

/// The linear HDR image `draw` made.
pub fn read_linear(r: &Renderer, samples: u32) -> Result<Vec<[f32; 4]>, render::RenderError> {
    if samples <= 1 { r.read_hdr() } else { r.read_accumulated() }
}

/// Warns on stderr when even the brightest pixel of `hdr` (a read-back frame of `scene`) lies
/// below the half-float target's normal range (`render::passes::hdr_too_dim`): `render` and the
/// Python `Renderer.render` share it.
pub fn warn_if_too_dim(scene: &scene::Scene, hdr: &[[f32; 4]]) {
    // (A scene that nothing lights has had its own warning.)
    let lit = scene::environment::LightSources::of(scene).any();
    if let Some(max) = render::passes::hdr_too_dim(hdr).filter(|_| lit) {
        let what = if max > 0.0 {
            format!("the brightest pixel is {max:.2e}")
        } else {
            "every pixel is 0".to_string()
        };
        eprintln!(
            "warning: {what}, below the smallest normal value of the real-time renderer's half-float \
             target ({:.1e}; nothing below 6e-8 is kept): the image is banded or black; raise --exposure \
             (applied before the target) or the scene's light (its intensities, --env-intensity)",
            render::passes::HDR_MIN_NORMAL
        );
    }
}

/// Where one frame goes: `--out` and `--spectral-out`, or a sequence's frame of them.
struct Outputs {
    out: PathBuf,
    spectral_out: Option<PathBuf>,
}

/// Renders the frame and writes its outputs; `first`: the renderer's warnings about the scene
/// are printed (a sequence's later frames would repeat them).
#[allow(clippy::too_many_arguments)]
fn render_frame(
    r: &mut Renderer,
    args: &RenderArgs,
    outputs: &Outputs,
    scene: &scene::Scene,
    settings: &RenderSettings,
    custom: Option<render::CustomShader>,
    format: OutFormat,
    (width, height): (u32, u32),
    first: bool,
) -> Result<()> {
    // Before anything is allocated for the frame.
    if let Some(sp) = &outputs.spectral_out {
        r.check_spectral_capture(width, height, settings.wavelengths)
            .map_err(|e| anyhow!("--spectral-out {}: {e}", sp.display()))?;
    }
    r.set_scene(scene)?;
    if first {
        for w in r.scene_warnings() {
            eprintln!("warning: {}: {w}", scene.source);
        }
    }
    // The water's or the RGB medium's hooks.
    if let Some(c) = custom {
        r.set_custom_shader(c)?;
    }
    r.resize(width, height).map_err(|e| anyhow!("--size {width}x{height}: {e}"))?;
    if outputs.spectral_out.is_some() {
        r.set_spectral_capture(true);
    }
    // Encoding a large image takes seconds; Ctrl-C meanwhile must not be followed by a write.
    let interrupted =
        || if color::cancel::is_cancelled() { Err(render::RenderError::Cancelled) } else { Ok(()) };
    let samples = args.samples;
    draw(r, &scene.camera, settings, samples, &interrupted)?;
    // The exposure is in the HDR values already (the shaders apply it before the half float);
    // the spectral capture, an f32 buffer of radiance, takes it here.
    let k = settings.exposure_ev.exp2();
    // Linear outputs hold the HDR values themselves, so their clipping is worth a warning (a PNG
    // is tone mapped: a clipped pixel is white either way).
    let linear_out = outputs.spectral_out.is_some() || matches!(format, OutFormat::Exr);
    let hdr = read_linear(r, samples)?;
    warn_if_too_dim(scene, &hdr);
    let clipped = if linear_out { render::passes::hdr_clipped(&hdr) } else { 0 };
    if clipped > 0 {
        eprintln!(
            "warning: {clipped} pixels reached the HDR target's largest value ({}) and are clipped there; \
             lower --exposure (applied before the target) or the light (--env-intensity, the scene's intensities)",
            render::passes::HDR_MAX
        );
    }
    // An interrupt is honoured up to here; once the outputs are being written both are, held
    // against the forced exit (a Ctrl-C between them left a new spectral file beside the old
    // image, and said no output was written). Both are staged, complete on disk, before either
    // is put in place: a full disk on the second left the first replaced beside the second's
    // old version.
    interrupted()?;
    let _hold = color::cancel::hold();
    let mut staged = Vec::new();
    if let Some(sp) = &outputs.spectral_out {
        let cap = r.read_spectral_capture()?;
        let rgb = hdr.iter().map(|p| [p[0], p[1], p[2]]).collect();
        let rgb = compare::image::Image::new(width, height, rgb)?;
        let spec = compare::SpectralImage {
            width,
            height,
            kind: compare::SpectralKind::Emissive,
            edges: cap.edges,
            data: cap.data.into_iter().map(|v| v * k).collect(),
            white: Some(settings.white.clone()),
            centres: None,
        };
        let bytes = compare::encode_spectral_exr_framed(sp, &spec, Some(&rgb), None)
            .with_context(|| format!("writing {}", sp.display()))?;
        staged.push(super::stage_output(sp, &bytes)?);
    }
    let bytes = match format {
        OutFormat::Png => {
            let rgba = r.read_ldr()?;
            let img =
                image::RgbaImage::from_raw(width, height, rgba).context("readback has the wrong size")?;
            let mut bytes = std::io::Cursor::new(Vec::new());
            img.write_to(&mut bytes, image::ImageFormat::Png).context("encoding PNG")?;
            bytes.into_inner()
        }
        OutFormat::Exr => {
            let data = hdr.iter().map(|p| [p[0], p[1], p[2]]).collect();
            let img = compare::image::Image::new(width, height, data)?;
            compare::io::encode_image(&outputs.out, &img, Default::default())
                .with_context(|| format!("writing {}", outputs.out.display()))?
        }
    };
    staged.push(super::stage_output(&outputs.out, &bytes)?);
    super::commit_outputs(staged)
}

/// The outputs of frame `index` of a sequence, or the single frame's (`times` is `None`).
fn outputs(args: &RenderArgs, times: Option<&[f64]>, index: usize) -> Result<Outputs> {
    if times.is_none() {
        return Ok(Outputs { out: args.out.clone(), spectral_out: args.spectral_out.clone() });
    }
    Ok(Outputs {
        out: sequence::frame_path("--out", &args.out, index)?,
        spectral_out: args
            .spectral_out
            .as_deref()
            .map(|sp| sequence::frame_path("--spectral-out", sp, index))
            .transpose()?,
    })
}

pub fn run(args: RenderArgs) -> Result<()> {
    let format = out_format(&args.out)?;
    let (width, height) = parse_size(&args.size)?;
    let water_arg = args.look.water.water.as_deref();
    // A range to the animation's end needs the file: it is loaded at the start first.
    let mut loaded = None;
    let times = match args.times.as_deref() {
        None => None,
        Some(arg) => {
            sequence::require_gltf(arg, &args.scene.scene)?;
            let end = if sequence::needs_end(arg) {
                let scene = args.scene.load_at(water_arg, sequence::start(arg)?, true)?;
                let end = scene.animation_end;
                loaded = Some(scene);
                end
            } else {
                None
            };
            Some(sequence::parse_times(arg, end)?)
        }
    };
    let first = outputs(&args, times.as_deref(), 0)?;
    super::check_output("--out", &first.out)?;
    if let Some(sp) = &args.spectral_out {
        if !sp.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
            bail!(
                "--spectral-out {}: a spectral image is an OpenEXR file; give it a .exr name",
                sp.display()
            );
        }
        if args.samples > 1 {
            bail!(
                "--spectral-out writes one frame's node radiances: it cannot be combined with --samples {} (drop one)",
                args.samples
            );
        }
        if args.look.mode == Mode::Rgb {
            bail!(
                "--spectral-out needs --mode spectral (or naive): --mode rgb shades in RGB and has no wavelengths to write"
            );
        }
        super::check_output("--spectral-out", first.spectral_out.as_deref().unwrap_or(sp))?;
    }
    let scene = match (loaded, &times) {
        (Some(scene), _) => scene,
        (None, Some(t)) => args.scene.load_at(water_arg, t[0], true)?,
        (None, None) => args.scene.load(water_arg)?,
    };
    let mut inputs = args.scene.input_files(&scene);
    inputs.extend(args.look.table.input_files());
    inputs.extend(args.look.rgb_medium.input_files());
    inputs.extend(super::setup::observer_input(args.look.spectrum.observer.as_deref()));
    for i in 0..times.as_ref().map_or(1, Vec::len) {
        let o = outputs(&args, times.as_deref(), i)?;
        super::check_outputs(
            &[("--out", Some(&o.out)), ("--spectral-out", o.spectral_out.as_deref())],
            &inputs,
        )?;
    }
    let settings = args.look.settings(&scene, !args.no_shadows, false)?;
    let table = args.look.table.load()?;
    let media = args.look.media(&scene, &table)?;
    let mut r = Renderer::with_table(table)?;
    let size = (width, height);
    let frames = match &times {
        None => render_frame(&mut r, &args, &first, &scene, &settings, media.shader()?, format, size, true)
            .map(|()| String::new()),
        Some(times) => render_sequence(&mut r, &args, times, &scene, &settings, &media, format, size),
    };
    let frames = match frames {
        Ok(f) => f,
        Err(e) => {
            if color::cancel::is_cancelled() {
                // Dropping the device waits for the frame in flight (28 s at 4096² on lavapipe):
                // the process is about to exit, so let the OS reclaim it instead.
                std::mem::forget(r);
            }
            return Err(e);
        }
    };
    let water = media.water;
    let under = water.as_ref().map_or(String::new(), |m| {
        let ty = m.water_type.map_or("custom".to_string(), |t| t.to_string());
        format!(", under water {ty} at {} m", m.depth)
    });
    let under = match (&scene.environment, r.environment_residual()) {
        (Some(e), Some(res)) => {
            format!("{under}, environment {} × {} (basis residual {res:.1e})", e.source, e.intensity + 0.0)
        }
        (Some(e), None) => format!("{under}, environment {} × {}", e.source, e.intensity + 0.0),
        (None, _) => under,
    };
    let under = match r.environment_sun() {
        Some((towards, _)) => format!(
            "{under}, its sun a shadowed directional light ({:.1}° up; --no-env-sun: off)",
            towards.y.clamp(-1.0, 1.0).asin().to_degrees()
        ),
        None => under,
    };
    let under = match r.emitter_summary() {
        Some((n, polygons, _)) if n > 0 && n == polygons => format!("{under}, {n} emissive polygon light(s)"),
        Some((n, polygons, frac)) if frac > 0.0 => format!(
            "{under}, {n} emissive area lights for {polygons} emitting polygons (warning: {:.1} % of the emitted \
             power left out: {})",
            100.0 * frac,
            // The scene's own lights come first: with none left over, the emitters got no slot.
            if n == 0 {
                "the scene's lights fill the real-time renderer's light slots"
            } else {
                "more emitting materials than light slots left"
            }
        ),
        Some((n, polygons, _)) if n > 0 => format!(
            "{under}, {n} emissive area lights: {polygons} emitting polygons clustered, all of their power \
             (their shape approximated)"
        ),
        _ => under,
    };
    if let Some(sp) = &args.spectral_out {
        eprintln!(
            "{}: {} bands of {:.3} nm over {:.0}–{:.0} nm, the {} quadrature's node radiances{} (S0.<λ>nm channels, with R, G, B)",
            sp.display(),
            settings.wavelengths,
            settings.range.width() / settings.wavelengths as f64,
            settings.range.min,
            settings.range.max,
            settings.quadrature.name(),
            match settings.quadrature {
                color::Quadrature::Midpoint => "",
                _ => ", band means that integrate back only approximately (docs/spectral-exr.md)",
            }
        );
    }
    let under = if args.samples > 1 { format!("{under}, {} samples per pixel", args.samples) } else { under };
    // N and the range mean nothing to the RGB mode.
    let spectrum = match settings.mode {
        Mode::Rgb => String::new(),
        _ => format!(" N={} {:.0}–{:.0} nm", settings.wavelengths, settings.range.min, settings.range.max),
    };
    eprintln!(
        "{}{frames}: {} {}×{}, {}{spectrum}{under}, on {}",
        args.out.display(),
        scene.source,
        width,
        height,
        settings.mode.name(),
        r.gpu().describe()
    );
    Ok(())
}

/// Draws and writes each frame of `--times` in turn, the first from `first_scene`, the others
/// from the file loaded again at their moment (the pose is made when a file is loaded); what
/// the summary line adds (" (N frames …)").
#[allow(clippy::too_many_arguments)]
fn render_sequence(
    r: &mut Renderer,
    args: &RenderArgs,
    times: &[f64],
    first_scene: &scene::Scene,
    settings: &RenderSettings,
    media: &super::setup::RealtimeMedia,
    format: OutFormat,
    size: (u32, u32),
) -> Result<String> {
    let n = times.len();
    let (mut written, mut kept) = (Vec::new(), 0usize);
    let water_arg = args.look.water.water.as_deref();
    for (i, &t) in times.iter().enumerate() {
        let o = outputs(args, Some(times), i)?;
        if args.resume && o.out.is_file() && o.spectral_out.as_deref().is_none_or(Path::is_file) {
            kept += 1;
            continue;
        }
        let first = written.is_empty();
        let mut frame = || -> Result<()> {
            let later;
            let scene = if i == 0 {
                first_scene
            } else {
                later = args.scene.load_at(water_arg, t, false)?;
                &later
            };
            render_frame(r, args, &o, scene, settings, media.shader()?, format, size, first)
        };
        match frame() {
            Ok(()) => {
                eprintln!("{}: frame {}/{n} at {t} s", o.out.display(), i + 1);
                written.push(o.out);
            }
            // Ctrl-C: what the frame in flight surfaced as matters less than what was kept.
            Err(_) if color::cancel::is_cancelled() && !written.is_empty() => {
                return Err(super::KeptOnInterrupt(format!(
                    "{} of {n} frames written ({} … {}); rerun with --resume to draw the rest",
                    written.len() + kept,
                    written[0].display(),
                    written[written.len() - 1].display()
                ))
                .into());
            }
            Err(e) => {
                return Err(e.context(format!(
                    "frame {i} at {t} s ({} of {n} frames written before it)",
                    written.len() + kept
                )));
            }
        }
    }
    Ok(format!(
        " ({n} frames, {}–{} s{})",
        times[0],
        times[n - 1],
        if kept > 0 {
            format!("; {kept} already there kept, {} drawn", written.len())
        } else {
            String::new()
        }
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sample_offsets_cover_the_pixel_evenly() {
        assert_eq!(pixel_offset(0, 1), [0.0, 0.0]);
        let grid: Vec<_> = (0..16).map(|i| pixel_offset(i, 16)).collect();
        for (i, o) in grid.iter().enumerate() {
            let want = |j: usize| (j as f32 + 0.5) / 4.0 - 0.5;
            assert_eq!(*o, [want(i % 4), want(i / 4)]);
        }
        // Not a square: every offset inside the pixel, their mean near its centre, and each
        // quarter of the pixel holding about a quarter of them.
        for k in [2u32, 5, 10, 24, 100] {
            let o: Vec<_> = (0..k).map(|i| pixel_offset(i, k)).collect();
            assert!(o.iter().flatten().all(|c| (-0.5..0.5).contains(c)), "{k}: {o:?}");
            let mean = o.iter().fold([0.0f32; 2], |m, p| [m[0] + p[0] / k as f32, m[1] + p[1] / k as f32]);
            assert!(
                mean[0].abs() < 0.5 / k as f32 + 0.05 && mean[1].abs() < 0.5 / k as f32 + 0.05,
                "{k}: {mean:?}"
            );
            if k >= 24 {
                for q in 0..4 {
                    let n = o
                        .iter()
                        .filter(|p| (p[0] >= 0.0) == (q & 1 == 1) && (p[1] >= 0.0) == (q & 2 == 2))
                        .count();
                    assert!(
                        (n as f32 - k as f32 / 4.0).abs() <= 0.1 * k as f32 + 1.0,
                        "{k}: quarter {q} has {n}"
                    );
                }
            }
        }
    }

    #[test]
    fn extensions() {
        assert_eq!(out_format(Path::new("a.PNG")).unwrap(), OutFormat::Png);
        assert_eq!(out_format(Path::new("a.exr")).unwrap(), OutFormat::Exr);
        let e = out_format(Path::new("a.jpg")).unwrap_err().to_string();
        assert!(e.contains(".jpg") && e.contains(".png"), "{e}");
    }
}
