//! Both renderers draw the same scene because the scene owns its conventions (issue 16): a mesh
//! that comes without normals is faceted in both (glTF: flat normals), and `spectra.white` is
//! read by both. Block means (8×8) against the path tracer's direct lighting.

use super::measure;
use compare::Image;
use glam::{Vec3, Vec4};
use render::{Mode, RenderSettings, Renderer};
use scene::{Camera, Emission, Light, LightKind, Material, Mesh, Scene, SpectralSettings};
use std::sync::atomic::AtomicBool;

const SIZE: u32 = 64;
const BLOCK: u32 = 8;

/// A bumpy height field filling the view, as a shared-vertex grid with no normals: smoothing
/// its vertex normals and faceting it shade visibly differently under an oblique sun.
fn bumps() -> Mesh {
    let n = 6;
    let at = |i: usize| -1.2 + 2.4 * i as f32 / n as f32;
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (at(i), at(j));
            positions.push(Vec3::new(x, y, 0.2 * (3.1 * x).sin() * (2.6 * y + 0.4).cos()));
        }
    }
    let mut indices = Vec::new();
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let v = j * (n as u32 + 1) + i;
            let up = v + n as u32 + 1;
            indices.extend([v, v + 1, up + 1, v, up + 1, up]);
        }
    }
    Mesh { positions, indices, material: 0, ..Mesh::default() }
}

fn scene(mesh: Mesh, white: &str) -> Scene {
    let sun = Light {
        name: "sun".into(),
        // Light from 20° off the vertical: steeper than any slope of the field, so nothing is
        // in shadow and only the normals decide the shading.
        kind: LightKind::Directional { direction: Vec3::new(0.25, 0.22, -1.0).normalize() },
        emission: Emission::new(Vec3::ONE, std::f32::consts::PI, None).unwrap(),
        stands_in_for: None,
    };
    Scene {
        source: "test:bumps".into(),
        meshes: vec![mesh],
        materials: vec![Material {
            name: "grey".into(),
            // Grey: a flat spectrum, so N nodes integrate it exactly and only geometry and the
            // white's units can make the renderers differ.
            base_color: Vec4::new(0.5, 0.5, 0.5, 1.0),
            roughness: 1.0,
            metallic: 0.0,
            ..Material::default()
        }],
        textures: vec![],
        lights: vec![sun],
        camera: Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 0.5),
        spectral: SpectralSettings { white: Some(white.into()), ..SpectralSettings::default() },
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

fn table() -> std::sync::Arc<color::upsample::CoeffTable> {
    color::upsample::table("srgb").expect("the sRGB upsampling table")
}

fn truth(s: &Scene) -> Image {
    let mut st = truth::Settings::new(SIZE, SIZE, 64).unwrap();
    st.direct_only = true;
    st.lambert = true;
    st.white = color::illuminant::by_name(s.spectral.white_name()).unwrap();
    let t = table();
    let world = truth::World::new(s, t.as_ref(), &st.white, st.range, None).unwrap();
    let img = truth::render_world(&world, &st, &AtomicBool::new(false), &|_| {}).unwrap();
    Image::new(SIZE, SIZE, img.to_display(&st, color::film::CameraView::Balanced).unwrap()).unwrap()
}

fn realtime(s: &Scene) -> Image {
    let mut r = Renderer::with_table(table()).unwrap_or_else(|e| {
        panic!("no GPU adapter ({e}); install a Vulkan driver, e.g. apt-get install mesa-vulkan-drivers")
    });
    r.resize(SIZE, SIZE).unwrap();
    r.set_scene(s).unwrap();
    let settings = RenderSettings {
        white: s.spectral.white_name().into(),
        lambert: true,
        shadows: false,
        env_occlusion: false,
        ..measure::settings(Mode::Spectral, 16, color::WavelengthRange::VISIBLE)
    };
    measure::realtime(&mut r, s, &settings).unwrap()
}

fn block_de(reference: &Image, test: &Image) -> f64 {
    let (a, b) = (reference.block_mean(BLOCK).unwrap(), test.block_mean(BLOCK).unwrap());
    let maps = measure::diff(&a, &b).unwrap();
    maps.delta_e2000.iter().sum::<f64>() / maps.delta_e2000.len() as f64
}

/// Area-weighted vertex normals: what the real-time renderer made of a mesh without normals
/// before the scene owned the convention (the path tracer faceted it).
fn smoothed(mut m: Mesh) -> Mesh {
    let mut n = vec![Vec3::ZERO; m.positions.len()];
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
        for &i in t {
            n[i as usize] += (b - a).cross(c - a);
        }
    }
    m.normals = n.into_iter().map(|v| v.normalize_or(Vec3::Z)).collect();
    m
}

#[test]
fn a_mesh_without_normals_under_a_d50_white_renders_the_same_in_both() {
    let s = scene(bumps(), "D50");
    let t = truth(&s);
    let de = block_de(&t, &realtime(&s));
    // The old disagreement, rendered on purpose: the GPU's smoothed normals against the
    // tracer's facets. It must be far above the bound, or this test could not catch it.
    let old = block_de(&t, &realtime(&scene(smoothed(bumps()), "D50")));
    eprintln!("block-mean ΔE2000 against truth: {de:.3} (smoothed normals, the old GPU: {old:.3})");
    assert!(old > 0.3, "the smoothed control differs by only {old:.3}: the scene cannot tell the two apart");
    assert!(de <= 0.1, "block-mean ΔE2000 {de:.3} > 0.1");
    // The white is honoured by both: under D65 the same RGB scene has the same colours (the
    // white sets the units only, `RgbColorSpace::emission_white`).
    let d65 = scene(bumps(), "D65");
    let de65 = block_de(&realtime(&d65), &realtime(&s));
    assert!(de65 <= 0.01, "D50 vs D65 white, real time: {de65:.4}");
}
