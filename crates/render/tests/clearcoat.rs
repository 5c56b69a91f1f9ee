//! KHR_materials_clearcoat in real time against the extension's layering computed here on the
//! CPU (f64): coated = (1 − w)·material + w·coat lobe, w = strength·F(|v·n_c|) with Schlick's
//! F0 = 0.04, the coat lobe GGX D·V about the coat's own normal (its normal map, or the
//! geometric normal — not the base's normal map), in the RGB and spectral modes and through the
//! general node loop (the spectral capture).

mod common;

use common::*;
use glam::{Vec3, Vec4};
use render::{Mode, RenderSettings};
use scene::clearcoat::Clearcoat;
use scene::{Environment, Texture, TextureRef};

const W: u32 = 48;
const H: u32 = 32;

/// The coat's weight: strength × Schlick's Fresnel with F0 0.04 at |v·n_c|.
fn weight(strength: f64, n_c: Vec3, v: Vec3) -> f64 {
    let m = 1.0 - (n_c.dot(v) as f64).abs().min(1.0);
    strength * (0.04 + 0.96 * m.powi(5))
}

/// The coat lobe without its Fresnel term, × n·l: GGX D and height-correlated Smith V at
/// α = roughness² (the renderer's floor 1e-3 included).
fn coat_lobe(n: Vec3, v: Vec3, wi: Vec3, roughness: f64) -> f64 {
    let nl = n.dot(wi) as f64;
    if nl <= 0.0 {
        return 0.0;
    }
    let h = (wi + v).normalize();
    let nv = (n.dot(v) as f64).max(1e-4);
    let nh = (n.dot(h) as f64).max(0.0);
    let a2 = (roughness * roughness).max(1e-3).powi(2);
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (std::f64::consts::PI * dd * dd);
    let vis = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    nl * d * vis
}

fn coat(strength: f32, roughness: f32, normal_texture: Option<TextureRef>) -> Option<Clearcoat> {
    Some(Clearcoat {
        factor: strength,
        texture: None,
        roughness,
        roughness_texture: None,
        normal_texture,
        normal_scale: 1.0,
    })
}

/// A patch whose base is normal-mapped 45° towards +x, under a directional light: with the
/// coat's own normal map (the same tilt) or without one (the coat follows the quad).
#[test]
fn a_coat_reflects_about_its_own_normal_and_keeps_one_minus_its_weight_of_the_base() {
    let chart = Chart { colours: vec![[1.0, 1.0, 1.0]], cols: 1, rows: 1, gap: 0.0 };
    let tilt = [218u8, 128, 218, 255];
    let base = [120u8, 60, 30, 255];
    let tn = Vec3::new(
        tilt[0] as f32 / 255.0 * 2.0 - 1.0,
        tilt[1] as f32 / 255.0 * 2.0 - 1.0,
        tilt[2] as f32 / 255.0 * 2.0 - 1.0,
    )
    .normalize();
    let albedo = [decode8(base[0]), decode8(base[1]), decode8(base[2])];
    let normal_map = TextureRef { transform: None, index: 1, tex_coord: 0 };
    // The light lies near the coat's mirror direction: about the quad's normal, or about the
    // tilted one where the coat has the normal map.
    let near = Vec3::new(0.4, 0.0, 1.0).normalize();
    let tilted = Vec3::new(1.0, 0.0, 0.25).normalize();
    let nearer = Vec3::new(0.12, 0.0, 1.0).normalize();
    for (strength, roughness, coat_map, wi) in
        [(1.0, 0.3, None, near), (0.8, 0.35, Some(normal_map), tilted), (1.0, 0.15, None, nearer)]
    {
        let mut scene = chart.scene(white_light(2.0, None), 0.7, 0.0);
        scene.lights[0].kind = scene::LightKind::Directional { direction: -wi };
        scene.textures = vec![
            Texture {
                sampler: Default::default(),
                name: "base".into(),
                width: 1,
                height: 1,
                rgba8: base.to_vec(),
                srgb: true,
            },
            Texture {
                sampler: Default::default(),
                name: "normal".into(),
                width: 1,
                height: 1,
                rgba8: tilt.to_vec(),
                srgb: false,
            },
        ];
        let m = &mut scene.materials[0];
        m.base_color_texture = Some(TextureRef { transform: None, index: 0, tex_coord: 0 });
        m.normal_texture = Some(normal_map);
        m.clearcoat = coat(strength, roughness, coat_map);
        let n_c = if coat_map.is_some() { tn } else { Vec3::Z };
        let mut expected = Vec::new();
        let mut coat_de = Vec::new();
        for y in 0..H {
            for x in 0..W {
                let (p, d) = pixel_to_chart(x, y, W, H);
                let v = -d;
                expected.push(chart.patch_at(p, 0.05).map(|_| {
                    let (a, b) = brdf_factors(tn, v, wi, 0.0, 0.7);
                    let w = weight(strength as f64, n_c, v);
                    let c = coat_lobe(n_c, v, wi, roughness as f64);
                    let base = albedo.map(|r| (r * a + b) * 2.0);
                    let coated = base.map(|l| l * (1.0 - w) + w * c * 2.0);
                    coat_de.push(color::ciede2000(lab(coated), lab(base)));
                    coated
                }));
            }
        }
        // The coat must change the image by far more than the tolerance, or the test proves
        // nothing.
        let coat_effect = coat_de.iter().sum::<f64>() / coat_de.len() as f64;
        assert!(coat_effect > 1.0, "the coat changes the image by ΔE2000 {coat_effect} only");
        let mut r = renderer();
        r.set_scene(&scene).unwrap();
        r.resize(W, H).unwrap();
        for (mode, n, capture) in
            [(Mode::Rgb, 16, false), (Mode::Spectral, 16, false), (Mode::Spectral, 8, true)]
        {
            let s = RenderSettings { mode, wavelengths: n, shadows: false, ..Default::default() };
            r.set_spectral_capture(capture);
            r.render(&scene.camera, &s).unwrap();
            let actual: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
            let name =
                format!("clearcoat-{strength}-{roughness}-{}-{mode:?}-{n}-{capture}", coat_map.is_some());
            let c = (H / 2 * W + W / 2) as usize;
            println!(
                "{name}: centre actual {:?} expected {:?}, the coat's own ΔE2000 {coat_effect:.2}",
                actual[c], expected[c]
            );
            assert_delta_e(&name, W, H, &actual, &expected, 0.15, 0.4);
        }
    }
}

/// A black dielectric sphere in a uniform environment of radiance 1: uncoated it shows only
/// its own specular; a smooth coat of strength s adds w = s·F(|v·n|) of the sky and keeps 1 − w
/// of the rest, so coated = (1 − w)·uncoated + w·A, with A the split sum's albedo of a mirror
/// lobe (1 up to the table's error). The sphere's normal at each pixel comes from the ray.
#[test]
fn a_coat_in_the_furnace_weighs_sky_and_base_by_its_fresnel_term() {
    const SIZE: u32 = 48;
    let material =
        scene::Material { base_color: Vec4::new(0.0, 0.0, 0.0, 1.0), roughness: 0.5, ..Default::default() };
    let mut scene = sphere_scene(material, Environment::uniform(Vec3::ONE), 96);
    let mut r = renderer();
    let mut render_it = |scene: &scene::Scene, mode: Mode, capture: bool| {
        let s = RenderSettings { mode, wavelengths: 8, shadows: false, ..Default::default() };
        render_frame(&mut r, scene, SIZE, &s, capture)
    };
    for strength in [1.0f32, 0.5] {
        for (mode, capture) in [(Mode::Rgb, false), (Mode::Spectral, false), (Mode::Spectral, true)] {
            scene.materials[0].clearcoat = None;
            let bare = render_it(&scene, mode, capture);
            scene.materials[0].clearcoat = coat(strength, 0.0, None);
            let coated = render_it(&scene, mode, capture);
            let mut worst = 0.0f64;
            let mut compared = 0;
            let mut largest_w = 0.0f64;
            for y in 0..SIZE {
                for x in 0..SIZE {
                    // Pixels whose ray passes near the rim are left out (the mesh's silhouette
                    // is not the sphere's).
                    let Some((n, d)) = sphere_hit(x, y, SIZE) else { continue };
                    let cos = n.dot(-d) as f64;
                    if cos < 0.25 {
                        continue;
                    }
                    let w = weight(strength as f64, n, -d);
                    largest_w = largest_w.max(w);
                    let i = (y * SIZE + x) as usize;
                    for c in 0..3 {
                        let want = (1.0 - w) * bare[i][c] as f64 + w;
                        worst = worst.max((coated[i][c] as f64 - want).abs());
                    }
                    compared += 1;
                }
            }
            println!(
                "{mode:?} capture {capture} strength {strength}: {compared} pixels, worst {worst:.5}, largest w {largest_w:.3}"
            );
            assert!(compared > 500, "{compared}");
            // The coat must move the image by far more than the tolerance.
            assert!(largest_w > 0.1, "{largest_w}");
            assert!(worst < 0.006, "{mode:?} capture {capture} strength {strength}: worst {worst}");
        }
    }
}
