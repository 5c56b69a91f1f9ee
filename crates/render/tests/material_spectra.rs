//! The spectral mode takes the coefficients of colours that are constant over a material from
//! the CPU (`render::material_spectra`) and fetches the others per pixel: both must give the
//! same image. The same ColorChecker chart (with emissive and unlit patches) is rendered as it
//! is, where every colour is constant, and with white vertex colours on every mesh, which sends
//! every pixel through the shader's fetch of the G-buffer's colours. The colours are exact in
//! f16, so that the G-buffer holds them unrounded and both paths start from the same numbers.
//!
//! A constant colour's reflection is also integrated on the CPU (`material_spectra::
//! reflected_xyz`: its XYZ under each light and the environment's basis spectra), where the
//! fetched one goes through the shader's node loop: four lights of different spectra (three to
//! a table entry, so the fourth starts the next) and an environment check the table's layout.

mod common;

use common::*;
use glam::{Vec3, Vec4};
use render::{Mode, RenderSettings};
use scene::{Emission, Environment, Light, LightKind};

#[test]
fn constant_material_coefficients_match_the_per_pixel_fetch() {
    let f16 = |v: f32| half::f16::from_f32(v).to_f32();
    let mut chart = Chart::colorchecker();
    for c in &mut chart.colours {
        *c = c.map(f16);
    }
    let mut scene = chart.scene(white_light(3.0, None), 0.5, 0.0);
    let f11 = color::illuminant::by_name("F11").unwrap();
    for (i, (direction, emission)) in [
        (Vec3::new(0.3, -0.2, -1.0), white_light(1.0, Some(f11))),
        (
            Vec3::new(-0.4, 0.3, -1.0),
            Emission { rgb: Vec3::new(1.0, 0.5, 0.2), intensity: 1.5, spectrum: None },
        ),
        (
            Vec3::new(0.1, 0.5, -1.0),
            Emission { rgb: Vec3::new(0.2, 0.4, 1.0), intensity: 2.0, spectrum: None },
        ),
    ]
    .into_iter()
    .enumerate()
    {
        scene.lights.push(Light {
            name: format!("light {i}"),
            kind: LightKind::Directional { direction: direction.normalize() },
            emission,
            stands_in_for: None,
        });
    }
    scene.environment = Some(Environment::default_sky());
    // Metals too: their reflectance tints the specular lobe, which the table holds as well.
    for (i, m) in scene.materials.iter_mut().enumerate() {
        if i % 4 == 2 {
            m.metallic = 1.0;
        }
    }
    // Emission over the whole colour range (dim, saturated, near white and past 1), and unlit
    // surfaces, whose colour the G-buffer carries as emission.
    for (i, m) in scene.materials.iter_mut().enumerate() {
        match i % 6 {
            1 => m.emissive = (Vec3::new(0.9, 0.2, 0.05) * (i as f32 / 8.0)).map(f16),
            3 => m.emissive = Vec3::splat(f16(0.7 + i as f32 / 10.0)),
            5 => m.unlit = true,
            _ => {}
        }
    }
    let mut r = renderer();
    let mut render = |scene: &scene::Scene, n: usize| {
        r.set_scene(scene).unwrap();
        r.set_environment(scene.environment.as_ref());
        let cam = r.scene_camera().unwrap();
        let s = RenderSettings { mode: Mode::Spectral, wavelengths: n, shadows: false, ..Default::default() };
        r.resize(96, 64).unwrap();
        r.render(&cam, &s).unwrap();
        r.read_hdr().unwrap()
    };
    let mut coloured = scene.clone();
    for m in &mut coloured.meshes {
        m.colors = vec![Vec4::ONE; m.positions.len()];
    }
    // N = 32: past the four groups whose reflectance the shader keeps per pixel.
    for n in [4, 16, 32] {
        let constant = render(&scene, n);
        let fetched = render(&coloured, n);
        let mut worst = 0.0f64;
        let mut lit = 0;
        for (a, b) in constant.iter().zip(&fetched) {
            let (a, b) = (rgb_of(a), rgb_of(b));
            if a.iter().all(|&c| c < 1e-3) && b.iter().all(|&c| c < 1e-3) {
                continue;
            }
            lit += 1;
            worst = worst.max(rel_err(a, b));
        }
        assert!(lit > 1000, "N = {n}: only {lit} lit pixels");
        // The same colours and table: they differ by the f32 rounding of the two fetches (the
        // CPU and WGSL ones agree to ΔE2000 1e-3, coeff_table's tests) and the f16 target's.
        assert!(worst < 2e-3, "N = {n}: constant-colour coefficients differ from the fetch by {worst:.2e}");
    }
}
