//! `KHR_materials_diffuse_transmission`: thin translucent surfaces (leaves, paper, lampshades,
//! thin plastic) that pass part of their diffuse light to the other side. The extension replaces
//! the dielectric's diffuse BRDF by
//!
//!   mix(diffuse_brdf(baseColor), diffuse_btdf(diffuseTransmissionColor), diffuseTransmission)
//!
//! under the same Fresnel-weighted specular layer: a Lambertian lobe on the far side of the
//! surface (colour/π for light and view on opposite sides, 0 otherwise), whose weight the
//! reflected diffuse loses. The specular lobe, the metal and the layers above (coat, sheen) are
//! untouched. With `KHR_materials_transmission` the specular transmission takes its share first
//! (base = mix(diffuse_bsdf, specular_btdf, transmission)), and with `KHR_materials_volume` the
//! light that crosses the boundary enters the volume.
//!
//! One home for the values both renderers read ([`DiffuseTransmission::factor_at`],
//! [`DiffuseTransmission::color_at`]) and for the lobe's two halves ([`lobes`]).

use crate::TextureRef;
use glam::Vec3;

/// A material's diffuse transmission as the extension gives it; the values at a point are the
/// factors times the textures' channels.
#[derive(Clone, Debug, PartialEq)]
pub struct DiffuseTransmission {
    /// `diffuseTransmissionFactor` in [0, 1]: the share of the diffuse light transmitted.
    pub factor: f32,
    /// `diffuseTransmissionTexture`: its A channel (linear) multiplies `factor`.
    pub texture: Option<TextureRef>,
    /// `diffuseTransmissionColorFactor`, linear RGB in [0, 1]: the colour of the transmitted
    /// light.
    pub color: Vec3,
    /// `diffuseTransmissionColorTexture` (sRGB): its RGB multiplies `color`.
    pub color_texture: Option<TextureRef>,
}

impl DiffuseTransmission {
    /// The transmitted share at a point whose `diffuseTransmissionTexture` reads `a` (A channel).
    pub fn factor_at(&self, a: Option<f32>) -> f32 {
        (self.factor * a.unwrap_or(1.0)).clamp(0.0, 1.0)
    }

    /// The transmitted colour at a point whose `diffuseTransmissionColorTexture` reads `rgb`
    /// (linear, after sRGB decoding).
    pub fn color_at(&self, rgb: Option<Vec3>) -> Vec3 {
        (self.color * rgb.unwrap_or(Vec3::ONE)).clamp(Vec3::ZERO, Vec3::ONE)
    }

    /// Whether the extension changes nothing: a zero factor (its default) leaves the diffuse BRDF
    /// as it was, whatever the textures hold.
    pub fn is_off(&self) -> bool {
        self.factor == 0.0
    }
}

/// The diffuse part of the dielectric base at a point, as weights of the two Lambertian lobes:
/// (reflected, transmitted) = ((1 − t)·ρ_base, t·ρ_transmitted), each to be divided by π and
/// applied on its own side of the surface (view and light on the same side for the first, on
/// opposite sides for the second). `t` is [`DiffuseTransmission::factor_at`]'s share. The sum
/// of the two never exceeds max(ρ_base, ρ_transmitted) per channel: no energy is made.
pub fn lobes(base: Vec3, t: f32, transmitted: Vec3) -> (Vec3, Vec3) {
    let t = t.clamp(0.0, 1.0);
    (base * (1.0 - t), transmitted * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dt(factor: f32, color: Vec3) -> DiffuseTransmission {
        DiffuseTransmission { factor, texture: None, color, color_texture: None }
    }

    #[test]
    fn the_values_are_the_factors_times_the_textures() {
        let d = dt(0.5, Vec3::new(1.0, 0.9, 0.85));
        assert_eq!(d.factor_at(None), 0.5);
        assert_eq!(d.factor_at(Some(0.5)), 0.25);
        assert_eq!(d.color_at(None), Vec3::new(1.0, 0.9, 0.85));
        assert_eq!(d.color_at(Some(Vec3::new(0.5, 1.0, 0.0))), Vec3::new(0.5, 0.9, 0.0));
        assert!(dt(0.0, Vec3::ONE).is_off() && !d.is_off());
    }

    /// The extension's mix: at t = 0 the diffuse BRDF alone, at 1 the BTDF alone, and a white
    /// surface splits its light between the sides without making or losing any.
    #[test]
    fn the_mix_moves_light_between_the_sides() {
        let base = Vec3::new(0.2, 0.6, 0.1);
        let tr = Vec3::new(0.9, 0.1, 0.3);
        assert_eq!(lobes(base, 0.0, tr), (base, Vec3::ZERO));
        assert_eq!(lobes(base, 1.0, tr), (Vec3::ZERO, tr));
        let (r, t) = lobes(Vec3::ONE, 0.3, Vec3::ONE);
        assert!((r + t - Vec3::ONE).abs().max_element() < 1e-6);
        for k in 0..=10 {
            let (r, t) = lobes(base, k as f32 / 10.0, tr);
            assert!((r + t).cmple(base.max(tr) + 1e-6).all());
        }
    }
}
