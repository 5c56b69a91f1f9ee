//! Shadows from several lights: each light has its own shadow map, so an occluder that blocks
//! light B but not light A leaves exactly A's analytic contribution; a stand-in light shadows
//! like any other but not through its own emissive mesh; every light up to
//! `passes::shadow::MAX_SHADOWS` (all the lights the shading pass draws) has its map.

mod common;

use common::*;
use glam::{Vec2, Vec3, Vec4};
use render::passes::shadow::MAX_SHADOWS;
use render::{Mode, RenderSettings, Renderer};
use scene::{Light, LightKind, Material, Mesh, Scene};

const W: u32 = 128;
const H: u32 = 96;
/// Pixels compared are this far (world units, ≈ 1.5 px) from every shadow or patch edge.
const MARGIN: f32 = 0.08;
/// Light B comes from the upper left: a point at height z shadows the chart at
/// (x + 0.3·z, y − 0.3·z).
const DIR_B: Vec3 = Vec3::new(0.3, -0.3, -1.0);
const E_A: f32 = 1.0;
const E_B: f32 = 1.5;

/// Axis-aligned rectangle (x0, x1, y0, y1) on or parallel to the chart.
type Rect = (f32, f32, f32, f32);

fn inside(p: Vec2, r: Rect, margin: f32) -> bool {
    p.x > r.0 + margin && p.x < r.1 - margin && p.y > r.2 + margin && p.y < r.3 - margin
}

/// The rectangle at height `z` shadowed from light B on the chart (z = 0).
fn shadow_of(r: Rect, z: f32) -> Rect {
    (r.0 + 0.3 * z, r.1 + 0.3 * z, r.2 - 0.3 * z, r.3 - 0.3 * z)
}

/// The chart region the camera (on the +z axis at `CAMERA_DISTANCE`) cannot see behind `r`.
fn hidden_by(r: Rect, z: f32) -> Rect {
    let s = CAMERA_DISTANCE / (CAMERA_DISTANCE - z);
    (r.0 * s, r.1 * s, r.2 * s, r.3 * s)
}

fn quad(r: Rect, z: f32, material: usize) -> Mesh {
    Mesh {
        colors: vec![],
        uvs1: vec![],
        positions: vec![
            Vec3::new(r.0, r.2, z),
            Vec3::new(r.1, r.2, z),
            Vec3::new(r.1, r.3, z),
            Vec3::new(r.0, r.3, z),
        ],
        normals: vec![Vec3::Z; 4],
        tangents: vec![],
        uvs: vec![Vec2::ZERO; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        material,
    }
}

/// Occluder: a black square at z = 1.5 (blocks B over patch 15, and A only where the camera
/// cannot see). Lamp: an emissive square at z = 3 that light B stands in for; were it drawn
/// into B's own map it would shadow patch 11.
const OCCLUDER: (Rect, f32) = ((-1.0, 0.0, -0.5, 0.5), 1.5);
const LAMP: (Rect, f32) = ((1.5, 2.0, 1.0, 1.5), 3.0);

fn directional(name: &str, direction: Vec3, intensity: f32) -> Light {
    Light {
        name: name.into(),
        kind: LightKind::Directional { direction: direction.normalize() },
        emission: white_light(intensity, None),
        stands_in_for: None,
    }
}

/// The chart lit by `lights_a` (all along −z, `E_A` in total) and then light B (a stand-in for
/// the lamp mesh), with the occluder and the lamp in front of it.
fn scene(n_a: usize) -> (Scene, Chart) {
    let chart = Chart::colorchecker();
    let mut s = chart.scene(white_light(1.0, None), 1.0, 0.0);
    s.lights = (0..n_a).map(|i| directional(&format!("A{i}"), Vec3::NEG_Z, E_A / n_a as f32)).collect();
    let occluder_mat = s.materials.len();
    s.materials.push(Material { name: "occluder".into(), base_color: Vec4::ZERO, ..Default::default() });
    let lamp_mat = s.materials.len();
    s.materials.push(Material {
        name: "lamp".into(),
        base_color: Vec4::ZERO,
        emissive: Vec3::ONE,
        ..Default::default()
    });
    s.meshes.push(quad(OCCLUDER.0, OCCLUDER.1, occluder_mat));
    let lamp_mesh = s.meshes.len();
    s.meshes.push(quad(LAMP.0, LAMP.1, lamp_mat));
    s.lights.push(Light { stands_in_for: Some(lamp_mesh), ..directional("B", DIR_B, E_B) });
    (s, chart)
}

fn render(r: &mut Renderer, shadows: bool) -> Vec<[f64; 3]> {
    let cam = r.scene_camera().unwrap();
    r.render(&cam, &RenderSettings { mode: Mode::Rgb, shadows, ..Default::default() }).unwrap();
    r.read_hdr().unwrap().iter().map(rgb_of).collect()
}

/// Where a pixel lands relative to the shadows (`None`: near an edge or not on a patch).
#[derive(Clone, Copy, PartialEq, Debug)]
enum Zone {
    /// Light B blocked by the occluder, light A not.
    ShadowB,
    /// Where the lamp would shadow B if it were drawn into B's map.
    LampShadow,
    /// Nothing blocks either light.
    Lit,
}

fn zone(chart: &Chart, p: Vec2) -> Option<Zone> {
    chart.patch_at(p, MARGIN)?;
    let (occ, oz) = OCCLUDER;
    let (lamp, lz) = LAMP;
    if inside(p, hidden_by(occ, oz), -MARGIN) || inside(p, hidden_by(lamp, lz), -MARGIN) {
        return None;
    }
    if inside(p, shadow_of(occ, oz), MARGIN) {
        return Some(Zone::ShadowB);
    }
    if inside(p, shadow_of(lamp, lz), MARGIN) {
        return Some(Zone::LampShadow);
    }
    if inside(p, shadow_of(occ, oz), -MARGIN) || inside(p, shadow_of(lamp, lz), -MARGIN) {
        return None;
    }
    Some(Zone::Lit)
}

/// Analytic radiance of `albedo` seen along `d` from the lights listed (direction, illuminance).
fn analytic(albedo: [f32; 3], d: Vec3, lights: &[(Vec3, f32)]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for &(dir, e) in lights {
        let (a, b) = brdf_factors(Vec3::Z, -d, -dir.normalize(), 0.0, 1.0);
        for c in 0..3 {
            out[c] += (albedo[c] as f64 * a + b) * e as f64;
        }
    }
    out
}

/// Renders the scene with `n_a` A lights and compares every classified pixel with the analytic
/// value where B is blocked in `ShadowB` pixels iff `b_shadowed`. Returns pixel counts per zone.
fn check(name: &str, n_a: usize, b_shadowed: bool) -> [usize; 3] {
    check_on(&mut renderer(), name, n_a, b_shadowed)
}

/// `check` with renderer `r` (which may have drawn other scenes before).
fn check_on(r: &mut Renderer, name: &str, n_a: usize, b_shadowed: bool) -> [usize; 3] {
    let (s, chart) = scene(n_a);
    r.set_scene(&s).unwrap();
    r.resize(W, H).unwrap();
    let actual = render(r, true);
    let mut counts = [0; 3];
    let expected: Vec<Option<[f64; 3]>> = (0..W * H)
        .map(|i| {
            let (p, d) = pixel_to_chart(i % W, i / W, W, H);
            let z = zone(&chart, p)?;
            counts[z as usize] += 1;
            let albedo = chart.colours[chart.patch_at(p, MARGIN)?];
            let a_only = [(Vec3::NEG_Z, E_A)];
            let both = [(Vec3::NEG_Z, E_A), (DIR_B, E_B)];
            Some(analytic(albedo, d, if z == Zone::ShadowB && b_shadowed { &a_only } else { &both }))
        })
        .collect();
    // Only f16 storage rounding separates rendering and reference where the maps are exact.
    assert_delta_e(name, W, H, &actual, &expected, 0.05, 0.15);
    counts
}

#[test]
fn every_light_casts_its_own_shadow() {
    let counts = check("shadows-two-lights", 1, true);
    assert!(counts.iter().all(|&c| c >= 15), "pixels per zone (shadow B, lamp, lit): {counts:?}");
}

#[test]
fn every_light_up_to_the_maximum_has_its_map() {
    // MAX_SHADOWS − 1 A lights and B: B's is the last layer. The same renderer drew a scene of
    // two maps first, so its depth array is made again with more layers (and the shading
    // pass's inputs with it); a renderer that kept the old array leaves B unshadowed.
    let mut r = renderer();
    check_on(&mut r, "shadows-two-layers-first", 1, true);
    let counts = check_on(&mut r, "shadows-every-layer", MAX_SHADOWS - 1, true);
    assert!(counts[0] >= 15, "pixels in B's shadow zone: {counts:?}");
    // And back to fewer layers.
    check_on(&mut r, "shadows-two-layers-again", 1, true);
}

#[test]
fn shadows_off_lights_everything() {
    let (s, chart) = scene(1);
    let mut r = renderer();
    r.set_scene(&s).unwrap();
    r.resize(W, H).unwrap();
    let (on, off) = (render(&mut r, true), render(&mut r, false));
    let mut darker = 0;
    for i in 0..(W * H) as usize {
        let (p, _) = pixel_to_chart(i as u32 % W, i as u32 / W, W, H);
        if zone(&chart, p) == Some(Zone::ShadowB) {
            assert!(on[i][1] < 0.7 * off[i][1], "pixel {i} at {p}: {} vs {}", on[i][1], off[i][1]);
            darker += 1;
        }
    }
    assert!(darker >= 15, "{darker} pixels in B's shadow");
}

/// The shadow maps are drawn once per scene and setting and kept while neither changes (they do
/// not depend on the camera): a second frame, shadows off and on again, and a new scene with
/// light B from another side all give the image a fresh renderer gives.
#[test]
fn cached_shadow_maps_follow_the_scene_and_the_setting() {
    let fresh = |s: &Scene, shadows: bool| {
        let mut r = renderer();
        r.set_scene(s).unwrap();
        r.resize(W, H).unwrap();
        render(&mut r, shadows)
    };
    let (s, _) = scene(1);
    let mut r = renderer();
    r.set_scene(&s).unwrap();
    r.resize(W, H).unwrap();
    let first = render(&mut r, true);
    assert_eq!(render(&mut r, true), first, "second frame");
    let off = render(&mut r, false);
    assert_ne!(off, first, "shadows off changes the image");
    assert_eq!(off, fresh(&s, false), "shadows off");
    assert_eq!(render(&mut r, true), first, "shadows on again");
    // Light B from the other side: its shadow moves.
    let mut moved = s.clone();
    let b = moved.lights.last_mut().unwrap();
    b.kind = LightKind::Directional { direction: Vec3::new(-0.3, 0.3, -1.0).normalize() };
    r.set_scene(&moved).unwrap();
    let after = render(&mut r, true);
    assert_ne!(after, first, "the moved light's shadow");
    assert_eq!(after, fresh(&moved, true), "new scene");
}
