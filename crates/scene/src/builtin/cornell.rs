//! `cornell`: the Cornell box in metres, with ColorChecker reflectances on the walls.
//!
//! Box 0.555 m on a side, open towards +Z, floor at y = 0. Left wall ColorChecker "red",
//! right wall "green", floor/ceiling/back and both blocks "white 9.5". The lamp is a
//! 0.13 × 0.105 m quad just under the ceiling emitting a D65-shaped spectrum with luminance
//! [`LAMP_RADIANCE`]; a downward spot light with `stands_in_for` pointing at the lamp mesh
//! carries the same spectrum and the same on-axis intensity (radiance × area), for renderers
//! that can only shade punctual lights. The path tracer lights with the quad and skips the spot.

use glam::Vec3;

use super::{empty, light_emission, measured_material, patch, patch_index, shapes};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::{Camera, Light, LightKind, Material, Scene};

/// Side of the box, m.
pub const SIZE: f32 = 0.555;
/// Lamp size, m (the original's 130 × 105 mm).
pub const LAMP: (f32, f32) = (0.13, 0.105);
/// Luminance of the lamp quad (glTF emissive strength on a white emissive colour). With the
/// white floor (ρ ≈ 0.9) this puts the floor under the lamp near 0.5.
pub const LAMP_RADIANCE: f32 = 40.0;

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let h = SIZE * 0.5;
    let camera =
        Camera::look_at(Vec3::new(0.0, h, 1.08), Vec3::new(0.0, h, 0.0), Vec3::Y, 39.3f32.to_radians());
    let mut s = empty(ctx, camera);
    s.camera.aspect = Some(1.0);

    let white = patch(patch_index("white 9.5 (.05 D)"));
    s.materials.push(measured_material("white (ColorChecker white 9.5)", &white));
    s.materials.push(measured_material("red (ColorChecker red)", &patch(patch_index("red"))));
    s.materials.push(measured_material("green (ColorChecker green)", &patch(patch_index("green"))));
    let (w, r, g) = (0, 1, 2);

    // Walls, each facing into the box.
    let (x0, x1, y1, z0, z1) = (-h, h, SIZE, -h, h);
    s.meshes.push(shapes::quad(Vec3::new(x0, 0.0, z1), Vec3::X * SIZE, -Vec3::Z * SIZE, w)); // floor
    s.meshes.push(shapes::quad(Vec3::new(x0, y1, z0), Vec3::X * SIZE, Vec3::Z * SIZE, w)); // ceiling
    s.meshes.push(shapes::quad(Vec3::new(x0, 0.0, z0), Vec3::X * SIZE, Vec3::Y * SIZE, w)); // back
    s.meshes.push(shapes::quad(Vec3::new(x0, 0.0, z1), -Vec3::Z * SIZE, Vec3::Y * SIZE, r)); // left
    s.meshes.push(shapes::quad(Vec3::new(x1, 0.0, z0), Vec3::Z * SIZE, Vec3::Y * SIZE, g)); // right
    // The two blocks of the original, turned ±17°.
    s.meshes.push(shapes::cuboid(Vec3::new(0.093, 0.0, 0.065), Vec3::splat(0.165), (-17f32).to_radians(), w));
    s.meshes.push(shapes::cuboid(
        Vec3::new(-0.095, 0.0, -0.075),
        Vec3::new(0.165, 0.33, 0.165),
        17f32.to_radians(),
        w,
    ));

    // The lamp: an emissive quad facing down, 1 mm under the ceiling so it is not coplanar.
    let d65 = color::illuminant::by_name("D65").map_err(|e| ctx.invalid("lamp", e.to_string()))?;
    let lamp_emission = light_emission(ctx, "lamp", &d65, LAMP_RADIANCE)?;
    let lamp_mat = s.materials.len();
    s.materials.push(Material {
        name: "lamp (D65)".into(),
        base_color: glam::Vec4::new(0.78, 0.78, 0.78, 1.0),
        emissive: lamp_emission.rgb * LAMP_RADIANCE,
        emission_spectrum: lamp_emission.spectrum.clone(),
        ..Material::default()
    });
    let y = SIZE - 0.001;
    let lamp_mesh = s.meshes.len();
    s.meshes.push(shapes::quad(
        Vec3::new(-LAMP.0 * 0.5, y, -LAMP.1 * 0.5),
        Vec3::X * LAMP.0,
        Vec3::Z * LAMP.1,
        lamp_mat,
    ));
    // Stand-in: a Lambertian emitter of radiance L and area A has intensity L·A·cosθ, so L·A on
    // axis. The spot's glTF cone (inner 0, outer 90°) falls off as cos²θ instead of cosθ and
    // casts hard shadows; the difference is the price of a punctual light.
    let intensity = LAMP_RADIANCE * LAMP.0 * LAMP.1;
    s.lights.push(Light {
        name: "lamp stand-in (spot, D65)".into(),
        kind: LightKind::Spot {
            position: Vec3::new(0.0, y - 0.001, 0.0),
            direction: -Vec3::Y,
            inner_cone: 0.0,
            outer_cone: std::f32::consts::FRAC_PI_2,
            range: None,
        },
        emission: light_emission(ctx, "lamp stand-in", &d65, intensity)?,
        stands_in_for: Some(lamp_mesh),
    });
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::SpectralReflectance;

    #[test]
    fn lamp_and_stand_in_agree() {
        let s = build(&Ctx::builtin("cornell")).unwrap();
        let spot = &s.lights[0];
        let lamp = spot.stands_in_for.expect("spot stands in for the lamp");
        let mat = &s.materials[s.meshes[lamp].material];
        let (ls, ss) = (mat.emission_spectrum.as_ref().unwrap(), spot.emission.spectrum.as_ref().unwrap());
        // Same spectral shape, ratio = lamp area (intensity = radiance × area).
        let area = LAMP.0 * LAMP.1;
        for l in [420.0, 550.0, 680.0] {
            assert!((ss.eval(l) / ls.eval(l) - area as f64).abs() < 1e-6, "at {l} nm");
        }
        let y = crate::emission::spectrum_luminance(ls);
        assert!((y - LAMP_RADIANCE as f64).abs() < 1e-3 * y, "lamp luminance {y}");
        // The walls carry the measured spectra.
        assert!(s.materials[..3].iter().all(|m| matches!(m.spectral, Some(SpectralReflectance::Uniform(_)))));
        assert!(
            s.materials[1].base_color.x > 0.3 && s.materials[1].base_color.y < 0.1,
            "red wall {}",
            s.materials[1].base_color
        );
    }
}
