//! `KHR_materials_specular`: the strength and colour of a dielectric's specular reflection.
//! Both renderers use the extension's `fresnel_mix` as written, with this module's values:
//!
//! dielectric = s·F(λ)·specular_brdf + (1 − s·F_max)·diffuse_brdf,
//! F(λ) = F0c(λ) + (1 − F0c(λ))(1 − |v·h|)⁵,  F_max the same with F0c_max,
//!
//! where s = specularFactor × specularTexture.a is the weight, and the F0 colour
//! F0c = min(F0(η)·specularColorFactor·specularColorTexture.rgb, 1) per channel (F0(η) the
//! index's reflectance, 0.04 at 1.5; the clamp before the weight, as the extension says). The
//! metal is unchanged. F0c is an RGB reflectance in [0, 1], so the spectral modes upsample it as
//! a reflectance (a grey F0c is the constant F0c.r, exactly); the diffuse's share uses the
//! largest of its RGB channels, F0c_max, in every mode (the extension's `max_value`, which keeps
//! the diffuse from taking the complementary colour), so that RGB and spectral renders take
//! the same energy from it.
//!
//! Not on unlit materials (the extension excludes them), and not on materials with a thin film
//! or a transmission: the loader drops the extension there with a warning naming the material
//! ([`crate::Material::specular`]), and both renderers draw them from their index alone.

use crate::TextureRef;
use glam::Vec3;

/// A material's specular strength and colour, as the extension gives them; the values at a
/// point are the factors times the textures' channels ([`Specular::weight_at`],
/// [`Specular::color_at`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Specular {
    /// `specularFactor` in [0, 1].
    pub factor: f32,
    /// `specularTexture`: its A channel multiplies `factor`.
    pub texture: Option<TextureRef>,
    /// `specularColorFactor`, linear RGB, each ≥ 0 (the extension allows more than 1: F0 beyond
    /// the index's, up to the clamp at 1).
    pub color: Vec3,
    /// `specularColorTexture` (sRGB): its RGB multiplies `color`.
    pub color_texture: Option<TextureRef>,
}

/// Largest `specularColorFactor` channel accepted: the F0 colour is clamped at 1 past 1/F0(η),
/// which 10⁶ reaches at any index ≥ 1.002 (F0 ≥ 10⁻⁶); the bound keeps f32 finite.
pub const MAX_COLOR: f32 = 1.0e6;

impl Specular {
    /// The weight s at a point whose `specularTexture` reads `a` (A channel, 0–1).
    pub fn weight_at(&self, a: Option<f32>) -> f32 {
        (self.factor * a.unwrap_or(1.0)).clamp(0.0, 1.0)
    }

    /// The specular colour at a point whose `specularColorTexture` reads `rgb` (linear).
    pub fn color_at(&self, rgb: Option<Vec3>) -> Vec3 {
        self.color * rgb.unwrap_or(Vec3::ONE)
    }

    /// Whether the extension changes nothing: weight 1 and colour white without textures.
    pub fn is_default(&self) -> bool {
        self.factor == 1.0
            && self.color == Vec3::ONE
            && self.texture.is_none()
            && self.color_texture.is_none()
    }
}

/// The F0 colour min(f0·colour, 1) per channel, for a dielectric whose index gives `f0`
/// ([`crate::dielectric_f0`]). Without the extension it is the grey `f0`.
pub fn f0_color(f0: f32, color: Vec3) -> Vec3 {
    (color * f0).clamp(Vec3::ZERO, Vec3::ONE)
}

/// Schlick's term with normal-incidence reflectance `f0` at `cos` = |v·h|: the factor that
/// multiplies the specular lobe (times the weight) and, with F0c_max, what the diffuse loses.
pub fn fresnel(f0: f32, cos: f32) -> f32 {
    let m = (1.0 - cos.abs().min(1.0)).max(0.0);
    let m2 = m * m;
    f0 + (1.0 - f0) * m2 * m2 * m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f0_colour_is_clamped_before_the_weight() {
        assert_eq!(f0_color(0.04, Vec3::ONE), Vec3::splat(0.04));
        assert_eq!(f0_color(0.04, Vec3::new(25.0, 50.0, 0.5)), Vec3::new(1.0, 1.0, 0.02));
        let s = Specular { factor: 0.5, texture: None, color: Vec3::new(2.0, 1.0, 0.0), color_texture: None };
        assert_eq!(s.weight_at(Some(0.5)), 0.25);
        assert_eq!(s.color_at(Some(Vec3::new(0.5, 1.0, 1.0))), Vec3::new(1.0, 1.0, 0.0));
        assert!(!s.is_default());
        assert_eq!(fresnel(0.04, 1.0), 0.04);
        assert_eq!(fresnel(0.04, 0.0), 1.0);
        assert!((fresnel(0.2, 0.5) - (0.2 + 0.8 * 0.5f32.powi(5))).abs() < 1e-7);
    }
}
