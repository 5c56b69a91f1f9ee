//! KHR_materials_sheen in real time against the extension computed here on the CPU in f64 with
//! scene::sheen's functions (the path tracer's): f = sheenColor·D·V + f_base·s, s = min(1 −
//! c·E(n·v), 1 − c·E(n·l)), in the RGB and spectral modes and through the general node loop
//! (the spectral capture); factors and textures; and in a uniform environment, where a white
//! sheen over a black sphere adds its directional albedo E(n·v) to what the base keeps.

mod common;

use common::*;
use glam::{Vec3, Vec4};
use render::{Mode, RenderSettings};
use scene::sheen::Sheen;
use scene::{Environment, TextureRef};

const W: u32 = 48;
const H: u32 = 32;

/// Radiance per unit irradiance of a dielectric of albedo `rho` (roughness 0.5) under a sheen
/// of colour `sheen` and roughness `r`, lit from `wi`, seen from `v` (normal +z).
fn sheened(v: Vec3, wi: Vec3, rho: [f64; 3], sheen: [f64; 3], r: f64) -> [f64; 3] {
    let n = Vec3::Z;
    let (a, b) = brdf_factors(n, v, wi, 0.0, 0.5);
    let nl = n.dot(wi) as f64;
    let nv = (n.dot(v) as f64).max(1e-4);
    let nh = n.dot((wi + v).normalize()) as f64;
    let c = sheen[0].max(sheen[1]).max(sheen[2]);
    let s = scene::sheen::albedo_scaling(c, scene::sheen::albedo(nv, r), scene::sheen::albedo(nl, r));
    let dv = scene::sheen::brdf(nl, nv, nh, r);
    std::array::from_fn(|k| (rho[k] * a + b) * s + sheen[k] * dv * nl)
}

/// A test case: its name, the base albedo, the sheen, and its colour and roughness at the pixels.
type Case = (&'static str, [f64; 3], Sheen, [f64; 3], f64);

/// A patch under a directional light at grazing incidence (where the sheen lives), seen at a
/// grazing angle too, with the sheen as factors (a saturated orange at roughness 0.8; a white
/// one at the clamped 0.2; over a dark base) and as textures (colour in sRGB, roughness in A).
#[test]
fn the_sheen_follows_the_extension_under_a_directional_light() {
    let chart = Chart { colours: vec![[1.0, 1.0, 1.0]], cols: 1, rows: 1, gap: 0.0 };
    let wi = Vec3::new(-0.9, 0.0, 0.25).normalize();
    let tex = |i| Some(TextureRef { transform: None, index: i, tex_coord: 0 });
    let colour_texel = [255u8, 120, 200, 255];
    let rough_texel = [255u8, 255, 255, 170];
    let cases: Vec<Case> = vec![
        (
            "orange",
            [0.1, 0.2, 0.4],
            Sheen {
                color: Vec3::new(1.0, 0.3, 0.1),
                color_texture: None,
                roughness: 0.8,
                roughness_texture: None,
            },
            [1.0, 0.3, 0.1],
            0.8,
        ),
        (
            "white-sharp",
            [0.05, 0.05, 0.05],
            Sheen { color: Vec3::ONE, color_texture: None, roughness: 0.2, roughness_texture: None },
            [1.0; 3],
            0.2,
        ),
        (
            "textures",
            [0.3, 0.3, 0.1],
            Sheen {
                color: Vec3::new(0.9, 0.9, 0.9),
                color_texture: tex(0),
                roughness: 0.9,
                roughness_texture: tex(1),
            },
            colour_texel.map(|c| 0.9 * decode8(c))[..3].try_into().unwrap(),
            0.9 * 170.0 / 255.0,
        ),
    ];
    let mut r = renderer();
    for (name, rho, sheen, colour, roughness) in cases {
        let mut scene = chart.scene(white_light(2.0, None), 0.5, 0.0);
        scene.lights[0].kind = scene::LightKind::Directional { direction: -wi };
        scene.textures =
            vec![texel_texture("colour", colour_texel, true), texel_texture("roughness", rough_texel, false)];
        let m = &mut scene.materials[0];
        m.base_color = Vec4::new(rho[0] as f32, rho[1] as f32, rho[2] as f32, 1.0);
        m.sheen = Some(sheen);
        let mut expected = Vec::new();
        let mut effect = Vec::new();
        for y in 0..H {
            for x in 0..W {
                let (p, d) = pixel_to_chart(x, y, W, H);
                expected.push(chart.patch_at(p, 0.05).map(|_| {
                    let want = sheened(-d, wi, rho, colour, roughness).map(|l| l * 2.0);
                    let plain = sheened(-d, wi, rho, [0.0; 3], roughness).map(|l| l * 2.0);
                    effect.push(color::ciede2000(lab(want), lab(plain)));
                    want
                }));
            }
        }
        let effect = effect.iter().sum::<f64>() / effect.len() as f64;
        assert!(effect > 1.0, "{name}: the sheen changes the image by ΔE2000 {effect} only");
        for (mode, n, capture) in
            [(Mode::Rgb, 16, false), (Mode::Spectral, 16, false), (Mode::Spectral, 16, true)]
        {
            let s = RenderSettings { mode, wavelengths: n, shadows: false, ..Default::default() };
            let actual: Vec<[f64; 3]> =
                render_frame_wh(&mut r, &scene, (W, H), &s, capture).iter().map(rgb_of).collect();
            let label = format!("sheen-{name}-{mode:?}-{n}-{capture}");
            let c = (H / 2 * W + W / 2) as usize;
            println!(
                "{label}: centre {:?} expected {:?}; the sheen's own ΔE2000 {effect:.2}",
                actual[c], expected[c]
            );
            assert_delta_e(&label, W, H, &actual, &expected, 0.15, 0.4);
        }
    }
}

/// A black sphere under a white sheen in a uniform environment of radiance 1: what the base
/// keeps, (1 − E(n·v))·B with B the bare sphere's, plus E(n·v) — so (sheened − B)/(1 − B) is
/// the sheen's directional albedo at each pixel, in every mode.
#[test]
fn in_the_furnace_a_white_sheen_reflects_its_albedo() {
    const SIZE: u32 = 40;
    let material =
        scene::Material { base_color: Vec4::new(0.0, 0.0, 0.0, 1.0), roughness: 0.6, ..Default::default() };
    let mut scene = sphere_scene(material, Environment::uniform(Vec3::ONE), 64);
    let mut r = renderer();
    for roughness in [0.5f32, 1.0] {
        for (mode, capture) in [(Mode::Rgb, false), (Mode::Spectral, false), (Mode::Spectral, true)] {
            let s = RenderSettings { mode, wavelengths: 8, shadows: false, ..Default::default() };
            scene.materials[0].sheen = None;
            let bare = render_frame(&mut r, &scene, SIZE, &s, capture);
            scene.materials[0].sheen =
                Some(Sheen { color: Vec3::ONE, color_texture: None, roughness, roughness_texture: None });
            let sheened = render_frame(&mut r, &scene, SIZE, &s, capture);
            let (mut worst, mut sum, mut compared) = (0.0f64, 0.0, 0);
            for i in 0..(SIZE * SIZE) as usize {
                let (n, d) = match sphere_hit(i as u32 % SIZE, i as u32 / SIZE, SIZE) {
                    Some((n, d)) if n.dot(-d) >= 0.2 => (n, d),
                    _ => continue,
                };
                let e = scene::sheen::albedo(n.dot(-d) as f64, roughness as f64);
                for c in 0..3 {
                    let b = bare[i][c] as f64;
                    let got = (sheened[i][c] as f64 - b) / (1.0 - b);
                    worst = worst.max((got - e).abs());
                    sum += (got - e).abs();
                    compared += 1;
                }
            }
            let mean = sum / compared as f64;
            println!(
                "roughness {roughness} {mode:?} capture {capture}: {compared} values; |E − want| mean {mean:.5} worst {worst:.5}"
            );
            assert!(compared > 900, "{compared}");
            assert!(mean < 0.002 && worst < 0.01, "{mode:?} {capture}: mean {mean} worst {worst}");
        }
    }
}

/// A sheen on a see-through material has no room in the transmissive layer's G-buffer: the
/// upload says it is not drawn, naming the material, and the frame is the one without it.
#[test]
fn a_see_through_sheen_is_reported_and_left_out() {
    let chart = Chart { colours: vec![[0.5, 0.4, 0.3]], cols: 1, rows: 1, gap: 0.0 };
    let mut plain = chart.scene(white_light(2.0, None), 0.7, 0.0);
    plain.materials[0].name = "tulle".into();
    plain.materials[0].transmission =
        Some(scene::transmission::Transmission { factor: 0.5, texture: None, volume: None, dispersion: 0.0 });
    let mut sheened = plain.clone();
    sheened.materials[0].sheen = Some(Sheen {
        color: Vec3::new(1.0, 0.3, 0.1),
        color_texture: None,
        roughness: 0.8,
        roughness_texture: None,
    });
    let mut r = renderer();
    let s = RenderSettings { mode: Mode::Spectral, shadows: false, ..Default::default() };
    let without = render_frame_wh(&mut r, &plain, (W, H), &s, false);
    assert!(r.scene_warnings().is_empty(), "{:?}", r.scene_warnings());
    let with = render_frame_wh(&mut r, &sheened, (W, H), &s, false);
    let w = r.scene_warnings();
    assert!(w.len() == 1 && w[0].contains("KHR_materials_sheen") && w[0].contains("'tulle'"), "{w:?}");
    assert!(with == without);
}
