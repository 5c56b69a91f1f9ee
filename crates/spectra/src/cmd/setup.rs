//! What the commands that render a scene share on the command line, and how it becomes a
//! scene, settings and media: the scene and how it is loaded (`SceneArgs`: `render`, `view`,
//! `truth`, `bench`), the spectral settings (`SpectrumArgs`: range, observer, white), the
//! water (`WaterArgs`), the RGB medium (`RgbMediumArgs`), the upsampling table (`TableArgs`,
//! also `eval`), the real-time picture (`LookArgs`: `render`, `view`) and `--size`. Each
//! default that falls back to the scene is resolved here, once.

use anyhow::{Context, Result, anyhow, bail};
use clap::Args;
use color::WavelengthRange;
use color::upsample::CoeffTable;
use render::passes::underwater;
use render::settings::MAX_WAVELENGTHS;
use render::{CustomShader, Mode, RenderSettings, Tonemap};
use std::path::PathBuf;
use std::sync::Arc;

/// The scene on the command line: a built-in or a file, how it is loaded, and the
/// environment light put into it.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Built-in scene name (cornell, colorchecker, metamerism, iridescence, glass, clearcoat, specular, sheen, anisotropy, translucent, underwater, fog, tinted-fog) or a .gltf/.glb file.
    pub scene: String,
    #[command(flatten)]
    pub files: SceneFileArgs,
    #[command(flatten)]
    pub env: EnvArgs,
}

impl SceneArgs {
    /// The files `scene` (loaded from these arguments) was read from, named for messages: the
    /// glTF file, every file it references, and `--env`'s file.
    pub fn input_files(&self, scene: &scene::Scene) -> Vec<(String, PathBuf)> {
        let mut v: Vec<(String, PathBuf)> = scene
            .inputs
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let what = if i == 0 {
                    "scene file".to_string()
                } else {
                    format!("file the scene references ({})", p.display())
                };
                (what, p.clone())
            })
            .collect();
        if let Some(e) = self
            .env
            .env
            .as_deref()
            .filter(|e| !["default", "none"].contains(&e.to_ascii_lowercase().as_str()))
        {
            v.push(("--env file".into(), PathBuf::from(e)));
        }
        v
    }

    /// Loads the scene, prints the loader's warnings and applies the environment flags;
    /// `water`: `--water`, if given (a scene with no lights is lit otherwise under water).
    pub fn load(&self, water: Option<&str>) -> Result<scene::Scene> {
        let mut scene = self.files.load(&self.scene)?;
        print_warnings(&scene);
        self.env.apply(&mut scene, water.is_some())?;
        Ok(scene)
    }

    /// As [`Self::load`], posed at `time` (a sequence's frame); `say`: print the loader's
    /// warnings and the environment's note (the first frame says what every frame would).
    pub fn load_at(&self, water: Option<&str>, time: f64, say: bool) -> Result<scene::Scene> {
        let mut files = self.files.clone();
        files.time = Some(time);
        let mut scene = files.load(&self.scene)?;
        if say {
            print_warnings(&scene);
            self.env.apply(&mut scene, water.is_some())?;
        } else {
            self.env.choice(water.is_some()).apply(&mut scene)?;
        }
        Ok(scene)
    }
}

/// What the picture looks like: shared by `spectra render` and `spectra view`.
#[derive(Args, Debug, Clone)]
pub struct LookArgs {
    /// rgb (classic), naive (box upsampling) or spectral (Jakob–Hanika); any case.
    #[arg(long, value_enum, ignore_case = true, default_value_t = Mode::Spectral)]
    pub mode: Mode,
    /// Number of wavelength samples (default: the scene's, else 16; the viewer shows 1–64).
    #[arg(long)]
    pub wavelengths: Option<usize>,
    #[command(flatten)]
    pub spectrum: SpectrumArgs,
    /// How the N wavelength nodes are integrated: prefiltered (light × observer integrated
    /// densely against the nodes' cubic interpolant, so line spectra never alias) or midpoint
    /// (the paper's point-sampled sum).
    #[arg(long, default_value = "prefiltered", value_parser = parse_quadrature)]
    pub quadrature: color::Quadrature,
    /// Exposure in stops: the radiance is multiplied by 2^EV as the frame is written to its
    /// half-float target (range 6.1e-5…65504), so it also brings a scene lit far below or above
    /// that range into it.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Tone mapping (PNG output and the window): none, reinhard or aces; any case.
    #[arg(long, value_enum, ignore_case = true, default_value_t = Tonemap::None)]
    pub tonemap: Tonemap,
    #[command(flatten)]
    pub table: TableArgs,
    #[command(flatten)]
    pub water: WaterArgs,
    #[command(flatten)]
    pub rgb_medium: RgbMediumArgs,
    /// Under water or in an RGB medium: ray-march steps for single scattering of the scene's
    /// lights (0–32; under water 0 = the paper's analytic in-scattering alone, in an RGB
    /// medium attenuation alone).
    #[arg(long, value_name = "STEPS", default_value_t = underwater::Options::default().steps)]
    pub scatter_steps: u32,
    /// In an RGB medium: single scattering only, without the multiple-scattering term (what
    /// `spectra truth --direct-only` computes; docs/rgb-media.md).
    #[arg(long)]
    pub single_scattering: bool,
    /// Under water: Henyey–Greenstein asymmetry g of single scattering (default: Petzold's 0.924).
    #[arg(long, value_name = "G", allow_negative_numbers = true,
          default_value_t = underwater::Options::default().phase_g)]
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
    #[arg(long, value_name = "DEG", default_value_t = underwater::FORWARD_CONE_DEG)]
    pub forward_cone: f32,
    /// Under water, light-field model: photons per wavelength node and source for the
    /// table's solver (solved once per water type, sun, sky and depth range, then cached).
    #[arg(long, value_name = "N", default_value_t = underwater::LIGHT_FIELD_PHOTONS)]
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
    /// The frame's settings: the arguments first, then the scene's spectral defaults, then
    /// the renderer's. `shadows` and `timestamps` are the command's own choices. Errors name
    /// the argument.
    pub fn settings(&self, scene: &scene::Scene, shadows: bool, timestamps: bool) -> Result<RenderSettings> {
        let sp = self.spectrum.resolve(scene)?;
        let wavelengths = self
            .wavelengths
            .or(scene.spectral.wavelengths.map(|n| n as usize))
            .unwrap_or(RenderSettings::default().wavelengths);
        let s = RenderSettings {
            mode: self.mode,
            wavelengths,
            range: sp.range,
            observer: sp.observer,
            white: sp.white,
            camera_view: sp.camera_view,
            exposure_ev: self.exposure,
            tonemap: self.tonemap,
            shadows,
            timestamps,
            jitter: None,
            pixel_offset: None,
            texture_lod_bias: 0.0,
            quadrature: self.quadrature,
            lambert: self.lambert,
            env_occlusion: !self.no_env_occlusion,
        };
        s.validate().map_err(|e| match self.wavelengths {
            Some(n) if n == s.wavelengths && !(1..=MAX_WAVELENGTHS).contains(&n) => {
                anyhow!("--wavelengths {n}: {e}")
            }
            // The scene's own count (checked by the loader as a count only: the path tracer
            // takes no N): named by its file and field, as the loader names the others.
            None if !(1..=MAX_WAVELENGTHS).contains(&s.wavelengths) => {
                anyhow!(
                    "{}: extras.spectra.wavelengths = {}: {e}; or give --wavelengths",
                    scene.source,
                    s.wavelengths
                )
            }
            _ if !(-render::settings::MAX_EXPOSURE_EV..=render::settings::MAX_EXPOSURE_EV)
                .contains(&self.exposure) =>
            {
                anyhow!("--exposure {}: {e}", self.exposure)
            }
            _ => anyhow!("{e}"),
        })?;
        Ok(s)
    }

    /// The underwater model's options from `--scatter-steps`, `--phase-g` and the model flags.
    pub fn underwater(&self) -> Result<underwater::Options> {
        let o = if self.paper_model {
            underwater::Options::paper()
        } else {
            underwater::Options {
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
        o.validate().map_err(|e| self.flag_error(e))?;
        Ok(o)
    }

    /// An underwater option's error, naming the flag that gave the value.
    fn flag_error(&self, e: ::render::passes::underwater::OptionsError) -> anyhow::Error {
        use ::render::passes::underwater::OptionsError as E;
        let flag = match e {
            E::Steps(_) | E::LightFieldNoMarch => format!("--scatter-steps {}", self.scatter_steps),
            E::PhaseG(_) => format!("--phase-g {}", self.phase_g),
            E::ForwardCone(_) => format!("--forward-cone {}", self.forward_cone),
            E::Photons(_) => format!("--light-field-photons {}", self.light_field_photons),
            E::NeedsIsotropic => "--split-beams / --scalar-irradiance".to_string(),
        };
        anyhow!("{flag}: {e}")
    }

    /// The bounds of the media's numeric options, checked whatever the scene holds (a value
    /// out of range on a dry scene was accepted silently; found by a sweep): each error names
    /// its flag. Combinations of the underwater model's flags are checked under water only.
    fn check_media_ranges(&self) -> Result<()> {
        use ::render::passes::underwater::{MAX_FORWARD_CONE_DEG, MAX_PHOTONS, MAX_STEPS};
        let most = MAX_STEPS;
        if self.scatter_steps > most {
            bail!("--scatter-steps {}: media are marched in 0–{most} steps", self.scatter_steps);
        }
        if !(self.phase_g.is_finite() && self.phase_g.abs() < 1.0) {
            bail!("--phase-g {}: the Henyey–Greenstein g must lie strictly between −1 and 1", self.phase_g);
        }
        if !(self.forward_cone.is_finite() && (0.0..=MAX_FORWARD_CONE_DEG).contains(&self.forward_cone)) {
            bail!(
                "--forward-cone {}: the cone's half-angle must be 0–{MAX_FORWARD_CONE_DEG}°",
                self.forward_cone
            );
        }
        if !(1..=MAX_PHOTONS).contains(&self.light_field_photons) {
            bail!(
                "--light-field-photons {}: 1–{MAX_PHOTONS} photons per node and source",
                self.light_field_photons
            );
        }
        Ok(())
    }

    /// The RGB medium's real-time options (`--scatter-steps`, `--single-scattering`).
    pub fn rgb_medium_options(&self) -> ::render::passes::rgb_medium::Options {
        ::render::passes::rgb_medium::Options { steps: self.scatter_steps, multiple: !self.single_scattering }
    }

    /// The media of a real-time frame: the water (`--water`/`--depth` or the scene's) with
    /// its model options, or the RGB medium (`--rgb-medium` or the scene's) as its hooks;
    /// both at once is an error.
    pub fn media(&self, scene: &scene::Scene, table: &CoeffTable) -> Result<RealtimeMedia> {
        self.check_media_ranges()?;
        let water = self.water.medium(scene)?;
        // As the path tracer refuses it (truth::World): the water's light field has its own sky,
        // and an environment drawn through the water's hooks lit the floor and shone through
        // glass at full strength 5 m down (found by a sweep).
        if let (Some(_), Some(env)) = (&water, scene.environment.as_ref().filter(|e| !e.is_black())) {
            bail!(
                "an environment map ({}) cannot light a scene under a water surface: the surface shows the water \
                 settings' sky (drop the environment, e.g. --env none)",
                env.source
            );
        }
        // The model's options matter only under water (as before, bad ones are refused there).
        let water_options = if water.is_some() { self.underwater()? } else { underwater::Options::default() };
        let rgb =
            realtime_medium(scene, self.rgb_medium.arg(), water.is_some(), table, self.rgb_medium_options())?;
        Ok(RealtimeMedia { water, water_options, rgb })
    }
}

/// What fills the space between the camera and the surfaces in a real-time frame
/// ([`LookArgs::media`]); at most one of `water` and `rgb` is set.
pub struct RealtimeMedia {
    /// The water the camera is in.
    pub water: Option<scene::water::WaterMedium>,
    /// The underwater model's choices (used when `water` is set).
    pub water_options: underwater::Options,
    /// The RGB medium filling the scene, as its hooks.
    pub rgb: Option<CustomShader>,
}

impl RealtimeMedia {
    /// The custom shader that draws them: the underwater pass, or the RGB medium's.
    pub fn shader(&self) -> Result<Option<CustomShader>> {
        Ok(match &self.water {
            Some(m) => Some(underwater::shader_with(m, &self.water_options)?),
            None => self.rgb.clone(),
        })
    }
}

/// The spectral settings both renderers share (the real-time one adds `--wavelengths`).
#[derive(Args, Debug, Clone, Default)]
pub struct SpectrumArgs {
    /// Wavelength range in nm, MIN:MAX (default: the scene's, else 380:730).
    #[arg(long, value_name = "MIN:MAX")]
    pub range: Option<String>,
    /// Observer: a name `spectra observers` lists (cie1931, cie1964, a camera) or a sensitivity
    /// file, CSV or rawtoaces JSON (docs/cameras.md; default: the scene's, else cie1931).
    #[arg(long)]
    pub observer: Option<String>,
    /// Scene white: an illuminant name (D65, D50, A, F11, …, or a temperature such as 5000K;
    /// default: the scene's spectra.white, else D65). It is the unit of radiance (a radiance
    /// equal to it has Y = 1), not a tint: RGB colours emit sRGB's D65 at its luminance and
    /// measured lights keep their stated luminance, so the image is the same whatever it is.
    /// It is what a --spectral-out file's bands are normalised by (recorded as spectra.white).
    #[arg(long)]
    pub white: Option<String>,
    /// Show a camera (any non-CIE observer) through its least-squares matrix to CIE XYZ over
    /// the ColorChecker under the white, then sRGB — roughly its photograph — instead of its
    /// white-balanced channels as display RGB. CIE observers are shown as they are.
    #[arg(long)]
    pub camera_to_display: bool,
}

/// A warning when the render range holds less than 1 % of what the observer sees over
/// 360–830 nm (its three sensitivities summed, 1 nm midpoint rule): such an image is black
/// (780–830 nm under CIE 1931) or normalised up from almost nothing, never the scene's colour.
pub fn range_warning(obs: &color::Observer, name: &str, range: WavelengthRange) -> Option<String> {
    let seen = |lo: f64, hi: f64| -> f64 {
        let n = (hi - lo).ceil().max(1.0) as usize;
        let d = (hi - lo) / n as f64;
        (0..n).map(|i| obs.eval(lo + (i as f64 + 0.5) * d).iter().sum::<f64>() * d).sum()
    };
    let all = seen(color::spectrum::LAMBDA_MIN, color::spectrum::LAMBDA_MAX);
    let share = seen(range.min, range.max) / all;
    (all > 0.0 && share < 0.01).then(|| {
        format!(
            "warning: observer {name} sees only {:.2} % of its 360–830 nm response inside the render range {}–{} nm: \
             the image will be black or its colours meaningless; widen --range",
            100.0 * share,
            range.min,
            range.max
        )
    })
}

/// `--observer FILE` as an input that no output may overwrite (nothing for a built-in name).
pub fn observer_input(observer: Option<&str>) -> Vec<(String, PathBuf)> {
    observer
        .filter(|o| color::observer_file::is_file_name(o))
        .map(|o| ("--observer file".to_string(), PathBuf::from(o.trim())))
        .into_iter()
        .collect()
}

/// [`SpectrumArgs`] with the scene's defaults and the renderers' filled in, checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectrum {
    pub range: WavelengthRange,
    /// A name `color::Observer::by_name` knows.
    pub observer: String,
    /// A name `color::illuminant::by_name` knows.
    pub white: String,
    /// How a camera's channels are shown (`--camera-to-display`).
    pub camera_view: color::film::CameraView,
}

impl SpectrumArgs {
    /// The arguments first, then the scene's `spectra` settings, then the defaults; an
    /// unknown name is an error naming the flag or the scene.
    pub fn resolve(&self, scene: &scene::Scene) -> Result<Spectrum> {
        let d = RenderSettings::default();
        let range = match (&self.range, scene.spectral.range) {
            (Some(r), _) => WavelengthRange::parse(r).with_context(|| format!("--range '{r}'"))?,
            (None, Some((a, b))) => WavelengthRange::new(a as f64, b as f64)
                .with_context(|| format!("scene {}: spectral range", scene.source))?,
            (None, None) => d.range,
        };
        let from = |flag: &str, given: &Option<String>| match given {
            Some(v) => format!("{flag} '{v}'"),
            None => format!("scene {}: spectra {}", scene.source, &flag[2..]),
        };
        let observer = self.observer.clone().or(scene.spectral.observer.clone()).unwrap_or(d.observer);
        let obs = color::Observer::by_name(&observer).with_context(|| from("--observer", &self.observer))?;
        if color::observer_file::is_file_name(&observer)
            && let color::Spectrum::Piecewise { lambda, .. } = &obs.bar[0]
        {
            let (lo, hi) = (lambda[0], lambda[lambda.len() - 1]);
            if hi <= range.min || lo >= range.max {
                bail!(
                    "observer file {observer}: its wavelengths {lo}–{hi} nm do not overlap the render range {}–{} nm",
                    range.min,
                    range.max
                );
            }
            if lo > range.min || hi < range.max {
                eprintln!(
                    "warning: observer file {observer} covers {lo}–{hi} nm, less than the render range {}–{} nm; \
                     its sensitivities are taken as zero outside it",
                    range.min, range.max
                );
            }
        }
        if let Some(w) = range_warning(&obs, &observer, range) {
            eprintln!("{w}");
        }
        if let Some(w) = scene.short_reflectances(range.min, range.max) {
            eprintln!("warning: scene {}: {w}", scene.source);
        }
        let white = self.white.clone().unwrap_or_else(|| scene.spectral.white_name().to_string());
        color::illuminant::by_name(&white).with_context(|| from("--white", &self.white))?;
        let camera_view = color::film::CameraView::from_flag(self.camera_to_display);
        if camera_view == color::film::CameraView::Display {
            // Fitted here so that an observer the chart cannot fit is refused before any work.
            let w = color::illuminant::by_name(&white)?;
            color::film::to_linear_srgb(&obs, obs.white_balance(&w), &w, camera_view)
                .with_context(|| format!("--camera-to-display with observer {observer}"))?;
        }
        Ok(Spectrum { range, observer, white, camera_view })
    }
}

/// Water on the command line (`render`, `view`, `truth`).
#[derive(Args, Debug, Clone, Default)]
pub struct WaterArgs {
    /// Render under water: a Jerlov type (I, IA, IB, II, III, 1C … 9C, or a blend such as
    /// II.5). Default: the scene's own water settings, if it has any. (The path tracer makes
    /// it a participating medium with a forward-peaked phase function, see `truth::water`.)
    #[arg(long, value_name = "TYPE")]
    pub water: Option<String>,
    /// Camera depth below the water surface, metres (default: the scene's, else 10).
    #[arg(long, value_name = "METRES", allow_negative_numbers = true)]
    pub depth: Option<f64>,
}

impl WaterArgs {
    /// The water the camera is in, if any: [`water_medium`] with these flags.
    pub fn medium(&self, scene: &scene::Scene) -> Result<Option<scene::water::WaterMedium>> {
        water_medium(scene, self.water.as_deref(), self.depth)
    }
}

/// `--rgb-medium` (`render`, `view`, `bench`, `truth`).
#[derive(Args, Debug, Clone, Default)]
pub struct RgbMediumArgs {
    /// A homogeneous medium filling the scene, given in RGB: inline JSON or a JSON file, e.g.
    /// '{"absorption": [0.02, 0.05, 0.1], "scattering": [0.3, 0.3, 0.3], "g": 0.3}' or
    /// '{"attenuation_color": [0.8, 0.6, 0.5], "attenuation_distance": 4, "albedo": [0.9, 0.9, 0.9]}'
    /// (per metre / metres; docs/rgb-media.md). Replaces the scene's extras.medium.
    #[arg(long, value_name = "JSON|FILE")]
    pub rgb_medium: Option<String>,
}

impl RgbMediumArgs {
    pub fn arg(&self) -> Option<&str> {
        self.rgb_medium.as_deref()
    }

    /// `--rgb-medium`'s file (not an inline JSON object), named for [`super::check_outputs`].
    pub fn input_files(&self) -> Vec<(String, PathBuf)> {
        self.arg()
            .filter(|a| !inline_json(a))
            .map(|a| ("--rgb-medium file".to_string(), PathBuf::from(a)))
            .into_iter()
            .collect()
    }
}

/// `--table` (`render`, `view`, `bench`, `truth`, `eval`).
#[derive(Args, Debug, Clone, Default)]
pub struct TableArgs {
    /// Jakob–Hanika coefficient table (.coeff). Default: the sRGB 64³ table, fitted once per
    /// machine and cached (see `spectra lut`, $SPECTRA_CACHE_DIR).
    #[arg(long)]
    pub table: Option<PathBuf>,
}

impl TableArgs {
    /// `--table`'s file, named for [`super::check_outputs`].
    pub fn input_files(&self) -> Vec<(String, PathBuf)> {
        self.table.iter().map(|p| ("--table file".to_string(), p.clone())).collect()
    }

    /// The table: `--table`, else the colour crate's cached sRGB fit (fitted on first use).
    pub fn load(&self) -> Result<Arc<CoeffTable>> {
        load_table(self.table.as_deref())
    }
}

/// `--table FILE` or, without one, the colour crate's cached sRGB fit (fitted on first use).
pub fn load_table(explicit: Option<&std::path::Path>) -> Result<Arc<CoeffTable>> {
    match explicit {
        Some(p) => {
            let t = CoeffTable::read(p).with_context(|| format!("reading table {}", p.display()))?;
            // The scene's colours are linear sRGB (scene::Material), whatever space a file was fitted for.
            color::upsample::cache::check_usable(&t, &color::RgbColorSpace::srgb())
                .map_err(|e| anyhow!("--table {}: {e}", p.display()))?;
            Ok(Arc::new(t))
        }
        None => color::upsample::table("srgb").context("the sRGB coefficient table"),
    }
}

/// `--size` of every command: `WIDTHxHEIGHT`, the separator `x`, `X` or `*` (every spelling
/// `render` or `truth` ever accepted), blanks around the numbers allowed; both positive.
pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let (w, h) = s
        .split_once(['x', 'X', '*'])
        .ok_or_else(|| anyhow!("--size '{s}' must look like WIDTHxHEIGHT, e.g. 640x480"))?;
    let num = |v: &str| v.trim().parse::<u64>().ok().filter(|&n| n > 0);
    match (num(w), num(h)) {
        (Some(w), Some(h)) => match (u32::try_from(w), u32::try_from(h)) {
            (Ok(w), Ok(h)) => Ok((w, h)),
            _ => bail!("--size '{s}': {} is too large a side (a device draws at most 16384 or so)", w.max(h)),
        },
        _ => bail!("--size '{s}': width and height must be positive integers"),
    }
}

/// `--quadrature NAME`.
pub fn parse_quadrature(s: &str) -> std::result::Result<color::Quadrature, String> {
    color::Quadrature::parse(s).map_err(|e| e.to_string())
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
    // One bound for every command (the path tracer needs none, but a depth the real-time
    // renderer refuses would make the two disagree): the light-field table's deepest node, 20 m
    // below the camera rounded up to 20 m, or the sea floor, within its range.
    let max_z = scene::water::light_field::MAX_Z;
    let (z_max, why) = match &medium.floor {
        Some(f) => {
            (medium.depth + f.below_camera, format!("with the sea floor {:.2} m below it", f.below_camera))
        }
        None => {
            (underwater::light_field_range(medium.depth), "20 m below it, rounded up to 20 m".to_string())
        }
    };
    if let Some(f) = medium.floor.as_ref().filter(|f| f.below_camera >= max_z) {
        // No depth helps: the floor alone lies beyond the table (a water.scale of 1e30 gave
        // "a camera at most -1.2e30 m deep").
        bail!(
            "scene {}: its sea floor lies {} m below the camera at water.scale {:e} m per scene unit, beyond the \
             underwater light-field table's {max_z} m; lower water.scale or raise the floor",
            scene.source,
            metres(f.below_camera),
            medium.scale as f32
        );
    }
    if z_max > max_z {
        let what = match depth {
            Some(d) => format!("--depth {d}"),
            None => format!("scene {}: water.depth {}", scene.source, medium.depth),
        };
        bail!(
            "{what}: too deep: the underwater light-field table reaches {z_max:.1} m ({why}), beyond its {max_z} m \
             (here a camera at most {:.1} m deep)",
            medium.floor.as_ref().map_or(max_z - 20.0, |f| max_z - f.below_camera)
        );
    }
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
        // No allowed depth reaches that high: say what to change instead of a depth the bound
        // above refuses (water.scale 1e30 suggested a 31-digit --depth).
        let deepest = medium.floor.as_ref().map_or(max_z - 20.0, |f| max_z - f.below_camera);
        if above > deepest {
            bail!(
                "scene {}: its geometry reaches {} m above the camera at water.scale {:e} m per scene unit, above \
                 any water surface allowed (a camera at most {deepest:.1} m deep); lower water.scale or keep the \
                 geometry below the surface",
                scene.source,
                metres(above),
                medium.scale as f32
            );
        }
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

/// A length for a message: two decimals, or three significant digits where that would run to
/// many digits.
fn metres(x: f64) -> String {
    if x.abs() < 1e6 { format!("{x:.2}") } else { format!("{x:.3e}") }
}

/// Prints what the loader skipped or approximated, one `warning: <scene>: <text>` line each on
/// stderr (unsupported optional glTF extensions, points and lines, …).
pub fn print_warnings(scene: &scene::Scene) {
    for w in &scene.warnings {
        eprintln!("warning: {}: {w}", scene.source);
    }
}

/// `--rgb-medium`: inline JSON (starting with `{`) or a file holding it (`render`, `view`,
/// `bench`, `truth`).
/// Whether a medium argument is JSON written inline: it starts with '{' and names no file.
pub fn inline_json(arg: &str) -> bool {
    arg.trim_start().starts_with('{') && !std::path::Path::new(arg).is_file()
}

pub fn rgb_medium_arg(arg: &str) -> Result<scene::medium::RgbMedium> {
    let (text, origin) = if inline_json(arg) {
        (arg.to_string(), "--rgb-medium".to_string())
    } else {
        let p = std::path::Path::new(arg);
        let t = color::input::read_regular_string(p, ::truth::medium_file::MAX_MEDIUM_FILE_BYTES)
            .with_context(|| format!("--rgb-medium {arg}: cannot read"))?;
        (t, format!("--rgb-medium {arg}"))
    };
    scene::medium::RgbMedium::from_json_str(&text).map_err(|e| anyhow!("{origin}: {e}"))
}

/// The real-time renderer's RGB medium: `--rgb-medium`, else the scene's `extras.medium`;
/// with water (which is a medium of its own) it is an error, as for `spectra truth`. As a
/// custom shader with `steps` march steps, upsampled through `table`.
pub fn realtime_medium(
    scene: &scene::Scene,
    arg: Option<&str>,
    water: bool,
    table: &color::upsample::CoeffTable,
    opts: ::render::passes::rgb_medium::Options,
) -> Result<Option<CustomShader>> {
    let m = match (arg, &scene.medium) {
        (Some(a), _) => rgb_medium_arg(a)?,
        (None, Some(m)) => m.clone(),
        (None, None) => return Ok(None),
    };
    if water {
        bail!(
            "--rgb-medium / the scene's medium and water (from --water or the scene) cannot be combined: pick one medium"
        );
    }
    let most = ::render::passes::rgb_medium::MAX_STEPS;
    if opts.steps > most {
        bail!("--scatter-steps {}: an RGB medium is marched in 0–{most} steps", opts.steps);
    }
    if let Some(w) = m.unlit_warning(scene) {
        eprintln!("{w}");
    }
    Ok(Some(::render::passes::rgb_medium::shader(&m, table, &opts)?))
}

/// How a scene file is loaded, shared by every command that takes a scene (`render`, `view`,
/// `truth`, `bench`).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct SceneFileArgs {
    /// Let the scene's file references (buffers, images, CSV spectra, environment maps) leave
    /// its folder: absolute paths, `..`, symlinks to elsewhere. Off by default so that a scene
    /// from elsewhere cannot read your other files (docs/scene-format.md, "File references").
    #[arg(long)]
    pub allow_outside_scene_dir: bool,
    /// Draw this KHR_materials_variants variant of the file's materials (by name; the loader's
    /// warning lists a file's variants). Default: the primitives' own materials.
    #[arg(long, value_name = "NAME")]
    pub variant: Option<String>,
    /// Pose the scene by this glTF animation (its name, or its index in the file; the loader's
    /// warning lists them) at `--time`. Default: drawn at rest, as the file's nodes stand
    /// (skins and morph weights applied).
    #[arg(long, value_name = "NAME|INDEX")]
    pub animation: Option<String>,
    /// An animation by its index alone (the Python API's `animation=2`), which `animation`
    /// would first look for among the names.
    #[arg(skip)]
    pub animation_index: Option<usize>,
    /// The moment of the animation, in seconds (default 0; alone, it poses the file's first
    /// animation). Animations hold their first and last keyframes outside their range.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub time: Option<f64>,
}

impl SceneFileArgs {
    /// Loads a built-in scene or a .gltf/.glb file, with these options.
    pub fn load(&self, name: &str) -> Result<scene::Scene> {
        let lower = name.to_ascii_lowercase();
        if !(lower.ends_with(".gltf") || lower.ends_with(".glb")) {
            if let Some(v) = &self.variant {
                bail!("--variant {v}: material variants belong to glTF files; '{name}' is a built-in scene");
            }
            if let Some(a) = self.animation.clone().or(self.animation_index.map(|i| i.to_string())) {
                bail!("--animation {a}: animations belong to glTF files; '{name}' is a built-in scene");
            }
            if let Some(t) = self.time {
                bail!("--time {t}: animations belong to glTF files; '{name}' is a built-in scene");
            }
        }
        let opts = scene::LoadOptions {
            allow_outside_scene_dir: self.allow_outside_scene_dir,
            variant: self.variant.clone(),
            animation: match (&self.animation, self.animation_index) {
                (_, Some(i)) => Some(scene::AnimationRef::Index(i)),
                (Some(a), None) => Some(scene::AnimationRef::NameOrIndex(a.clone())),
                (None, None) => None,
            },
            time: self.time,
        };
        scene::load_any_with(name, &opts).with_context(|| format!("loading scene '{name}'"))
    }
}

/// The environment light on the command line, shared by `render`, `view` and `truth`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct EnvArgs {
    /// Environment light: an equirectangular .hdr or .exr of linear radiance, `default` (a
    /// uniform white D65 sky over a grey ground) or `none`. Default: the scene's own
    /// (extras.environment), else the default environment when the scene has no lights at all
    /// (under water a sun overhead instead: the path tracer lets no environment in there).
    #[arg(long, value_name = "FILE|default|none")]
    pub env: Option<String>,
    /// Multiplies the environment's radiance.
    #[arg(long, value_name = "K", allow_negative_numbers = true)]
    pub env_intensity: Option<f32>,
    /// Turns the environment about +Y, degrees.
    #[arg(long, value_name = "DEGREES", allow_negative_numbers = true)]
    pub env_rotation: Option<f32>,
    /// Real time: light with the whole map, its sun unshadowed, instead of the sun (a compact
    /// region of ≥ 15 % of the map's light, docs/environment.md) as a shadowed directional light
    /// and the rest as the map. The path tracer samples the whole map either way.
    #[arg(long)]
    pub no_env_sun: bool,
    /// Real time: the share of the map's light (∫ luminance dω) that a compact bright region
    /// must give to be lit with as the sun, in (0, 1]. Default 0.15.
    #[arg(long, value_name = "SHARE", allow_negative_numbers = true)]
    pub env_sun_share: Option<f32>,
}

impl EnvArgs {
    /// Sets the scene's environment as asked; prints the note (default environment chosen) or
    /// warning (nothing lights the scene) on stderr.
    pub fn choice(&self, under_water: bool) -> scene::environment::EnvironmentChoice {
        scene::environment::EnvironmentChoice {
            env: self.env.clone(),
            intensity: self.env_intensity,
            rotation: self.env_rotation,
            no_sun: self.no_env_sun,
            sun_share: self.env_sun_share,
            under_water,
        }
    }

    pub fn apply(&self, scene: &mut scene::Scene, under_water: bool) -> Result<()> {
        if let Some(note) = self.choice(under_water).apply(scene)? {
            eprintln!("{note}");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_the_observer_barely_sees_is_warned_about() {
        let cie = color::Observer::cie1931();
        let r = |a, b| WavelengthRange::new(a, b).unwrap();
        let w = range_warning(&cie, "cie1931", r(780.0, 830.0)).unwrap();
        assert!(w.contains("780–830") && w.contains("--range"), "{w}");
        assert!(range_warning(&cie, "cie1931", r(360.0, 361.0)).is_some());
        assert!(range_warning(&cie, "cie1931", r(380.0, 730.0)).is_none());
        assert!(range_warning(&cie, "cie1931", r(550.0, 560.0)).is_none());
    }

    #[test]
    fn sizes() {
        assert_eq!(parse_size("64x48").unwrap(), (64, 48));
        assert_eq!(parse_size("64X48").unwrap(), (64, 48));
        assert_eq!(parse_size("64*32").unwrap(), (64, 32));
        assert_eq!(parse_size(" 64 x 32 ").unwrap(), (64, 32));
        assert!(parse_size("64").unwrap_err().to_string().contains("WIDTHxHEIGHT"));
        assert!(parse_size("0x10").unwrap_err().to_string().contains("positive"));
        assert!(parse_size("64,32").is_err());
        // Too large for any device is said so, not called "not a positive integer".
        assert!(parse_size("99999999999x1").unwrap_err().to_string().contains("99999999999 is too large"));
    }

    /// The flags win over the scene's `spectra` settings, which win over the defaults; an
    /// unknown name is refused naming where it came from.
    #[test]
    fn spectrum_flags_then_scene_then_defaults() {
        let mut scene = scene::builtin("cornell").unwrap();
        let none = SpectrumArgs::default();
        let s = none.resolve(&scene).unwrap();
        assert_eq!((s.observer.as_str(), s.white.as_str()), ("cie1931", scene::DEFAULT_WHITE));
        assert_eq!(s.range, RenderSettings::default().range);
        scene.spectral.white = Some("D50".into());
        scene.spectral.observer = Some("cie1964".into());
        scene.spectral.range = Some((400.0, 700.0));
        let s = none.resolve(&scene).unwrap();
        assert_eq!(
            (s.observer.as_str(), s.white.as_str(), s.range.min, s.range.max),
            ("cie1964", "D50", 400.0, 700.0)
        );
        let flags = SpectrumArgs {
            range: Some("390:720".into()),
            observer: Some("cie1931".into()),
            white: Some("A".into()),
            ..Default::default()
        };
        let s = flags.resolve(&scene).unwrap();
        assert_eq!(
            (s.observer.as_str(), s.white.as_str(), s.range.min, s.range.max),
            ("cie1931", "A", 390.0, 720.0)
        );
        let e = |a: SpectrumArgs, sc: &scene::Scene| format!("{:#}", a.resolve(sc).unwrap_err());
        let m = e(SpectrumArgs { white: Some("1K".into()), ..Default::default() }, &scene);
        assert!(m.contains("--white '1K'") && m.contains("500–1000000 K"), "{m}");
        let m = e(SpectrumArgs { observer: Some("cat".into()), ..Default::default() }, &scene);
        assert!(m.contains("--observer 'cat'"), "{m}");
        scene.spectral.white = Some("Z99".into());
        let m = e(SpectrumArgs::default(), &scene);
        assert!(m.contains("spectra white") && m.contains("Z99"), "{m}");
    }

    /// `render`/`view`/`bench` take the medium from `--rgb-medium` or the scene, refuse it with
    /// water, and name the flag in every error.
    #[test]
    fn realtime_rgb_medium_comes_from_the_flag_or_the_scene() {
        let table = color::upsample::table("srgb").unwrap();
        let fog = scene::builtin("fog").unwrap();
        let cornell = scene::builtin("cornell").unwrap();
        use render::passes::rgb_medium::Options;
        assert!(realtime_medium(&cornell, None, false, &table, Default::default()).unwrap().is_none());
        let s = realtime_medium(&fog, None, false, &table, Default::default())
            .unwrap()
            .expect("the scene's medium");
        assert_eq!(s.params[0], 16.0);
        let m = r#"{"absorption": [0.5, 0.2, 0.1], "g": 0.5}"#;
        let s = realtime_medium(&cornell, Some(m), false, &table, Options { steps: 8, multiple: true })
            .unwrap()
            .expect("the flag's medium");
        assert_eq!((s.params[0], s.params[1], &s.params[8..11]), (8.0, 0.5, &[0.5f32, 0.2, 0.1][..]));
        let e = |scene: &scene::Scene, arg: Option<&str>, water: bool, steps: u32| {
            format!(
                "{:#}",
                realtime_medium(scene, arg, water, &table, Options { steps, ..Default::default() })
                    .unwrap_err()
            )
        };
        let msg = e(&fog, None, true, 16);
        assert!(msg.contains("--rgb-medium") && msg.contains("water"), "{msg}");
        let msg = e(&cornell, Some(r#"{"absorption": [0.5, 0.2, 0.1], "g": 1}"#), false, 16);
        assert!(msg.contains("--rgb-medium") && msg.contains("g:"), "{msg}");
        let msg = e(&cornell, Some("no-such-medium.json"), false, 16);
        assert!(msg.contains("--rgb-medium no-such-medium.json"), "{msg}");
        let msg = e(&cornell, Some(m), false, 33);
        assert!(msg.contains("--scatter-steps 33") && msg.contains("0–32"), "{msg}");
    }

    #[test]
    fn geometry_above_the_surface_is_refused() {
        let cornell = scene::builtin("cornell").unwrap();
        let e = format!("{:#}", water_medium(&cornell, Some("II"), Some(0.0)).unwrap_err());
        assert!(e.contains("above the water surface") && e.contains("--depth"), "{e}");
        assert!(water_medium(&cornell, Some("II"), Some(50.0)).unwrap().is_some());
        // No allowed depth covers it: the scale is named, no impossible --depth suggested.
        let mut huge = scene::builtin("underwater").unwrap();
        huge.water.as_mut().unwrap().scale = 1e30;
        let e = format!("{:#}", water_medium(&huge, None, None).unwrap_err());
        assert!(e.contains("sea floor lies 1.200e30 m") && e.contains("water.scale 1e30"), "{e}");
        // Without a floor under the camera: the geometry above the surface.
        let mut high = scene::builtin("colorchecker").unwrap();
        high.water = scene::builtin("underwater").unwrap().water;
        high.lights.clear();
        high.water.as_mut().unwrap().scale = 1e30;
        let e = format!("{:#}", water_medium(&high, None, None).unwrap_err());
        assert!(e.contains("m above the camera at water.scale 1e30") && !e.contains("--depth"), "{e}");
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
