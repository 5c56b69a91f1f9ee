//! KHR_materials_diffuse_transmission in real time against the extension computed here on the CPU
//! in f64: a sheet lit from behind passes t·colour/π·|n·l|·E·(1 − F(v·h')) to the viewer (h' the
//! half vector of v and the light mirrored through the sheet, the dielectric's weighting of its
//! diffuse), and a sheet lit from the front keeps 1 − t of its reflected diffuse — in the RGB and
//! spectral modes and through the general node loop (the spectral capture), with factors and
//! textures, with shadows (the sheet does not shadow the light that crosses it; a blocker behind
//! it does), in both shading stages, and under an environment that only lights the far side.

mod common;

use common::*;
use glam::{Vec2, Vec3, Vec4};
use render::{Mode, RenderSettings, ShadingStage};
use scene::diffuse_transmission::DiffuseTransmission;
use scene::{Environment, Mesh, Scene, TextureRef};
use std::f64::consts::PI;

const W: u32 = 40;
const H: u32 = 32;
const E: f64 = 2.0;

/// The sheet: the unit patch at z = 0 facing +z, double-sided, seen head-on by the orthographic
/// camera (v = +z), under one directional light of `E` lux arriving along `wi` (towards the
/// light).
fn sheet(wi: Vec3, rho: [f32; 3], dt: Option<DiffuseTransmission>) -> Scene {
    let chart = Chart { colours: vec![rho], cols: 1, rows: 1, gap: 0.0 };
    let mut scene = chart.scene(white_light(E as f32, None), 0.5, 0.0);
    scene.camera = front_ortho_camera();
    scene.lights[0].kind = scene::LightKind::Directional { direction: -wi };
    let m = &mut scene.materials[0];
    m.double_sided = true;
    m.diffuse_transmission = dt;
    scene
}

/// World (x, y) of pixel (px, py) under `front_ortho_camera`.
fn pixel_xy(px: u32, py: u32) -> Vec2 {
    Vec2::new((px as f32 + 0.5) / W as f32 * 2.0 - 1.0, 0.8 - (py as f32 + 0.5) / H as f32 * 1.6)
}

/// The sheet's pixels (0.05 inside its edges) with `f` of their world position.
fn on_sheet(f: impl Fn(Vec2) -> Option<[f64; 3]>) -> Vec<Option<[f64; 3]>> {
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let p = pixel_xy(x, y);
            let inside = p.x.abs() <= 0.45 && p.y.abs() <= 0.45;
            out.push(if inside { f(p) } else { None });
        }
    }
    out
}

/// The transmitted radiance per unit colour: t·|n·l|·E·(1 − F(v·h'))/π, F Schlick's at F0 0.04,
/// n = v = +z, l = `wi` on the far side.
fn transmitted(wi: Vec3, t: f64) -> f64 {
    let wi = wi.as_dvec3();
    let nl = wi.z;
    assert!(nl < 0.0);
    let mirrored = glam::DVec3::new(wi.x, wi.y, -wi.z);
    let h = (mirrored + glam::DVec3::Z).normalize();
    let fres = (1.0 - h.z).powi(5);
    t * -nl * E * (1.0 - (0.04 + 0.96 * fres)) / PI
}

fn modes() -> [(Mode, usize, bool); 3] {
    [(Mode::Rgb, 16, false), (Mode::Spectral, 16, false), (Mode::Spectral, 16, true)]
}

fn render(
    r: &mut render::Renderer,
    scene: &Scene,
    mode: Mode,
    n: usize,
    capture: bool,
    shadows: bool,
) -> Vec<[f64; 3]> {
    let s = RenderSettings { mode, wavelengths: n, shadows, ..Default::default() };
    render_frame_wh(r, scene, (W, H), &s, capture).iter().map(rgb_of).collect()
}

fn dt(factor: f32, color: Vec3) -> DiffuseTransmission {
    DiffuseTransmission { factor, texture: None, color, color_texture: None }
}

/// Lit from behind and seen from the front, a sheet shows only its transmitted lobe (no
/// reflection: the light is on the other side), t·colour times `transmitted`; with shadows on,
/// the sheet does not shadow it.
#[test]
fn a_sheet_lit_from_behind_passes_its_transmitted_lobe() {
    let wi = Vec3::new(0.35, -0.2, -0.9).normalize();
    let colour = [0.9, 0.55, 0.2];
    let t = 0.7;
    let scene = sheet(wi, [0.2, 0.6, 0.3], Some(dt(t as f32, Vec3::from_array(colour.map(|c| c as f32)))));
    let expected = on_sheet(|_| Some(colour.map(|c| c * transmitted(wi, t))));
    let mut r = renderer();
    for shadows in [false, true] {
        for (mode, n, capture) in modes() {
            let actual = render(&mut r, &scene, mode, n, capture, shadows);
            let label = format!("dt-behind-{mode:?}-{n}-{capture}-shadows{shadows}");
            let c = (H / 2 * W + W / 2) as usize;
            println!("{label}: centre {:?} expected {:?}", actual[c], expected[c]);
            assert_delta_e(&label, W, H, &actual, &expected, 0.15, 0.4);
        }
    }
    // Without the extension the same sheet is black from the front.
    let plain = render(&mut r, &sheet(wi, [0.2, 0.6, 0.3], None), Mode::Rgb, 16, false, false);
    let c = (H / 2 * W + W / 2) as usize;
    assert_eq!(plain[c], [0.0; 3], "no light reaches the front without the extension");
}

/// The naive mode (box spectra, which do not give back an RGB colour) upsamples the colour as it
/// does a base colour: the sheet lit from behind shows t times what the same sheet without the
/// extension, of that base colour and lit from the mirrored direction, reflects in its diffuse
/// (its reflection less a black sheet's, the specular lobe; the half vector and the cosine are
/// the same).
#[test]
fn the_naive_mode_upsamples_the_colour_as_a_base_colour() {
    let wi = Vec3::new(0.35, -0.2, -0.9).normalize();
    let mirrored = Vec3::new(wi.x, wi.y, -wi.z);
    let colour = [0.9f32, 0.55, 0.2];
    let t = 0.7;
    let through = sheet(wi, [0.2, 0.6, 0.3], Some(dt(t, Vec3::from_array(colour))));
    let mut r = renderer();
    for capture in [false, true] {
        let a = render(&mut r, &through, Mode::Naive, 16, capture, false);
        let b = render(&mut r, &sheet(mirrored, colour, None), Mode::Naive, 16, capture, false);
        let b0 = render(&mut r, &sheet(mirrored, [0.0; 3], None), Mode::Naive, 16, capture, false);
        let inside = on_sheet(|_| Some([0.0; 3]));
        let c = (H / 2 * W + W / 2) as usize;
        let want: [f64; 3] = std::array::from_fn(|k| t as f64 * (b[c][k] - b0[c][k]));
        println!("dt-naive-{capture}: centre {:?}, t·(reflected − specular) {want:?}", a[c]);
        let mut worst = 0.0f64;
        for (i, e) in inside.iter().enumerate() {
            if e.is_some() {
                for k in 0..3 {
                    let w = t as f64 * (b[i][k] - b0[i][k]);
                    worst = worst.max((a[i][k] - w).abs() / w);
                }
            }
        }
        println!("dt-naive-{capture}: worst relative difference {worst:.2e}");
        // The images are half floats: three of them a few f16 steps (2⁻¹¹) apart at most.
        assert!(worst < 4e-3, "naive {capture}: {worst:.2e} from t times the base colour's diffuse");
        // And the box spectra are not the RGB colour: the test compares what the mode does.
        let rgb = colour.map(|x| x as f64 * transmitted(wi, t as f64));
        assert!(color::ciede2000(lab(a[c]), lab(rgb)) > 1.0);
    }
}

/// Lit from the front, the reflected diffuse keeps 1 − t; the specular lobe is untouched.
#[test]
fn a_sheet_lit_from_the_front_loses_the_transmitted_share_of_its_diffuse() {
    let wi = Vec3::new(0.3, 0.25, 0.9).normalize();
    let rho = [0.7, 0.4, 0.25];
    let t = 0.6;
    let scene = sheet(wi, rho.map(|c| c as f32), Some(dt(t as f32, Vec3::new(1.0, 0.2, 0.1))));
    let (a, b) = brdf_factors(Vec3::Z, Vec3::Z, wi, 0.0, 0.5);
    let expected = on_sheet(|_| Some(rho.map(|c| E * (c * a * (1.0 - t) + b))));
    let whole = on_sheet(|_| Some(rho.map(|c| E * (c * a + b))));
    let effect = color::ciede2000(
        lab(expected[(H / 2 * W + W / 2) as usize].unwrap()),
        lab(whole[(H / 2 * W + W / 2) as usize].unwrap()),
    );
    assert!(effect > 5.0, "the share changes the image by ΔE2000 {effect} only");
    let mut r = renderer();
    for (mode, n, capture) in modes() {
        let actual = render(&mut r, &scene, mode, n, capture, true);
        assert_delta_e(&format!("dt-front-{mode:?}-{n}-{capture}"), W, H, &actual, &expected, 0.15, 0.4);
    }
}

/// The factor × the factor texture's A (linear) and the colour × the colour texture's RGB
/// (sRGB), as two textures and as one (the extension's packing).
#[test]
fn textures_scale_the_factor_and_the_colour() {
    let wi = Vec3::new(-0.3, 0.2, -0.9).normalize();
    let tex = |i| Some(TextureRef { transform: None, index: i, tex_coord: 0 });
    let colour_texel = [230u8, 140, 60, 255];
    let factor_texel = [10u8, 250, 90, 150];
    let packed_texel = [230u8, 140, 60, 150];
    let colour = [decode8(230), decode8(140), decode8(60)].map(|c| 0.8 * c);
    let t = 0.9 * 150.0 / 255.0;
    let mut r = renderer();
    for packed in [false, true] {
        let mut d = dt(0.9, Vec3::splat(0.8));
        if packed {
            d.texture = tex(0);
            d.color_texture = tex(0);
        } else {
            d.texture = tex(1);
            d.color_texture = tex(0);
        }
        let mut scene = sheet(wi, [0.5, 0.5, 0.5], Some(d));
        scene.textures = if packed {
            vec![texel_texture("packed", packed_texel, true)]
        } else {
            vec![texel_texture("colour", colour_texel, true), texel_texture("factor", factor_texel, false)]
        };
        let expected = on_sheet(|_| Some(colour.map(|c| c * transmitted(wi, t))));
        for (mode, n, capture) in modes() {
            let actual = render(&mut r, &scene, mode, n, capture, false);
            assert_delta_e(
                &format!("dt-textures-packed{packed}-{mode:?}-{n}-{capture}"),
                W,
                H,
                &actual,
                &expected,
                0.15,
                0.4,
            );
        }
    }
}

/// A factor of 0 is no extension: the same bits, with the scene's other materials transmitting
/// (the shader compiled with it, the share 0 at the pixel) or with none (not compiled).
#[test]
fn a_zero_factor_draws_the_same_bits_as_no_extension() {
    let wi = Vec3::new(0.3, 0.25, 0.9).normalize();
    let mut r = renderer();
    let env = Environment::uniform(Vec3::new(0.3, 0.35, 0.4));
    for (mode, n, capture) in modes() {
        let mut plain = sheet(wi, [0.6, 0.3, 0.2], None);
        plain.environment = Some(env.clone());
        let none = render(&mut r, &plain, mode, n, capture, true);
        let mut zero = plain.clone();
        zero.materials[0].diffuse_transmission = Some(dt(0.0, Vec3::ONE));
        assert_eq!(render(&mut r, &zero, mode, n, capture, true), none, "{mode:?} factor 0");
        // A texture's A of 0 on a material of factor 1, beside a transmitting one out of view.
        let mut textured = plain.clone();
        textured.textures = vec![texel_texture("zero", [255, 255, 255, 0], false)];
        let mut d = dt(1.0, Vec3::ONE);
        d.texture = Some(TextureRef { transform: None, index: 0, tex_coord: 0 });
        textured.materials[0].diffuse_transmission = Some(d);
        let mut other = textured.materials[0].clone();
        other.diffuse_transmission = Some(dt(0.5, Vec3::ONE));
        textured.materials.push(other);
        let mut far = textured.meshes[0].clone();
        far.positions.iter_mut().for_each(|p| p.x += 10.0);
        far.material = 1;
        textured.meshes.push(far);
        let got = render(&mut r, &textured, mode, n, capture, true);
        let differ = got.iter().zip(&none).filter(|(a, b)| a != b).count();
        println!("{mode:?} {capture}: texture A = 0 in a transmitting scene: {differ} pixels differ");
        assert_eq!(differ, 0, "{mode:?} {capture}: a zero share in a scene that compiles the extension");
    }
}

/// A blocker between the light and the sheet shadows the transmitted light where it covers the
/// sheet, and nowhere else.
#[test]
fn a_blocker_behind_the_sheet_shadows_the_transmitted_light() {
    let wi = Vec3::new(0.0, 0.0, -1.0);
    let colour = [0.8, 0.8, 0.8];
    let t = 1.0;
    let mut scene = sheet(wi, [0.5, 0.5, 0.5], Some(dt(t as f32, Vec3::splat(0.8))));
    // Covers x < 0 behind the sheet.
    let blocker = Mesh {
        colors: vec![],
        uvs1: vec![],
        positions: [(-2.0, -2.0), (0.0, -2.0), (0.0, 2.0), (-2.0, 2.0)]
            .map(|(x, y)| Vec3::new(x, y, -0.5))
            .to_vec(),
        normals: vec![Vec3::NEG_Z; 4],
        tangents: vec![],
        uvs: vec![Vec2::ZERO; 4],
        indices: vec![0, 2, 1, 0, 3, 2],
        material: 1,
    };
    scene.meshes.push(blocker);
    let mut black = scene.materials[0].clone();
    black.diffuse_transmission = None;
    black.base_color = Vec4::new(0.0, 0.0, 0.0, 1.0);
    scene.materials.push(black);
    let lit = colour.map(|c| c * transmitted(wi, t));
    let expected = on_sheet(|p| (p.x.abs() > 0.1).then_some(if p.x < 0.0 { [0.0; 3] } else { lit }));
    let mut r = renderer();
    for (mode, n, capture) in modes() {
        let actual = render(&mut r, &scene, mode, n, capture, true);
        let shadowed: Vec<f64> = actual
            .iter()
            .zip(&expected)
            .filter(|(_, e)| e.is_some_and(|e| e == [0.0; 3]))
            .map(|(a, _)| a[0].max(a[1]).max(a[2]))
            .collect();
        let worst = shadowed.iter().copied().fold(0.0, f64::max);
        println!("dt-blocker-{mode:?}-{capture}: brightest shadowed pixel {worst:.2e} (lit {:.4})", lit[0]);
        assert!(!shadowed.is_empty() && worst < 1e-3 * lit[0], "{mode:?}: the blocker lets {worst} through");
        let lit_side: Vec<Option<[f64; 3]>> = expected.iter().map(|e| e.filter(|e| *e != [0.0; 3])).collect();
        assert_delta_e(&format!("dt-blocker-{mode:?}-{n}-{capture}"), W, H, &actual, &lit_side, 0.15, 0.4);
    }
}

/// An environment of radiance L on the far hemisphere (z < 0) and none on the near one: the
/// sheet shows t·colour·(1 − F̄(n·v))·L, F̄ the cosine-weighted mean of Schlick's term (f64
/// quadrature here), its reflection nothing.
#[test]
fn an_environment_behind_the_sheet_shines_through_it() {
    let (w, h) = (64u32, 32u32);
    let l_far = 0.8f32;
    let mut texels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            // Columns 16..48 are the directions with z < 0 (`Environment::direction`).
            let _ = y;
            texels.push(if (16..48).contains(&x) { Vec3::splat(l_far) } else { Vec3::ZERO });
        }
    }
    let env = Environment::from_rgb("far side", w, h, texels).unwrap();
    let colour = [0.9, 0.6, 0.3];
    let t = 0.8;
    let mut scene =
        sheet(Vec3::Z, [0.3, 0.3, 0.3], Some(dt(t as f32, Vec3::from_array(colour.map(|c| c as f32)))));
    scene.lights.clear();
    scene.environment = Some(env);
    // F̄ at n·v = 1: ∫ F(v·h) cos θ dω / π over the hemisphere, midpoint rule in θ (φ-independent).
    let steps = 20000;
    let mut mean = 0.0;
    for i in 0..steps {
        let theta = (i as f64 + 0.5) / steps as f64 * PI / 2.0;
        let vh = (theta / 2.0).cos();
        let f = 0.04 + 0.96 * (1.0 - vh).powi(5);
        mean += f * theta.cos() * theta.sin() * 2.0 * (PI / 2.0 / steps as f64);
    }
    let expected = on_sheet(|_| Some(colour.map(|c| t * c * (1.0 - mean) * l_far as f64)));
    let mut r = renderer();
    for (mode, n, capture) in modes() {
        let actual = render(&mut r, &scene, mode, n, capture, false);
        let c = (H / 2 * W + W / 2) as usize;
        println!(
            "dt-env-{mode:?}-{capture}: centre {:?} expected {:?} (F̄ {mean:.5})",
            actual[c], expected[c]
        );
        assert_delta_e(&format!("dt-env-{mode:?}-{n}-{capture}"), W, H, &actual, &expected, 0.3, 0.6);
    }
}

/// An emissive polygon behind the sheet (radiance 1, the square |x|, |y| ≤ 1.5 at z = −1,
/// facing the sheet): t·colour/π·∫ L·(1 − F(v·h'(l)))·cos θ dω over it, integrated here in f64
/// (the renderer takes the clipped cosine exactly and F at the polygon's centroid), with and
/// without shadows (the sheet does not shadow the light that crosses it).
#[test]
fn a_polygon_light_behind_the_sheet_shines_through_it() {
    let colour = [0.85, 0.7, 0.4];
    let t = 0.75;
    let mut scene =
        sheet(Vec3::Z, [0.4, 0.4, 0.4], Some(dt(t as f32, Vec3::from_array(colour.map(|c| c as f32)))));
    scene.lights.clear();
    let s = 1.5f32;
    let emitter = Mesh {
        colors: vec![],
        uvs1: vec![],
        positions: [(-s, -s), (s, -s), (s, s), (-s, s)].map(|(x, y)| Vec3::new(x, y, -1.0)).to_vec(),
        normals: vec![Vec3::Z; 4],
        tangents: vec![],
        uvs: vec![Vec2::ZERO; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        material: 1,
    };
    scene.meshes.push(emitter);
    scene.materials.push(scene::Material {
        name: "emitter".into(),
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        emissive: Vec3::ONE,
        ..Default::default()
    });
    // ∫ (1 − F(v·h')) cos θ_s cos θ_e / r² dA over the square, at the sheet's point p (z = 0):
    // both cosines are 1/r (the square is 1 below, parallel), so the integrand is (1 − F)/r⁴.
    let steps = 150;
    let irradiance = |p: Vec2| -> f64 {
        let (px, py) = (p.x as f64, p.y as f64);
        let da = (2.0 * s as f64 / steps as f64).powi(2);
        let mut sum = 0.0;
        for i in 0..steps {
            for j in 0..steps {
                let u = -(s as f64) + (i as f64 + 0.5) * 2.0 * s as f64 / steps as f64;
                let w = -(s as f64) + (j as f64 + 0.5) * 2.0 * s as f64 / steps as f64;
                let d = glam::DVec3::new(u - px, w - py, -1.0);
                let r2 = d.length_squared();
                let mirrored = glam::DVec3::new(d.x, d.y, 1.0) / r2.sqrt();
                let h = (mirrored + glam::DVec3::Z).normalize();
                let f = 0.04 + 0.96 * (1.0 - h.z).powi(5);
                sum += (1.0 - f) / (r2 * r2) * da;
            }
        }
        sum
    };
    let expected = on_sheet(|p| {
        let e = irradiance(p);
        Some(colour.map(|c| t * c * e / PI))
    });
    let mut r = renderer();
    for shadows in [false, true] {
        for (mode, n, capture) in modes() {
            let actual = render(&mut r, &scene, mode, n, capture, shadows);
            let c = (H / 2 * W + W / 2) as usize;
            println!(
                "dt-polygon-{mode:?}-{capture}-shadows{shadows}: centre {:?} expected {:?}",
                actual[c], expected[c]
            );
            assert_delta_e(
                &format!("dt-polygon-{mode:?}-{n}-{capture}-shadows{shadows}"),
                W,
                H,
                &actual,
                &expected,
                0.3,
                0.6,
            );
        }
    }
}

/// The fragment and the compute stage shade a transmitting sheet alike (lavapipe: the same bits).
#[test]
fn both_shading_stages_agree() {
    let wi = Vec3::new(0.35, -0.2, -0.9).normalize();
    let mut scene = sheet(wi, [0.2, 0.6, 0.3], Some(dt(0.7, Vec3::new(0.9, 0.55, 0.2))));
    scene.environment = Some(Environment::uniform(Vec3::new(0.2, 0.25, 0.3)));
    let mut r = renderer();
    for (mode, n, capture) in modes() {
        let s = RenderSettings { mode, wavelengths: n, ..Default::default() };
        r.set_shading_stage(ShadingStage::Fragment).unwrap();
        let a = render_frame_wh(&mut r, &scene, (W, H), &s, capture);
        r.set_shading_stage(ShadingStage::Compute).unwrap();
        let b = render_frame_wh(&mut r, &scene, (W, H), &s, capture);
        let worst = a
            .iter()
            .flatten()
            .zip(b.iter().flatten())
            .map(|(x, y)| (x - y).abs() / x.abs().max(y.abs()).max(1e-3))
            .fold(0.0f32, f32::max);
        println!("dt-stages-{mode:?}-{capture}: worst relative difference {worst:.2e}");
        assert!(worst <= 1.0 / 1024.0, "{mode:?} {capture}: the stages differ by {worst:.2e}");
        let c = (H / 2 * W + W / 2) as usize;
        assert!(a[c][0] > 0.0, "{mode:?}: the sheet is lit");
    }
}

/// Under a clear coat and a sheen the transmitted lobe is weighted as the reflected diffuse is:
/// × (1 − w_c) with w_c = strength·F_coat(n·v) (the coat reflects nothing of a light behind), ×
/// the sheen's albedo scaling min(1 − c·E(n·v), 1 − c·E(|n·l|)) at the mirrored direction (the
/// sheen's lobe, a reflection, takes nothing from behind either).
#[test]
fn a_coat_and_a_sheen_weigh_the_transmitted_lobe_as_the_diffuse() {
    let wi = Vec3::new(0.8, -0.2, -0.35).normalize();
    let colour = [0.9, 0.55, 0.2];
    let t = 0.7;
    let (strength, sheen_colour, sheen_roughness) = (0.8, [1.0, 0.9, 0.8], 1.0);
    let mut scene =
        sheet(wi, [0.2, 0.6, 0.3], Some(dt(t as f32, Vec3::from_array(colour.map(|c| c as f32)))));
    let m = &mut scene.materials[0];
    m.clearcoat = Some(scene::clearcoat::Clearcoat {
        factor: strength as f32,
        texture: None,
        roughness: 0.3,
        roughness_texture: None,
        normal_texture: None,
        normal_scale: 1.0,
    });
    m.sheen = Some(scene::sheen::Sheen {
        color: Vec3::from_array(sheen_colour.map(|c| c as f32)),
        color_texture: None,
        roughness: sheen_roughness as f32,
        roughness_texture: None,
    });
    // n = v = +z: the coat's Fresnel term at normal incidence is its F0.
    let coat_keeps = 1.0 - strength * 0.04;
    let max_c = sheen_colour.iter().copied().fold(0.0, f64::max);
    let sheen_keeps = scene::sheen::albedo_scaling(
        max_c,
        scene::sheen::albedo(1.0, sheen_roughness),
        scene::sheen::albedo(-wi.z as f64, sheen_roughness),
    );
    let expected = on_sheet(|_| Some(colour.map(|c| c * transmitted(wi, t) * coat_keeps * sheen_keeps)));
    println!("coat keeps {coat_keeps:.4}, sheen keeps {sheen_keeps:.4}");
    assert!(sheen_keeps < 0.9, "the sheen's scaling is {sheen_keeps}: the test would not see it");
    let mut r = renderer();
    for (mode, n, capture) in modes() {
        let actual = render(&mut r, &scene, mode, n, capture, true);
        assert_delta_e(&format!("dt-layers-{mode:?}-{n}-{capture}"), W, H, &actual, &expected, 0.15, 0.4);
    }
}

/// A diffuse transmission on a see-through material has no room in the transmissive layer's
/// G-buffer: the upload says it is not drawn, naming the material, and the frame is the one
/// without it.
#[test]
fn a_see_through_diffuse_transmission_is_reported_and_left_out() {
    let wi = Vec3::new(0.35, -0.2, -0.9).normalize();
    let mut plain = sheet(wi, [0.5, 0.4, 0.3], None);
    plain.materials[0].name = "frosted".into();
    plain.materials[0].transmission =
        Some(scene::transmission::Transmission { factor: 0.5, texture: None, volume: None, dispersion: 0.0 });
    let mut with_dt = plain.clone();
    with_dt.materials[0].diffuse_transmission = Some(dt(0.6, Vec3::ONE));
    let mut r = renderer();
    let s = RenderSettings { mode: Mode::Spectral, shadows: false, ..Default::default() };
    let without = render_frame_wh(&mut r, &plain, (W, H), &s, false);
    assert!(r.scene_warnings().is_empty(), "{:?}", r.scene_warnings());
    let with = render_frame_wh(&mut r, &with_dt, (W, H), &s, false);
    let w = r.scene_warnings();
    assert!(
        w.len() == 1 && w[0].contains("KHR_materials_diffuse_transmission") && w[0].contains("'frosted'"),
        "{w:?}"
    );
    assert!(with == without);
}

/// Beside an anisotropy's texture (at the transmission's slot) the factor's texture has a slot
/// only when it is the colour's too (the extension's packing): then it is drawn (the sheet lit
/// from behind shows no specular, so the anisotropy leaves it as it was); a factor texture of its
/// own is reported by name and left out (the factor alone).
#[test]
fn beside_an_anisotropy_texture_the_factor_texture_needs_the_packing() {
    let wi = Vec3::new(-0.3, 0.2, -0.9).normalize();
    let tex = |i| Some(TextureRef { transform: None, index: i, tex_coord: 0 });
    let mut scene = sheet(wi, [0.5, 0.5, 0.5], None);
    scene.materials[0].name = "leaf".into();
    scene.materials[0].anisotropy =
        Some(scene::anisotropy::Anisotropy { strength: 0.8, rotation: 0.3, texture: tex(0) });
    scene.textures = vec![
        texel_texture("direction", [200, 128, 255, 255], false),
        texel_texture("packed", [230, 140, 60, 150], true),
        texel_texture("factor", [255, 255, 255, 60], false),
    ];
    let colour = [decode8(230), decode8(140), decode8(60)].map(|c| 0.8 * c);
    let mut r = renderer();
    let s = RenderSettings { mode: Mode::Spectral, shadows: false, ..Default::default() };
    // Packed: drawn, no warning.
    let mut packed = scene.clone();
    packed.materials[0].diffuse_transmission = Some(DiffuseTransmission {
        factor: 0.9,
        texture: tex(1),
        color: Vec3::splat(0.8),
        color_texture: tex(1),
    });
    let actual: Vec<[f64; 3]> =
        render_frame_wh(&mut r, &packed, (W, H), &s, false).iter().map(rgb_of).collect();
    assert!(r.scene_warnings().is_empty(), "{:?}", r.scene_warnings());
    let t = 0.9 * 150.0 / 255.0;
    let expected = on_sheet(|_| Some(colour.map(|c| c * transmitted(wi, t))));
    assert_delta_e("dt-aniso-packed", W, H, &actual, &expected, 0.15, 0.4);
    // A factor texture of its own: reported, drawn with the factor alone.
    let mut own = scene.clone();
    own.materials[0].diffuse_transmission = Some(DiffuseTransmission {
        factor: 0.9,
        texture: tex(2),
        color: Vec3::splat(0.8),
        color_texture: tex(1),
    });
    let with_texture = render_frame_wh(&mut r, &own, (W, H), &s, false);
    let w = r.scene_warnings();
    assert!(w.len() == 1 && w[0].contains("diffuseTransmissionTexture") && w[0].contains("'leaf'"), "{w:?}");
    own.materials[0].diffuse_transmission.as_mut().unwrap().texture = None;
    assert!(render_frame_wh(&mut r, &own, (W, H), &s, false) == with_texture);
}
