//! Material inputs through the G-buffer: base-colour texture × factor (sRGB-decoded) and
//! normal mapping through generated tangents, against the CPU BRDF.

mod common;

use common::*;
use glam::Vec3;
use render::{Mode, RenderSettings};
use scene::{Texture, TextureRef};

const W: u32 = 48;
const H: u32 = 32;

#[test]
fn textured_and_normal_mapped_patch_matches_cpu_brdf() {
    let chart = Chart { colours: vec![[1.0, 1.0, 1.0]], cols: 1, rows: 1, gap: 0.0 };
    // Tangent-space normal tilted 45° towards +u (the quad's +x), 8-bit encoded.
    let tilt = [218u8, 128, 218, 255];
    let base = [200u8, 100, 50, 255];
    let wi = Vec3::new(1.0, 0.0, 1.0).normalize();
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
    m.base_color = glam::Vec4::new(0.5, 1.0, 1.0, 1.0);
    m.base_color_texture = Some(TextureRef { transform: None, index: 0, tex_coord: 0 });
    m.normal_texture = Some(TextureRef { transform: None, index: 1, tex_coord: 0 });

    let mut r = renderer();
    r.set_scene(&scene).unwrap();
    r.resize(W, H).unwrap();
    let s = RenderSettings { mode: Mode::Rgb, shadows: false, ..Default::default() };
    r.render(&scene.camera, &s).unwrap();
    let actual: Vec<[f64; 3]> = r.read_hdr().unwrap().iter().map(rgb_of).collect();

    let albedo = [decode8(base[0]) * 0.5, decode8(base[1]), decode8(base[2])];
    let tn = Vec3::new(
        tilt[0] as f32 / 255.0 * 2.0 - 1.0,
        tilt[1] as f32 / 255.0 * 2.0 - 1.0,
        tilt[2] as f32 / 255.0 * 2.0 - 1.0,
    );
    // Tangent +x, bitangent +y (v runs downwards in the image, up the quad: glTF convention),
    // normal +z.
    let n = tn.normalize();
    let mut expected = Vec::new();
    let mut flat_ratio = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let (p, d) = pixel_to_chart(x, y, W, H);
            expected.push(chart.patch_at(p, 0.05).map(|_| {
                let (a, b) = brdf_factors(n, -d, wi, 0.0, 0.7);
                let (fa, fb) = brdf_factors(Vec3::Z, -d, wi, 0.0, 0.7);
                flat_ratio.push((albedo[1] * a + b) / (albedo[1] * fa + fb));
                albedo.map(|c| (c * a + b) * 2.0)
            }));
        }
    }
    let c = (H / 2 * W + W / 2) as usize;
    println!("centre: actual {:?} expected {:?}", actual[c], expected[c]);
    assert_delta_e("normal-mapped", W, H, &actual, &expected, 0.1, 0.3);
    // The tilt towards the light must matter (≈ 1/cos 45°), or the test proves nothing.
    assert!(flat_ratio.iter().all(|&k| k > 1.3), "normal map barely changes shading: {:?}", &flat_ratio[..3]);
}

/// A normal map whose normal faces away from the viewer (a texel whose tangent-space z is
/// negative, as a strong bump seen at a grazing angle gives) shades with the face's own normal,
/// the path tracer's rule: the patch draws as it does without the map, whatever the texel's
/// tilt. Its base colour is lit from the side the texel tilts to, where the mapped normal would
/// catch more light than the face's.
#[test]
fn a_normal_facing_away_from_the_viewer_gives_way_to_the_faces() {
    let chart = Chart { colours: vec![[1.0, 1.0, 1.0]], cols: 1, rows: 1, gap: 0.0 };
    let wi = Vec3::new(1.0, 0.0, 0.4).normalize();
    let mut scene = chart.scene(white_light(2.0, None), 0.5, 0.0);
    scene.lights[0].kind = scene::LightKind::Directional { direction: -wi };
    scene.materials[0].base_color = glam::Vec4::new(0.6, 0.5, 0.4, 1.0);
    let mut r = renderer();
    let s = RenderSettings { mode: Mode::Rgb, shadows: false, ..Default::default() };
    let mut draw = |scene: &scene::Scene| -> Vec<[f64; 3]> {
        r.set_scene(scene).unwrap();
        r.resize(W, H).unwrap();
        r.render(&scene.camera, &s).unwrap();
        r.read_hdr().unwrap().iter().map(rgb_of).collect()
    };
    let plain = draw(&scene);
    let expected: Vec<Option<[f64; 3]>> = (0..H)
        .flat_map(|y| (0..W).map(move |x| (x, y)))
        .zip(&plain)
        .map(|((x, y), &p)| chart.patch_at(pixel_to_chart(x, y, W, H).0, 0.05).map(|_| p))
        .collect();
    assert!(plain.iter().any(|p| p[0] > 0.05), "the patch is not lit");
    // (1, 0, −0.69): tilted past the surface towards +u, the light's side.
    scene.textures = vec![texel_texture("away", [255, 128, 40, 255], false)];
    scene.materials[0].normal_texture = Some(TextureRef { transform: None, index: 0, tex_coord: 0 });
    let mapped = draw(&scene);
    assert_delta_e("normal-facing-away", W, H, &mapped, &expected, 0.01, 0.05);
    // A legitimate tilt towards the light still shows.
    scene.textures = vec![texel_texture("tilt", [218, 128, 218, 255], false)];
    let tilted = draw(&scene);
    let c = (H / 2 * W + W / 2) as usize;
    assert!(tilted[c][0] > 1.2 * plain[c][0], "{:?} vs {:?}", tilted[c], plain[c]);
}
