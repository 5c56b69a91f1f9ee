//! A double-sided surface seen from behind turns its whole tangent frame with its normal
//! (scene::facing_tangent, the Khronos sample viewer's rule, which the path tracer follows too:
//! normal, tangent and bitangent all negated). Its back face therefore draws as the same surface
//! built facing the viewer with the three negated: a normal map's normal is the front's negated
//! (the same bump seen from behind) and an anisotropy's direction keeps its axis. Checked on a
//! normal-mapped, brushed metal sphere under a directional light, in RGB and spectral modes:
//! the sphere built inside out (winding reversed, normals and tangents (xyz, w) negated) and
//! seen from outside draws as the ordinary sphere; keeping the handedness (the bitangent not
//! negated) mirrors the tilt and the direction, and shows.

mod common;

use common::*;
use glam::{Vec3, Vec4};
use render::{Mode, RenderSettings};
use scene::anisotropy::Anisotropy;
use scene::{Light, LightKind, Material, Scene, TextureRef};

const SIZE: u32 = 64;

/// The unit sphere's tangent at normal `n`, along its parallels (handedness +1).
fn sphere_tangent(n: Vec3) -> Vec4 {
    Vec3::new(-n.z, 0.0, n.x).normalize_or(Vec3::X).extend(1.0)
}

/// A white metal sphere, normal-mapped by one texel tilted ~35° towards +t and +b alike and
/// brushed at 45° to its parallels, lit from above left. `inside_out`: built facing inwards
/// (seen from the camera, its back faces), with the tangents (xyz, w) as `flip` makes them
/// from the outward sphere's.
fn sphere(inside_out: Option<fn(Vec4) -> Vec4>) -> Scene {
    let material = Material {
        name: "brushed".into(),
        base_color: Vec4::new(0.9, 0.6, 0.3, 1.0),
        metallic: 1.0,
        roughness: 0.35,
        double_sided: true,
        normal_texture: Some(TextureRef { index: 0, tex_coord: 0, transform: None }),
        anisotropy: Some(Anisotropy { strength: 0.8, rotation: std::f32::consts::FRAC_PI_4, texture: None }),
        ..Default::default()
    };
    let mut scene = sphere_scene(material, scene::Environment::uniform(Vec3::ONE), 64);
    scene.environment = None;
    scene.textures = vec![texel_texture("tilt", [191, 191, 218, 255], false)];
    scene.lights = vec![Light {
        name: "sun".into(),
        kind: LightKind::Directional { direction: -Vec3::new(-0.5, 0.7, 1.0).normalize() },
        emission: white_light(2.0, None),
        stands_in_for: None,
    }];
    let mesh = &mut scene.meshes[0];
    mesh.tangents = mesh.normals.iter().map(|&n| sphere_tangent(n)).collect();
    if let Some(flip) = inside_out {
        for t in mesh.indices.chunks_exact_mut(3) {
            t.swap(1, 2);
        }
        mesh.normals.iter_mut().for_each(|n| *n = -*n);
        mesh.tangents.iter_mut().for_each(|t| *t = flip(*t));
    }
    scene
}

#[test]
fn a_back_face_turns_its_tangent_frame_with_its_normal() {
    let mut r = renderer();
    for (mode, n) in [(Mode::Rgb, 1), (Mode::Spectral, 8)] {
        let s = RenderSettings { mode, wavelengths: n, shadows: false, ..Default::default() };
        let mut draw = |scene: &Scene| -> Vec<[f64; 3]> {
            render_frame(&mut r, scene, SIZE, &s, false).iter().map(rgb_of).collect()
        };
        let front = draw(&sphere(None));
        let lit = front.iter().filter(|p| p[1] > 0.0).count();
        assert!(lit > 1000, "{mode:?}: the sphere is hardly lit ({lit} pixels)");
        let expected: Vec<Option<[f64; 3]>> = front.iter().map(|&p| Some(p)).collect();
        let back = draw(&sphere(Some(|t| -t)));
        assert_delta_e(&format!("back-face-{mode:?}"), SIZE, SIZE, &back, &expected, 0.02, 0.2);
        // The frame turned without its handedness: the bitangent stays, which mirrors the tilt
        // and the direction (the rule both renderers followed in part before).
        let mirrored = draw(&sphere(Some(|t| (-t.truncate()).extend(t.w))));
        let de: Vec<f64> =
            mirrored.iter().zip(&front).map(|(a, b)| color::ciede2000(lab(*a), lab(*b))).collect();
        let (mean, _) = stats(de);
        println!("{mode:?}: the bitangent kept: ΔE2000 mean {mean:.2}");
        assert!(mean > 2.0, "{mode:?}: a mirrored frame barely shows (mean ΔE2000 {mean})");
    }
}
