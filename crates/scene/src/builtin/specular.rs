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

use super::{Showcase, measured_material, patch, patch_index};
use crate::Scene;
use crate::context::Ctx;
use crate::error::SceneError;
use crate::specular::Specular;

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
    let mut stage = Showcase::new(ctx);
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
        stage.sphere(0, i, m);
    }
    for (i, (name, weight)) in WEIGHTED.iter().enumerate() {
        let mut m =
            measured_material(&format!("{name} with a specular of {weight}"), &patch(patch_index(name)));
        m.roughness = 0.4;
        m.specular =
            Some(Specular { factor: *weight, texture: None, color: Vec3::splat(5.0), color_texture: None });
        stage.sphere(1, i, m);
    }
    stage.finish(ctx, ("front spot (D65)", "D65"), ("side spot (F11)", "F11"))
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
