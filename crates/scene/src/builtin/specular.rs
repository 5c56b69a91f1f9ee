//! `specular`: dielectrics whose specular strength and colour are set by
//! `KHR_materials_specular`, the extension Blender writes for its "IOR level" and specular tint.
//!
//! Two rows of four spheres on a neutral floor. Back row: a near-black base (ColorChecker black,
//! roughness 0.3) under tinted F0 colours (gold, copper, green and blue tints, × 10: F0 up to
//! 0.4), whose reflection is all the colour there is — a tinted Fresnel term depends on λ, which
//! the spectral modes carry through their nodes. Front row: the measured red, green, blue and
//! yellow bases (roughness 0.4) under grey F0s of different strength (weights 0.25 to 1 of a
//! white × 5, F0 0.2). One D65 spot from above and in front of the camera, one CIE F11 spot from
//! the side (a narrow-band fluorescent, where a tinted F0's spectrum matters).

use glam::Vec3;

use super::{empty, measured_material, patch, patch_index, shapes, showcase_spots};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::specular::Specular;
use crate::{Camera, Scene};

/// The back row's F0 tints (linear RGB, × [`TINT_SCALE`]).
pub const TINTS: [(&str, [f32; 3]); 4] = [
    ("gold", [1.0, 0.75, 0.3]),
    ("copper", [1.0, 0.55, 0.4]),
    ("green", [0.35, 1.0, 0.5]),
    ("blue", [0.4, 0.6, 1.0]),
];

/// The tints' scale: F0 = 0.04 × 10 × tint.
pub const TINT_SCALE: f32 = 10.0;

/// The front row's bases and specular weights (of a white × 5: F0 0.2).
pub const WEIGHTED: [(&str, f32); 4] = [("red", 0.25), ("green", 0.5), ("blue", 0.75), ("yellow", 1.0)];

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let camera =
        Camera::look_at(Vec3::new(0.0, 0.75, 1.55), Vec3::new(0.0, 0.12, 0.0), Vec3::Y, 40f32.to_radians());
    let mut s = empty(ctx, camera);
    s.materials
        .push(measured_material("floor (ColorChecker neutral 5)", &patch(patch_index("neutral 5 (.70 D)"))));
    let floor = 0;
    let (r, step) = (0.12f32, 0.3f32);
    let black = patch(patch_index("black 2 (1.5 D)"));
    for (i, (name, tint)) in TINTS.iter().enumerate() {
        let mut m = measured_material(&format!("black under a {name} F0"), &black);
        m.roughness = 0.3;
        m.specular = Some(Specular {
            factor: 1.0,
            texture: None,
            color: Vec3::from(*tint) * TINT_SCALE,
            color_texture: None,
        });
        s.materials.push(m);
        let x = (i as f32 - 1.5) * step;
        s.meshes.push(shapes::sphere(Vec3::new(x, r, -0.2), r, 14, 22, s.materials.len() - 1));
    }
    for (i, (name, weight)) in WEIGHTED.iter().enumerate() {
        let mut m =
            measured_material(&format!("{name} with a specular of {weight}"), &patch(patch_index(name)));
        m.roughness = 0.4;
        m.specular =
            Some(Specular { factor: *weight, texture: None, color: Vec3::splat(5.0), color_texture: None });
        s.materials.push(m);
        let x = (i as f32 - 1.5) * step;
        s.meshes.push(shapes::sphere(Vec3::new(x, r, 0.15), r, 14, 22, s.materials.len() - 1));
    }
    let fw = 2.0f32;
    s.meshes.push(shapes::quad(Vec3::new(-fw * 0.5, 0.0, fw * 0.5), Vec3::X * fw, -Vec3::Z * fw, floor));
    s.lights = showcase_spots(ctx, ("front spot (D65)", "D65"), ("side spot (F11)", "F11"))?;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sphere_has_a_specular_over_its_measured_base() {
        let s = build(&Ctx::builtin("specular")).unwrap();
        for m in &s.meshes[..8] {
            let mat = &s.materials[m.material];
            assert!(mat.specular.is_some() && mat.spectral.is_some(), "{}", mat.name);
        }
        assert!(s.materials[0].specular.is_none(), "the floor is plain");
        let tinted = s.materials[1].specular.as_ref().unwrap();
        let f0c = crate::specular::f0_color(s.materials[1].dielectric_f0(), tinted.color);
        assert!(f0c.abs_diff_eq(Vec3::new(0.4, 0.3, 0.12), 1e-6), "{f0c}");
        assert_eq!(s.lights.len(), 2);
    }
}
