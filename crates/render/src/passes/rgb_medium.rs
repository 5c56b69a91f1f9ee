//! An RGB participating medium filling the scene (issue 18, docs/rgb-media.md) as a
//! [`CustomShader`]: `Renderer::set_custom_shader(rgb_medium::shader(&medium, &table, &options)?)`.
//!
//! The medium is homogeneous, everywhere (the camera is inside it), with σ_a, σ_s and a
//! Henyey–Greenstein g: `scene::medium::RgbMedium`, the path tracer's medium
//! (`truth::Medium::from_rgb`). Per pixel the hooks return
//!
//! `L(λ) = L_surface(λ)·e^{−σ_t(λ)·d} + Σ_lights σ_s(λ)·∫₀ᵈ p(θ)·I(λ)·V·e^{−σ_t(λ)·(t + r(t))}/r(t)² dt`
//!
//! - `L_surface` is what the shading pass computes, except that every light's direct light
//!   at the surface is multiplied by its transmittance `e^{−σ_t(λ)·r}` over the straight
//!   distance r from the light (a polygon light's centroid) to the surface, per wavelength
//!   (the `custom_light_transmittance` hooks). A directional light does not reach into a
//!   medium without end: its transmittance is 0 wherever σ_t > 0, as in the path tracer; nor
//!   does the environment, whose light on surfaces the `custom_env_transmittance` hooks take to
//!   0 there (the background is extinguished by the view's attenuation).
//! - The in-scattering is single scattering of the first [`SS_LIGHTS`] point, spot and polygon
//!   lights (a polygon as a point at its centroid with intensity L·area·cos), shadow-mapped,
//!   integrated by [`Options::steps`] equiangular steps (Kulla & Fajardo 2012; the underwater
//!   pass's march for point lights, `medium_common.wgsl`); background rays are marched to
//!   [`CAP_OPTICAL_DEPTH`] optical depths of the clearest wavelength.
//!
//! Modes: spectral takes σ_s(λ), σ_t(λ) from `color::upsample::medium::medium` with the
//! medium's own upsampling (the function the path tracer uses), naive the same with boxes
//! (the naive mode's basis for everything), rgb the RGB coefficients themselves — what an RGB
//! renderer does. A box medium's transmittance e^{−σ_t(λ)·s} is exactly the box spectrum of
//! the per-channel e^{−σ_t,c·s}: box media (naive mode, and spectral mode with box upsampling)
//! compute it per channel and give each wavelength node the mean of that box spectrum over the
//! node's footprint, since a step sampled at the nodes would move to the nearest node
//! (docs/rgb-media.md); the albedo σ_s/σ_t, smooth, is sampled at the nodes.
//!
//! Multiple scattering ([`Options::multiple`], on by default): the fluence of the light that
//! has collided at least once around each marched light, in closed form per wavelength
//! (the once-collided term exactly, the higher orders with their exact total and the transport
//! solution's far-field decay; the model is derived at the end of `rgb_medium.wgsl`),
//! scattered once more along the view ray and falling on surfaces (`custom_irradiance`).
//!
//! Left out (docs/rgb-media.md): light reflected by surfaces and scattered back by the medium, the environment light's extinction (an
//! environment map still lights surfaces, attenuated only along the view), attenuation of a
//! polygon light over its extent (its centroid stands for it).

use super::custom::{CustomShader, MEDIUM_COMMON};
use crate::error::{RenderError, Result};
use color::upsample::CoeffTable;
use color::upsample::medium::Attenuation;
use scene::medium::RgbMedium;

/// The WGSL hooks (after [`MEDIUM_COMMON`]).
pub const HOOKS: &str = include_str!("rgb_medium.wgsl");

/// Lights that get in-scattering (the first non-directional ones); `RM_SS_LIGHTS` in the WGSL
/// (checked by `layout_tests`).
pub const SS_LIGHTS: usize = 4;
/// Most march steps; `RM_MAX_STEPS` in the WGSL (checked by `layout_tests`).
pub const MAX_STEPS: u32 = 32;
/// How far background rays are marched: this many optical depths of the clearest wavelength
/// (what lies beyond contributes < e^{−6}); never more than [`MAX_MARCH`] scene units.
pub const CAP_OPTICAL_DEPTH: f64 = 6.0;
/// Longest march (scene units), for media with a transparent wavelength.
pub const MAX_MARCH: f64 = 1e4;

/// The real-time model's choices beyond the medium itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Equiangular steps per light for the in-scattering (0 = attenuation only).
    pub steps: u32,
    /// The multiple-scattering term (the collided light's fluence around each marched light,
    /// scattered along the view and onto surfaces; docs/rgb-media.md); off = single scattering
    /// only, which is what the path tracer computes with `--direct-only`.
    pub multiple: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options { steps: 16, multiple: true }
    }
}

/// The spectra the hooks read, per scene unit: σ_s and σ_t upsampled by `medium`'s method, and
/// the albedo σ_s/σ_t of the box-upsampled medium (box media compute their steps per channel).
fn spectra(medium: &RgbMedium, table: &CoeffTable) -> Result<[color::Spectrum; 4]> {
    let grid = || (360..=830).map(f64::from);
    let sampled = |f: &dyn Fn(f64) -> f64| color::Spectrum::Piecewise {
        lambda: grid().collect(),
        values: grid().map(f).collect(),
    };
    let (a, s) = medium.spectra(table)?;
    let t = sampled(&|l| a.eval(l) + s.eval(l));
    let boxed = RgbMedium { upsampling: Attenuation::Box, ..medium.clone() };
    let (ab, sb) = boxed.spectra(table)?;
    let albedo = sampled(&|l| {
        let t = ab.eval(l) + sb.eval(l);
        if t > 0.0 { sb.eval(l) / t } else { 0.0 }
    });
    Ok([s, t, albedo, color::Spectrum::Constant(0.0)])
}

/// The custom shader drawing `medium`, upsampled through `table` (the scene colour space's
/// Jakob–Hanika table, as for the path tracer).
pub fn shader(medium: &RgbMedium, table: &CoeffTable, options: &Options) -> Result<CustomShader> {
    if options.steps > MAX_STEPS {
        return Err(RenderError::CustomShader(format!(
            "RGB medium: march steps must be 0..={MAX_STEPS}, got {}",
            options.steps
        )));
    }
    let spectra = spectra(medium, table)?;
    let k = medium.scale;
    let sigma_s = medium.scattering.map(|x| (x * k) as f32);
    let sigma_t = medium.extinction().map(|x| (x * k) as f32);
    let clearest = (360..=830)
        .map(|l| spectra[1].eval(l as f64))
        .chain(sigma_t.iter().map(|&x| x as f64))
        .fold(f64::INFINITY, f64::min);
    let cap = if clearest > 0.0 { (CAP_OPTICAL_DEPTH / clearest).min(MAX_MARCH) } else { MAX_MARCH };
    let mut params = [0.0f32; 16];
    params[0] = options.steps as f32;
    params[1] = medium.g as f32;
    params[2] = cap as f32;
    params[3] = if medium.upsampling == Attenuation::Box { 1.0 } else { 0.0 };
    let (blue_green, green_red) = crate::spectral_data::naive_band_edges();
    params[12] = blue_green as f32;
    params[13] = green_red as f32;
    params[4..7].copy_from_slice(&sigma_s);
    params[7] = if options.multiple { 1.0 } else { 0.0 };
    params[8..11].copy_from_slice(&sigma_t);
    Ok(CustomShader {
        source: format!("{MEDIUM_COMMON}\n{HOOKS}"),
        params,
        spectra: spectra.to_vec(),
        ..Default::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rgb_medium_shader_holds_the_upsampled_coefficients() {
        let table = color::upsample::table("srgb").unwrap();
        let m = RgbMedium::new([0.1, 0.2, 0.4], [0.5, 0.5, 0.5], 0.3, 2.0, Attenuation::Unbounded).unwrap();
        let s = shader(&m, &table, &Options::default()).unwrap();
        assert_eq!(&s.params[..3], &[16.0, 0.3, s.params[2]]);
        // Per scene unit: 2 m per unit doubles the coefficients.
        assert_eq!(&s.params[4..8], &[1.0, 1.0, 1.0, 1.0]);
        let single = shader(&m, &table, &Options { multiple: false, ..Default::default() }).unwrap();
        assert_eq!(single.params[7], 0.0);
        assert_eq!(&s.params[8..11], &[1.2, 1.4, 1.8]);
        // One home: the truth's spectra, per scene unit.
        let (a, sc) = m.spectra(&table).unwrap();
        for l in [420.0, 550.0, 640.0] {
            assert_eq!(s.spectra[0].eval(l), sc.eval(l));
            assert!((s.spectra[1].eval(l) - a.eval(l) - sc.eval(l)).abs() < 1e-12);
        }
        // Box media: the albedo of the box medium, smooth (a reflectance through the table).
        assert!((s.spectra[2].eval(450.0) - 1.0 / 1.8).abs() < 0.02, "{}", s.spectra[2].eval(450.0));
        assert!((s.spectra[2].eval(650.0) - 1.0 / 1.2).abs() < 0.02, "{}", s.spectra[2].eval(650.0));
        assert_eq!((s.params[3], s.params[12], s.params[13]), (0.0, 490.0, 585.0));
        assert!(s.params[2] > 0.0 && s.params[2] <= (CAP_OPTICAL_DEPTH / 1.2) as f32 * 1.5);
        assert!(
            s.defines("custom_light_transmittance") && s.assembled().contains("CUSTOM_LIGHT_T: bool = true")
        );
        assert!(s.defines("custom_irradiance") && s.assembled().contains("CUSTOM_IRRADIANCE: bool = true"));
        assert!(s.defines("custom_env_transmittance") && s.assembled().contains("CUSTOM_ENV_T: bool = true"));
        let e = shader(&m, &table, &Options { steps: 33, ..Default::default() }).unwrap_err().to_string();
        assert!(e.contains("march steps") && e.contains("33"), "{e}");
    }
}
