//! Shared helpers for the GPU tests: a renderer that FAILS (not skips) without an adapter, a
//! fitted coefficient table, a test chart scene, an independent CPU shading reference, ΔE
//! statistics, and images written to `target/test-output/` when a comparison fails.

#![allow(dead_code)]

use color::quadrature::{Nodes, Quadrature, integrate_nodes, sum_weights};
use color::upsample::CoeffTable;
use color::{Observer, RgbColorSpace, Spectrum};
use glam::{DMat3, DVec3, Mat4, Vec2, Vec3, Vec4};
use render::{CustomShader, RenderError, RenderSettings, Renderer};
use scene::{Camera, Emission, Light, LightKind, Material, Mesh, Scene, SpectralSettings};
use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

/// The sRGB Jakob–Hanika table the renderer uses (64³, fitted once per machine and cached by
/// the colour crate).
pub fn table() -> Arc<CoeffTable> {
    static T: OnceLock<Arc<CoeffTable>> = OnceLock::new();
    T.get_or_init(|| color::upsample::table("srgb").expect("the sRGB coefficient table")).clone()
}

/// A renderer, or a test failure that says what to install.
pub fn renderer() -> Renderer {
    match Renderer::with_table(table()) {
        Ok(r) => r,
        Err(e @ RenderError::NoAdapter { .. }) => panic!("{e}"),
        Err(e) => panic!("creating the renderer failed: {e}"),
    }
}

/// One `size`×`size` frame of `scene` through `r` (the scene set and the targets sized anew),
/// with the spectral capture on or off: the HDR image.
pub fn render_frame(
    r: &mut Renderer,
    scene: &Scene,
    size: u32,
    settings: &RenderSettings,
    capture: bool,
) -> Vec<[f32; 4]> {
    render_frame_wh(r, scene, (size, size), settings, capture)
}

/// [`render_frame`] at `width`×`height`.
pub fn render_frame_wh(
    r: &mut Renderer,
    scene: &Scene,
    (width, height): (u32, u32),
    settings: &RenderSettings,
    capture: bool,
) -> Vec<[f32; 4]> {
    r.set_scene(scene).unwrap();
    r.resize(width, height).unwrap();
    r.set_spectral_capture(capture);
    r.render(&scene.camera, settings).unwrap();
    r.read_hdr().unwrap()
}

/// An 8-bit sRGB-encoded value, linear.
pub fn decode8(v: u8) -> f64 {
    color::colorspace::srgb_decode(v as f64 / 255.0)
}

/// A 1×1 texture of `rgba` (sRGB-encoded colour or linear data).
pub fn texel_texture(name: &str, rgba: [u8; 4], srgb: bool) -> scene::Texture {
    scene::Texture {
        sampler: Default::default(),
        name: name.into(),
        width: 1,
        height: 1,
        rgba8: rgba.to_vec(),
        srgb,
    }
}

pub fn output_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output");
    std::fs::create_dir_all(&dir).expect("creating target/test-output");
    dir
}

/// Layout of the test chart: `cols × rows` unit patches with gaps, in the z = 0 plane,
/// facing +z, seen by a narrow camera on the +z axis (so every pixel looks almost straight on).
pub struct Chart {
    pub colours: Vec<[f32; 3]>,
    pub cols: usize,
    pub rows: usize,
    pub gap: f32,
}

pub const CAMERA_DISTANCE: f32 = 60.0;
pub const CAMERA_YFOV: f32 = 0.09;

impl Chart {
    /// The 24 ColorChecker patches as linear sRGB albedos (their reflectances under D65,
    /// computed by the colour crate) in chart order.
    pub fn colorchecker() -> Self {
        let space = RgbColorSpace::srgb();
        let d65 = color::illuminant::by_name("D65").unwrap();
        let integ = color::SpectralIntegrator::reference(
            &color::Observer::cie1931(),
            &d65,
            color::WavelengthRange::FULL,
        )
        .unwrap();
        let colours = color::data::colorchecker::SPECTRA
            .iter()
            .map(|t| {
                let s = Spectrum::from_table(t);
                let rgb = space.xyz_to_rgb(integ.integrate(|l| s.eval(l)));
                rgb.map(|c| c.clamp(0.0, 1.0) as f32)
            })
            .collect();
        Chart { colours, cols: 6, rows: 4, gap: 0.15 }
    }

    pub fn origin(&self, col: usize, row: usize) -> Vec2 {
        let pitch = 1.0 + self.gap;
        let w = self.cols as f32 * pitch - self.gap;
        let h = self.rows as f32 * pitch - self.gap;
        Vec2::new(-w / 2.0 + col as f32 * pitch, h / 2.0 - row as f32 * pitch - 1.0)
    }

    /// Index of the patch containing `p` (world x, y) at least `margin` inside its edges.
    pub fn patch_at(&self, p: Vec2, margin: f32) -> Option<usize> {
        (0..self.rows * self.cols).find(|&i| {
            let o = self.origin(i % self.cols, i / self.cols);
            p.x >= o.x + margin
                && p.x <= o.x + 1.0 - margin
                && p.y >= o.y + margin
                && p.y <= o.y + 1.0 - margin
        })
    }

    /// A scene with one quad per patch (material base colour = the patch), lit by `light`.
    pub fn scene(&self, light: Emission, roughness: f32, metallic: f32) -> Scene {
        let mut meshes = Vec::new();
        let mut materials = Vec::new();
        for (i, c) in self.colours.iter().enumerate() {
            let o = self.origin(i % self.cols, i / self.cols);
            let p = |x: f32, y: f32| Vec3::new(o.x + x, o.y + y, 0.0);
            meshes.push(Mesh {
                colors: vec![],
                uvs1: vec![],
                positions: vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)],
                normals: vec![Vec3::Z; 4],
                tangents: vec![],
                uvs: vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)],
                indices: vec![0, 1, 2, 0, 2, 3],
                material: i,
            });
            materials.push(Material {
                name: format!("patch {i}"),
                base_color: Vec4::new(c[0], c[1], c[2], 1.0),
                roughness,
                metallic,
                ..Default::default()
            });
        }
        Scene {
            warnings: vec![],
            source: "test:chart".into(),
            meshes,
            materials,
            textures: vec![],
            lights: vec![Light {
                name: "sun".into(),
                kind: LightKind::Directional { direction: Vec3::NEG_Z },
                emission: light,
                stands_in_for: None,
            }],
            camera: chart_camera(),
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
}

pub fn chart_camera() -> Camera {
    Camera::look_at(Vec3::new(0.0, 0.0, CAMERA_DISTANCE), Vec3::ZERO, Vec3::Y, CAMERA_YFOV)
}

/// An orthographic camera at z = 2 looking down −Z at the window x ∈ [−1, 1], y ∈ [−0.8, 0.8].
pub fn front_ortho_camera() -> Camera {
    Camera {
        transform: Mat4::from_translation(Vec3::new(0.0, 0.0, 2.0)),
        yfov: 0.5,
        znear: 0.1,
        zfar: 10.0,
        aspect: None,
        ortho: Some((1.0, 0.8)),
    }
}

/// World (x, y) on the z = 0 plane seen through the centre of pixel (px, py).
pub fn pixel_to_chart(px: u32, py: u32, w: u32, h: u32) -> (Vec2, Vec3) {
    let cam = chart_camera();
    let aspect = w as f32 / h as f32;
    let inv =
        (Mat4::perspective_rh(cam.yfov, aspect, cam.znear, cam.zfar) * cam.transform.inverse()).inverse();
    let ndc = Vec2::new((px as f32 + 0.5) / w as f32 * 2.0 - 1.0, 1.0 - (py as f32 + 0.5) / h as f32 * 2.0);
    let a = inv.project_point3(ndc.extend(0.0));
    let b = inv.project_point3(ndc.extend(1.0));
    let d = (b - a).normalize();
    let t = -a.z / d.z;
    let hit = a + d * t;
    (hit.truncate(), d)
}

/// Independent CPU implementation of the renderer's BRDF (glTF metallic-roughness: Lambert +
/// GGX, height-correlated Smith, Schlick), as (A, B) with radiance = E·(ρ·A + B).
pub fn brdf_factors(n: Vec3, v: Vec3, wi: Vec3, metallic: f64, roughness: f64) -> (f64, f64) {
    brdf_factors_f0(n, v, wi, metallic, roughness, 0.04)
}

/// [`brdf_factors`] with the dielectric's F0 (`KHR_materials_ior`).
pub fn brdf_factors_f0(n: Vec3, v: Vec3, wi: Vec3, metallic: f64, roughness: f64, f0: f64) -> (f64, f64) {
    let nl = n.dot(wi) as f64;
    if nl <= 0.0 {
        return (0.0, 0.0);
    }
    let h = (wi + v).normalize();
    let nv = (n.dot(v) as f64).max(1e-4);
    let nh = (n.dot(h) as f64).max(0.0);
    let vh = (v.dot(h) as f64).max(0.0);
    let alpha = (roughness * roughness).max(1e-3);
    let a2 = alpha * alpha;
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (std::f64::consts::PI * dd * dd);
    let vis = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    let fres = (1.0 - vh).powi(5);
    let fd = f0 + (1.0 - f0) * fres;
    let a = nl * ((1.0 - metallic) * (1.0 - fd) / std::f64::consts::PI + metallic * d * vis * (1.0 - fres));
    let b = nl * d * vis * ((1.0 - metallic) * fd + metallic * fres);
    (a, b)
}

/// CIELAB (D65 white) of a linear sRGB colour.
pub fn lab(rgb: [f64; 3]) -> [f64; 3] {
    let space = RgbColorSpace::srgb();
    color::xyz_to_lab(space.rgb_to_xyz(rgb), space.white_xyz())
}

/// Mean and 99th percentile of a list of ΔE values.
pub fn stats(mut de: Vec<f64>) -> (f64, f64) {
    assert!(!de.is_empty(), "no pixels compared");
    de.sort_by(f64::total_cmp);
    let mean = de.iter().sum::<f64>() / de.len() as f64;
    let p99 = de[((de.len() - 1) as f64 * 0.99).round() as usize];
    (mean, p99)
}

fn srgb8(v: f64) -> u8 {
    (color::colorspace::srgb_encode(v.clamp(0.0, 1.0)) * 255.0).round() as u8
}

/// Writes `actual`, `expected` and a ΔE heatmap (white = ΔE ≥ 5) next to each other.
pub fn write_failure_images(
    name: &str,
    w: u32,
    h: u32,
    actual: &[[f64; 3]],
    expected: &[[f64; 3]],
    de: &[f64],
) {
    let dir = output_dir();
    let img = |px: &dyn Fn(usize) -> [u8; 3]| {
        image::RgbImage::from_fn(w, h, |x, y| image::Rgb(px((y * w + x) as usize)))
    };
    let _ = img(&|i| actual[i].map(srgb8)).save(dir.join(format!("{name}-actual.png")));
    let _ = img(&|i| expected[i].map(srgb8)).save(dir.join(format!("{name}-expected.png")));
    let _ = img(&|i| [(de[i] / 5.0 * 255.0).min(255.0) as u8; 3]).save(dir.join(format!("{name}-diff.png")));
}

/// Compares two linear-sRGB images over the pixels where `expected` is `Some`; fails with the
/// statistics and writes images when the mean or 99th-percentile ΔE2000 exceeds the limits.
pub fn assert_delta_e(
    name: &str,
    w: u32,
    h: u32,
    actual: &[[f64; 3]],
    expected: &[Option<[f64; 3]>],
    max_mean: f64,
    max_p99: f64,
) -> (f64, f64) {
    let de: Vec<f64> = actual
        .iter()
        .zip(expected)
        .map(|(a, e)| e.map(|e| color::ciede2000(lab(*a), lab(e))).unwrap_or(0.0))
        .collect();
    let compared: Vec<f64> = de.iter().zip(expected).filter(|(_, e)| e.is_some()).map(|(d, _)| *d).collect();
    let (mean, p99) = stats(compared);
    println!("{name}: ΔE2000 mean {mean:.4}, p99 {p99:.4}");
    if mean > max_mean || p99 > max_p99 {
        let exp: Vec<[f64; 3]> = expected.iter().map(|e| e.unwrap_or([0.0; 3])).collect();
        write_failure_images(name, w, h, actual, &exp, &de);
        panic!(
            "{name}: ΔE2000 mean {mean:.4} (limit {max_mean}), p99 {p99:.4} (limit {max_p99}); \
             images in target/test-output/{name}-*.png"
        );
    }
    (mean, p99)
}

pub fn rgb_of(px: &[f32; 4]) -> [f64; 3] {
    [px[0] as f64, px[1] as f64, px[2] as f64]
}

/// A white light (linear sRGB (1, 1, 1)) of `intensity` lux, optionally with a spectrum.
pub fn white_light(intensity: f32, spectrum: Option<Spectrum>) -> Emission {
    Emission { rgb: Vec3::ONE, intensity, spectrum }
}

/// One frame of `scene` (already set, at the renderer's size) with `custom`'s hooks, as read
/// back from the HDR target.
pub fn render_custom(
    r: &mut Renderer,
    scene: &Scene,
    settings: &RenderSettings,
    custom: CustomShader,
) -> Vec<[f32; 4]> {
    r.set_custom_shader(custom).unwrap();
    r.render(&scene.camera, settings).unwrap();
    r.read_hdr().unwrap()
}

/// [`render_custom`] at one wavelength (N = 1) with the spectral capture on: the pixels' values
/// as `unit` (the colour of unit radiance at the node) times the captured f32 radiance, free of
/// the HDR target's f16 rounding. A GPU-vs-CPU comparison read from the f16 image spends up to
/// 2⁻¹¹ of relative error on each rounding (two where a dry frame enters the expected value:
/// lavapipe's worst was 9.7·10⁻⁴ of a 10⁻³ budget, an NVIDIA GPU's 1.0·10⁻³). Checks that the
/// image is the capture to f16's rounding, so that the capture is what the frame shows.
pub fn render_custom_captured(
    r: &mut Renderer,
    scene: &Scene,
    settings: &RenderSettings,
    custom: CustomShader,
    unit: glam::DVec3,
) -> Vec<[f64; 3]> {
    assert_eq!(settings.wavelengths, 1, "one node per pixel");
    r.set_spectral_capture(true);
    let hdr = render_custom(r, scene, settings, custom);
    let cap = r.read_spectral_capture().unwrap();
    r.set_spectral_capture(false);
    hdr.iter()
        .zip(&cap.data)
        .enumerate()
        .map(|(i, (h, &l))| {
            let v = (unit * l as f64).to_array();
            for c in 0..3 {
                let step = (v[c].abs() * 2f64.powi(-10)).max(F16_SUBNORMAL_STEP);
                assert!(
                    (h[c] as f64 - v[c]).abs() <= step,
                    "pixel {i} channel {c}: image {} vs capture × unit {}",
                    h[c],
                    v[c]
                );
            }
            v
        })
        .collect()
}

/// One step of the HDR target's f16 below its smallest normal value (6.1e-5): the storage
/// cannot resolve differences smaller than this, whatever the shader computes.
pub const F16_SUBNORMAL_STEP: f64 = 5.960464477539063e-8;

/// Error of `gpu` against `cpu` relative to the largest channel (max over channels), after
/// discounting one f16 subnormal step of storage quantisation.
pub fn rel_err(gpu: [f64; 3], cpu: [f64; 3]) -> f64 {
    let scale = cpu.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = (0..3).fold(0.0f64, |m, c| m.max((gpu[c] - cpu[c]).abs()));
    (diff - F16_SUBNORMAL_STEP).max(0.0) / scale.max(1e-12)
}

/// Independent CPU spectral shading of a patch: ρ from the table (the colour crate's fetch) at
/// the nodes, the light's node weights from `color::quadrature` (midpoint or prefiltered),
/// scaled to the requested luminance, and the XYZ → sRGB matrix corrected so that the white
/// D65 as the same quadrature integrates it is the sRGB white.
pub struct CpuSpectral {
    pub lambda: Vec<f64>,
    /// The light's normalised node weights.
    light: Vec<[f64; 3]>,
    /// D65's normalised node weights (for emission).
    white: Vec<[f64; 3]>,
    /// The same split by the naive bands (red, green, blue): D65·1_b.
    white_bands: [Vec<[f64; 3]>; 3],
    to_rgb: DMat3,
}

impl CpuSpectral {
    pub fn new(n: usize, rule: Quadrature, light_spectrum: &Spectrum, luminance: f64) -> Self {
        let nodes = Nodes::new(color::WavelengthRange::VISIBLE, n, 0.5).unwrap();
        let quad = render::spectral_data::node_quadrature(rule, nodes, &Observer::cie1931());
        let d65 = color::illuminant::by_name("D65").unwrap();
        let white_raw = quad.weights(|l| d65.eval(l));
        let white_xyz = sum_weights(&white_raw);
        let k = white_xyz[1];
        let raw = quad.weights(|l| light_spectrum.eval(l));
        let white_bands = std::array::from_fn(|b| {
            let mut unit = [0.0; 3];
            unit[b] = 1.0;
            let band = color::upsample::boxes::BoxSpectrum { rgb: unit };
            quad.weights(|l| d65.eval(l) * band.eval(l)).iter().map(|w| w.map(|c| c / k)).collect()
        });
        let scale = luminance / sum_weights(&raw)[1];
        let space = RgbColorSpace::srgb();
        let t = space.white_xyz();
        let corr = DMat3::from_diagonal(DVec3::new(
            t[0] * k / white_xyz[0],
            t[1] * k / white_xyz[1],
            t[2] * k / white_xyz[2],
        ));
        CpuSpectral {
            lambda: quad.nodes.lambda.clone(),
            light: raw.iter().map(|w| w.map(|c| c * scale)).collect(),
            white: white_raw.iter().map(|w| w.map(|c| c / k)).collect(),
            white_bands,
            to_rgb: space.from_xyz * corr,
        }
    }

    pub fn shade(&self, table: &CoeffTable, albedo: [f32; 3], a: f64, b: f64) -> [f64; 3] {
        let poly = table.fetch(albedo.map(f64::from));
        self.shade_with(|l| poly.to_f32_poly_eval(l), a, b)
    }

    /// Naive mode: the colour crate's box spectrum of the albedo.
    pub fn shade_box(&self, albedo: [f32; 3], a: f64, b: f64) -> [f64; 3] {
        let boxed = color::upsample::boxes::BoxSpectrum { rgb: albedo.map(f64::from) };
        self.shade_with(|l| boxed.eval(l), a, b)
    }

    pub fn shade_with(&self, rho: impl Fn(f64) -> f64, a: f64, b: f64) -> [f64; 3] {
        self.shade_values(|l| rho(l) * a + b)
    }

    /// Linear RGB of a radiance over the light's emission given per node wavelength.
    pub fn shade_values(&self, value: impl Fn(f64) -> f64) -> [f64; 3] {
        let values: Vec<f64> = self.lambda.iter().map(|&l| value(l)).collect();
        (self.to_rgb * DVec3::from(integrate_nodes(&self.light, &values))).to_array()
    }

    /// An emitter of linear RGB `e` with the illuminant variant: s·ρ(e/s)(λ)·D65(λ), s = 2·max.
    pub fn emitter(&self, table: &CoeffTable, e: [f64; 3]) -> [f64; 3] {
        let values = self.emitter_nodes(table, e);
        (self.to_rgb * DVec3::from(integrate_nodes(&self.white, &values))).to_array()
    }

    /// The illuminant-variant emitter's spectrum s·ρ(e/s)(λ) at the nodes (the white's factor
    /// is in the weights).
    fn emitter_nodes(&self, table: &CoeffTable, e: [f64; 3]) -> Vec<f64> {
        let s = 2.0 * e[0].max(e[1]).max(e[2]);
        let poly = table.fetch(e.map(|c| c / s));
        self.lambda.iter().map(|&l| s * poly.to_f32_poly_eval(l)).collect()
    }

    /// That emitter seen through a box spectrum (`boxed`, one value per naive band, e.g. a
    /// per-channel transmittance), the box taken into the weights: Σ_b boxed_b·Σᵢ eᵢ·W^b_i, exact
    /// for the box's steps.
    pub fn emitter_through_box(&self, table: &CoeffTable, e: [f64; 3], boxed: [f64; 3]) -> [f64; 3] {
        let values = self.emitter_nodes(table, e);
        let xyz = (0..3).fold(DVec3::ZERO, |acc, b| {
            acc + boxed[b] * DVec3::from(integrate_nodes(&self.white_bands[b], &values))
        });
        (self.to_rgb * xyz).to_array()
    }

    /// The same with the box sampled at the nodes instead (what the renderer did before).
    pub fn emitter_through_box_at_nodes(&self, table: &CoeffTable, e: [f64; 3], boxed: [f64; 3]) -> [f64; 3] {
        let b = color::upsample::boxes::BoxSpectrum { rgb: boxed };
        let values: Vec<f64> =
            self.emitter_nodes(table, e).iter().zip(&self.lambda).map(|(v, &l)| v * b.eval(l)).collect();
        (self.to_rgb * DVec3::from(integrate_nodes(&self.white, &values))).to_array()
    }
}

/// Evaluates the sigmoid the way the GPU stores it (coefficients rounded to f32).
pub trait F32Eval {
    fn to_f32_poly_eval(&self, lambda: f64) -> f64;
}

impl F32Eval for color::upsample::SigmoidPolynomial {
    fn to_f32_poly_eval(&self, lambda: f64) -> f64 {
        let c = self.to_f32().map(f64::from);
        color::upsample::SigmoidPolynomial::new(c[0], c[1], c[2]).eval(lambda)
    }
}

/// A unit sphere about the origin, `n` rings of `2n` quads, with normals and UVs.
pub fn sphere(n: u32) -> Mesh {
    let mut m = Mesh::default();
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..=2 * n {
            let phi = std::f32::consts::PI * j as f32 / n as f32;
            let p = Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
            m.positions.push(p);
            m.normals.push(p);
            m.uvs.push(Vec2::new(j as f32 / (2 * n) as f32, i as f32 / n as f32));
        }
    }
    let row = 2 * n + 1;
    for i in 0..n {
        for j in 0..2 * n {
            let (a, b, c, d) = (i * row + j, i * row + j + 1, (i + 1) * row + j, (i + 1) * row + j + 1);
            m.indices.extend([a, b, c, b, d, c]);
        }
    }
    m
}

/// Where [`sphere_scene`]'s camera stands, and its vertical field of view.
pub const SPHERE_EYE: Vec3 = Vec3::new(0.0, 0.0, 4.0);
pub const SPHERE_YFOV: f32 = 0.6;

/// A unit sphere (`rings` rings) of `material` at the origin in the environment `env`, seen
/// from [`SPHERE_EYE`] with a vertical field of view of [`SPHERE_YFOV`].
pub fn sphere_scene(material: Material, env: scene::Environment, rings: u32) -> Scene {
    Scene {
        warnings: vec![],
        source: "test:sphere".into(),
        meshes: vec![sphere(rings)],
        materials: vec![material],
        textures: vec![],
        lights: vec![],
        camera: Camera::look_at(SPHERE_EYE, Vec3::ZERO, Vec3::Y, SPHERE_YFOV),
        spectral: SpectralSettings::default(),
        water: None,
        environment: Some(env),
        medium: None,
        inputs: vec![],
        origin: glam::DVec3::ZERO,
        input_stamps: vec![],
        choices: vec![],
        animation_end: None,
    }
}

/// The ray through the centre of pixel (x, y) of a size × size image of [`sphere_scene`] and the
/// true sphere's unit normal where it meets it: (normal, direction), or None where it misses.
pub fn sphere_hit(x: u32, y: u32, size: u32) -> Option<(Vec3, Vec3)> {
    let t = (SPHERE_YFOV / 2.0).tan();
    let ndc = ((x as f32 + 0.5) / size as f32 * 2.0 - 1.0, 1.0 - (y as f32 + 0.5) / size as f32 * 2.0);
    let d = Vec3::new(ndc.0 * t, ndc.1 * t, -1.0).normalize();
    let b = SPHERE_EYE.dot(d);
    let disc = b * b - (SPHERE_EYE.dot(SPHERE_EYE) - 1.0);
    (disc > 0.0).then(|| ((SPHERE_EYE + d * (-b - disc.sqrt())).normalize(), d))
}
