//! `spectra render`: one frame of the real-time renderer, headless, to PNG (tone-mapped) or
//! EXR (linear HDR × 2^EV).

use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use color::WavelengthRange;
use color::upsample::CoeffTable;
use render::{Mode, RenderSettings, Renderer, Tonemap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Built-in scene name (cornell, colorchecker, metamerism, underwater, fog, tinted-fog) or a .gltf/.glb file.
    pub scene: String,
    #[command(flatten)]
    pub files: super::SceneFileArgs,
    #[command(flatten)]
    pub look: LookArgs,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480")]
    pub size: String,
    /// Disable shadow maps (otherwise each of the first eight lights casts shadows).
    #[arg(long)]
    pub no_shadows: bool,
    /// Output file: .png (tone-mapped, sRGB) or .exr (linear HDR).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the radiance at the N wavelength nodes as a spectral EXR (the OpenEXR layout
    /// of Fichet et al. 2021, as `truth --spectral-out` writes it: channels S0.<λ>nm for the N
    /// equal bins around the nodes, with the linear R, G, B beside them). With --quadrature
    /// midpoint the bins integrate back to the frame's XYZ; with the default prefiltered rule
    /// they hold the radiance averaged around each node (docs/spectral-exr.md). Spectral or
    /// naive mode.
    #[arg(long, value_name = "FILE.exr")]
    pub spectral_out: Option<PathBuf>,
}

/// What the picture looks like: shared by `spectra render` and `spectra view`.
#[derive(Args, Debug)]
pub struct LookArgs {
    /// rgb (classic), naive (box upsampling) or spectral (Jakob–Hanika).
    #[arg(long, default_value = "spectral")]
    pub mode: String,
    /// Number of wavelength samples (default: the scene's, else 16; the viewer shows 1–64).
    #[arg(long)]
    pub wavelengths: Option<usize>,
    /// Wavelength range in nm, MIN:MAX (default: the scene's, else 380:730).
    #[arg(long)]
    pub range: Option<String>,
    /// How the N wavelength nodes are integrated: prefiltered (light × observer integrated
    /// densely against the nodes' cubic interpolant, so line spectra never alias) or midpoint
    /// (the paper's point-sampled sum).
    #[arg(long, default_value = "prefiltered", value_parser = parse_quadrature)]
    pub quadrature: color::Quadrature,
    /// Observer: cie1931 or cie1964 (default: the scene's, else cie1931).
    #[arg(long)]
    pub observer: Option<String>,
    /// Exposure in stops (the image is multiplied by 2^EV).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Tone mapping (PNG output and the window): none, reinhard or aces.
    #[arg(long, default_value = "none")]
    pub tonemap: String,
    /// Jakob–Hanika coefficient table (.coeff). Default: the sRGB 64³ table, fitted once per
    /// machine and cached (see `spectra lut`, $SPECTRA_CACHE_DIR).
    #[arg(long)]
    pub table: Option<PathBuf>,
    /// Render under water: a Jerlov type (I, IA, IB, II, III, 1C … 9C, or a blend such as
    /// II.5). Default: the scene's own water settings, if it has any.
    #[arg(long, value_name = "TYPE")]
    pub water: Option<String>,
    /// Camera depth below the water surface, metres (default: the scene's, else 10).
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    pub depth: Option<f64>,
    /// A homogeneous medium filling the scene, given in RGB (inline JSON or a JSON file, as for
    /// `spectra truth --rgb-medium`; docs/rgb-media.md). Replaces the scene's extras.medium.
    #[arg(long, value_name = "JSON|FILE")]
    pub rgb_medium: Option<String>,
    /// Under water or in an RGB medium: ray-march steps for single scattering of the scene's
    /// lights (0–32; under water 0 = the paper's analytic in-scattering alone, in an RGB
    /// medium attenuation alone).
    #[arg(long, value_name = "STEPS", default_value_t = render::passes::underwater::Options::default().steps)]
    pub scatter_steps: u32,
    /// In an RGB medium: single scattering only, without the multiple-scattering term (what
    /// `spectra truth --direct-only` computes; docs/rgb-media.md).
    #[arg(long)]
    pub single_scattering: bool,
    /// Under water: Henyey–Greenstein asymmetry g of single scattering (default: Petzold's 0.924).
    #[arg(long, value_name = "G", allow_negative_numbers = true,
          default_value_t = render::passes::underwater::Options::default().phase_g)]
    pub phase_g: f32,
    /// Under water: the paper's model exactly (isotropic scattering of the plane irradiance
    /// attenuated by the tabulated Kd, no single scattering).
    #[arg(long, conflicts_with_all = ["scatter_steps", "phase_g", "scalar_irradiance", "split_beams", "water_surface",
          "isotropic", "tabulated_kd", "light_field_photons", "no_water_surface", "no_sea_floor",
          "no_surface_irradiance", "forward_cone"])]
    pub paper_model: bool,
    /// Under water: the paper's isotropic in-scattering term with the tabulated Kd plus the
    /// marched single scattering (the previous default) instead of the light-field source.
    #[arg(long, conflicts_with_all = ["tabulated_kd", "light_field_photons", "no_surface_irradiance"])]
    pub isotropic: bool,
    /// Under water, light-field model: attenuate surfaces by the type's tabulated Kd instead
    /// of the downwelling irradiance derived from a, b and the phase function.
    #[arg(long)]
    pub tabulated_kd: bool,
    /// Under water, light-field model: light surfaces as the paper does (the scene's lights
    /// attenuated by the downwelling irradiance, the sky straight down) instead of with the
    /// sun's beam plus the water column's diffuse irradiance for each surface's normal.
    #[arg(long)]
    pub no_surface_irradiance: bool,
    /// Under water, light-field model: half-angle (degrees, 0–45) of the forward cone whose
    /// scattering view rays treat as not scattering (objects keep their image through turbid
    /// water); 0 = the plain source term.
    #[arg(long, value_name = "DEG", default_value_t = render::passes::underwater::FORWARD_CONE_DEG)]
    pub forward_cone: f32,
    /// Under water, light-field model: photons per wavelength node and source for the
    /// table's solver (solved once per water type, sun, sky and depth range, then cached).
    #[arg(long, value_name = "N", default_value_t = render::passes::underwater::LIGHT_FIELD_PHOTONS)]
    pub light_field_photons: usize,
    /// Under water: scatter the diffuse light's scalar irradiance (Kd/a)·E_d (Gershun's law)
    /// instead of the paper's plane irradiance E_d.
    #[arg(long)]
    pub scalar_irradiance: bool,
    /// Under water: take the unscattered sun beams out of the isotropic term (single
    /// scattering counts them with the real phase function) instead of adding single
    /// scattering on top of the paper's term.
    #[arg(long)]
    pub split_beams: bool,
    /// Under water, isotropic model: draw the surface seen from below (Snell's window with the
    /// sky, Fresnel reflection and total internal reflection of the water below, not of the sea
    /// floor). The light-field model draws it by default, sea floor included.
    #[arg(long)]
    pub water_surface: bool,
    /// Under water, light-field model: do not draw the surface seen from below (the view ray
    /// ends in the water's own in-scattering, as in the paper).
    #[arg(long, conflicts_with_all = ["isotropic", "water_surface"])]
    pub no_water_surface: bool,
    /// Under water, light-field model: solve the water column without the sea floor under the
    /// camera (a bottomless column), i.e. without the light the floor sends back into the water.
    #[arg(long, conflicts_with = "isotropic")]
    pub no_sea_floor: bool,
    #[command(flatten)]
    pub env: super::EnvArgs,
    /// Lambert only: every surface reflects base colour / π, no specular (like `truth
    /// --lambert`; for comparisons with renderers without the glTF BRDF, and the white furnace).
    #[arg(long)]
    pub lambert: bool,
    /// Turn off the screen-space occlusion of ambient light: the environment and the water's
    /// diffuse irradiance (then every point sees the whole environment or water column).
    #[arg(long)]
    pub no_env_occlusion: bool,
}

impl LookArgs {
    /// Range, N and observer: the arguments first, then the scene's spectral defaults, then
    /// the renderer's.
    pub fn spectral(&self, scene: &scene::Scene) -> Result<(WavelengthRange, usize, String)> {
        let d = RenderSettings::default();
        let range = match (&self.range, scene.spectral.range) {
            (Some(r), _) => WavelengthRange::parse(r).with_context(|| format!("--range '{r}'"))?,
            (None, Some((a, b))) => WavelengthRange::new(a as f64, b as f64)
                .with_context(|| format!("scene {}: spectral range", scene.source))?,
            (None, None) => d.range,
        };
        let wavelengths =
            self.wavelengths.or(scene.spectral.wavelengths.map(|n| n as usize)).unwrap_or(d.wavelengths);
        let observer = self.observer.clone().or(scene.spectral.observer.clone()).unwrap_or(d.observer);
        Ok((range, wavelengths, observer))
    }

    /// The underwater model's options from `--scatter-steps` and `--phase-g`.
    /// The RGB medium's real-time options.
    pub fn rgb_medium_options(&self) -> render::passes::rgb_medium::Options {
        render::passes::rgb_medium::Options { steps: self.scatter_steps, multiple: !self.single_scattering }
    }

    pub fn underwater(&self) -> Result<render::passes::underwater::Options> {
        let o = if self.paper_model {
            render::passes::underwater::Options::paper()
        } else {
            render::passes::underwater::Options {
                steps: self.scatter_steps,
                phase_g: self.phase_g,
                scalar_irradiance: self.scalar_irradiance,
                split_beams: self.split_beams,
                surface: if self.isotropic || self.scalar_irradiance || self.split_beams {
                    self.water_surface
                } else {
                    !self.no_water_surface
                },
                light_field: !(self.isotropic || self.scalar_irradiance || self.split_beams),
                sea_floor: !self.no_sea_floor,
                tabulated_kd: self.tabulated_kd,
                irradiance: !(self.no_surface_irradiance || self.tabulated_kd),
                forward_cone_deg: self.forward_cone,
                photons: self.light_field_photons,
            }
        };
        o.validate().map_err(|e| anyhow!("underwater model options: {e}"))?;
        Ok(o)
    }
}

/// Camera depth used when `--water` is given for a scene without water settings.
pub const DEFAULT_WATER_DEPTH: f64 = 10.0;

/// The water the camera is in: the scene's `WaterSettings` with `--water`/`--depth` applied on
/// top, or `None` when neither the scene nor the flags ask for water. Unknown types, negative
/// or non-finite depths and `--depth` without any water are clear errors.
pub fn water_medium(
    scene: &scene::Scene,
    water: Option<&str>,
    depth: Option<f64>,
) -> Result<Option<scene::water::WaterMedium>> {
    let mut settings = scene.water.clone();
    if let Some(ty) = water {
        let base = settings.unwrap_or(scene::WaterSettings {
            water_type: String::new(),
            depth: DEFAULT_WATER_DEPTH as f32,
            sun_direction: glam::Vec3::Y,
            scale: 1.0,
            sky: 0.0,
        });
        settings = Some(scene::WaterSettings { water_type: ty.to_string(), ..base });
    }
    let Some(mut settings) = settings else {
        if let Some(d) = depth {
            bail!("--depth {d}: scene {} has no water; add --water TYPE (e.g. --water II)", scene.source);
        }
        return Ok(None);
    };
    if let Some(d) = depth {
        if !(d.is_finite() && d >= 0.0) {
            bail!("--depth {d}: the camera depth must be a finite number of metres ≥ 0 below the surface");
        }
        settings.depth = d as f32;
    }
    // `water.sun_direction` drives the light-field table: a dry scene given --water takes it
    // from the scene's sun (undoing the refraction), and a scene whose sun disagrees with its
    // own setting is refused rather than rendered with a table for another sun.
    let sun = scene.lights.iter().find_map(|l| match l.kind {
        scene::LightKind::Directional { direction } if l.stands_in_for.is_none() && direction.y < 0.0 => {
            Some(-direction.normalize())
        }
        _ => None,
    });
    if let (None, Some(to_sun)) = (&scene.water, sun) {
        let h = glam::Vec3::new(to_sun.x, 0.0, to_sun.z) * scene::water::WATER_IOR as f32;
        if h.length() < 1.0 {
            settings.sun_direction = glam::Vec3::new(h.x, (1.0 - h.length_squared()).sqrt(), h.z);
        }
    }
    // The message already includes its cause; anyhow's chain would print it twice.
    let medium = scene::water::WaterMedium::from_settings(&settings).map_err(|e| match water {
        Some(w) => anyhow!("--water '{w}': {e}"),
        None => anyhow!("scene {}: water settings: {e}", scene.source),
    })?;
    let mut medium = medium;
    // The floor under the camera closes the light-field model's water column.
    medium.floor = scene::water::floor::below_camera(scene, medium.scale)
        .map_err(|e| anyhow!("scene {}: {e}", scene.source))?;
    if let (Some(_), Some(to_sun)) = (&scene.water, sun) {
        let want = medium.sun_dir_underwater();
        let angle = to_sun.dot(want).clamp(-1.0, 1.0).acos().to_degrees();
        if angle > 0.5 {
            bail!(
                "scene {}: its sun shines from {to_sun:?} under water, but water.sun_direction {:?} refracts \
                 to {want:?} ({angle:.1}° apart); make the light's direction the refracted water.sun_direction \
                 (the underwater light-field table is computed for water.sun_direction)",
                scene.source,
                medium.sun_dir
            );
        }
    }
    // Both renderers put the whole scene under a flat surface `depth` above the camera: geometry
    // above it would be lit and seen as if under water by the rasteriser and as in air by the
    // path tracer.
    if let Some((_, hi)) = scene.bounds() {
        let above = (hi.y - scene.camera.position().y) as f64 * medium.scale;
        if above > medium.depth + 1e-6 {
            bail!(
                "scene {}: its geometry reaches {above:.2} m above the camera, above the water surface {:.2} m \
                 up; use --depth {:.2} or more (or a larger water scale)",
                scene.source,
                medium.depth,
                above
            );
        }
    }
    Ok(Some(medium))
}

/// Parses `640x480` (also `640X480`, `640*480`).
pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let (w, h) = s
        .split_once(['x', 'X', '*'])
        .ok_or_else(|| anyhow!("--size '{s}' must look like WIDTHxHEIGHT, e.g. 640x480"))?;
    let num = |v: &str| v.trim().parse::<u32>().ok().filter(|&n| n > 0);
    match (num(w), num(h)) {
        (Some(w), Some(h)) => Ok((w, h)),
        _ => bail!("--size '{s}': width and height must be positive integers"),
    }
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

/// `--quadrature NAME`.
pub fn parse_quadrature(s: &str) -> std::result::Result<color::Quadrature, String> {
    color::Quadrature::parse(s).map_err(|e| e.to_string())
}

/// Settings from the arguments, falling back to the scene's spectral defaults.
fn settings(args: &RenderArgs, scene: &scene::Scene) -> Result<RenderSettings> {
    let (range, wavelengths, observer) = args.look.spectral(scene)?;
    let s = RenderSettings {
        mode: Mode::parse(&args.look.mode)?,
        wavelengths,
        range,
        observer,
        white: scene.spectral.white_name().into(),
        exposure_ev: args.look.exposure,
        tonemap: Tonemap::parse(&args.look.tonemap)?,
        shadows: !args.no_shadows,
        timestamps: false,
        jitter: None,
        quadrature: args.look.quadrature,
        lambert: args.look.lambert,
        env_occlusion: !args.look.no_env_occlusion,
    };
    s.validate()
        .map_err(|e| if s.wavelengths == 0 { anyhow!("--wavelengths 0: {e}") } else { anyhow!("{e}") })?;
    Ok(s)
}

/// The sRGB table: `--table`, else the colour crate's cached fit (fitted on first use).
pub fn load_table(explicit: Option<&Path>) -> Result<Arc<CoeffTable>> {
    match explicit {
        Some(p) => {
            Ok(Arc::new(CoeffTable::read(p).with_context(|| format!("reading table {}", p.display()))?))
        }
        None => color::upsample::table("srgb").context("the sRGB coefficient table"),
    }
}

/// Renders the frame and writes `args.out`.
fn render_frame(
    r: &mut Renderer,
    args: &RenderArgs,
    scene: &scene::Scene,
    settings: &RenderSettings,
    custom: Option<render::CustomShader>,
    format: OutFormat,
    (width, height): (u32, u32),
) -> Result<()> {
    // Before anything is allocated for the frame.
    if let Some(sp) = &args.spectral_out {
        r.check_spectral_capture(width, height, settings.wavelengths)
            .map_err(|e| anyhow!("--spectral-out {}: {e}", sp.display()))?;
    }
    r.set_scene(scene)?;
    for w in r.scene_warnings() {
        eprintln!("warning: {}: {w}", scene.source);
    }
    // The water's or the RGB medium's hooks.
    if let Some(c) = custom {
        r.set_custom_shader(c)?;
    }
    r.resize(width, height)?;
    if args.spectral_out.is_some() {
        r.set_spectral_capture(true);
    }
    r.render(&scene.camera, settings)?;
    // Encoding a large image takes seconds; Ctrl-C meanwhile must not be followed by a write.
    let interrupted =
        || if color::cancel::is_cancelled() { Err(render::RenderError::Cancelled) } else { Ok(()) };
    let k = settings.exposure_ev.exp2();
    // The spectral file first: an interrupted run leaves neither complete, never a colour image
    // without the spectral one it was asked to go with.
    if let Some(sp) = &args.spectral_out {
        let cap = r.read_spectral_capture()?;
        let rgb = r.read_hdr()?.iter().map(|p| [p[0] * k, p[1] * k, p[2] * k]).collect();
        let rgb = compare::image::Image::new(width, height, rgb)?;
        let spec = compare::SpectralImage {
            width,
            height,
            kind: compare::SpectralKind::Emissive,
            edges: cap.edges,
            data: cap.data.into_iter().map(|v| v * k).collect(),
            white: Some(settings.white.clone()),
        };
        interrupted()?;
        compare::write_spectral_exr(sp, &spec, Some(&rgb))
            .with_context(|| format!("writing {}", sp.display()))?;
    }
    match format {
        OutFormat::Png => {
            let rgba = r.read_ldr()?;
            let img =
                image::RgbaImage::from_raw(width, height, rgba).context("readback has the wrong size")?;
            let mut bytes = std::io::Cursor::new(Vec::new());
            img.write_to(&mut bytes, image::ImageFormat::Png).context("encoding PNG")?;
            interrupted()?;
            compare::atomic::write_atomic(&args.out, bytes.get_ref())
                .with_context(|| format!("writing {}", args.out.display()))?;
        }
        OutFormat::Exr => {
            let data = r.read_hdr()?.iter().map(|p| [p[0] * k, p[1] * k, p[2] * k]).collect();
            let img = compare::image::Image::new(width, height, data)?;
            interrupted()?;
            compare::io::write_image(&args.out, &img, Default::default())
                .with_context(|| format!("writing {}", args.out.display()))?;
        }
    }
    Ok(())
}

pub fn run(args: RenderArgs) -> Result<()> {
    let format = out_format(&args.out)?;
    let (width, height) = parse_size(&args.size)?;
    super::check_output("--out", &args.out)?;
    if let Some(sp) = &args.spectral_out {
        if !sp.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
            bail!(
                "--spectral-out {}: a spectral image is an OpenEXR file; give it a .exr name",
                sp.display()
            );
        }
        if Mode::parse(&args.look.mode)? == Mode::Rgb {
            bail!(
                "--spectral-out needs --mode spectral (or naive): --mode rgb shades in RGB and has no wavelengths to write"
            );
        }
        super::check_output("--spectral-out", sp)?;
    }
    let mut scene = args.files.load(&args.scene)?;
    super::print_warnings(&scene);
    args.look.env.apply(&mut scene)?;
    let settings = settings(&args, &scene)?;
    let water = water_medium(&scene, args.look.water.as_deref(), args.look.depth)?;
    let table = load_table(args.look.table.as_deref())?;
    let medium = super::realtime_medium(
        &scene,
        args.look.rgb_medium.as_deref(),
        water.is_some(),
        &table,
        args.look.rgb_medium_options(),
    )?;
    let mut r = Renderer::with_table(table)?;
    let custom = match &water {
        Some(m) => Some(render::passes::underwater::shader_with(m, &args.look.underwater()?)?),
        None => medium,
    };
    let frame = render_frame(&mut r, &args, &scene, &settings, custom, format, (width, height));
    if let Err(e) = frame {
        if color::cancel::is_cancelled() {
            // Dropping the device waits for the frame in flight (28 s at 4096² on lavapipe):
            // the process is about to exit, so let the OS reclaim it instead.
            std::mem::forget(r);
        }
        return Err(e);
    }
    let under = water.as_ref().map_or(String::new(), |m| {
        let ty = m.water_type.map_or("custom".to_string(), |t| t.to_string());
        format!(", under water {ty} at {} m", m.depth)
    });
    let under = match (&scene.environment, r.environment_residual()) {
        (Some(e), Some(res)) => {
            format!("{under}, environment {} × {} (basis residual {res:.1e})", e.source, e.intensity)
        }
        (Some(e), None) => format!("{under}, environment {} × {}", e.source, e.intensity),
        (None, _) => under,
    };
    let under = match r.emitter_summary() {
        Some((n, 0, _)) if n > 0 => format!("{under}, {n} emissive polygon light(s)"),
        Some((n, dropped, frac)) if dropped > 0 => format!(
            "{under}, {n} emissive polygon lights (warning: {dropped} more left out, {:.1} % of the emitted power)",
            100.0 * frac
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
    eprintln!(
        "{}: {} {}×{}, {} N={} {:.0}–{:.0} nm{under}, on {}",
        args.out.display(),
        scene.source,
        width,
        height,
        settings.mode.name(),
        settings.wavelengths,
        settings.range.min,
        settings.range.max,
        r.gpu().describe()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_extensions() {
        assert_eq!(parse_size("64x48").unwrap(), (64, 48));
        assert!(parse_size("64").unwrap_err().to_string().contains("WIDTHxHEIGHT"));
        assert!(parse_size("0x10").is_err());
        assert_eq!(out_format(Path::new("a.PNG")).unwrap(), OutFormat::Png);
        assert_eq!(out_format(Path::new("a.exr")).unwrap(), OutFormat::Exr);
        let e = out_format(Path::new("a.jpg")).unwrap_err().to_string();
        assert!(e.contains(".jpg") && e.contains(".png"), "{e}");
    }

    #[test]
    fn geometry_above_the_surface_is_refused() {
        let cornell = scene::builtin("cornell").unwrap();
        let e = format!("{:#}", water_medium(&cornell, Some("II"), Some(0.0)).unwrap_err());
        assert!(e.contains("above the water surface") && e.contains("--depth"), "{e}");
        assert!(water_medium(&cornell, Some("II"), Some(50.0)).unwrap().is_some());
    }

    #[test]
    fn water_flags_override_the_scene_and_reject_bad_input() {
        let dry = scene::builtin("colorchecker").unwrap();
        assert!(water_medium(&dry, None, None).unwrap().is_none());
        let m = water_medium(&dry, Some("3C"), None).unwrap().unwrap();
        assert_eq!((m.water_type.unwrap().to_string(), m.depth), ("3C".to_string(), DEFAULT_WATER_DEPTH));
        let e = format!("{:#}", water_medium(&dry, None, Some(5.0)).unwrap_err());
        assert!(e.contains("--water"), "{e}");
        let e = format!("{:#}", water_medium(&dry, Some("XIV"), None).unwrap_err());
        assert!(e.contains("XIV"), "{e}");
        let e = format!("{:#}", water_medium(&dry, Some("II"), Some(-2.0)).unwrap_err());
        assert!(e.contains("-2") && e.contains("depth"), "{e}");
        let wet = scene::builtin("underwater").unwrap();
        let m = water_medium(&wet, None, Some(20.0)).unwrap().unwrap();
        assert_eq!((m.water_type.unwrap().to_string(), m.depth), ("IB".to_string(), 20.0));
        // water.sun_direction drives the light-field table: the built-in's sun is its refraction,
        // a scene whose sun disagrees is refused, naming both.
        let sun = wet.lights.iter().find(|l| l.stands_in_for.is_none()).unwrap();
        let scene::LightKind::Directional { direction } = sun.kind else { panic!("a sun") };
        assert!((-direction - m.sun_dir_underwater()).length() < 1e-5);
        let mut tilted = wet.clone();
        tilted.water.as_mut().unwrap().sun_direction = glam::Vec3::new(1.0, 0.3, 0.0).normalize();
        let e = format!("{:#}", water_medium(&tilted, None, None).unwrap_err());
        assert!(e.contains("water.sun_direction") && e.contains("°"), "{e}");
    }
}
