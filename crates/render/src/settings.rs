//! Per-frame render settings: everything a viewer may change between two frames.

use crate::error::{RenderError, Result};
use color::{Quadrature, WavelengthRange};

/// How surfaces and lights are coloured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Mode {
    /// Classic RGB shading (the baseline every engine uses).
    Rgb,
    /// Spectral, with RGB upsampled to box spectra (each band takes one channel).
    Naive,
    /// Spectral, with Jakob–Hanika sigmoid upsampling (this project's method).
    #[default]
    Spectral,
}

impl Mode {
    pub const NAMES: &'static [&'static str] = &["rgb", "naive", "spectral"];
    pub const ALL: [Mode; 3] = [Mode::Rgb, Mode::Naive, Mode::Spectral];

    /// Other spellings `parse` (and the command line) accept.
    fn aliases(self) -> &'static [&'static str] {
        match self {
            Mode::Rgb => &[],
            Mode::Naive => &["box"],
            Mode::Spectral => &["jh"],
        }
    }

    /// A name or alias, any case.
    pub fn parse(s: &str) -> Result<Self> {
        by_name(&Self::ALL, s, Self::name, Self::aliases)
            .ok_or_else(|| RenderError::Settings(format!("unknown mode '{s}'; known: rgb, naive, spectral")))
    }

    pub fn name(self) -> &'static str {
        match self {
            Mode::Rgb => "rgb",
            Mode::Naive => "naive",
            Mode::Spectral => "spectral",
        }
    }

    /// The value of `FrameUniforms::mode`.
    pub(crate) fn gpu(self) -> u32 {
        match self {
            Mode::Rgb => 0,
            Mode::Naive => 1,
            Mode::Spectral => 2,
        }
    }
}

/// Tone-mapping operator applied after exposure, before sRGB encoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Tonemap {
    /// Clamp to [0, 1]: what the reference-image tests use, so colours are not distorted.
    #[default]
    None,
    /// `c / (1 + c)` per channel.
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve.
    Aces,
}

impl Tonemap {
    pub const ALL: [Tonemap; 3] = [Tonemap::None, Tonemap::Reinhard, Tonemap::Aces];

    /// Other spellings `parse` (and the command line) accept.
    fn aliases(self) -> &'static [&'static str] {
        match self {
            Tonemap::None => &["clamp"],
            Tonemap::Reinhard | Tonemap::Aces => &[],
        }
    }

    /// A name or alias, any case.
    pub fn parse(s: &str) -> Result<Self> {
        by_name(&Self::ALL, s, Self::name, Self::aliases).ok_or_else(|| {
            RenderError::Settings(format!("unknown tone map '{s}'; known: none, reinhard, aces"))
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Tonemap::None => "none",
            Tonemap::Reinhard => "reinhard",
            Tonemap::Aces => "aces",
        }
    }

    pub(crate) fn gpu(self) -> u32 {
        match self {
            Tonemap::None => 0,
            Tonemap::Reinhard => 1,
            Tonemap::Aces => 2,
        }
    }
}

/// The value of `all` whose name or one of whose aliases is `s`, ignoring case: one lookup for
/// `parse` and the command line's `ValueEnum`, so both accept the same spellings.
fn by_name<T: Copy>(
    all: &[T],
    s: &str,
    name: fn(T) -> &'static str,
    aliases: fn(T) -> &'static [&'static str],
) -> Option<T> {
    all.iter()
        .copied()
        .find(|&v| name(v).eq_ignore_ascii_case(s) || aliases(v).iter().any(|a| a.eq_ignore_ascii_case(s)))
}

/// `--mode`/`--tonemap` for clap (feature `clap`, which the `spectra` binary turns on): the
/// names and aliases of `parse`; callers set `ignore_case` to accept any case as `parse` does.
#[cfg(feature = "clap")]
mod cli {
    use super::{Mode, Tonemap};
    use clap::builder::PossibleValue;

    impl clap::ValueEnum for Mode {
        fn value_variants<'a>() -> &'a [Self] {
            &Self::ALL
        }
        fn to_possible_value(&self) -> Option<PossibleValue> {
            Some(PossibleValue::new(self.name()).aliases(self.aliases().iter().copied()))
        }
    }

    impl clap::ValueEnum for Tonemap {
        fn value_variants<'a>() -> &'a [Self] {
            &Self::ALL
        }
        fn to_possible_value(&self) -> Option<PossibleValue> {
            Some(PossibleValue::new(self.name()).aliases(self.aliases().iter().copied()))
        }
    }
}

/// Largest number of wavelengths per pixel.
pub const MAX_WAVELENGTHS: usize = 256;
/// Largest |exposure| in stops ([`RenderSettings::exposure_ev`]).
pub const MAX_EXPOSURE_EV: f32 = 64.0;

/// Narrowest wavelength range a render accepts (nm).
pub const MIN_RANGE_NM: f64 = 1.0;

/// Settings read at every [`crate::Renderer::render`]. Changing the wavelengths, range or
/// observer re-uploads a few small buffers; nothing is recompiled.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub mode: Mode,
    /// Number of wavelength nodes N (1..=[`MAX_WAVELENGTHS`]), equally spaced over `range` at
    /// the centres of N equal bins.
    pub wavelengths: usize,
    /// How the N node values are integrated against the lights and the observer
    /// ([`color::quadrature`]): `Prefiltered` (the default) integrates light × observer densely
    /// against the cardinal functions of the nodes, so line spectra never alias; `Midpoint` is
    /// the paper's point-sampled sum.
    pub quadrature: Quadrature,
    pub range: WavelengthRange,
    /// Observer name for `color::Observer::by_name`.
    pub observer: String,
    /// The scene's reference white, an illuminant name for `color::illuminant::by_name`
    /// (`spectra.white`, default D65): the units of the XYZ normalisation, with RGB emission
    /// following it ([`color::RgbColorSpace::emission_white`], as in the path tracer).
    pub white: String,
    /// How a camera's (any non-CIE observer's) balanced channels are shown
    /// ([`color::film`]; `--camera-to-display`). CIE observers ignore it.
    pub camera_view: color::film::CameraView,
    /// Exposure in stops: the radiance is multiplied by 2^EV as it is written to the half-float
    /// HDR target (before tone mapping), so the exposure also brings a scene whose radiance lies
    /// below f16's range (6.1e-5) or above it (65504) into it. What is read back
    /// (`Renderer::read_hdr`) is exposed.
    pub exposure_ev: f32,
    pub tonemap: Tonemap,
    /// Render a shadow map for each light, stand-ins and emissive polygons included (every
    /// light with a frustum: [`crate::passes::shadow::MAX_SHADOWS`] is the shading pass's
    /// light limit).
    pub shadows: bool,
    /// Measure each pass with GPU timestamp queries (when the adapter supports them).
    pub timestamps: bool,
    /// Stratified wavelength jitter for frame accumulation: `Some(u)` with u in [0, 1) puts
    /// node i at `range.min + (i + u)·Δ` instead of the bin centre. It also switches every
    /// normalisation (emission weights, the white correction of the XYZ → RGB matrix, the
    /// scale of spectral lights) from "these N nodes" to a dense 1 nm integral over `range`.
    /// With the midpoint rule each frame is then an unbiased estimate of the continuous
    /// integral and the average of frames at stratified offsets converges to it; with the
    /// prefiltered rule the average settles at the interpolation error instead (a shifted,
    /// prefiltered grid cannot be unbiased: docs/quadrature.md). `None` (the default) keeps the
    /// nodes at the bin centres with per-N normalisation, which makes white exact at every N.
    pub jitter: Option<f32>,
    /// Where in each pixel the frame samples the scene, in pixels from the pixel's centre (x
    /// right, y down; each in [−½, ½]): the projection is shifted by that much, so every pass
    /// (G-buffer, shading, screen-space occlusion and refraction) sees the same moved view. The
    /// mean of frames at offsets spread over the pixel (with accumulation on) is the image
    /// box-filtered over each pixel — antialiased, as the path tracer's pixels are
    /// (`spectra render --samples`). `None` (the default) samples the centre.
    pub pixel_offset: Option<[f32; 2]>,
    /// Added to the level of detail at which material textures are read (0: the pixel's own
    /// footprint). A mean of K frames at offsets over the pixel samples it 1/√K pixel apart, so
    /// `spectra render --samples K` reads at −½·log₂ K (one level finer per doubling of the
    /// sample spacing's density), as the path tracer reads its textures per sample; within ±8.
    pub texture_lod_bias: f32,
    /// Replace the glTF BRDF by Lambert (base colour / π, no specular) for every surface and
    /// light, as the path tracer's `lambert` does: for comparisons with renderers that lack the
    /// glTF BRDF, and the white furnace.
    pub lambert: bool,
    /// Screen-space occlusion of ambient light, the environment and a custom hook's diffuse
    /// irradiance (the water column's; horizon-based, from the depth buffer; the occlusion pass,
    /// `passes/occlusion.rs`):
    /// concave parts and contact regions see less of the sky or the water around them.
    pub env_occlusion: bool,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            mode: Mode::Spectral,
            wavelengths: 16,
            quadrature: Quadrature::Prefiltered,
            range: WavelengthRange::VISIBLE,
            observer: "cie1931".into(),
            white: scene::DEFAULT_WHITE.into(),
            camera_view: color::film::CameraView::Balanced,
            exposure_ev: 0.0,
            tonemap: Tonemap::None,
            shadows: true,
            timestamps: false,
            jitter: None,
            pixel_offset: None,
            texture_lod_bias: 0.0,
            lambert: false,
            env_occlusion: true,
        }
    }
}

impl RenderSettings {
    /// Refuses values the GPU path cannot honour, naming the value.
    pub fn validate(&self) -> Result<()> {
        if self.wavelengths == 0 || self.wavelengths > MAX_WAVELENGTHS {
            return Err(RenderError::Settings(format!(
                "the number of wavelengths must be between 1 and {MAX_WAVELENGTHS} (got {})",
                self.wavelengths
            )));
        }
        WavelengthRange::new(self.range.min, self.range.max)?;
        if self.range.width() < MIN_RANGE_NM {
            return Err(RenderError::Settings(format!(
                "the wavelength range {}–{} nm is narrower than {MIN_RANGE_NM} nm: nothing visible can be \
                 integrated over it",
                self.range.min, self.range.max
            )));
        }
        // 2^±64 keeps every finite f16 pixel finite (2^1e30 wrote ∞ and NaN).
        if !(-MAX_EXPOSURE_EV..=MAX_EXPOSURE_EV).contains(&self.exposure_ev) {
            return Err(RenderError::Settings(format!(
                "exposure must be within ±{MAX_EXPOSURE_EV} stops (got {})",
                self.exposure_ev
            )));
        }
        if let Some(u) = self.jitter
            && !(0.0..1.0).contains(&u)
        {
            return Err(RenderError::Settings(format!("the wavelength jitter must be in [0, 1) (got {u})")));
        }
        if let Some(o) = self.pixel_offset
            && !o.iter().all(|c| (-0.5..=0.5).contains(c))
        {
            return Err(RenderError::Settings(format!(
                "the pixel offset must be within ±0.5 pixel on each axis (got {o:?})"
            )));
        }
        if !(-8.0..=8.0).contains(&self.texture_lod_bias) {
            return Err(RenderError::Settings(format!(
                "the texture level-of-detail bias must be within ±8 (got {})",
                self.texture_lod_bias
            )));
        }
        let observer = color::Observer::by_name(&self.observer)?;
        let white = color::illuminant::by_name(&self.white)?;
        if self.camera_view == color::film::CameraView::Display {
            // A dichromat's repeated receptor cannot be fitted to XYZ: refused here, not mid-frame.
            color::film::to_linear_srgb(&observer, observer.white_balance(&white), &white, self.camera_view)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_camera_view_the_chart_cannot_fit_is_refused() {
        let display = color::film::CameraView::Display;
        let s = RenderSettings { observer: "dog".into(), camera_view: display, ..Default::default() };
        assert!(s.validate().unwrap_err().to_string().contains("dog"));
        assert!(RenderSettings { observer: "dog".into(), ..Default::default() }.validate().is_ok());
        let s =
            RenderSettings { observer: "canon_eos_r5".into(), camera_view: display, ..Default::default() };
        assert!(s.validate().is_ok());
    }

    #[test]
    fn parse_and_validate() {
        assert_eq!(Mode::parse("RGB").unwrap(), Mode::Rgb);
        assert!(Mode::parse("hsv").unwrap_err().to_string().contains("hsv"));
        assert_eq!(Tonemap::parse("aces").unwrap(), Tonemap::Aces);
        assert!(RenderSettings::default().validate().is_ok());
        let bad = RenderSettings { wavelengths: 0, ..Default::default() };
        assert!(bad.validate().unwrap_err().to_string().contains("got 0"));
        let bad = RenderSettings { observer: "cat".into(), ..Default::default() };
        assert!(bad.validate().unwrap_err().to_string().contains("cat"));
        assert!(RenderSettings { jitter: Some(0.0), ..Default::default() }.validate().is_ok());
        // `WavelengthRange::new` refuses this too; the fields are public, so check both.
        assert!(WavelengthRange::new(500.0, 500.0000001).is_err());
        let narrow =
            RenderSettings { range: WavelengthRange { min: 500.0, max: 500.0000001 }, ..Default::default() };
        assert!(narrow.validate().unwrap_err().to_string().contains("500.0000001"));
        for u in [1.0, -0.1, f32::NAN] {
            let bad = RenderSettings { jitter: Some(u), ..Default::default() };
            assert!(bad.validate().unwrap_err().to_string().contains("jitter"), "{u}");
        }
        assert!(RenderSettings { pixel_offset: Some([0.5, -0.5]), ..Default::default() }.validate().is_ok());
        for o in [[0.6, 0.0], [0.0, -0.51], [f32::NAN, 0.0], [0.0, f32::INFINITY]] {
            let bad = RenderSettings { pixel_offset: Some(o), ..Default::default() };
            assert!(bad.validate().unwrap_err().to_string().contains("pixel offset"), "{o:?}");
        }
    }
}
