//! `anisotropy`: brushed and satin surfaces whose highlights `KHR_materials_anisotropy`
//! stretches (AnisotropyBarnLamp's brushed metal, the grain of a machined part).
//!
//! Two rows of four spheres on a neutral floor; each sphere's tangent runs along its parallels
//! (the UV sphere's u direction, MikkTSpace tangents), so a direction of 0 stretches the
//! highlight around the vertical axis and π/2 along the meridians. Back row: coloured metals
//! (ColorChecker red, green, blue and yellow reflectances as F0: anodised aluminium), roughness
//! 0.3, strength growing left to right (0.25 to 1): the highlight widens from a spot into a
//! band, and a tinted metal's reflection is all its colour — the spectral modes carry the F0's
//! spectrum through their nodes, which matters under the F11 spot. Front row: measured orange,
//! purple, cyan and magenta dielectrics, roughness 0.2 at strength 0.8, the direction turned by
//! 0, π/4, π/2 and 3π/4 (`anisotropyRotation`): the same band, turning. One D65 spot from above
//! and in front of the camera, one CIE F11 spot from the side.

use super::{Showcase, measured_material, patch, patch_index};
use crate::Scene;
use crate::anisotropy::Anisotropy;
use crate::context::Ctx;
use crate::error::SceneError;

/// The back row's metals (ColorChecker patch names as F0) and anisotropy strengths.
pub const METALS: [(&str, f32); 4] = [("red", 0.25), ("green", 0.5), ("blue", 0.75), ("yellow", 1.0)];

/// The front row's dielectrics (ColorChecker patch names) and directions (radians).
pub const TURNED: [(&str, f32); 4] = [
    ("orange", 0.0),
    ("purple", std::f32::consts::FRAC_PI_4),
    ("cyan", std::f32::consts::FRAC_PI_2),
    ("magenta", 3.0 * std::f32::consts::FRAC_PI_4),
];

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let mut stage = Showcase::new(ctx);
    for (i, &(name, strength)) in METALS.iter().enumerate() {
        let mut m =
            measured_material(&format!("{name} metal, anisotropy {strength}"), &patch(patch_index(name)));
        m.metallic = 1.0;
        m.roughness = 0.3;
        m.anisotropy = Some(Anisotropy { strength, rotation: 0.0, texture: None });
        stage.sphere(0, i, m);
    }
    for (i, &(name, rotation)) in TURNED.iter().enumerate() {
        let mut m = measured_material(
            &format!("{name}, anisotropy 0.8 turned {:.0}°", rotation.to_degrees()),
            &patch(patch_index(name)),
        );
        m.roughness = 0.2;
        m.anisotropy = Some(Anisotropy { strength: 0.8, rotation, texture: None });
        stage.sphere(1, i, m);
    }
    let scene = stage.finish(ctx, ("front spot (D65)", "D65"), ("side spot (F11)", "F11"))?;
    // The spheres' tangents (MikkTSpace on their UVs), made here so that every consumer of the
    // scene — both renderers, the exporter — sees the same frame.
    Ok(scene.completed().into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sphere_is_anisotropic_with_tangents_along_its_parallels() {
        let s = build(&Ctx::builtin("anisotropy")).unwrap();
        assert_eq!(s.meshes.len(), 9, "eight spheres and the floor");
        for m in &s.meshes[..8] {
            let mat = &s.materials[m.material];
            let a = mat.anisotropy.as_ref().unwrap_or_else(|| panic!("{} is isotropic", mat.name));
            assert!(!a.is_off() && mat.spectral.is_some(), "{}", mat.name);
            assert_eq!(m.tangents.len(), m.positions.len(), "{}", mat.name);
            // Away from the poles the tangent runs along a parallel, within the facets' error
            // (per-face MikkTSpace tangents of a 14 × 22 sphere: a few degrees).
            for (t, n) in m.tangents.iter().zip(&m.normals) {
                if n.y.abs() < 0.5 {
                    let parallel = glam::Vec3::Y.cross(*n).normalize();
                    let t = t.truncate();
                    assert!(
                        t.dot(parallel).abs() > 0.99 && t.dot(*n).abs() < 1e-3,
                        "{}: {t} at {n}",
                        mat.name
                    );
                }
            }
        }
        assert!(s.materials[0].anisotropy.is_none(), "the floor is plain");
        assert!(s.meshes[8].tangents.is_empty());
        assert_eq!(s.materials[1].metallic, 1.0);
        assert_eq!(s.lights.len(), 2);
    }
}
