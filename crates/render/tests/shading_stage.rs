//! The shading pass runs its opaque layer as a compute pass over the screen (GPUs) or as a
//! fullscreen triangle's fragments (CPU drivers): `render::ShadingStage`. Both call the same WGSL
//! functions, so every image and capture must be the same: in every mode and with every feature
//! the pass compiles in (emission, a textured fetch, films, see-through layers, the environment
//! and its occlusion, the spectral capture, the underwater hooks, a custom pass after it).

mod common;

use color::water::WaterType;
use glam::Vec3;
use render::passes::underwater;
use render::{CustomShader, Mode, RenderSettings, Renderer, ShadingStage};
use scene::Scene;
use scene::water::WaterMedium;

const W: u32 = 44;
const H: u32 = 34;

/// What one frame gives: the HDR image and, when capturing, the spectral capture.
fn frame(
    r: &mut Renderer,
    scene: &Scene,
    settings: &RenderSettings,
    stage: ShadingStage,
) -> (Vec<f32>, Vec<f32>) {
    r.set_shading_stage(stage).unwrap();
    assert_eq!(r.shading_stage(), stage);
    r.render(&scene.camera, settings).unwrap();
    let hdr = r.read_hdr().unwrap().into_iter().flatten().collect();
    let capture = if settings.mode == Mode::Rgb {
        Vec::new()
    } else {
        r.read_spectral_capture().map_or(Vec::new(), |c| c.data)
    };
    (hdr, capture)
}

/// The largest difference between the two stages' values relative to the value (a driver may
/// contract a multiply-add differently in each stage; lavapipe gives the same bits), and how
/// many differ at all.
fn compare(what: &str, a: &[f32], b: &[f32]) -> (f32, usize) {
    assert_eq!(a.len(), b.len(), "{what}: sizes");
    assert!(a.iter().all(|v| v.is_finite()), "{what}: a value that is not finite");
    let mut worst = 0.0f32;
    let mut differ = 0;
    for (x, y) in a.iter().zip(b) {
        if x.to_bits() != y.to_bits() {
            differ += 1;
            worst = worst.max((x - y).abs() / x.abs().max(y.abs()).max(1e-3));
        }
    }
    (worst, differ)
}

fn check(r: &mut Renderer, name: &str, scene: &Scene, settings: &RenderSettings) {
    let (hdr_f, cap_f) = frame(r, scene, settings, ShadingStage::Fragment);
    let (hdr_c, cap_c) = frame(r, scene, settings, ShadingStage::Compute);
    let lit = hdr_f.chunks(4).filter(|p| p[..3].iter().any(|&v| v > 0.0)).count();
    assert!(lit > (W * H / 8) as usize, "{name} {:?}: only {lit} pixels are lit", settings.mode);
    for (what, a, b) in [("image", &hdr_f, &hdr_c), ("capture", &cap_f, &cap_c)] {
        let (worst, differ) = compare(&format!("{name} {what}"), a, b);
        println!(
            "{name} {:?} N = {} {what}: {differ} of {} values differ, worst {worst:.2e}",
            settings.mode,
            settings.wavelengths,
            a.len()
        );
        // One f16 step (the image is half floats).
        assert!(
            worst <= 1.0 / 1024.0,
            "{name} {:?} {what}: the stages differ by {worst:.2e} ({differ} values)",
            settings.mode
        );
    }
}

fn settings(mode: Mode, n: usize) -> RenderSettings {
    RenderSettings { mode, wavelengths: n, ..Default::default() }
}

#[test]
fn both_shading_stages_draw_the_same_frames() {
    let mut r = common::renderer();
    r.resize(W, H).unwrap();
    // Cornell (an emissive lamp, shadows) in every mode, then the textured chart (the per-pixel
    // fetch), films and see-through glass (the transmissive layer, drawn by its meshes in both
    // stages). Each pipeline is compiled per stage, which is most of the test's time.
    let cornell = scene::builtin("cornell").unwrap();
    r.set_scene(&cornell).unwrap();
    for s in [settings(Mode::Naive, 4), settings(Mode::Spectral, 5)] {
        check(&mut r, "cornell", &cornell, &s);
    }
    for name in ["cornell", "colorchecker", "iridescence", "glass"] {
        let scene = scene::builtin(name).unwrap();
        r.set_scene(&scene).unwrap();
        for s in [settings(Mode::Rgb, 8), settings(Mode::Spectral, 8)] {
            check(&mut r, name, &scene, &s);
        }
    }
    // The environment and its occlusion pass; then the spectral capture (the general node loop).
    let mut scene = scene::builtin("cornell").unwrap();
    scene.environment = Some(scene::Environment::default_sky());
    r.set_scene(&scene).unwrap();
    check(&mut r, "cornell + sky", &scene, &settings(Mode::Spectral, 8));
    check(&mut r, "cornell + sky", &scene, &settings(Mode::Rgb, 8));
    r.set_spectral_capture(true);
    check(&mut r, "cornell + sky, captured", &scene, &settings(Mode::Spectral, 8));
    r.set_spectral_capture(false);
    // A custom pass after the shading: the compute pass writes its input instead of the image.
    let custom = CustomShader::new(
        "fn custom_pixel(hdr: vec4<f32>, ctx: SurfaceContext) -> vec4<f32> { return hdr * vec4<f32>(0.5, 1.0, 2.0, 1.0); }",
    );
    r.set_custom_shader(custom).unwrap();
    check(&mut r, "cornell + custom pass", &scene, &settings(Mode::Spectral, 8));
    // Under water: the hooks' general node loop, the light-field table and the march.
    let scene = scene::builtin("underwater").unwrap();
    let medium = WaterMedium::new(WaterType::parse("IB").unwrap(), 5.0, Vec3::Y, 1.0).unwrap();
    r.set_custom_shader(underwater::shader_with(&medium, &underwater::Options::default()).unwrap()).unwrap();
    r.set_scene(&scene).unwrap();
    for s in [settings(Mode::Rgb, 8), settings(Mode::Spectral, 8)] {
        check(&mut r, "underwater", &scene, &s);
    }
}
