//! `translucent`: thin sheets lit from behind, which `KHR_materials_diffuse_transmission` lets
//! glow (leaves, paper, a lampshade, coloured plastic film).
//!
//! Four upright double-sided panels in a row on a neutral floor, facing the camera; each
//! reflects a measured ColorChecker reflectance and transmits a share of its diffuse light in
//! another patch's colour (the RGB under D65 of that patch, upsampled by both renderers like
//! every RGB colour): foliage passing yellow green at 0.6 (a leaf), white passing white at 0.4
//! (paper), orange yellow passing orange at 0.5 (a lampshade), red passing red at 0.9 (a
//! coloured film). A D65 spot behind the panels lights their far sides, so what the camera sees
//! of them is mostly transmitted light, the product of the spot's spectrum and the transmitted
//! colour's; a dimmer F11 spot from the front shows their reflectances, and what passes the
//! other way lights nothing the camera sees but the floor behind.

use super::{empty, measured_material, patch, patch_index, reflectance_rgb, shapes, spot_at};
use crate::Scene;
use crate::context::Ctx;
use crate::diffuse_transmission::DiffuseTransmission;
use crate::error::SceneError;
use glam::Vec3;

/// Each panel's reflectance (patch), transmitted colour (patch) and share, left to right.
pub const PANELS: [(&str, &str, f32); 4] = [
    ("foliage", "yellow green", 0.6),
    ("white 9.5 (.05 D)", "white 9.5 (.05 D)", 0.4),
    ("orange yellow", "orange", 0.5),
    ("red", "red", 0.9),
];

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let camera = crate::Camera::look_at(
        Vec3::new(0.0, 0.55, 1.5),
        Vec3::new(0.0, 0.17, 0.0),
        Vec3::Y,
        40f32.to_radians(),
    );
    let mut scene = empty(ctx, camera);
    scene
        .materials
        .push(measured_material("floor (ColorChecker neutral 5)", &patch(patch_index("neutral 5 (.70 D)"))));
    let fw = 2.0f32;
    scene.meshes.push(shapes::quad(Vec3::new(-fw * 0.5, 0.0, fw * 0.5), Vec3::X * fw, -Vec3::Z * fw, 0));
    let (w, h, step) = (0.24f32, 0.32f32, 0.3f32);
    for (i, &(reflects, passes, share)) in PANELS.iter().enumerate() {
        let mut m = measured_material(
            &format!("{reflects}, passing {share} of its diffuse light as {passes}"),
            &patch(patch_index(reflects)),
        );
        m.roughness = 0.5;
        m.double_sided = true;
        let color = reflectance_rgb(&patch(patch_index(passes))).clamp(glam::DVec3::ZERO, glam::DVec3::ONE);
        m.diffuse_transmission = Some(DiffuseTransmission {
            factor: share,
            texture: None,
            color: color.as_vec3(),
            color_texture: None,
        });
        scene.materials.push(m);
        let x = (i as f32 - 1.5) * step - w * 0.5;
        // Facing the camera (+z): u × v = x × y.
        scene.meshes.push(shapes::quad(Vec3::new(x, 0.02, 0.0), Vec3::X * w, Vec3::Y * h, i + 1));
    }
    let target = Vec3::new(0.0, 0.18, 0.0);
    let back = Vec3::new(0.15, 0.8, -1.1);
    let front = Vec3::new(-0.6, 0.9, 1.1);
    let cones = (35f32.to_radians(), 60f32.to_radians());
    scene.lights = vec![
        // ≈ 2π lux on the panels' far sides, ≈ π/2 from the front.
        spot_at(
            ctx,
            "back spot (D65)",
            "D65",
            back,
            target,
            2.0 * std::f32::consts::PI * (target - back).length_squared(),
            cones,
        )?,
        spot_at(
            ctx,
            "front spot (F11)",
            "F11",
            front,
            target,
            0.5 * std::f32::consts::PI * (target - front).length_squared(),
            cones,
        )?,
    ];
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_panels_transmit_and_the_back_spot_lights_their_far_sides() {
        let s = build(&Ctx::builtin("translucent")).unwrap();
        assert_eq!(s.meshes.len(), 5, "the floor and four panels");
        assert!(s.materials[0].diffuse_transmission.is_none(), "the floor is opaque");
        let eye = s.camera.transform.transform_point3(Vec3::ZERO);
        let crate::LightKind::Spot { position: back, .. } = s.lights[0].kind else { panic!("a spot") };
        for m in &s.meshes[1..] {
            let mat = &s.materials[m.material];
            let d = mat.diffuse_transmission.as_ref().unwrap_or_else(|| panic!("{} is opaque", mat.name));
            assert!(!d.is_off() && mat.double_sided && mat.spectral.is_some(), "{}", mat.name);
            let (p, n) = (m.positions[0], m.normals[0]);
            assert!(
                n.dot(eye - p) > 0.0 && n.dot(back - p) < 0.0,
                "{}: the camera and the back spot on one side",
                mat.name
            );
        }
    }
}
