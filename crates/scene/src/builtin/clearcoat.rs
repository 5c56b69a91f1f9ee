//! `clearcoat`: clear coats (`KHR_materials_clearcoat`) over measured bases, the layer car paint
//! and varnish add to real assets.
//!
//! Two rows of four spheres on a neutral floor, the bases ColorChecker red, green, blue and
//! yellow (measured reflectances, roughness 0.6, so that the base alone has a broad, dull
//! highlight). Back row: a full, glossy coat (clearcoat 1, roughness 0.05) — a sharp highlight
//! of each spot over the colour, and the colour dimmed by the coat's Fresnel term towards the
//! rims; front row: the same bases under a half-strength satin coat (0.5, roughness 0.3). One D65
//! spot from above and in front of the camera, one CIE F11 spot from the side (a narrow-band
//! fluorescent, where the bases' spectra matter: the coat itself reflects every wavelength alike).

use super::{Showcase, measured_material, patch, patch_index};
use crate::Scene;
use crate::clearcoat::Clearcoat;
use crate::context::Ctx;
use crate::error::SceneError;

/// The bases, left to right (ColorChecker patch names).
pub const BASES: [&str; 4] = ["red", "green", "blue", "yellow"];

/// (strength, roughness) of the back and the front row's coats.
pub const COATS: [(f32, f32); 2] = [(1.0, 0.05), (0.5, 0.3)];

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let mut stage = Showcase::new(ctx);
    for (row, &(strength, roughness)) in COATS.iter().enumerate() {
        for (i, name) in BASES.iter().enumerate() {
            let what = if row == 0 { "glossy" } else { "satin" };
            let mut m = measured_material(&format!("{name} under a {what} coat"), &patch(patch_index(name)));
            m.roughness = 0.6;
            m.clearcoat = Some(Clearcoat {
                factor: strength,
                texture: None,
                roughness,
                roughness_texture: None,
                normal_texture: None,
                normal_scale: 1.0,
            });
            stage.sphere(row, i, m);
        }
    }
    // Two spots aimed at the middle of the rows, ≈ π lux there each: D65 in front, F11 aside.
    stage.finish(ctx, ("front spot (D65)", "D65"), ("side spot (F11)", "F11"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sphere_is_coated_over_its_measured_base() {
        let s = build(&Ctx::builtin("clearcoat")).unwrap();
        for m in &s.meshes[..8] {
            let mat = &s.materials[m.material];
            assert!(mat.clearcoat.is_some() && mat.spectral.is_some(), "{}", mat.name);
        }
        assert!(s.materials[0].clearcoat.is_none(), "the floor is bare");
        assert_eq!(s.lights.len(), 2);
    }
}
