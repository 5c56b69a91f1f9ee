//! glTF material and camera features in the real-time renderer (issue 12), as small reference
//! images: `COLOR_0`, `TEXCOORD_1` with `KHR_texture_transform`, sampler wrap modes, mipmaps,
//! `doubleSided` (back faces, and which side of a single-sided surface casts a shadow),
//! `alphaMode` MASK (G-buffer and shadow map) and BLEND (stochastic, averaged by accumulation),
//! and orthographic cameras.
//!
//! Every scene is lit by directional lights in Lambert mode (`RenderSettings::lambert`), so a
//! lit surface facing a light of π lux head-on shows exactly its base colour.

mod common;

use common::*;
use glam::{Vec2, Vec3, Vec4};
use render::{Mode, RenderSettings, Renderer};
use scene::{
    AlphaMode, Camera, Environment, Filter, Light, LightKind, Material, Mesh, Sampler, Scene,
    SpectralSettings, Texture, TextureRef, TextureTransform, Wrap,
};
use std::f32::consts::PI;

/// Axis-aligned rectangle (x0, x1, y0, y1).
type Rect = (f32, f32, f32, f32);

/// A quad in the plane `z` over `r`; u runs along +x, v down the quad (glTF: v = 0 at the
/// image's top row). `facing_up`: counter-clockwise seen from +z (normal +z), else from −z.
fn quad(r: Rect, z: f32, facing_up: bool, material: usize) -> Mesh {
    let positions =
        vec![Vec3::new(r.0, r.2, z), Vec3::new(r.1, r.2, z), Vec3::new(r.1, r.3, z), Vec3::new(r.0, r.3, z)];
    let uvs = vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
    let (normal, indices) =
        if facing_up { (Vec3::Z, vec![0, 1, 2, 0, 2, 3]) } else { (Vec3::NEG_Z, vec![0, 2, 1, 0, 3, 2]) };
    Mesh {
        positions,
        normals: vec![normal; 4],
        tangents: vec![],
        uvs,
        uvs1: vec![],
        colors: vec![],
        indices,
        material,
    }
}

/// The quad's (u, v) at world point `p` (see [`quad`]).
fn uv_of(r: Rect, p: Vec2) -> Vec2 {
    Vec2::new((p.x - r.0) / (r.1 - r.0), (r.3 - p.y) / (r.3 - r.2))
}

fn inside(p: Vec2, r: Rect, margin: f32) -> bool {
    p.x > r.0 + margin && p.x < r.1 - margin && p.y > r.2 + margin && p.y < r.3 - margin
}

fn material(name: &str, base: Vec4) -> Material {
    Material {
        name: name.into(),
        base_color: base,
        roughness: 1.0,
        double_sided: false,
        ..Default::default()
    }
}

fn sun(direction: Vec3, lux: f32) -> Light {
    Light {
        name: "sun".into(),
        kind: LightKind::Directional { direction: direction.normalize() },
        emission: white_light(lux, None),
        stands_in_for: None,
    }
}

fn scene(meshes: Vec<Mesh>, materials: Vec<Material>, textures: Vec<Texture>, lights: Vec<Light>) -> Scene {
    Scene {
        source: "test:gltf-features".into(),
        meshes,
        materials,
        textures,
        lights,
        camera: top_camera(Vec2::ZERO, 1.0),
        spectral: SpectralSettings::default(),
        water: None,
        warnings: vec![],
        environment: None,
        medium: None,
        inputs: vec![],
        origin: glam::DVec3::ZERO,
        input_stamps: vec![],
        choices: vec![],
        animation_end: None,
    }
}

/// A narrow perspective camera 60 units above `centre` looking down −z, seeing `half_height`
/// world units above and below it on the z = 0 plane.
fn top_camera(centre: Vec2, half_height: f32) -> Camera {
    let d = 60.0;
    Camera::look_at(centre.extend(d), centre.extend(0.0), Vec3::Y, 2.0 * (half_height / d).atan())
}

/// Where the ray through the centre of pixel (px, py) meets the plane `z`.
fn hit(cam: &Camera, w: u32, h: u32, px: u32, py: u32, z: f32) -> Vec2 {
    let inv = (render::renderer::projection(cam, w as f32 / h as f32) * cam.transform.inverse()).inverse();
    let ndc = Vec2::new((px as f32 + 0.5) / w as f32 * 2.0 - 1.0, 1.0 - (py as f32 + 0.5) / h as f32 * 2.0);
    let a = inv.project_point3(ndc.extend(0.0));
    let b = inv.project_point3(ndc.extend(1.0));
    let t = (z - a.z) / (b.z - a.z);
    (a + (b - a) * t).truncate()
}

fn settings(shadows: bool) -> RenderSettings {
    RenderSettings { mode: Mode::Rgb, shadows, lambert: true, ..Default::default() }
}

fn render(s: &Scene, cam: &Camera, w: u32, h: u32, shadows: bool) -> Vec<[f64; 3]> {
    let mut r = renderer();
    r.set_scene(s).unwrap();
    r.resize(w, h).unwrap();
    r.render(cam, &settings(shadows)).unwrap();
    r.read_hdr().unwrap().iter().map(rgb_of).collect()
}

/// Compares `actual` with `expected` (None: not compared) channel by channel; on failure
/// writes the images and names the worst pixel.
fn assert_close(name: &str, w: u32, h: u32, actual: &[[f64; 3]], expected: &[Option<[f64; 3]>], tol: f64) {
    let mut worst = (0.0f64, 0usize);
    let mut n = 0;
    for (i, (a, e)) in actual.iter().zip(expected).enumerate() {
        if let Some(e) = e {
            n += 1;
            let d = (0..3).map(|c| (a[c] - e[c]).abs()).fold(0.0, f64::max);
            if d > worst.0 {
                worst = (d, i);
            }
        }
    }
    assert!(n > 0, "{name}: no pixel compared");
    println!("{name}: {n} pixels, largest difference {:.4}", worst.0);
    if worst.0 > tol {
        let exp: Vec<[f64; 3]> = expected.iter().map(|e| e.unwrap_or([0.0; 3])).collect();
        let de: Vec<f64> = actual
            .iter()
            .zip(expected)
            .map(|(a, e)| e.map_or(0.0, |e| (0..3).map(|c| (a[c] - e[c]).abs()).fold(0.0, f64::max) * 50.0))
            .collect();
        write_failure_images(name, w, h, actual, &exp, &de);
        let i = worst.1;
        panic!(
            "{name}: pixel ({}, {}) is {:?}, expected {:?} (difference {:.4} > {tol}); images in \
             target/test-output/{name}-*.png",
            i as u32 % w,
            i as u32 / w,
            actual[i],
            expected[i].unwrap(),
            worst.0
        );
    }
}

/// A 2×2 sRGB texture: red, green / blue, yellow (linear 0 or 1 exactly).
const TEXELS: [[u8; 4]; 4] = [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [255, 255, 0, 255]];

fn texture_2x2(sampler: Sampler) -> Texture {
    Texture { name: "2x2".into(), width: 2, height: 2, rgba8: TEXELS.concat(), srgb: true, sampler }
}

fn nearest(wrap: Wrap) -> Sampler {
    Sampler { wrap_s: wrap, wrap_t: wrap, mag: Filter::Nearest, min: Filter::Nearest, mipmaps: false }
}

/// The texel of [`TEXELS`] nearest-sampled at `uv` after wrapping, or `None` within `margin`
/// (in texels) of a texel edge, where rounding may go either way.
fn texel_at(uv: Vec2, wrap: Wrap, margin: f32) -> Option<[f64; 3]> {
    let wrap1 = |t: f32| match wrap {
        Wrap::Repeat => t - t.floor(),
        Wrap::ClampToEdge => t.clamp(0.0, 1.0),
        Wrap::MirroredRepeat => {
            let m = t.rem_euclid(2.0);
            if m > 1.0 { 2.0 - m } else { m }
        }
    };
    let mut idx = [0usize; 2];
    for (k, t) in [uv.x, uv.y].into_iter().enumerate() {
        let s = wrap1(t) * 2.0;
        // Clamped coordinates stay on their texel however near the image's edge.
        let interior = s > margin && s < 2.0 - margin;
        if (s - s.round()).abs() < margin && (interior || wrap != Wrap::ClampToEdge) {
            return None;
        }
        idx[k] = (s.floor() as usize).min(1);
    }
    let t = TEXELS[idx[1] * 2 + idx[0]];
    Some([t[0], t[1], t[2]].map(|c| c as f64 / 255.0))
}

#[test]
fn vertex_colours_multiply_base_colour_and_alpha() {
    let base = Vec4::new(0.8, 0.6, 1.0, 1.0);
    // Top left: one colour; top right: red on the left edge to blue on the right; bottom: alpha
    // below / above a MASK cutoff of 0.5, carried by COLOR_0 alone.
    let rects: [Rect; 4] =
        [(-2.0, -0.2, 0.2, 2.0), (0.2, 2.0, 0.2, 2.0), (-2.0, -0.2, -2.0, -0.2), (0.2, 2.0, -2.0, -0.2)];
    let mut meshes: Vec<Mesh> = rects.iter().enumerate().map(|(i, r)| quad(*r, 0.0, true, i)).collect();
    meshes[0].colors = vec![Vec4::new(0.5, 1.0, 0.25, 1.0); 4];
    let (red, blue) = (Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 0.0, 1.0, 1.0));
    meshes[1].colors = vec![red, blue, blue, red];
    meshes[2].colors = vec![Vec4::new(1.0, 1.0, 1.0, 0.3); 4];
    meshes[3].colors = vec![Vec4::new(1.0, 1.0, 1.0, 0.7); 4];
    let mut materials: Vec<Material> = (0..4).map(|i| material(&format!("m{i}"), base)).collect();
    for m in &mut materials[2..] {
        m.alpha_mode = AlphaMode::Mask { cutoff: 0.5 };
    }
    let s = scene(meshes, materials, vec![], vec![sun(Vec3::NEG_Z, PI)]);
    let (w, h) = (48, 32);
    let cam = top_camera(Vec2::ZERO, 2.2);
    let actual = render(&s, &cam, w, h, false);
    let b = base.truncate().as_dvec3();
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p = hit(&cam, w, h, px, py, 0.0);
            let m = 0.08;
            if inside(p, rects[0], m) {
                Some([b.x * 0.5, b.y, b.z * 0.25])
            } else if inside(p, rects[1], m) {
                let u = uv_of(rects[1], p).x as f64;
                Some([b.x * (1.0 - u), 0.0, b.z * u])
            } else if inside(p, rects[2], m) {
                Some([0.0; 3])
            } else if inside(p, rects[3], m) {
                Some(b.to_array())
            } else {
                None
            }
        })
        .collect();
    assert_close("vertex-colours", w, h, &actual, &expected, 0.01);
}

#[test]
fn texcoord1_and_texture_transform_pick_the_texels() {
    // TEXCOORD_0 is constant (it would show the red texel everywhere); the textures read
    // TEXCOORD_1 through a transform: left, the right column stretched over the quad (offset,
    // scale); right, the image turned a quarter (rotation, offset).
    let rects: [Rect; 2] = [(-2.0, -0.2, -0.9, 0.9), (0.2, 2.0, -0.9, 0.9)];
    let transforms = [
        TextureTransform { offset: Vec2::new(0.5, 0.0), rotation: 0.0, scale: Vec2::new(0.5, 1.0) },
        TextureTransform { offset: Vec2::new(0.0, 1.0), rotation: PI / 2.0, scale: Vec2::ONE },
    ];
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    for (i, r) in rects.iter().enumerate() {
        let mut q = quad(*r, 0.0, true, i);
        q.uvs1 = q.uvs.clone();
        q.uvs = vec![Vec2::splat(0.25); 4];
        meshes.push(q);
        materials.push(Material {
            base_color_texture: Some(TextureRef { index: 0, tex_coord: 1, transform: Some(transforms[i]) }),
            ..material(&format!("m{i}"), Vec4::ONE)
        });
    }
    let s = scene(meshes, materials, vec![texture_2x2(nearest(Wrap::Repeat))], vec![sun(Vec3::NEG_Z, PI)]);
    let (w, h) = (48, 24);
    let cam = top_camera(Vec2::ZERO, 1.0);
    let actual = render(&s, &cam, w, h, false);
    let mut seen = [Vec::new(), Vec::new()];
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p = hit(&cam, w, h, px, py, 0.0);
            let i = rects.iter().position(|r| inside(p, *r, 0.05))?;
            let e = texel_at(transforms[i].apply(uv_of(rects[i], p)), Wrap::Repeat, 0.15)?;
            if !seen[i].contains(&e) {
                seen[i].push(e);
            }
            Some(e)
        })
        .collect();
    // The left quad shows green over yellow, the right all four texels: not the red of
    // TEXCOORD_0, or the test proves nothing.
    assert_eq!(seen[0].len(), 2, "{:?}", seen[0]);
    assert_eq!(seen[1].len(), 4, "{:?}", seen[1]);
    assert_close("texcoord1-transform", w, h, &actual, &expected, 0.01);
}

#[test]
fn wrap_modes_clamp_repeat_and_mirror_a_2x2_texture_over_uv_0_to_3() {
    let wraps = [Wrap::ClampToEdge, Wrap::Repeat, Wrap::MirroredRepeat];
    let rects: [Rect; 3] = [(-2.6, -1.0, -0.8, 0.8), (-0.8, 0.8, -0.8, 0.8), (1.0, 2.6, -0.8, 0.8)];
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    let mut textures = Vec::new();
    for (i, r) in rects.iter().enumerate() {
        let mut q = quad(*r, 0.0, true, i);
        q.uvs = q.uvs.iter().map(|uv| *uv * 3.0).collect();
        meshes.push(q);
        materials.push(Material {
            base_color_texture: Some(TextureRef::new(i)),
            ..material(&format!("{:?}", wraps[i]), Vec4::ONE)
        });
        textures.push(texture_2x2(nearest(wraps[i])));
    }
    let s = scene(meshes, materials, textures, vec![sun(Vec3::NEG_Z, PI)]);
    let (w, h) = (64, 24);
    let cam = top_camera(Vec2::ZERO, 1.0);
    let actual = render(&s, &cam, w, h, false);
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p = hit(&cam, w, h, px, py, 0.0);
            let i = rects.iter().position(|r| inside(p, *r, 0.03))?;
            texel_at(uv_of(rects[i], p) * 3.0, wraps[i], 0.2)
        })
        .collect();
    assert_close("wrap-modes", w, h, &actual, &expected, 0.01);
}

#[test]
fn mipmaps_average_a_minified_checkerboard_to_grey() {
    // A 64×64 checkerboard of single black and white texels seen about 5× minified: with
    // mipmaps every pixel is the linear mean (0.5, filtered after sRGB decoding); sampling
    // level 0 only aliases.
    let n = 64u32;
    let rgba8: Vec<u8> = (0..n * n)
        .flat_map(|i| if (i % n + i / n).is_multiple_of(2) { [255u8; 4] } else { [0, 0, 0, 255] })
        .collect();
    let rects: [Rect; 2] = [(-1.7, -0.2, -0.75, 0.75), (0.2, 1.7, -0.75, 0.75)];
    let mut textures = Vec::new();
    let mut materials = Vec::new();
    for (i, mipmaps) in [true, false].into_iter().enumerate() {
        let sampler = Sampler { mipmaps, ..Default::default() };
        textures.push(Texture {
            name: "checker".into(),
            width: n,
            height: n,
            rgba8: rgba8.clone(),
            srgb: true,
            sampler,
        });
        materials.push(Material { base_color_texture: Some(TextureRef::new(i)), ..material("m", Vec4::ONE) });
    }
    let meshes = rects.iter().enumerate().map(|(i, r)| quad(*r, 0.0, true, i)).collect();
    let s = scene(meshes, materials, textures, vec![sun(Vec3::NEG_Z, PI)]);
    let (w, h) = (40, 20);
    let cam = top_camera(Vec2::ZERO, 1.0);
    let actual = render(&s, &cam, w, h, false);
    let mut values = [Vec::new(), Vec::new()];
    for py in 0..h {
        for px in 0..w {
            let p = hit(&cam, w, h, px, py, 0.0);
            if let Some(i) = rects.iter().position(|r| inside(p, *r, 0.1)) {
                values[i].push(actual[(py * w + px) as usize][1]);
            }
        }
    }
    let range =
        |v: &[f64]| (v.iter().cloned().fold(f64::MAX, f64::min), v.iter().cloned().fold(0.0, f64::max));
    let (lo, hi) = range(&values[0]);
    let (alo, ahi) = range(&values[1]);
    println!("mipmapped {lo:.3}..{hi:.3} over {} pixels; level 0 only {alo:.3}..{ahi:.3}", values[0].len());
    assert!(values[0].len() > 50);
    assert!(lo > 0.47 && hi < 0.53, "mipmapped checkerboard not grey: {lo}..{hi}");
    assert!(ahi - alo > 0.3, "without mipmaps the checkerboard should alias: {alo}..{ahi}");
}

#[test]
fn single_sided_back_faces_are_invisible_and_double_sided_ones_drawn() {
    // Left and right: a red quad at z = 1 whose front faces away from the camera (−z), over a
    // green floor. Left single-sided: the camera sees the floor through it. Right double-sided:
    // the red quad, its normal flipped towards the viewer (so lit by the light from +z).
    let floor: Rect = (-2.5, 2.5, -1.0, 1.0);
    let rects: [Rect; 2] = [(-2.0, -0.3, -0.7, 0.7), (0.3, 2.0, -0.7, 0.7)];
    let red = Vec4::new(0.9, 0.1, 0.1, 1.0);
    let green = Vec4::new(0.1, 0.7, 0.2, 1.0);
    let materials = vec![
        material("single", red),
        Material { double_sided: true, ..material("double", red) },
        material("floor", green),
    ];
    let meshes =
        vec![quad(rects[0], 1.0, false, 0), quad(rects[1], 1.0, false, 1), quad(floor, 0.0, true, 2)];
    let s = scene(meshes, materials, vec![], vec![sun(Vec3::NEG_Z, PI)]);
    let (w, h) = (48, 24);
    let cam = top_camera(Vec2::ZERO, 1.1);
    let actual = render(&s, &cam, w, h, false);
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p1 = hit(&cam, w, h, px, py, 1.0);
            if inside(p1, rects[0], 0.05) {
                Some(green.truncate().as_dvec3().to_array())
            } else if inside(p1, rects[1], 0.05) {
                Some(red.truncate().as_dvec3().to_array())
            } else {
                None
            }
        })
        .collect();
    assert_close("back-faces", w, h, &actual, &expected, 0.01);
}

/// Light from the upper left at 45° (a point at height z shadows the floor z units to its
/// right), shadow-mapped.
const SLANT: Vec3 = Vec3::new(1.0, 0.0, -1.0);

#[test]
fn single_sided_surfaces_shadow_only_what_lies_on_their_front_side() {
    // Two single-sided quads at z = 1 over x ∈ [−1, 0], their shadows at x ∈ [0, 1] on the
    // floor. Top: front towards the floor (the camera above sees its back: culled) — it
    // shadows the floor. Bottom: front towards the light — no shadow (from the floor, only its
    // back face is on the way to the light).
    let floor: Rect = (-2.0, 3.0, -1.4, 1.4);
    let rects: [Rect; 2] = [(-1.0, 0.0, 0.2, 1.2), (-1.0, 0.0, -1.2, -0.2)];
    let grey = Vec4::new(0.6, 0.6, 0.6, 1.0);
    let materials = vec![material("occluder", Vec4::new(0.2, 0.2, 0.9, 1.0)), material("floor", grey)];
    let meshes = vec![quad(rects[0], 1.0, false, 0), quad(rects[1], 1.0, true, 0), quad(floor, 0.0, true, 1)];
    let lit = (grey.x * (PI / 4.0).cos()) as f64;
    let s = scene(meshes, materials, vec![], vec![sun(SLANT, PI)]);
    let (w, h) = (48, 32);
    let cam = top_camera(Vec2::new(0.5, 0.0), 1.5);
    let actual = render(&s, &cam, w, h, true);
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p = hit(&cam, w, h, px, py, 0.0);
            if inside(p, (0.0, 1.0, 0.2, 1.2), 0.1) {
                Some([0.0; 3])
            } else if inside(p, (0.0, 1.0, -1.2, -0.2), 0.1) || inside(p, (1.0, 3.0, -1.4, 1.4), 0.1) {
                Some([lit; 3])
            } else {
                None
            }
        })
        .collect();
    assert_close("single-sided-shadow", w, h, &actual, &expected, 0.01);
}

#[test]
fn alpha_cutout_lets_light_and_sight_through_where_alpha_is_below_the_cutoff() {
    // A double-sided blue quad at z = 1 over x ∈ [−1, 1], cut (texture alpha 0.2 < 0.5) on its
    // right half, over a grey floor. Light A comes at 45° (shadow-mapped), light B straight down.
    // Through the cut the camera sees the floor at x ∈ [0, 1], in A's shadow of the opaque half;
    // the floor at x ∈ [1, 2] gets A through the cut, as if the quad were not there.
    let cut: Rect = (-1.0, 1.0, -1.0, 1.0);
    let floor: Rect = (-2.0, 3.5, -1.5, 1.5);
    let blue = Vec4::new(0.1, 0.2, 0.9, 0.9);
    let grey = Vec4::new(0.6, 0.6, 0.6, 1.0);
    let texture = Texture {
        name: "cutout".into(),
        width: 2,
        height: 1,
        rgba8: vec![255, 255, 255, 255, 255, 255, 255, 51],
        srgb: true,
        sampler: nearest(Wrap::ClampToEdge),
    };
    let materials = vec![
        Material {
            alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
            double_sided: true,
            base_color_texture: Some(TextureRef::new(0)),
            ..material("cutout", blue)
        },
        material("floor", grey),
    ];
    let meshes = vec![quad(cut, 1.0, true, 0), quad(floor, 0.0, true, 1)];
    let (e_a, e_b) = (PI, 0.5 * PI);
    let s = scene(meshes, materials, vec![texture], vec![sun(SLANT, e_a), sun(Vec3::NEG_Z, e_b)]);
    let (w, h) = (64, 24);
    let cam = top_camera(Vec2::new(0.75, 0.0), 1.2);
    let actual = render(&s, &cam, w, h, true);
    let g = grey.x as f64;
    let a = (e_a / PI * (PI / 4.0).cos()) as f64;
    let b = (e_b / PI) as f64;
    let blue_lit = blue.truncate().as_dvec3() * (a + b);
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p1 = hit(&cam, w, h, px, py, 1.0);
            let p0 = hit(&cam, w, h, px, py, 0.0);
            let m = 0.1;
            if inside(p1, (-1.0, 0.0, -1.0, 1.0), m) {
                Some(blue_lit.to_array())
            } else if inside(p1, (0.0, 1.0, -1.0, 1.0), m) && inside(p0, (0.0, 1.0, -1.0, 1.0), m) {
                Some([g * b; 3])
            } else if inside(p0, (1.0, 3.5, -1.0, 1.0), m) && !inside(p1, cut, -m) {
                Some([g * (a + b); 3])
            } else {
                None
            }
        })
        .collect();
    assert_close("alpha-cutout", w, h, &actual, &expected, 0.01);
}

#[test]
fn blend_is_stochastic_coverage_that_averages_to_alpha() {
    // A red BLEND quad of alpha 0.5 (0.5 factor × COLOR_0 alpha 1) at z = 1 over a green floor,
    // lit at 45° with shadows: one frame shows about half red pixels and half floor (and the
    // same noise every frame); accumulated frames converge to half red, and the floor in the
    // quad's shadow (x ∈ [1, 2]) receives half the light.
    let blend: Rect = (-1.0, 1.0, -1.0, 1.0);
    let floor: Rect = (-2.0, 3.5, -1.5, 1.5);
    let red = Vec4::new(1.0, 0.0, 0.0, 0.5);
    let green = Vec4::new(0.0, 1.0, 0.0, 1.0);
    let materials = vec![
        Material { alpha_mode: AlphaMode::Blend, double_sided: true, ..material("glass", red) },
        material("floor", green),
    ];
    let mut q = quad(blend, 1.0, true, 0);
    q.colors = vec![Vec4::ONE; 4];
    let s = scene(vec![q, quad(floor, 0.0, true, 1)], materials, vec![], vec![sun(SLANT, PI * 2f32.sqrt())]);
    let (w, h) = (64, 24);
    let cam = top_camera(Vec2::new(0.75, 0.0), 1.2);
    let mut r = renderer();
    r.set_scene(&s).unwrap();
    r.resize(w, h).unwrap();
    let m = 0.1;
    let (mut on_quad, mut in_shadow, mut sunlit) = (Vec::new(), Vec::new(), Vec::new());
    for py in 0..h {
        for px in 0..w {
            let i = (py * w + px) as usize;
            let (p1, p0) = (hit(&cam, w, h, px, py, 1.0), hit(&cam, w, h, px, py, 0.0));
            if inside(p1, blend, m) {
                on_quad.push(i);
            } else if inside(p0, (1.0, 2.0, -1.0, 1.0), m) && !inside(p1, blend, -m) {
                in_shadow.push(i);
            } else if inside(p0, (2.0, 3.5, -1.0, 1.0), m) {
                sunlit.push(i);
            }
        }
    }
    let mean = |img: &[[f64; 3]], px: &[usize], c: usize| {
        px.iter().map(|&i| img[i][c]).sum::<f64>() / px.len() as f64
    };

    // One frame: each quad pixel is red or not, about half of them red; the same next frame.
    r.render(&cam, &settings(true)).unwrap();
    let one: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
    r.render(&cam, &settings(true)).unwrap();
    let again: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
    assert_eq!(one, again, "without accumulation the noise is stable");
    let red_px = on_quad.iter().filter(|&&i| one[i][0] > 0.9).count();
    let floor_px = on_quad.iter().filter(|&&i| one[i][0] < 0.01).count();
    let frac = red_px as f64 / on_quad.len() as f64;
    println!("one frame: {red_px} red, {floor_px} floor of {} quad pixels", on_quad.len());
    assert_eq!(red_px + floor_px, on_quad.len(), "a pixel is the quad or the floor, not a mix");
    assert!((frac - 0.5).abs() < 0.1, "coverage {frac}");

    // Accumulated: the mean converges to alpha.
    r.set_accumulation(true);
    let frames = 48;
    for _ in 0..frames {
        r.render(&cam, &settings(true)).unwrap();
    }
    assert_eq!(r.accumulated_frames(), frames);
    let acc: Vec<[f64; 3]> =
        r.read_accumulated().unwrap().iter().map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]).collect();
    let coverage = mean(&acc, &on_quad, 0);
    let lit = mean(&acc, &sunlit, 1);
    let transmitted = mean(&acc, &in_shadow, 1) / lit;
    // Per pixel, 48 frames leave a binomial spread of about 0.07 (the worst of ~340 pixels ≈ 3.5σ).
    let worst = on_quad.iter().map(|&i| (acc[i][0] - 0.5).abs()).fold(0.0, f64::max);
    println!(
        "accumulated {frames} frames: coverage {coverage:.3} (worst pixel off by {worst:.3}), light \
         through the quad {transmitted:.3}, sunlit floor {lit:.3}"
    );
    assert!((lit - 1.0).abs() < 0.01, "sunlit floor {lit}");
    assert!((coverage - 0.5).abs() < 0.04, "mean coverage {coverage}");
    assert!(worst < 0.35, "a pixel's mean is {worst} from 0.5");
    assert!((transmitted - 0.5).abs() < 0.06, "transmitted {transmitted}");
}

#[test]
fn blend_coverage_is_not_darkened_by_the_environment_occlusion() {
    // A frontal red BLEND quad of alpha 0.5 one unit above a green floor in a uniform white
    // environment, no lights: nothing hides the quad's upper hemisphere, so each kept pixel
    // shades as the opaque quad does. Its screen neighbours are often the floor behind it (the
    // coverage is dithered); a facet rebuilt from them lay along the view ray, and the floor
    // then rose above it as a false horizon (the kept pixels lost 11 % of the light).
    let blend: Rect = (-1.0, 1.0, -1.0, 1.0);
    let floor: Rect = (-2.0, 3.5, -1.5, 1.5);
    let frame = |alpha_mode: AlphaMode| {
        let materials = vec![
            Material { alpha_mode, double_sided: true, ..material("quad", Vec4::new(1.0, 0.0, 0.0, 0.5)) },
            material("floor", Vec4::new(0.0, 1.0, 0.0, 1.0)),
        ];
        let mut s =
            scene(vec![quad(blend, 1.0, true, 0), quad(floor, 0.0, true, 1)], materials, vec![], vec![]);
        s.environment = Some(Environment::uniform(Vec3::ONE));
        render(&s, &top_camera(Vec2::new(0.75, 0.0), 1.2), 64, 24, false)
    };
    let opaque = frame(AlphaMode::Opaque);
    let dithered = frame(AlphaMode::Blend);
    let (w, h) = (64, 24);
    let cam = top_camera(Vec2::new(0.75, 0.0), 1.2);
    let mut kept = 0;
    let mut worst: f64 = 0.0;
    for py in 0..h {
        for px in 0..w {
            let i = (py * w + px) as usize;
            if !inside(hit(&cam, w, h, px, py, 1.0), blend, 0.1) || dithered[i][0] < 0.05 {
                continue;
            }
            kept += 1;
            worst = worst.max((dithered[i][0] / opaque[i][0] - 1.0).abs());
        }
    }
    println!("{kept} kept quad pixels; worst relative difference from the opaque quad {worst:.4}");
    assert!(kept > 100, "only {kept} kept pixels");
    assert!(opaque.iter().any(|p| p[0] > 0.5), "the opaque quad is lit");
    assert!(worst < 0.01, "a kept BLEND pixel differs from the opaque quad by {worst}");
}

/// A pixel mask of where `img` is not black.
fn coverage_mask(img: &[[f64; 3]]) -> Vec<bool> {
    img.iter().map(|p| p[0] + p[1] + p[2] > 0.05).collect()
}

#[test]
fn an_orthographic_camera_keeps_sizes_and_parallel_lines() {
    let (w, h) = (48u32, 32u32);
    // Two unit squares facing the camera, 20 units apart in depth.
    let squares: [(Rect, f32); 2] = [((-1.5, -0.5, -0.5, 0.5), 0.0), ((0.5, 1.5, -0.5, 0.5), -20.0)];
    let white = Vec4::new(0.8, 0.8, 0.8, 1.0);
    let meshes = squares.iter().map(|(r, z)| quad(*r, *z, true, 0)).collect();
    let s = scene(meshes, vec![material("white", white)], vec![], vec![sun(Vec3::NEG_Z, PI)]);
    let eye = Vec3::new(0.0, 0.0, 10.0);
    let ortho = Camera { ortho: Some((3.0, 2.0)), ..Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.5) };
    let persp = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.5);
    let img = render(&s, &ortho, w, h, true);
    // ymag 2: 8 pixels per unit; the target's aspect (1.5) gives xmag 3 (the file's is unused).
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p = Vec2::new((px as f32 + 0.5) / 8.0 - 3.0, 2.0 - (py as f32 + 0.5) / 8.0);
            if squares.iter().any(|(r, _)| inside(p, *r, 0.1)) {
                Some(white.truncate().as_dvec3().to_array())
            } else if squares.iter().all(|(r, _)| !inside(p, *r, -0.1)) {
                Some([0.0; 3])
            } else {
                None
            }
        })
        .collect();
    assert_close("ortho-squares", w, h, &img, &expected, 0.01);
    let count = |mask: &[bool], left: bool| {
        (0..(w * h) as usize).filter(|&i| mask[i] && ((i as u32 % w) < w / 2) == left).count()
    };
    let (o, p) = (coverage_mask(&img), coverage_mask(&render(&s, &persp, w, h, true)));
    println!(
        "pixels near/far: ortho {}/{}, perspective {}/{}",
        count(&o, true),
        count(&o, false),
        count(&p, true),
        count(&p, false)
    );
    assert_eq!(count(&o, true), 64);
    assert_eq!(count(&o, false), 64);
    assert!(count(&p, false) * 3 < count(&p, true), "the perspective sanity check");

    // A strip (2 units wide: 16 pixels in orthographic projection) on the ground running away from a camera that looks down at it: its width in
    // pixels is the same on every row in orthographic projection, and shrinks with distance in
    // perspective.
    let strip = Mesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, -40.0),
            Vec3::new(-1.0, -1.0, -40.0),
        ],
        normals: vec![Vec3::Y; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..quad((0.0, 1.0, 0.0, 1.0), 0.0, true, 0)
    };
    let s = scene(vec![strip], vec![material("white", white)], vec![], vec![sun(Vec3::NEG_Y, PI)]);
    let eye = Vec3::new(0.0, 4.0, 8.0);
    let target = Vec3::new(0.0, -1.0, -12.0);
    let widths = |cam: &Camera| {
        let m = coverage_mask(&render(&s, cam, w, h, false));
        (0..h)
            .map(|y| (0..w).filter(|&x| m[(y * w + x) as usize]).count())
            .filter(|&n| n > 0)
            .collect::<Vec<_>>()
    };
    let o = widths(&Camera { ortho: Some((3.0, 2.0)), ..Camera::look_at(eye, target, Vec3::Y, 0.8) });
    let p = widths(&Camera::look_at(eye, target, Vec3::Y, 0.8));
    println!("strip widths per row: ortho {o:?}, perspective {p:?}");
    assert!(o.len() >= 10, "the strip spans rows");
    assert!(o.iter().all(|&n| n.abs_diff(16) <= 1), "ortho widths {o:?}");
    assert!(p.first().unwrap() * 2 < *p.last().unwrap(), "perspective widths {p:?}");
}

#[test]
fn an_orthographic_camera_sees_the_environment_along_its_forward_axis() {
    // An environment whose colour changes with longitude: a perspective camera sees the
    // background change across the image; an orthographic one sees one direction (its forward
    // axis) in every pixel, and a glossy quad reflects the same everywhere.
    let (ew, eh) = (32u32, 16u32);
    let texels = (0..ew * eh)
        .map(|i| Vec3::new((i % ew) as f32 / ew as f32, 0.3, 1.0 - (i % ew) as f32 / ew as f32))
        .collect();
    let env = Environment::from_rgb("gradient", ew, eh, texels).unwrap();
    let mut s = scene(
        vec![quad((-0.5, 0.5, -0.5, 0.5), 0.0, true, 0)],
        vec![Material { metallic: 1.0, roughness: 0.3, ..material("metal", Vec4::ONE) }],
        vec![],
        vec![],
    );
    s.environment = Some(env);
    let (w, h) = (32u32, 16u32);
    let eye = Vec3::new(0.0, 0.0, 10.0);
    let look = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 1.2);
    // ymag: the quad about as large as in `look` (half-height = distance × tan(yfov / 2)).
    let ortho_cam = Camera { ortho: Some((1.0, 10.0 * (0.6f32).tan())), ..look };
    let quad_rect = (-0.5, 0.5, -0.5, 0.5);
    let spread = |img: &[[f64; 3]], cam: &Camera, on_quad: bool| {
        let mut lo = [f64::MAX; 3];
        let mut hi = [f64::MIN; 3];
        for py in 0..h {
            for px in 0..w {
                let p = hit(cam, w, h, px, py, 0.0);
                let take = if on_quad { inside(p, quad_rect, 0.05) } else { !inside(p, quad_rect, -0.05) };
                if take {
                    let c = img[(py * w + px) as usize];
                    (0..3).for_each(|k| {
                        lo[k] = lo[k].min(c[k]);
                        hi[k] = hi[k].max(c[k]);
                    });
                }
            }
        }
        (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max)
    };
    let mut r = renderer();
    r.set_scene(&s).unwrap();
    r.resize(w, h).unwrap();
    let mut shot = |cam: &Camera| {
        let settings = RenderSettings { mode: Mode::Rgb, ..Default::default() };
        r.render(cam, &settings).unwrap();
        r.read_hdr().unwrap().iter().map(rgb_of).collect::<Vec<_>>()
    };
    let persp = shot(&look);
    let ortho = shot(&ortho_cam);
    let (pb, ob) = (spread(&persp, &look, false), spread(&ortho, &ortho_cam, false));
    let (pq, oq) = (spread(&persp, &look, true), spread(&ortho, &ortho_cam, true));
    println!(
        "background spread: perspective {pb:.4}, ortho {ob:.4}; quad spread: perspective {pq:.4}, ortho {oq:.4}"
    );
    assert!(pb > 0.1, "the perspective sanity check");
    assert!(ob < 2e-3, "ortho background varies by {ob}");
    assert!(oq < 2e-3, "ortho reflection varies by {oq}");
}

#[test]
fn bad_material_inputs_are_errors_naming_the_material() {
    let mut s = scene(
        vec![quad((-1.0, 1.0, -1.0, 1.0), 0.0, true, 0)],
        vec![material("leaf", Vec4::ONE)],
        vec![texture_2x2(Sampler::default())],
        vec![],
    );
    s.materials[0].base_color_texture = Some(TextureRef { index: 0, tex_coord: 2, transform: None });
    let mut r: Renderer = renderer();
    let e = r.set_scene(&s).unwrap_err().to_string();
    assert!(e.contains("leaf") && e.contains("TEXCOORD_2"), "{e}");
    s.materials[0].base_color_texture = Some(TextureRef::new(0));
    s.materials[0].alpha_mode = AlphaMode::Mask { cutoff: f32::NAN };
    let e = r.set_scene(&s).unwrap_err().to_string();
    assert!(e.contains("leaf") && e.contains("cutoff"), "{e}");
    s.materials[0].alpha_mode = AlphaMode::Opaque;
    s.meshes[0].colors = vec![Vec4::ONE; 3];
    let e = r.set_scene(&s).unwrap_err().to_string();
    assert!(e.contains("colors"), "{e}");
    s.meshes[0].colors.clear();
    r.set_scene(&s).unwrap();
    r.resize(8, 8).unwrap();
    let cam = Camera { ortho: Some((1.0, 0.0)), ..s.camera };
    let e = r.render(&cam, &settings(false)).unwrap_err().to_string();
    assert!(e.contains("orthographic") && e.contains("ymag 0"), "{e}");
}

#[test]
fn unlit_surfaces_show_their_base_colour_whatever_the_light() {
    // Left: unlit, base factor × COLOR_0; right: the same colour, lit by a grazing sun and the
    // default sky (which the unlit quad must ignore too). Specular on, Lambert off, so that a
    // highlight or the environment's specular would show on the unlit quad if it reflected.
    let rects: [Rect; 2] = [(-2.0, -0.2, -1.0, 1.0), (0.2, 2.0, -1.0, 1.0)];
    let mut meshes: Vec<Mesh> = rects.iter().enumerate().map(|(i, r)| quad(*r, 0.0, true, i)).collect();
    meshes[0].colors = vec![Vec4::new(1.0, 0.5, 1.0, 1.0); 4];
    let base = Vec4::new(0.8, 0.6, 0.2, 1.0);
    let mut materials = vec![material("unlit", base), material("lit", base)];
    materials[0].unlit = true;
    materials[0].roughness = 0.2;
    let mut s = scene(meshes, materials, vec![], vec![sun(Vec3::new(0.0, 1.0, -0.3), 20.0)]);
    s.environment = Some(Environment::default_sky());
    let (w, h) = (48, 24);
    let cam = top_camera(Vec2::ZERO, 1.1);
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p = hit(&cam, w, h, px, py, 0.0);
            inside(p, rects[0], 0.08).then_some([0.8, 0.3, 0.2])
        })
        .collect();
    let dark = Scene { lights: vec![], environment: None, ..s.clone() };
    let draw = |scene: &Scene, mode: Mode| -> Vec<[f64; 3]> {
        let mut r = renderer();
        r.set_scene(scene).unwrap();
        r.resize(w, h).unwrap();
        let settings = RenderSettings { mode, shadows: false, lambert: false, ..Default::default() };
        r.render(&cam, &settings).unwrap();
        r.read_hdr().unwrap().iter().map(rgb_of).collect()
    };
    // Naive mode's box spectra do not return an RGB exactly (the baseline's own error), so it
    // is held only to ignoring the light.
    for (mode, tol) in [(Mode::Rgb, Some(0.002)), (Mode::Naive, None), (Mode::Spectral, Some(0.02))] {
        let actual = draw(&s, mode);
        if let Some(tol) = tol {
            assert_close(&format!("unlit-{mode:?}"), w, h, &actual, &expected, tol);
        }
        let unlit_in_the_dark: Vec<Option<[f64; 3]>> =
            draw(&dark, mode).into_iter().zip(&expected).map(|(d, e)| e.map(|_| d)).collect();
        assert_close(&format!("unlit-dark-{mode:?}"), w, h, &actual, &unlit_in_the_dark, 0.001);
        // The lit quad beside it does change with the light (so the light is on).
        let lit: Vec<usize> = (0..(w * h) as usize)
            .filter(|&i| inside(hit(&cam, w, h, i as u32 % w, i as u32 / w, 0.0), rects[1], 0.08))
            .collect();
        let g = lit.iter().map(|&i| actual[i][1]).sum::<f64>() / lit.len() as f64;
        assert!((g - 0.6).abs() > 0.05, "{mode:?}: the lit quad shows {g}, as if unlit");
    }
}

#[test]
fn a_measured_emission_spectrum_colours_its_surface_in_every_mode() {
    // Left: a constant grey emission with an illuminant-A spectrum (`extras.emission`); right:
    // the same spectrum under an emissive texture (the 2×2 texels' luminance scales it, as the
    // path tracer's `emitted` does). Both glow orange at their emissive luminance in every mode
    // and through the capture's loop; they showed the RGB colour (grey, red, …) before.
    let rects: [Rect; 2] = [(-2.0, -0.2, -1.0, 1.0), (0.2, 2.0, -1.0, 1.0)];
    let meshes: Vec<Mesh> = rects.iter().enumerate().map(|(i, r)| quad(*r, 0.0, true, i)).collect();
    let a = color::illuminant::by_name("A").unwrap();
    let mut materials = vec![material("constant", Vec4::ONE), material("textured", Vec4::ONE)];
    materials[0].emissive = Vec3::splat(0.6);
    materials[1].emissive = Vec3::splat(0.9);
    materials[1].emissive_texture = Some(scene::TextureRef::new(0));
    for m in &mut materials {
        m.emission_spectrum = Some(a.clone());
        m.base_color = Vec4::new(0.0, 0.0, 0.0, 1.0);
    }
    let s = scene(meshes, materials, vec![texture_2x2(nearest(Wrap::ClampToEdge))], vec![]);
    // Illuminant A's colour per unit luminance, from its dense XYZ (independent of either renderer).
    let xyz = scene::emission::spectrum_xyz(&a);
    let unit = scene::srgb::xyz_to_linear([xyz[0] / xyz[1], 1.0, xyz[2] / xyz[1]]);
    let (w, h) = (48, 24);
    let cam = top_camera(Vec2::ZERO, 1.1);
    let expected: Vec<Option<[f64; 3]>> = (0..h)
        .flat_map(|py| (0..w).map(move |px| (px, py)))
        .map(|(px, py)| {
            let p = hit(&cam, w, h, px, py, 0.0);
            let lum = if inside(p, rects[0], 0.08) {
                Some(0.6)
            } else if inside(p, rects[1], 0.08) {
                texel_at(uv_of(rects[1], p), Wrap::ClampToEdge, 0.1)
                    .map(|t| 0.9 * scene::srgb::luminance(glam::DVec3::from_array(t).as_vec3()))
            } else {
                None
            };
            lum.map(|l| (unit * l).to_array())
        })
        .collect();
    assert!(unit.x > 1.5 * unit.z, "illuminant A is orange: {unit}");
    for (mode, n) in [(Mode::Rgb, 16), (Mode::Spectral, 8), (Mode::Spectral, 16), (Mode::Naive, 16)] {
        let mut r = renderer();
        r.set_scene(&s).unwrap();
        r.resize(w, h).unwrap();
        let settings = RenderSettings { mode, wavelengths: n, shadows: false, ..Default::default() };
        r.render(&cam, &settings).unwrap();
        let actual: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
        assert_close(&format!("measured-emission-{mode:?}-{n}"), w, h, &actual, &expected, 0.01);
        if mode != Mode::Rgb {
            // The capture's loop (and every spectral hook's) draws it as the plain loop does.
            r.set_spectral_capture(true);
            r.render(&cam, &settings).unwrap();
            let captured: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
            r.set_spectral_capture(false);
            let plain: Vec<Option<[f64; 3]>> = actual.iter().map(|v| Some(*v)).collect();
            assert_close(&format!("measured-emission-captured-{mode:?}-{n}"), w, h, &captured, &plain, 0.002);
        }
    }
}

/// Emission is one-sided, towards the vertex normals, as in the path tracer: the back of a
/// double-sided lamp is black in every mode and loop (it glowed at full strength, found by a
/// sweep), whether its emission is fetched from the G-buffer, the material's constant or a
/// measured spectrum; its front still glows.
#[test]
fn a_double_sided_emitter_is_dark_from_behind_in_every_mode() {
    let rects: [Rect; 3] = [(-2.0, -0.8, -1.0, 1.0), (-0.6, 0.6, -1.0, 1.0), (0.8, 2.0, -1.0, 1.0)];
    let mut materials = vec![
        material("constant", Vec4::ONE),
        material("textured", Vec4::ONE),
        material("measured", Vec4::ONE),
    ];
    for m in &mut materials {
        m.double_sided = true;
        m.emissive = Vec3::splat(0.7);
        m.base_color = Vec4::new(0.0, 0.0, 0.0, 1.0);
    }
    materials[1].emissive_texture = Some(scene::TextureRef::new(0));
    materials[2].emission_spectrum = Some(color::illuminant::by_name("A").unwrap());
    let (w, h) = (48, 24);
    let cam = top_camera(Vec2::ZERO, 1.1);
    for facing_up in [false, true] {
        let meshes: Vec<Mesh> = rects.iter().enumerate().map(|(i, r)| quad(*r, 0.0, facing_up, i)).collect();
        let s = scene(meshes, materials.clone(), vec![texture_2x2(nearest(Wrap::ClampToEdge))], vec![]);
        for (mode, n) in [(Mode::Rgb, 16), (Mode::Spectral, 8), (Mode::Naive, 16)] {
            for capture in [false, true] {
                if capture && mode == Mode::Rgb {
                    continue;
                }
                let mut r = renderer();
                r.set_scene(&s).unwrap();
                r.resize(w, h).unwrap();
                r.set_spectral_capture(capture);
                let settings = RenderSettings { mode, wavelengths: n, shadows: false, ..Default::default() };
                r.render(&cam, &settings).unwrap();
                let px: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();
                // The middle row crosses all three quads.
                let row = &px[(h / 2 * w) as usize..((h / 2 + 1) * w) as usize];
                let lit = row.iter().filter(|p| p.iter().any(|&c| c > 0.05)).count();
                let brightest = px.iter().flatten().fold(0.0f64, |a, &c| a.max(c));
                if facing_up {
                    assert!(
                        lit > w as usize / 2,
                        "{mode:?} {n} capture {capture}: the front glows ({lit} of {w})"
                    );
                } else {
                    assert_eq!(brightest, 0.0, "{mode:?} {n} capture {capture}: the back is dark");
                }
            }
        }
    }
}

/// A mesh of no triangles (a scene built in code; the glTF loader skips them) draws nothing:
/// alone it made the upload name a vertex buffer that was never made (a panic).
#[test]
fn a_mesh_without_triangles_draws_nothing() {
    let mut empty = quad((-1.0, 1.0, -1.0, 1.0), 0.0, true, 0);
    empty.indices.clear();
    let lit = scene(vec![empty.clone()], vec![material("m", Vec4::ONE)], vec![], vec![sun(Vec3::NEG_Z, PI)]);
    let cam = top_camera(Vec2::ZERO, 1.1);
    assert!(render(&lit, &cam, 16, 12, false).iter().all(|p| *p == [0.0; 3]));
    // Beside a real quad, the quad is drawn.
    let both = Scene { meshes: vec![empty, quad((-1.0, 1.0, -1.0, 1.0), 0.0, true, 0)], ..lit };
    let img = render(&both, &cam, 16, 12, false);
    assert!((img[6 * 16 + 8][1] - 1.0).abs() < 0.01, "{:?}", img[6 * 16 + 8]);
}
