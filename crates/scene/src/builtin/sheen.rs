//! `sheen`: fabrics whose fibres `KHR_materials_sheen` draws (velvet, cloth), the layer of
//! SheenChair, GlamVelvetSofa and ToyCar's seat cover.
//!
//! Two rows of four spheres on a neutral floor, every base diffuse (roughness 1, as cloth has no
//! gloss of its own). Back row: velvets — a near-black base (ColorChecker black) under saturated
//! red, green, blue and magenta sheens of roughness 0.3 to 0.6, whose grazing rim is all the
//! colour there is; the sheen colour is an RGB factor that the spectral modes upsample to a
//! reflectance, so under the F11 spot (a narrow-band fluorescent) the colour's spectrum, not
//! its three channels, sets the rim. The roughness grows left to right, from a sharp rim (0.3,
//! near the extension's smallest drawn lobe, 0.265) to a broad haze (0.6). Front row: the
//! measured red, green, blue and yellow bases under white and lightly tinted (warm, cool)
//! sheens of roughness 0.5 to 1: a pale sheen over a coloured base, which takes the base's
//! light away by the sheen's albedo (the extension's albedo scaling) and puts back a white rim —
//! the base's spectrum matters under F11, as on the ColorChecker. One D65 spot from above and in
//! front of the camera, one CIE F11 spot from the side, whose grazing light is where a sheen
//! shows most.

use glam::Vec3;

use super::{Showcase, measured_material, patch, patch_index};
use crate::Scene;
use crate::context::Ctx;
use crate::error::SceneError;
use crate::sheen::Sheen;

/// The back row's sheens over black: (name, colour in linear RGB, sheen roughness).
pub const VELVETS: [(&str, [f32; 3], f32); 4] = [
    ("red", [1.0, 0.12, 0.08], 0.3),
    ("green", [0.12, 0.9, 0.2], 0.4),
    ("blue", [0.12, 0.3, 1.0], 0.5),
    ("magenta", [0.9, 0.12, 0.8], 0.6),
];

/// The front row's bases (ColorChecker patch names) and the sheens over them: (base, sheen
/// colour in linear RGB, sheen roughness).
pub const SHEENED: [(&str, [f32; 3], f32); 4] = [
    ("red", [1.0, 1.0, 1.0], 0.5),
    ("green", [1.0, 0.9, 0.75], 0.65),
    ("blue", [0.8, 0.9, 1.0], 0.8),
    ("yellow", [1.0, 1.0, 1.0], 1.0),
];

fn sheen(color: [f32; 3], roughness: f32) -> Sheen {
    Sheen { color: Vec3::from(color), color_texture: None, roughness, roughness_texture: None }
}

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let mut stage = Showcase::new(ctx);
    let black = patch(patch_index("black 2 (1.5 D)"));
    for (i, &(name, color, roughness)) in VELVETS.iter().enumerate() {
        let mut m =
            measured_material(&format!("black under a {name} sheen of roughness {roughness}"), &black);
        m.sheen = Some(sheen(color, roughness));
        stage.sphere(0, i, m);
    }
    for (i, &(name, color, roughness)) in SHEENED.iter().enumerate() {
        let mut m = measured_material(
            &format!("{name} under a pale sheen of roughness {roughness}"),
            &patch(patch_index(name)),
        );
        m.sheen = Some(sheen(color, roughness));
        stage.sphere(1, i, m);
    }
    stage.finish(ctx, ("front spot (D65)", "D65"), ("side spot (F11)", "F11"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sphere_has_a_sheen_over_its_measured_base() {
        let s = build(&Ctx::builtin("sheen")).unwrap();
        assert_eq!(s.meshes.len(), 9, "eight spheres and the floor");
        for m in &s.meshes[..8] {
            let mat = &s.materials[m.material];
            let sh = mat.sheen.as_ref().unwrap_or_else(|| panic!("{} has no sheen", mat.name));
            assert!(mat.spectral.is_some(), "{}", mat.name);
            assert!(!sh.is_off(), "{}", mat.name);
            assert!(sh.roughness >= 0.3 && sh.roughness <= 1.0, "{}", mat.name);
            assert!(sh.color.max_element() <= 1.0 && sh.color.min_element() >= 0.0, "{}", mat.name);
        }
        assert!(s.materials[0].sheen.is_none(), "the floor is plain");
        assert_eq!(s.materials[1].sheen.as_ref().unwrap().color, Vec3::new(1.0, 0.12, 0.08));
        assert_eq!(s.lights.len(), 2);
    }
}
