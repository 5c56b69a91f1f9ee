//! `KHR_materials_clearcoat`: a clear dielectric coat (varnish, car paint's lacquer) over the
//! whole material, emission included. The extension defines the layering, and both renderers
//! use it as written:
//!
//! coated = (1 − w)·material + w·coat_brdf,  w = clearcoat · F(|V·N_c|),
//! F(c) = F0 + (1 − F0)(1 − c)⁵ (Schlick, F0 = 0.04: index 1.5),
//!
//! where `coat_brdf` is glTF's specular microfacet term (GGX D and Smith G, no Fresnel: it is in
//! `w`) with α = clearcoatRoughness² about the coat's own normal N_c (its normal map, or the
//! interpolated vertex normal: not the base's normal map). The weight depends on the view direction only,
//! so the coat is a mixture, the same at every wavelength: it reflects each wavelength of the
//! light alike and leaves the base's spectrum alone.

use crate::TextureRef;

/// The coat's normal-incidence reflectance: index 1.5, as the extension fixes it.
pub const COAT_F0: f32 = 0.04;

/// A material's clear coat. Values as the extension gives them; the per-point ones are the
/// factors times the textures' channels ([`Clearcoat::weight_at`], [`Clearcoat::roughness_at`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Clearcoat {
    /// `clearcoatFactor` in (0, 1] (a coat of 0 is no coat: `Material::clearcoat` is `None`).
    pub factor: f32,
    /// `clearcoatTexture`: its R channel multiplies `factor`.
    pub texture: Option<TextureRef>,
    /// `clearcoatRoughnessFactor` in [0, 1] (perceptual: α = roughness²).
    pub roughness: f32,
    /// `clearcoatRoughnessTexture`: its G channel multiplies `roughness`.
    pub roughness_texture: Option<TextureRef>,
    /// `clearcoatNormalTexture` (tangent space, as the base's `normalTexture`); without one the
    /// coat follows the interpolated vertex normal.
    pub normal_texture: Option<TextureRef>,
    /// `clearcoatNormalTexture.scale`.
    pub normal_scale: f32,
}

impl Clearcoat {
    /// The coat's strength at a point whose `clearcoatTexture` reads `r` (R channel, 0–1).
    pub fn weight_at(&self, r: Option<f32>) -> f32 {
        (self.factor * r.unwrap_or(1.0)).clamp(0.0, 1.0)
    }

    /// The coat's perceptual roughness at a point whose `clearcoatRoughnessTexture` reads `g`.
    pub fn roughness_at(&self, g: Option<f32>) -> f32 {
        (self.roughness * g.unwrap_or(1.0)).clamp(0.0, 1.0)
    }
}

/// The coat's Fresnel term at `cos` = |V·N_c| (Schlick with [`COAT_F0`]), as the extension's
/// `fresnel_coat`.
pub fn fresnel(cos: f32) -> f32 {
    let m = (1.0 - cos.abs().min(1.0)).max(0.0);
    let m2 = m * m;
    COAT_F0 + (1.0 - COAT_F0) * m2 * m2 * m
}

/// The layering weight w = strength · F(|V·N_c|): the coat's share of the reflection, and
/// 1 − w the share of everything under it (the base's reflection, transmission and emission).
pub fn layer_weight(strength: f32, cos_view: f32) -> f32 {
    strength.clamp(0.0, 1.0) * fresnel(cos_view)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_is_schlicks_with_index_1_5() {
        assert_eq!(fresnel(1.0), COAT_F0);
        assert_eq!(fresnel(0.0), 1.0);
        assert_eq!(fresnel(-1.0), COAT_F0);
        // F0 of index 1.5 from the Fresnel equations at normal incidence.
        assert!((COAT_F0 - ((1.5f32 - 1.0) / 2.5).powi(2)).abs() < 1e-7);
        let c = 0.5f32;
        assert!((fresnel(c) - (0.04 + 0.96 * 0.5f32.powi(5))).abs() < 1e-7);
        assert_eq!(layer_weight(0.0, 0.3), 0.0);
        assert!((layer_weight(0.5, 1.0) - 0.02).abs() < 1e-7);
    }
}
