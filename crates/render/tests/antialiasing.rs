//! Where a pixel looks (`RenderSettings::pixel_offset`) and the mean of frames looking all over
//! it: an orthographic camera sees an unlit white quad on black whose corner lies 0.3 pixel
//! into pixel (10, 8) on both axes. A pixel centre moved left or up onto the quad sees white,
//! moved right or down off it black (so the offset's axes point right and down, as pixel
//! coordinates do); the mean of a 4 × 4 grid of offsets gives the edge pixels the share of the
//! grid that falls on the quad — ¼ beside the edges, 1/16 at the corner — and leaves the pixels
//! away from the edges exactly as one frame draws them.

mod common;

use common::*;
use glam::{Vec3, Vec4};
use render::{Mode, RenderSettings};
use scene::{Material, Mesh, Scene, SpectralSettings};

const W: u32 = 40;
const H: u32 = 32;
const EDGE_X: u32 = 10;
const EDGE_Y: u32 = 8;
const INTO: f32 = 0.3;

fn scene() -> Scene {
    // 0.05 scene units per pixel: x from −1 (left) to 1, y from 0.8 (top) to −0.8.
    let px = 0.05f32;
    let right = -1.0 + (EDGE_X as f32 + INTO) * px;
    let bottom = 0.8 - (EDGE_Y as f32 + INTO) * px;
    Scene {
        warnings: vec![],
        source: "test:antialiasing".into(),
        meshes: vec![Mesh::quad(
            Vec3::new(-4.0, bottom, 0.0),
            Vec3::X * (right + 4.0),
            Vec3::Y * (4.0 - bottom),
            0,
        )],
        materials: vec![Material {
            name: "white".into(),
            base_color: Vec4::ONE,
            unlit: true,
            ..Default::default()
        }],
        textures: vec![],
        lights: vec![],
        camera: common::front_ortho_camera(),
        spectral: SpectralSettings::default(),
        water: None,
        environment: None,
        medium: None,
        inputs: vec![],
        origin: glam::DVec3::ZERO,
        input_stamps: vec![],
        choices: vec![],
        animation_end: None,
    }
}

fn settings(mode: Mode, offset: Option<[f32; 2]>) -> RenderSettings {
    RenderSettings { mode, shadows: false, pixel_offset: offset, ..Default::default() }
}

fn grey(px: [f32; 4]) -> f64 {
    f64::from(px[1])
}

#[test]
fn a_pixel_offset_moves_where_the_pixel_looks_and_the_mean_covers_the_pixel() {
    let s = scene();
    let mut r = renderer();
    r.set_scene(&s).unwrap();
    r.resize(W, H).unwrap();
    let at = |img: &[[f32; 4]], x: u32, y: u32| grey(img[(y * W + x) as usize]);
    for mode in [Mode::Rgb, Mode::Spectral] {
        r.set_accumulation(false);
        r.render(&s.camera, &settings(mode, None)).unwrap();
        let centre = r.read_hdr().unwrap();
        // The centres of the edge pixels lie off the quad; the inside pixels are white.
        assert!(at(&centre, EDGE_X, 4) < 1e-6 && at(&centre, 4, EDGE_Y) < 1e-6, "{mode:?}");
        let white = at(&centre, 4, 4);
        assert!((white - 1.0).abs() < 5e-3, "{mode:?}: white is {white}");
        let (column, row, corner) = ((EDGE_X, 4), (4, EDGE_Y), (EDGE_X, EDGE_Y));
        for (pixel, offset, sees_white) in [
            (column, [-0.3, 0.0], true),
            (column, [0.3, 0.0], false),
            (row, [0.0, -0.3], true),
            (row, [0.0, 0.3], false),
            (corner, [-0.45, -0.45], true),
            (corner, [-0.45, 0.45], false),
            (corner, [0.45, -0.45], false),
        ] {
            r.render(&s.camera, &settings(mode, Some(offset))).unwrap();
            let img = r.read_hdr().unwrap();
            let v = at(&img, pixel.0, pixel.1);
            assert_eq!(v > 0.5 * white, sees_white, "{mode:?} offset {offset:?}: pixel {pixel:?} is {v}");
        }
        r.set_accumulation(true);
        let cell = |j: u32| (j as f32 + 0.5) / 4.0 - 0.5;
        for i in 0..16 {
            r.render(&s.camera, &settings(mode, Some([cell(i % 4), cell(i / 4)]))).unwrap();
        }
        let mean = r.read_accumulated().unwrap();
        // Sample columns at 0.125, 0.375, 0.625, 0.875 of the pixel: one of four left of 0.3.
        let close = |got: f64, want: f64, what: &str| {
            assert!((got - want).abs() < 5e-3, "{mode:?} {what}: {got} vs {want}");
        };
        close(at(&mean, EDGE_X, 4), 0.25 * white, "edge column");
        close(at(&mean, 4, EDGE_Y), 0.25 * white, "edge row");
        close(at(&mean, EDGE_X, EDGE_Y), white / 16.0, "corner");
        for (x, y) in [(4, 4), (2, 20), (30, 4), (30, 20)] {
            assert_eq!(at(&mean, x, y), at(&centre, x, y), "{mode:?}: pixel ({x}, {y}) away from the edges");
        }
    }
}

/// `texture_lod_bias` reads material textures at a finer level: an unlit quad filling the view
/// with 256² texels of one-texel black and white columns (6.4 texels per pixel across, 8 down:
/// level 3) is a uniform grey at the pixel's own level (the mips average the columns away) and
/// shows the columns again three levels finer. (Columns, not a checker: the pixel centres fall
/// half-way between texel rows, where a bilinear checker is grey at every level.)
#[test]
fn a_negative_lod_bias_reads_finer_texture_levels() {
    const N: usize = 256;
    let mut s = scene();
    let mut rgba = Vec::with_capacity(N * N * 4);
    for _row in 0..N {
        for x in 0..N {
            let v = if x % 2 == 0 { 255 } else { 0 };
            rgba.extend_from_slice(&[v, v, v, 255]);
        }
    }
    s.textures.push(scene::Texture {
        sampler: Default::default(),
        name: "checker".into(),
        width: N as u32,
        height: N as u32,
        rgba8: rgba,
        srgb: true,
    });
    s.materials[0].base_color_texture = Some(scene::TextureRef { transform: None, index: 0, tex_coord: 0 });
    // Filling the view: x from −1 to 1, y from −0.8 to 0.8.
    s.meshes = vec![Mesh::quad(Vec3::new(-1.0, -0.8, 0.0), Vec3::X * 2.0, Vec3::Y * 1.6, 0)];
    let mut r = renderer();
    r.set_scene(&s).unwrap();
    r.resize(W, H).unwrap();
    let mut spread = |bias: f32| {
        let st = RenderSettings { texture_lod_bias: bias, ..settings(Mode::Rgb, None) };
        r.render(&s.camera, &st).unwrap();
        let v: Vec<f64> = r.read_hdr().unwrap().into_iter().map(grey).collect();
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
    };
    let (coarse, fine) = (spread(0.0), spread(-3.0));
    assert!(coarse < 0.05, "at the pixel's level the checker should average out: spread {coarse}");
    assert!(fine > 0.15, "three levels finer the checker should show: spread {fine}");
}
