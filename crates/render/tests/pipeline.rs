//! Pipeline behaviour: runtime switching of modes and wavelengths, the custom extension point,
//! shadows, tone mapping and sRGB output, timestamps, and error reporting.

mod common;

use common::*;
use glam::{Vec2, Vec3, Vec4};
use render::{CustomShader, Mode, RenderSettings, Renderer, Tonemap};
use scene::{Material, Mesh};

const W: u32 = 48;
const H: u32 = 32;

fn chart_renderer(intensity: f32) -> (Renderer, Chart) {
    let chart = Chart::colorchecker();
    let mut r = renderer();
    r.set_scene(&chart.scene(white_light(intensity, None), 1.0, 0.0)).unwrap();
    r.resize(W, H).unwrap();
    (r, chart)
}

fn hdr(r: &mut Renderer, s: &RenderSettings) -> Vec<[f64; 3]> {
    let cam = r.scene_camera().unwrap();
    r.render(&cam, s).unwrap();
    r.read_hdr().unwrap().iter().map(rgb_of).collect()
}

fn centre_pixel_of_patch(chart: &Chart, patch: usize) -> usize {
    (0..W * H)
        .find(|&i| chart.patch_at(pixel_to_chart(i % W, i / W, W, H).0, 0.3) == Some(patch))
        .expect("patch visible") as usize
}

#[test]
fn modes_wavelengths_and_range_switch_per_frame() {
    let (mut r, chart) = chart_renderer(1.0);
    let red = centre_pixel_of_patch(&chart, 14);
    let base = RenderSettings { shadows: false, ..Default::default() };
    let mut seen = Vec::new();
    for s in [
        RenderSettings { mode: Mode::Rgb, ..base.clone() },
        RenderSettings { mode: Mode::Spectral, wavelengths: 1, ..base.clone() },
        RenderSettings { mode: Mode::Spectral, wavelengths: 7, ..base.clone() },
        RenderSettings { mode: Mode::Spectral, wavelengths: 64, ..base.clone() },
        RenderSettings { mode: Mode::Naive, wavelengths: 16, ..base.clone() },
        RenderSettings {
            mode: Mode::Spectral,
            wavelengths: 16,
            range: color::WavelengthRange::new(400.0, 700.0).unwrap(),
            ..base.clone()
        },
    ] {
        let img = hdr(&mut r, &s);
        assert!(img.iter().all(|p| p.iter().all(|v| v.is_finite())), "{s:?} produced non-finite pixels");
        assert_eq!(r.spectral_setup().unwrap().len(), s.wavelengths);
        seen.push(img[red]);
    }
    // N = 1 integrates one wavelength: every colour collapses onto the white's chromaticity,
    // so the red patch comes out grey.
    let n1 = seen[1];
    assert!((n1[0] - n1[1]).abs() < 1e-3 && (n1[1] - n1[2]).abs() < 1e-3, "N=1 red patch {n1:?}");
    // Everything else keeps the patch red.
    for (i, p) in seen.iter().enumerate().filter(|(i, _)| *i != 1) {
        assert!(p[0] > 2.0 * p[1] && p[0] > 2.0 * p[2], "setting {i}: red patch is {p:?}");
    }
}

#[test]
fn custom_hooks_change_the_image_and_bad_code_is_an_error() {
    let (mut r, chart) = chart_renderer(1.0);
    let white = centre_pixel_of_patch(&chart, 18);
    let s = RenderSettings { shadows: false, ..Default::default() };
    let before = hdr(&mut r, &s)[white];

    // Pass 3 hook scaled by a parameter; pass 2 hook removes everything above 600 nm.
    let src = r#"
fn custom_spectral(lambda: vec4<f32>, radiance: mat3x4<f32>, group: u32, ctx: SurfaceContext) -> mat3x4<f32> {
    return s3_scale(radiance, select(vec4<f32>(1.0), vec4<f32>(0.0), lambda > vec4<f32>(600.0)));
}
fn custom_rgb(radiance: vec3<f32>, ctx: SurfaceContext) -> vec3<f32> { return radiance; }
fn custom_pixel(hdr: vec4<f32>, ctx: SurfaceContext) -> vec4<f32> {
    return vec4<f32>(hdr.rgb * custom.params[0].x, hdr.a);
}
"#;
    let mut custom = CustomShader::new(src);
    custom.params[0] = 0.5;
    r.set_custom_shader(custom).unwrap();
    let after = hdr(&mut r, &s)[white];
    // No long wavelengths: the white patch turns cyan (red drops far more than blue).
    assert!(after[0] < 0.5 * after[2], "white patch without λ > 600 nm: {after:?} (before {before:?})");

    // In rgb mode only the pass-3 hook applies: exactly half, then a quarter after changing
    // the parameter without recompiling.
    let rgb_s = RenderSettings { mode: Mode::Rgb, ..s.clone() };
    let half = hdr(&mut r, &rgb_s)[white];
    let mut params = [0.0; 16];
    params[0] = 0.25;
    r.set_custom_params(params);
    let quarter = hdr(&mut r, &rgb_s)[white];
    r.set_custom_shader(CustomShader::default()).unwrap();
    let full = hdr(&mut r, &rgb_s)[white];
    for c in 0..3 {
        assert!((half[c] - 0.5 * full[c]).abs() < 2e-3 * full[c].max(1e-3), "{half:?} vs {full:?}");
        assert!((quarter[c] - 0.25 * full[c]).abs() < 2e-3 * full[c].max(1e-3), "{quarter:?} vs {full:?}");
    }

    let err = r.set_custom_shader(CustomShader::new("fn custom_pixel( oops")).unwrap_err().to_string();
    assert!(err.contains("custom shader"), "{err}");
    // The previous shader is still in place and rendering still works.
    assert_eq!(hdr(&mut r, &rgb_s)[white], full);
}

#[test]
fn occluder_casts_a_shadow_from_the_main_light() {
    let chart = Chart::colorchecker();
    let mut scene = chart.scene(white_light(1.0, None), 1.0, 0.0);
    // A light slanted from the upper left, and a small square floating in front of the chart.
    scene.lights[0].kind =
        scene::LightKind::Directional { direction: Vec3::new(0.3, -0.3, -1.0).normalize() };
    let z = 1.5;
    scene.meshes.push(Mesh {
        colors: vec![],
        uvs1: vec![],
        positions: vec![
            Vec3::new(-1.0, -0.5, z),
            Vec3::new(0.0, -0.5, z),
            Vec3::new(0.0, 0.5, z),
            Vec3::new(-1.0, 0.5, z),
        ],
        normals: vec![Vec3::Z; 4],
        tangents: vec![],
        uvs: vec![Vec2::ZERO; 4],
        indices: vec![0, 1, 2, 0, 2, 3],
        material: scene.materials.len(),
    });
    scene.materials.push(Material { name: "occluder".into(), base_color: Vec4::ZERO, ..Default::default() });
    let mut r = renderer();
    r.set_scene(&scene).unwrap();
    r.resize(W * 2, H * 2).unwrap();
    let s = RenderSettings { mode: Mode::Rgb, ..Default::default() };
    let lit = hdr(&mut r, &RenderSettings { shadows: false, ..s.clone() });
    let shadowed = hdr(&mut r, &s);
    // The shadow falls at occluder + 1.5·(0.3, −0.3)/1 → centred near (−0.05, −0.45) on the chart;
    // the occluder itself hides (−1..0, −0.5..0.5) as seen from the camera (almost straight on).
    let (w, h) = (W * 2, H * 2);
    let mut darkened = 0;
    let mut unchanged_far = 0;
    for y in 0..h {
        for x in 0..w {
            let (p, _) = pixel_to_chart(x, y, w, h);
            let i = (y * w + x) as usize;
            let in_shadow = p.x > 0.1 && p.x < 0.35 && p.y > -0.85 && p.y < -0.05;
            let far = p.x > 1.5 || p.y > 1.2;
            if in_shadow && chart.patch_at(p, 0.05).is_some() {
                assert!(shadowed[i][1] < 0.02 * lit[i][1] + 1e-4, "pixel {x},{y} at {p} not in shadow");
                darkened += 1;
            }
            if far && chart.patch_at(p, 0.05).is_some() {
                assert!(
                    (shadowed[i][1] - lit[i][1]).abs() < 1e-3 * lit[i][1].max(1e-2),
                    "pixel {x},{y} at {p} shadowed"
                );
                unchanged_far += 1;
            }
        }
    }
    assert!(darkened > 10 && unchanged_far > 100, "{darkened} shadowed, {unchanged_far} lit pixels checked");
}

/// The exposure is applied as the radiance is written to the half-float target (2^EV times the
/// unexposed frame, to the f16 rounding of each), then post tone maps and encodes what the
/// target holds.
#[test]
fn post_applies_exposure_tonemap_and_srgb() {
    let (mut r, _) = chart_renderer(2.0);
    let unexposed = hdr(&mut r, &RenderSettings { mode: Mode::Rgb, ..Default::default() });
    for (tonemap, ev) in [(Tonemap::None, 0.0f32), (Tonemap::Reinhard, 1.0), (Tonemap::Aces, -0.5)] {
        let s = RenderSettings { mode: Mode::Rgb, tonemap, exposure_ev: ev, ..Default::default() };
        let cam = r.scene_camera().unwrap();
        r.render(&cam, &s).unwrap();
        let hdr = r.read_hdr().unwrap();
        let ldr = r.read_ldr().unwrap();
        let k = ev.exp2() as f64;
        for (p, u) in hdr.iter().zip(&unexposed) {
            for c in 0..3 {
                // One f16 rounding on each side (lavapipe truncates): two units in the last place.
                let (got, want) = (p[c] as f64, u[c] * k);
                assert!((got - want).abs() <= want.abs() * 2.0 / 1024.0 + 1e-7, "EV {ev}: {got} vs {want}");
            }
        }
        for (p, q) in hdr.iter().zip(ldr.chunks_exact(4)) {
            let want = rgb_of(p).map(|c| {
                let c = c.max(0.0);
                let t = match tonemap {
                    Tonemap::None => c,
                    Tonemap::Reinhard => c / (1.0 + c),
                    Tonemap::Aces => {
                        let v = c * 0.6;
                        (v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14)
                    }
                };
                color::colorspace::srgb_encode(t.clamp(0.0, 1.0)) * 255.0
            });
            for c in 0..3 {
                assert!((q[c] as f64 - want[c]).abs() <= 1.0, "{tonemap:?}: {} vs {}", q[c], want[c]);
            }
            assert_eq!(q[3], 255);
        }
    }
}

#[test]
fn timestamps_report_each_pass() {
    let (mut r, _) = chart_renderer(1.0);
    if !r.gpu().features.contains(wgpu::Features::TIMESTAMP_QUERY) {
        panic!("adapter {} has no timestamp queries", r.gpu().describe());
    }
    let cam = r.scene_camera().unwrap();
    r.render(&cam, &RenderSettings { timestamps: true, ..Default::default() }).unwrap();
    let t = r.read_timings().unwrap().expect("timings of the frame");
    assert!(t.ms.iter().all(|&ms| ms >= 0.0 && ms.is_finite()), "{t:?}");
    assert!(t.get("shading").unwrap() > 0.0, "{t:?}");
    // Without timestamps requested there is nothing to read.
    r.render(&cam, &RenderSettings::default()).unwrap();
    assert_eq!(r.read_timings().unwrap(), None);
}

/// With three or more shadow maps the passes between the first (begin timestamp) and the last
/// (end timestamp) write none; a pass given neither index is a validation error (issue 27: the
/// Khronos models with several lights failed `spectra bench`).
#[test]
fn timestamps_with_many_shadow_layers() {
    let (mut r, chart) = chart_renderer(1.0);
    if !r.gpu().features.contains(wgpu::Features::TIMESTAMP_QUERY) {
        panic!("adapter {} has no timestamp queries", r.gpu().describe());
    }
    let cam = r.scene_camera().unwrap();
    for lights in [1, 2, 3, 4, render::passes::shadow::MAX_SHADOWS] {
        let mut scene = chart.scene(white_light(1.0, None), 1.0, 0.0);
        scene.lights = (0..lights)
            .map(|i| scene::Light::point(&format!("p{i}"), Vec3::new(i as f32 - 1.5, 1.0, 4.0), 20.0))
            .collect();
        r.set_scene(&scene).unwrap();
        for mode in [Mode::Rgb, Mode::Spectral] {
            let s = RenderSettings { mode, wavelengths: 4, timestamps: true, ..Default::default() };
            r.render(&cam, &s).unwrap_or_else(|e| panic!("{lights} lights, {mode:?}: {e}"));
            let t = r.read_timings().unwrap().expect("timings of the frame");
            assert!(t.ms.iter().all(|&ms| ms >= 0.0 && ms.is_finite()), "{lights} lights: {t:?}");
        }
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let mut r = renderer();
    let cam = chart_camera();
    let e = r.render(&cam, &RenderSettings::default()).unwrap_err().to_string();
    assert!(e.contains("set_scene"), "{e}");
    assert!(r.resize(0, 10).unwrap_err().to_string().contains("0×10"));
    let chart = Chart::colorchecker();
    let mut scene = chart.scene(white_light(1.0, None), 1.0, 0.0);
    scene.meshes[0].indices.push(99);
    scene.meshes[0].indices.extend([0, 1]);
    let e = r.set_scene(&scene).unwrap_err().to_string();
    assert!(e.contains("test:chart") && e.contains("99"), "{e}");
    let mut scene = chart.scene(white_light(1.0, None), 1.0, 0.0);
    scene.materials[0].base_color_texture =
        Some(scene::TextureRef { transform: None, index: 3, tex_coord: 0 });
    let e = r.set_scene(&scene).unwrap_err().to_string();
    assert!(e.contains("texture 3"), "{e}");
    r.set_scene(&chart.scene(white_light(1.0, None), 1.0, 0.0)).unwrap();
    r.resize(8, 8).unwrap();
    let e = r.render(&cam, &RenderSettings { wavelengths: 0, ..Default::default() }).unwrap_err().to_string();
    assert!(e.contains("got 0"), "{e}");
}

/// The G-buffer's material slot is 16 bits: a material far past 255 still finds its own
/// spectra (the chart drawn with 300 unused materials before its own is the same image), and a
/// scene with more materials than the slot can name is refused with the count.
#[test]
fn material_slots_past_eight_bits_and_the_limit() {
    let chart = Chart::colorchecker();
    let scene = chart.scene(white_light(1.0, None), 1.0, 0.0);
    let mut shifted = scene.clone();
    let pad = 300;
    let grey = Material { base_color: Vec4::new(0.2, 0.2, 0.2, 1.0), ..Default::default() };
    shifted.materials = std::iter::repeat_n(grey, pad).chain(scene.materials.iter().cloned()).collect();
    for m in &mut shifted.meshes {
        m.material += pad;
    }
    let s = RenderSettings { shadows: false, wavelengths: 8, ..Default::default() };
    let mut images = Vec::new();
    for sc in [&scene, &shifted] {
        let mut r = renderer();
        r.set_scene(sc).unwrap();
        r.resize(W, H).unwrap();
        images.push(hdr(&mut r, &s));
    }
    let differ = images[0].iter().zip(&images[1]).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "pixels that differ with {pad} materials before the chart's own");

    let mut too_many = scene.clone();
    too_many.materials = vec![Material::default(); render::scene_gpu::MAX_MATERIALS + 1];
    for m in &mut too_many.meshes {
        m.material = 0;
    }
    let err = renderer().set_scene(&too_many).unwrap_err().to_string();
    assert!(err.contains("65535 materials") && err.contains("at most 65534"), "{err}");
}

/// A scene in units far below the half-float target's range (a 1e-9 lux light: every pixel
/// under f16's 6e-8, stored as 0) is brought into it by the exposure, which the shaders apply
/// before the target: at +30 EV it is the frame of a 2^30 times brighter light, in every mode.
#[test]
fn exposure_reaches_below_the_half_float_floor() {
    let dim = 1e-9f32;
    let (mut r, _) = chart_renderer(dim);
    let (mut bright, _) = chart_renderer(dim * 2f32.powi(30));
    for mode in [Mode::Rgb, Mode::Naive, Mode::Spectral] {
        let s = RenderSettings { mode, ..Default::default() };
        let unexposed = hdr(&mut r, &s);
        assert!(
            unexposed.iter().flatten().all(|c| *c == 0.0),
            "{mode:?}: the dim frame is below f16's range"
        );
        let exposed = hdr(&mut r, &RenderSettings { exposure_ev: 30.0, ..s.clone() });
        let want = hdr(&mut bright, &s);
        let peak = want.iter().flatten().fold(0.0f64, |m, c| m.max(c.abs()));
        assert!(peak > 0.1, "{mode:?}: the bright frame is lit ({peak})");
        let mut worst = 0.0f64;
        for (a, b) in exposed.iter().zip(&want) {
            for c in 0..3 {
                worst = worst.max((a[c] - b[c]).abs() / (b[c].abs() * 2.0 / 1024.0 + 1e-6));
            }
        }
        assert!(
            worst <= 1.0,
            "{mode:?}: {worst:.2} of the f16 bound between +30 EV and a 2^30 brighter light"
        );
    }
}

/// The pass-3 hook sees radiance, not the exposed values the target holds: a hook that adds a
/// constant adds it before the exposure.
#[test]
fn the_pixel_hook_sees_radiance_whatever_the_exposure() {
    let (mut r, chart) = chart_renderer(1.0);
    let grey = centre_pixel_of_patch(&chart, 21);
    let s = RenderSettings { mode: Mode::Rgb, shadows: false, ..Default::default() };
    let plain = hdr(&mut r, &s)[grey];
    let src = "fn custom_pixel(hdr: vec4<f32>, ctx: SurfaceContext) -> vec4<f32> { return vec4<f32>(hdr.rgb + 0.1, hdr.a); }";
    r.set_custom_shader(CustomShader::new(src)).unwrap();
    let exposed = hdr(&mut r, &RenderSettings { exposure_ev: 2.0, ..s.clone() })[grey];
    for c in 0..3 {
        let want = 4.0 * (plain[c] + 0.1);
        assert!((exposed[c] - want).abs() <= want * 2.0 / 1024.0, "{exposed:?} vs 4 × ({plain:?} + 0.1)");
    }
}
