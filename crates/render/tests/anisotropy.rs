//! KHR_materials_anisotropy in real time against the extension computed here on the CPU in f64
//! with scene::anisotropy's functions (the path tracer's): a metal sphere whose specular lobe is
//! stretched along its tangents, under a directional light, in the RGB and spectral modes and
//! through the general node loop (the spectral capture); the direction's rotation and texture
//! (a quarter turn is the bitangent's direction, and the highlight is long along it); strength 0
//! draws the bits of no extension; both shading stages draw the same frame; the environment's
//! stand-in lobe and its energy; a see-through material's anisotropy is reported and left out.

mod common;

use common::*;
use glam::{DVec3, Vec2, Vec3, Vec4};
use render::{Mode, RenderSettings, Renderer, ShadingStage};
use scene::anisotropy::Anisotropy;
use scene::{Environment, Light, LightKind, Material, Scene, TextureRef};

const SIZE: u32 = 64;
const RINGS: u32 = 96;

/// The unit sphere's tangent at normal `n`: along its parallels, dp/dφ of [`sphere`]'s
/// parametrisation (handedness +1).
fn sphere_tangent(n: Vec3) -> Vec4 {
    Vec3::new(-n.z, 0.0, n.x).normalize_or(Vec3::X).extend(1.0)
}

/// [`sphere_scene`] with tangents on its sphere, lit by a white directional light of
/// irradiance 2 from `wi` (towards the light), no environment.
fn lit_sphere(material: Material, wi: Vec3) -> Scene {
    let mut scene = sphere_scene(material, Environment::uniform(Vec3::ONE), RINGS);
    scene.environment = None;
    let mesh = &mut scene.meshes[0];
    mesh.tangents = mesh.normals.iter().map(|&n| sphere_tangent(n)).collect();
    scene.lights = vec![Light {
        name: "sun".into(),
        kind: LightKind::Directional { direction: -wi },
        emission: white_light(2.0, None),
        stands_in_for: None,
    }];
    scene
}

fn metal(colour: [f32; 3], roughness: f32, anisotropy: Option<Anisotropy>) -> Material {
    Material {
        name: "brushed".into(),
        base_color: Vec4::new(colour[0], colour[1], colour[2], 1.0),
        metallic: 1.0,
        roughness,
        anisotropy,
        ..Default::default()
    }
}

/// The light's irradiance ([`lit_sphere`]).
const E: f64 = 2.0;

/// An anisotropic metal at a pixel: base colour, roughness, the direction in the tangent frame
/// and the strength.
struct Brushed {
    rho: [f64; 3],
    roughness: f64,
    dir: Vec2,
    s: f64,
}

/// Radiance of the anisotropic metal `m` at unit normal `n` seen along `d`, lit from `wi` with
/// irradiance [`E`]: E·n·l·D·V·F with F Schlick's of the metal, D·V = scene::anisotropy::lobe in
/// the frame of the extension's convention (the tangent t0 of the sphere, b0 = n × t0, the
/// direction in it).
fn expected(n: Vec3, d: Vec3, wi: Vec3, m: &Brushed) -> [f64; 3] {
    let (n, v, l) = (n.as_dvec3(), -d.as_dvec3(), wi.as_dvec3());
    let nl = n.dot(l);
    if nl <= 0.0 {
        return [0.0; 3];
    }
    let t0 = sphere_tangent(n.as_vec3()).truncate().as_dvec3();
    let t0 = (t0 - n * n.dot(t0)).normalize();
    let b0 = n.cross(t0);
    let t = (t0 * m.dir.x as f64 + b0 * m.dir.y as f64).normalize();
    let b = n.cross(t);
    let local = |w: DVec3| DVec3::new(w.dot(t), w.dot(b), w.dot(n));
    let alpha = (m.roughness * m.roughness).max(1e-3);
    let (at, ab) = scene::anisotropy::alphas(alpha, m.s);
    let lobe = scene::anisotropy::lobe(at, ab, local(l), local(v.normalize()));
    let vh = v.dot((v + l).normalize()).max(0.0);
    let fres = (1.0 - vh).powi(5);
    m.rho.map(|r| E * nl * lobe * (r + (1.0 - r) * fres))
}

/// The image of `scene` and the sphere's pixels (the true sphere's normal and the ray) away from
/// its rim, where the tessellation's normals are near the true ones.
fn sphere_pixels() -> Vec<(usize, Vec3, Vec3)> {
    let mut px = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            if let Some((n, d)) = sphere_hit(x, y, SIZE)
                && n.dot(-d) > 0.3
            {
                px.push(((y * SIZE + x) as usize, n, d));
            }
        }
    }
    px
}

fn settings(mode: Mode, n: usize) -> RenderSettings {
    RenderSettings { mode, wavelengths: n, shadows: false, ..Default::default() }
}

fn render(r: &mut Renderer, scene: &Scene, s: &RenderSettings, capture: bool) -> Vec<[f64; 3]> {
    render_frame_wh(r, scene, (SIZE, SIZE), s, capture).iter().map(rgb_of).collect()
}

/// A copper-coloured metal sphere at roughness 0.35, its lobe stretched along the parallels
/// (strength 0.8) and, rotated 45°, across them; lit from above the camera: every pixel as
/// scene::anisotropy's lobe gives it, in RGB, spectral N = 16 and the capture's node loop.
#[test]
fn the_anisotropic_lobe_follows_the_extension_under_a_directional_light() {
    let wi = Vec3::new(0.3, 0.5, 1.0).normalize();
    let rho = [0.95, 0.64, 0.54];
    let colour = rho.map(|c| c as f32);
    let mut r = renderer();
    for (name, rotation, strength) in [("along", 0.0f32, 0.8f32), ("diagonal", 0.785, 0.6)] {
        let a = Anisotropy { strength, rotation, texture: None };
        let (dir, s) = a.at(None);
        let scene = lit_sphere(metal(colour, 0.35, Some(a)), wi);
        let iso = lit_sphere(metal(colour, 0.35, None), wi);
        let pixels = sphere_pixels();
        let mut want = vec![None; (SIZE * SIZE) as usize];
        let mut effect = Vec::new();
        for &(i, n, d) in &pixels {
            let m = Brushed { rho, roughness: 0.35, dir, s: s as f64 };
            let w = expected(n, d, wi, &m);
            let plain = expected(n, d, wi, &Brushed { s: 0.0, ..m });
            effect.push(color::ciede2000(lab(w), lab(plain)));
            want[i] = Some(w);
        }
        let effect = effect.iter().sum::<f64>() / effect.len() as f64;
        assert!(effect > 2.0, "{name}: the anisotropy changes the image by ΔE2000 {effect} only");
        for (mode, n, capture) in
            [(Mode::Rgb, 8, false), (Mode::Spectral, 16, false), (Mode::Spectral, 16, true)]
        {
            let s = settings(mode, n);
            let actual = render(&mut r, &scene, &s, capture);
            let label = format!("anisotropy-{name}-{mode:?}-{n}-{capture}");
            assert_delta_e(&label, SIZE, SIZE, &actual, &want, 0.15, 0.6);
            // And the isotropic lobe is far from it: the test sees the anisotropy.
            let plain = render(&mut r, &iso, &s, capture);
            let de: Vec<f64> = pixels
                .iter()
                .map(|&(i, _, _)| color::ciede2000(lab(plain[i]), lab(want[i].unwrap())))
                .collect();
            let (mean, _) = stats(de);
            assert!(mean > 1.0, "{label}: the isotropic frame is within ΔE2000 {mean} of the expected one");
        }
    }
}

/// The width at half maximum of the luminance along the row and the column through the
/// brightest pixel.
fn highlight_extent(img: &[[f64; 3]]) -> (usize, usize) {
    let lum = |p: &[f64; 3]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let (peak, max) = img.iter().enumerate().fold((0, 0.0), |(bi, bv), (i, p)| {
        let l = lum(p);
        if l > bv { (i, l) } else { (bi, bv) }
    });
    let (px, py) = (peak % SIZE as usize, peak / SIZE as usize);
    let row = (0..SIZE as usize).filter(|&x| lum(&img[py * SIZE as usize + x]) > max / 2.0).count();
    let col = (0..SIZE as usize).filter(|&y| lum(&img[y * SIZE as usize + px]) > max / 2.0).count();
    (row, col)
}

/// The direction's rotation and texture: a quarter turn of the tangent is the bitangent's
/// direction, which a texture's RG can give as well (the same frame to a texel's 8 bits); the
/// highlight is long along the direction (the parallels: across the image) and across it after
/// the quarter turn; the texture's B scales the strength.
#[test]
fn the_direction_turns_with_the_rotation_and_the_texture() {
    // Lit from the camera: the highlight sits in the middle, where the parallels run across.
    let wi = Vec3::Z;
    let colour = [0.9, 0.9, 0.9];
    let s = settings(Mode::Rgb, 8);
    let mut r = renderer();
    let with = |a: Anisotropy, textures: Vec<scene::Texture>| {
        let mut scene = lit_sphere(metal(colour, 0.25, Some(a)), wi);
        scene.textures = textures;
        scene
    };
    let tex = Some(TextureRef { transform: None, index: 0, tex_coord: 0 });
    let along =
        render(&mut r, &with(Anisotropy { strength: 0.9, rotation: 0.0, texture: None }, vec![]), &s, false);
    let turned = render(
        &mut r,
        &with(Anisotropy { strength: 0.9, rotation: std::f32::consts::FRAC_PI_2, texture: None }, vec![]),
        &s,
        false,
    );
    // RG (128, 255) is the direction (1/255, 1): the bitangent's to 0.004 rad.
    let textured = render(
        &mut r,
        &with(
            Anisotropy { strength: 0.9, rotation: 0.0, texture: tex },
            vec![texel_texture("direction", [128, 255, 255, 255], false)],
        ),
        &s,
        false,
    );
    // The mesh's tangents swapped for its bitangents, n × T: the quarter turn's frame (to the
    // interpolation of the one against the cross product of the interpolated others).
    let mut swapped = with(Anisotropy { strength: 0.9, rotation: 0.0, texture: None }, vec![]);
    let mesh = &mut swapped.meshes[0];
    mesh.tangents =
        mesh.normals.iter().zip(&mesh.tangents).map(|(n, t)| n.cross(t.truncate()).extend(1.0)).collect();
    let swapped = render(&mut r, &swapped, &s, false);
    let de: Vec<f64> =
        sphere_pixels().iter().map(|&(i, _, _)| color::ciede2000(lab(turned[i]), lab(swapped[i]))).collect();
    let (mean, p99) = stats(de);
    println!("a quarter turn against the swapped tangents: ΔE2000 mean {mean:.4}, p99 {p99:.4}");
    assert!(mean < 0.01 && p99 < 0.5, "a quarter turn and the swapped tangent frame differ: {mean}, {p99}");
    // The texel's direction, (1/255, 1), as the f64 formula draws it.
    let mut want = vec![None; (SIZE * SIZE) as usize];
    let (dir, strength) = Anisotropy { strength: 0.9, rotation: 0.0, texture: None }.at(Some(Vec3::new(
        128.0 / 255.0,
        1.0,
        1.0,
    )));
    for (i, n, d) in sphere_pixels() {
        want[i] =
            Some(expected(n, d, wi, &Brushed { rho: [0.9; 3], roughness: 0.25, dir, s: strength as f64 }));
    }
    assert_delta_e("anisotropy-texture-direction", SIZE, SIZE, &textured, &want, 0.15, 0.6);
    let (row, col) = highlight_extent(&along);
    println!("along the parallels: the highlight is {row} px wide and {col} px tall");
    assert!(row >= 2 * col, "not long along the tangent: {row} × {col}");
    let (row_t, col_t) = highlight_extent(&turned);
    println!("a quarter turn: {row_t} px wide and {col_t} px tall");
    assert!(col_t >= 2 * row_t, "not long along the bitangent: {row_t} × {col_t}");
    // B at half strength draws the factor's half; as the f64 formula does.
    let halved = render(
        &mut r,
        &with(
            Anisotropy { strength: 0.9, rotation: 0.0, texture: tex },
            vec![texel_texture("strength", [255, 128, 128, 255], false)],
        ),
        &s,
        false,
    );
    let a = Anisotropy { strength: 0.9, rotation: 0.0, texture: None };
    let (dir, strength) = a.at(Some(Vec3::new(1.0, 128.0 / 255.0, 128.0 / 255.0)));
    let mut want = vec![None; (SIZE * SIZE) as usize];
    for (i, n, d) in sphere_pixels() {
        want[i] =
            Some(expected(n, d, wi, &Brushed { rho: [0.9; 3], roughness: 0.25, dir, s: strength as f64 }));
    }
    assert_delta_e("anisotropy-texture-strength", SIZE, SIZE, &halved, &want, 0.15, 0.6);
}

/// Strength 0 is no extension: the scene compiles none of it, and the frames are the bits of
/// the material without it, in every mode.
#[test]
fn strength_zero_draws_the_bits_of_no_extension() {
    let scene = lit_sphere(metal([0.8, 0.5, 0.3], 0.4, None), Vec3::new(0.2, 0.4, 1.0).normalize());
    let mut off = scene.clone();
    off.materials[0].anisotropy = Some(Anisotropy { strength: 0.0, rotation: 0.3, texture: None });
    let mut r = renderer();
    for (mode, n) in [(Mode::Rgb, 8), (Mode::Spectral, 8), (Mode::Naive, 8)] {
        let s = settings(mode, n);
        let a = render_frame_wh(&mut r, &scene, (SIZE, SIZE), &s, false);
        let b = render_frame_wh(&mut r, &off, (SIZE, SIZE), &s, false);
        assert!(
            a.iter().flatten().zip(b.iter().flatten()).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{mode:?}"
        );
    }
}

/// The opaque layer's shading in a compute pass and in fragments gives the same anisotropic
/// frames (tests/shading_stage.rs's rule: within one f16 step), with a texture, a second,
/// isotropic material, a light and the environment.
#[test]
fn both_shading_stages_draw_the_same_anisotropy() {
    let mut scene = lit_sphere(
        metal(
            [0.9, 0.7, 0.4],
            0.3,
            Some(Anisotropy {
                strength: 0.7,
                rotation: 0.4,
                texture: Some(TextureRef { transform: None, index: 0, tex_coord: 0 }),
            }),
        ),
        Vec3::new(0.3, 0.6, 1.0).normalize(),
    );
    scene.textures = vec![texel_texture("direction", [200, 90, 230, 255], false)];
    scene.environment = Some(Environment::default_sky());
    let mut r = renderer();
    r.resize(SIZE, SIZE).unwrap();
    r.set_scene(&scene).unwrap();
    for s in [settings(Mode::Rgb, 8), settings(Mode::Spectral, 8), settings(Mode::Naive, 4)] {
        let mut frames = Vec::new();
        for stage in [ShadingStage::Fragment, ShadingStage::Compute] {
            r.set_shading_stage(stage).unwrap();
            r.render(&scene.camera, &s).unwrap();
            frames.push(r.read_hdr().unwrap().into_iter().flatten().collect::<Vec<f32>>());
        }
        let worst = frames[0]
            .iter()
            .zip(&frames[1])
            .map(|(x, y)| (x - y).abs() / x.abs().max(y.abs()).max(1e-3))
            .fold(0.0f32, f32::max);
        let lit = frames[0].chunks(4).filter(|p| p[..3].iter().any(|&v| v > 0.0)).count();
        println!("{:?}: {lit} pixels lit, the stages differ by {worst:.2e} at most", s.mode);
        assert!(lit > (SIZE * SIZE / 4) as usize && worst <= 1.0 / 1024.0, "{:?}: {worst}", s.mode);
    }
}

/// In an environment that is not uniform (a checker of warm and cool squares, 45° a side), the
/// stand-in lobe's wider lookup gives a finite frame that is not the isotropic one;
/// the sphere's light is moved, and scaled only as in a uniform environment (where the
/// directional albedo alone scales it: the stand-in roughness's, tested above).
#[test]
fn the_environment_reflects_the_stand_in_lobe() {
    let (w, h) = (32u32, 16u32);
    let texels = (0..w * h)
        .map(|i| {
            if ((i % w) / 4 + (i / w) / 4) % 2 == 0 {
                Vec3::new(1.0, 0.6, 0.2)
            } else {
                Vec3::new(0.1, 0.3, 1.0)
            }
        })
        .collect();
    let mut env = Environment::from_rgb("checker", w, h, texels).unwrap();
    env.sun_light = false;
    let mut r = renderer();
    for mode in [Mode::Rgb, Mode::Spectral] {
        let s = RenderSettings { mode, wavelengths: 8, shadows: false, ..Default::default() };
        let mut render_env = |a: Option<Anisotropy>, env: &Environment| {
            let mut scene = lit_sphere(metal([0.9, 0.9, 0.9], 0.3, a), Vec3::Y);
            scene.lights.clear();
            scene.environment = Some(env.clone());
            render(&mut r, &scene, &s, false)
        };
        let brushed = Some(Anisotropy { strength: 0.9, rotation: 0.0, texture: None });
        let iso = render_env(None, &env);
        let aniso = render_env(brushed.clone(), &env);
        let uniform = Environment::uniform(Vec3::ONE);
        let (iso_u, aniso_u) = (render_env(None, &uniform), render_env(brushed, &uniform));
        assert!(aniso.iter().flatten().all(|v| v.is_finite() && *v >= 0.0), "{mode:?}: not finite");
        let de: Vec<f64> =
            sphere_pixels().iter().map(|&(i, _, _)| color::ciede2000(lab(iso[i]), lab(aniso[i]))).collect();
        let (mean, p99) = stats(de);
        let sum = |img: &[[f64; 3]]| sphere_pixels().iter().map(|&(i, _, _)| img[i][1]).sum::<f64>();
        let ratio = sum(&aniso) / sum(&iso);
        let ratio_u = sum(&aniso_u) / sum(&iso_u);
        println!(
            "{mode:?}: the stand-in lobe moves the sphere by ΔE2000 {mean:.2} (p99 {p99:.2}); its light × {ratio:.3}, \
             × {ratio_u:.3} in a uniform environment"
        );
        assert!(mean > 1.0, "{mode:?}: the environment's reflection hardly changed ({mean})");
        assert!(
            (ratio / ratio_u - 1.0).abs() < 0.15,
            "{mode:?}: the sphere's light changed by {ratio} ({ratio_u})"
        );
    }
}

/// In a uniform white environment (a furnace) a white metal (Fresnel 1) reflects its lobe's
/// directional albedo. The split sum has no anisotropic albedo: it looks its own up at the
/// stand-in roughness (α = √((α_t² + α_b²)/2), `anisotropy_iso_roughness`), which must stay
/// within 0.06 of the anisotropic lobe's (f64 quadrature of scene::anisotropy::lobe) where the
/// view is within 0.8 rad of the normal — the base's own roughness, used before, is 0.3 off.
#[test]
fn the_environment_keeps_the_anisotropic_lobes_energy() {
    let mut r = renderer();
    let (roughness, strength) = (0.3f64, 1.0f64);
    let alpha = (roughness * roughness).max(1e-3);
    let (at, ab) = scene::anisotropy::alphas(alpha, strength);
    for mode in [Mode::Rgb, Mode::Spectral] {
        let s = RenderSettings { mode, wavelengths: 8, shadows: false, ..Default::default() };
        let mut scene = lit_sphere(
            metal(
                [1.0, 1.0, 1.0],
                roughness as f32,
                Some(Anisotropy { strength: 1.0, rotation: 0.0, texture: None }),
            ),
            Vec3::Y,
        );
        scene.lights.clear();
        scene.environment = Some(Environment::uniform(Vec3::ONE));
        let img = render(&mut r, &scene, &s, false);
        let (mut err, mut err_iso, mut count) = (0.0f64, 0.0f64, 0usize);
        for &(i, n, d) in &sphere_pixels() {
            let (n, v) = (n.as_dvec3(), -d.as_dvec3());
            if n.dot(v) < 0.8f64.cos() {
                continue;
            }
            let t0 = sphere_tangent(n.as_vec3()).truncate().as_dvec3();
            let t = (t0 - n * n.dot(t0)).normalize();
            let b = n.cross(t);
            let local = DVec3::new(v.dot(t), v.dot(b), v.dot(n));
            let want = scene::anisotropy::albedo(at, ab, local, 400);
            let got = img[i][1];
            err = err.max((got - want).abs());
            err_iso = err_iso.max((scene::anisotropy::albedo(alpha, alpha, local, 400) - want).abs());
            count += 1;
        }
        println!(
            "{mode:?}: {count} pixels, worst |albedo − the lobe's| {err:.3} (the isotropic lobe's: {err_iso:.3})"
        );
        assert!(count > 100, "{count}");
        assert!(err_iso > 0.2, "the isotropic albedo would pass too ({err_iso})");
        assert!(err < 0.06, "{mode:?}: worst albedo error {err}");
    }
}

/// An anisotropy on a see-through material has no room in the transmissive layer's G-buffer:
/// the upload says it is not drawn, naming the material, and the frame is the one without it.
#[test]
fn a_see_through_anisotropy_is_reported_and_left_out() {
    let mut plain = lit_sphere(metal([0.5, 0.4, 0.3], 0.3, None), Vec3::new(0.2, 0.5, 1.0).normalize());
    plain.materials[0].name = "frosted".into();
    plain.materials[0].metallic = 0.0;
    plain.materials[0].transmission =
        Some(scene::transmission::Transmission { factor: 0.5, texture: None, volume: None, dispersion: 0.0 });
    let mut brushed = plain.clone();
    brushed.materials[0].anisotropy = Some(Anisotropy { strength: 0.8, rotation: 0.0, texture: None });
    let mut r = renderer();
    let s = settings(Mode::Spectral, 8);
    let without = render_frame_wh(&mut r, &plain, (SIZE, SIZE), &s, false);
    assert!(r.scene_warnings().is_empty(), "{:?}", r.scene_warnings());
    let with = render_frame_wh(&mut r, &brushed, (SIZE, SIZE), &s, false);
    let w = r.scene_warnings();
    assert!(w.len() == 1 && w[0].contains("KHR_materials_anisotropy") && w[0].contains("'frosted'"), "{w:?}");
    assert!(with == without);
}
