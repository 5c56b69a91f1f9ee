//! KHR_materials_specular in real time against the extension's `fresnel_mix` computed here on
//! the CPU (f64): the dielectric's lobe × w·(F0c + (1 − F0c)(1 − v·h)⁵) per channel, its
//! diffuse × (1 − w·(F0c_max + (1 − F0c_max)(1 − v·h)⁵)), F0c = min(0.04·colour, 1)
//! (scene::specular), in the RGB and spectral modes and through the general node loop (the
//! spectral capture); factors and textures; and in a uniform environment, where the
//! weight scales the reflection and the colour tints it channel by channel.

mod common;

use common::*;
use glam::{Vec3, Vec4};
use render::{Mode, RenderSettings};
use scene::specular::Specular;
use scene::{Environment, TextureRef};

const W: u32 = 48;
const H: u32 = 32;

/// Radiance per unit irradiance × n·l of a material of albedo `rho` with specular weight `w`
/// and F0 colour `f0c`, as the extension writes its dielectric, mixed with glTF's metal by
/// `metallic` (glTF 2.0 appendix B: mix(dielectric_brdf, metal_brdf, metallic)).
#[allow(clippy::too_many_arguments)]
fn fresnel_mix(
    n: Vec3,
    v: Vec3,
    wi: Vec3,
    roughness: f64,
    rho: [f64; 3],
    w: f64,
    f0c: [f64; 3],
    metallic: f64,
) -> [f64; 3] {
    let nl = n.dot(wi) as f64;
    if nl <= 0.0 {
        return [0.0; 3];
    }
    let h = (wi + v).normalize();
    let nv = (n.dot(v) as f64).max(1e-4);
    let nh = (n.dot(h) as f64).max(0.0);
    let vh = (v.dot(h) as f64).max(0.0);
    let a2 = (roughness * roughness).max(1e-3).powi(2);
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (std::f64::consts::PI * dd * dd);
    let vis = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    let fres = (1.0 - vh).powi(5);
    let f0_max = f0c[0].max(f0c[1]).max(f0c[2]);
    let keep = 1.0 - w * (f0_max + (1.0 - f0_max) * fres);
    std::array::from_fn(|c| {
        let dielectric =
            rho[c] * keep / std::f64::consts::PI + d * vis * w * (f0c[c] + (1.0 - f0c[c]) * fres);
        let metal = d * vis * (rho[c] + (1.0 - rho[c]) * fres);
        nl * ((1.0 - metallic) * dielectric + metallic * metal)
    })
}

/// A test case: its name, the base albedo, the specular, its weight and colour at the pixels,
/// and the metallic factor.
type Case = (&'static str, [f64; 3], Specular, f64, [f64; 3], f64);

/// A patch under a directional light near its mirror direction, with the specular as factors
/// (grey weight; a yellow colour; a strong red colour over a white base, whose diffuse must stay
/// neutral) and as textures (strength in A, colour in sRGB).
#[test]
fn the_specular_weight_and_colour_follow_fresnel_mix() {
    let chart = Chart { colours: vec![[1.0, 1.0, 1.0]], cols: 1, rows: 1, gap: 0.0 };
    let wi = Vec3::new(0.3, 0.0, 1.0).normalize();
    let tex = |i| Some(TextureRef { transform: None, index: i, tex_coord: 0 });
    // (name, base albedo, specular, weight at the pixel, colour at the pixel)
    let strength_texel = [255u8, 255, 255, 128];
    let colour_texel = [255u8, 180, 40, 255];
    let cases: Vec<Case> = vec![
        (
            "weight",
            [0.2, 0.1, 0.05],
            Specular { factor: 0.3, texture: None, color: Vec3::ONE, color_texture: None },
            0.3,
            [1.0; 3],
            0.0,
        ),
        (
            "yellow",
            [0.0; 3],
            Specular { factor: 1.0, texture: None, color: Vec3::new(10.0, 10.0, 0.0), color_texture: None },
            1.0,
            [10.0, 10.0, 0.0],
            0.0,
        ),
        (
            "yellow-half-metal",
            [0.3, 0.5, 0.8],
            Specular { factor: 1.0, texture: None, color: Vec3::new(10.0, 10.0, 0.0), color_texture: None },
            1.0,
            [10.0, 10.0, 0.0],
            0.5,
        ),
        (
            "red-over-white",
            [0.8; 3],
            Specular { factor: 1.0, texture: None, color: Vec3::new(12.0, 1.0, 1.0), color_texture: None },
            1.0,
            [12.0, 1.0, 1.0],
            0.0,
        ),
        (
            "textures",
            [0.05, 0.05, 0.2],
            Specular { factor: 0.9, texture: tex(0), color: Vec3::splat(8.0), color_texture: tex(1) },
            0.9 * 128.0 / 255.0,
            colour_texel.map(|c| 8.0 * decode8(c))[..3].try_into().unwrap(),
            0.0,
        ),
    ];
    let mut r = renderer();
    for (name, rho, specular, w, colour, metallic) in cases {
        let mut scene = chart.scene(white_light(2.0, None), 0.3, metallic as f32);
        scene.lights[0].kind = scene::LightKind::Directional { direction: -wi };
        scene.textures = vec![
            texel_texture("strength", strength_texel, false),
            texel_texture("colour", colour_texel, true),
        ];
        let m = &mut scene.materials[0];
        m.base_color = Vec4::new(rho[0] as f32, rho[1] as f32, rho[2] as f32, 1.0);
        m.specular = Some(specular);
        let f0c = colour.map(|c| (0.04 * c).min(1.0));
        let mut expected = Vec::new();
        let mut effect = Vec::new();
        for y in 0..H {
            for x in 0..W {
                let (p, d) = pixel_to_chart(x, y, W, H);
                let v = -d;
                expected.push(chart.patch_at(p, 0.05).map(|_| {
                    let want = fresnel_mix(Vec3::Z, v, wi, 0.3, rho, w, f0c, metallic).map(|l| l * 2.0);
                    let plain =
                        fresnel_mix(Vec3::Z, v, wi, 0.3, rho, 1.0, [0.04; 3], metallic).map(|l| l * 2.0);
                    effect.push(color::ciede2000(lab(want), lab(plain)));
                    want
                }));
            }
        }
        let effect = effect.iter().sum::<f64>() / effect.len() as f64;
        assert!(effect > 2.0, "{name}: the specular changes the image by ΔE2000 {effect} only");
        r.set_scene(&scene).unwrap();
        r.resize(W, H).unwrap();
        for (mode, n, capture) in
            [(Mode::Rgb, 16, false), (Mode::Spectral, 16, false), (Mode::Spectral, 16, true)]
        {
            let s = RenderSettings { mode, wavelengths: n, shadows: false, ..Default::default() };
            r.set_spectral_capture(capture);
            r.render(&scene.camera, &s).unwrap();
            let actual: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
            let label = format!("specular-{name}-{mode:?}-{n}-{capture}");
            let c = (H / 2 * W + W / 2) as usize;
            println!(
                "{label}: centre {:?} expected {:?}; the specular's own ΔE2000 {effect:.2}",
                actual[c], expected[c]
            );
            assert_delta_e(&label, W, H, &actual, &expected, 0.15, 0.4);
        }
        r.set_spectral_capture(false);
    }
}

/// A black dielectric sphere in a uniform environment of radiance 1 reflects only its specular,
/// w·(F0c·A + B) per channel (the split sum's A, B): a weight w scales the image by w, and with
/// colours 0, 1 and c the difference (c − 0) / (1 − 0) is c, channel by channel.
#[test]
fn in_the_furnace_the_weight_scales_and_the_colour_tints_the_reflection() {
    const SIZE: u32 = 40;
    let material =
        scene::Material { base_color: Vec4::new(0.0, 0.0, 0.0, 1.0), roughness: 0.4, ..Default::default() };
    let mut scene = sphere_scene(material, Environment::uniform(Vec3::ONE), 64);
    let mut r = renderer();
    let mut render_it = |scene: &scene::Scene, mode: Mode, capture: bool| {
        let s = RenderSettings { mode, wavelengths: 8, shadows: false, ..Default::default() };
        render_frame(&mut r, scene, SIZE, &s, capture)
    };
    let spec =
        |factor: f32, color: Vec3| Some(Specular { factor, texture: None, color, color_texture: None });
    let tint = [20.0f64, 10.0, 0.0];
    for (mode, capture) in [(Mode::Rgb, false), (Mode::Spectral, false), (Mode::Spectral, true)] {
        scene.materials[0].specular = None;
        let bare = render_it(&scene, mode, capture);
        scene.materials[0].specular = spec(0.4, Vec3::ONE);
        let weighed = render_it(&scene, mode, capture);
        scene.materials[0].specular = spec(1.0, Vec3::ZERO);
        let zero = render_it(&scene, mode, capture);
        scene.materials[0].specular = spec(1.0, Vec3::new(tint[0] as f32, tint[1] as f32, tint[2] as f32));
        let tinted = render_it(&scene, mode, capture);
        let (mut worst_w, mut worst_c, mut compared) = (0.0f64, [0.0f64; 3], 0);
        let mut ratios = [0.0f64; 3];
        for i in 0..(SIZE * SIZE) as usize {
            // Pixels whose ray meets the sphere away from its rim (the background is the sky).
            match sphere_hit(i as u32 % SIZE, i as u32 / SIZE, SIZE) {
                Some((n, d)) if n.dot(-d) >= 0.3 => {}
                _ => continue,
            }
            compared += 1;
            for c in 0..3 {
                let b = bare[i][c] as f64;
                worst_w = worst_w.max((weighed[i][c] as f64 - 0.4 * b).abs() / b);
                let ratio = (tinted[i][c] - zero[i][c]) as f64 / (b - zero[i][c] as f64);
                ratios[c] += ratio;
                worst_c[c] = f64::max(worst_c[c], (ratio - tint[c]).abs());
            }
        }
        let mean = ratios.map(|s| s / compared as f64);
        println!(
            "{mode:?} capture {capture}: {compared} pixels; weight worst rel {worst_w:.4}; tint ratios mean {mean:?} worst {worst_c:?}"
        );
        assert!(compared > 300, "{compared}");
        assert!(worst_w < 0.01, "{mode:?} {capture}: the weight's worst relative error {worst_w}");
        // The spectral modes tint by the colour's upsampled spectrum, whose RGB under a flat
        // light is the colour to the table's accuracy.
        let tol = if mode == Mode::Rgb { 0.05 } else { 0.1 };
        for c in 0..3 {
            assert!(
                (mean[c] - tint[c]).abs() < tol,
                "{mode:?} {capture}: channel {c} ratio {} want {}",
                mean[c],
                tint[c]
            );
        }
    }
}
