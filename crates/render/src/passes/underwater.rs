//! Real-time underwater light transport (Monzón, Gutierrez, Akkaynak & Muñoz 2024) as a
//! [`CustomShader`]: `Renderer::set_custom_shader(underwater::shader(&medium))`.
//!
//! The hooks run in pass 2, per wavelength group, on the radiance the surface reflects from
//! the scene's lights (ρ·E·BRDF·cos), and return
//!
//! `L(λ) = L_surface(λ)·e^{−Kd·z_s}·e^{−c·d} + b·E0/(4π·k)·(1 − e^{−k·d})·e^{−Kd·z0}`,
//! `k = c + Kd·cosθ`,
//!
//! with d the camera–surface distance in metres (scene units × `scale`), z_s the surface depth,
//! z0 the camera depth and cosθ = −ω_y for the view direction ω. Background pixels get only the
//! in-scattering, up to the water surface when looking up and to infinity otherwise. E0 is the
//! downwelling irradiance just below the surface, computed in the shader from the scene's
//! directional lights (emission × cosine to the downward vertical), so it is in exactly the
//! units of the surface radiance in every mode. `scene::water::WaterMedium::pixel_terms` is the
//! CPU reference of every factor; `tests/underwater.rs` checks the GPU against it.
//!
//! Spectral and naive modes sample b, c and Kd at the frame's wavelengths (the renderer
//! resamples [`CustomShader::spectra`] whenever N or the range change). The RGB baseline uses
//! the coefficients at three wavelengths, [`RGB_WAVELENGTHS`], one per channel — what an
//! RGB renderer without spectral data does.
//!
//! Assumptions (shared with the paper): the scene's directional lights are the light field
//! under the surface (already refracted), all lights are attenuated by Kd over the surface's
//! depth (no diver's torch), in-scattering is isotropic, and nothing above the surface (sky,
//! Snell's window) is drawn.

use super::custom::CustomShader;
use scene::water::WaterMedium;

/// The WGSL hooks.
pub const HOOKS: &str = include_str!("underwater.wgsl");

/// Wavelengths (nm) at which the RGB mode takes c, Kd and b for its R, G, B channels: the
/// dominant wavelengths of the sRGB primaries under D65.
pub const RGB_WAVELENGTHS: [f64; 3] = [611.0, 549.0, 464.0];

/// The custom-shader parameters for `medium`: `[z0, scale, 0, 0]`, then c, Kd and b at
/// [`RGB_WAVELENGTHS`]. Use with `Renderer::set_custom_params` to move the camera's depth
/// without recompiling.
pub fn params(medium: &WaterMedium) -> [f32; 16] {
    let mut p = [0.0f32; 16];
    p[0] = medium.depth as f32;
    p[1] = medium.scale as f32;
    for (ch, &l) in RGB_WAVELENGTHS.iter().enumerate() {
        let k = medium.coefficients(l);
        p[4 + ch] = k.c as f32;
        p[8 + ch] = k.kd as f32;
        p[12 + ch] = k.b as f32;
    }
    p
}

/// The spectra the hooks read: b, c, Kd.
pub fn spectra(medium: &WaterMedium) -> Vec<color::Spectrum> {
    let p = &medium.properties;
    vec![p.b.clone(), p.c.clone(), p.kd.clone()]
}

/// The underwater custom shader for `medium`.
pub fn shader(medium: &WaterMedium) -> CustomShader {
    CustomShader { source: HOOKS.to_string(), params: params(medium), spectra: spectra(medium) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use color::water::WaterType;
    use glam::Vec3;

    #[test]
    fn params_hold_depth_scale_and_rgb_coefficients() {
        let m = WaterMedium::new(WaterType::parse("II").unwrap(), 7.5, Vec3::Y, 0.5).unwrap();
        let p = params(&m);
        assert_eq!((p[0], p[1]), (7.5, 0.5));
        let blue = m.coefficients(464.0);
        assert_eq!((p[6], p[10], p[14]), (blue.c as f32, blue.kd as f32, blue.b as f32));
        // Ocean water attenuates red more than blue, and its downwelling Kd by far (pure-water
        // absorption at 611 nm is ≈ 0.27 /m, in the blue ≈ 0.01 /m).
        assert!(p[4] > p[6] && p[8] > 3.0 * p[10], "{p:?}");
        let s = shader(&m);
        assert_eq!(s.spectra.len(), 3);
        assert_eq!(s.spectra[2].eval(500.0), m.coefficients(500.0).kd);
    }
}
