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

use glam::Vec3;

use super::{empty, measured_material, patch, patch_index, shapes, showcase_spots};
use crate::clearcoat::Clearcoat;
use crate::context::Ctx;
use crate::error::SceneError;
use crate::{Camera, Scene};

/// The bases, left to right (ColorChecker patch names).
pub const BASES: [&str; 4] = ["red", "green", "blue", "yellow"];

/// (strength, roughness) of the back and the front row's coats.
pub const COATS: [(f32, f32); 2] = [(1.0, 0.05), (0.5, 0.3)];

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let camera =
        Camera::look_at(Vec3::new(0.0, 0.75, 1.55), Vec3::new(0.0, 0.12, 0.0), Vec3::Y, 40f32.to_radians());
    let mut s = empty(ctx, camera);
    s.materials
        .push(measured_material("floor (ColorChecker neutral 5)", &patch(patch_index("neutral 5 (.70 D)"))));
    let floor = 0;
    let (r, step) = (0.12f32, 0.3f32);
    for (row, (&(strength, roughness), z)) in COATS.iter().zip([-0.2f32, 0.15]).enumerate() {
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
            s.materials.push(m);
            let x = (i as f32 - 1.5) * step;
            s.meshes.push(shapes::sphere(Vec3::new(x, r, z), r, 14, 22, s.materials.len() - 1));
        }
    }
    let fw = 2.0f32;
    s.meshes.push(shapes::quad(Vec3::new(-fw * 0.5, 0.0, fw * 0.5), Vec3::X * fw, -Vec3::Z * fw, floor));

    // Two spots aimed at the middle of the rows, ≈ π lux there each: D65 in front, F11 aside.
    s.lights = showcase_spots(ctx, ("front spot (D65)", "D65"), ("side spot (F11)", "F11"))?;
    Ok(s)
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
