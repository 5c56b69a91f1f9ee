//! Thin films (KHR_materials_iridescence) in the real-time renderer, against independent CPU
//! references: in the spectral and naive modes a filmed patch equals the CPU's per-node
//! evaluation — the glTF BRDF with the film's exact reflectance (`scene::film`, itself checked
//! against a transfer-matrix oracle by tools/check_film.py) in its Fresnel term, at the frame's
//! nodes and weights — to 1e-3 (relative above 1: the HDR target is f16; 2e-3 in the naive
//! mode, whose box spectrum is of the G-buffer's f16 colour), over dielectric and metal bases; the RGB mode draws the
//! extension's RGB film, which differs from the unfilmed surface; a film of weight 0 is no film.

mod common;

use color::quadrature::Quadrature;
use common::*;
use glam::Vec3;
use render::{Mode, RenderSettings, Renderer};
use scene::{Iridescence, Scene};

const W: u32 = 96;
const H: u32 = 64;
const MARGIN: f32 = 0.1;
const ROUGHNESS: f32 = 0.5;

fn settings(mode: Mode, n: usize, quadrature: Quadrature) -> RenderSettings {
    RenderSettings { mode, wavelengths: n, quadrature, shadows: false, ..Default::default() }
}

fn render_hdr(r: &mut Renderer, s: &RenderSettings) -> Vec<[f64; 3]> {
    let cam = r.scene_camera().unwrap();
    r.render(&cam, s).unwrap();
    r.read_hdr().unwrap().iter().map(rgb_of).collect()
}

/// Patch i's film: thickness 120–1040 nm and index 1.2–1.8 across the chart, weight 1 except
/// on every fourth patch (0.5).
fn film_of(i: usize) -> Iridescence {
    Iridescence {
        factor: if i % 4 == 3 { 0.5 } else { 1.0 },
        texture: None,
        ior: 1.2 + 0.2 * (i % 4) as f32,
        thickness_min: 0.0,
        thickness_max: 120.0 + 40.0 * i as f32,
        thickness_texture: None,
    }
}

fn filmed_chart(chart: &Chart, metallic: f32, films: bool) -> Scene {
    let mut s =
        chart.scene(white_light(1.5, Some(color::illuminant::by_name("F11").unwrap())), ROUGHNESS, metallic);
    if films {
        for (i, m) in s.materials.iter_mut().enumerate() {
            m.iridescence = Some(film_of(i));
            m.ior = ior_of(i);
        }
    }
    s
}

/// Patch i's dielectric index under the film (`KHR_materials_ior`): 1.5, 1.4 or 1.7.
fn ior_of(i: usize) -> f32 {
    [1.5, 1.4, 1.7][i % 3]
}

/// The light's geometry at a chart pixel seen along `d`, lit from +z: (kd, ks, v·h) with
/// radiance = E·(kd·(1 − F)·c_diff/π + ks·F), written out from the glTF BRDF (GGX,
/// height-correlated Smith).
fn terms(d: Vec3) -> (f64, f64, f64) {
    let (n, v, wi) = (Vec3::Z, -d, Vec3::Z);
    let nl = f64::from(n.dot(wi));
    let h = (wi + v).normalize();
    let nv = f64::from(n.dot(v)).max(1e-4);
    let nh = f64::from(n.dot(h)).max(0.0);
    let vh = f64::from(v.dot(h)).max(0.0);
    let alpha = (f64::from(ROUGHNESS) * f64::from(ROUGHNESS)).max(1e-3);
    let a2 = alpha * alpha;
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let dist = a2 / (std::f64::consts::PI * dd * dd);
    let vis = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    (nl, nl * dist * vis, vh)
}

/// The film's reflectance over a base of index `nb` as a spectral node of band `spacing`
/// carries it (`film_band_reflectance4`, in f64: Airy's form with u·sinc w for u = ab, the
/// window w growing from none at a quarter fringe period in the band to the whole band at half),
/// or at the node (`spacing` 0: the naive mode). Its distance from the band's exact mean is
/// `film_tests.rs`'s to check; this test checks the node loop around it.
fn band(film: &scene::film::Film, lambda: f64, c: f64, nb: f64, spacing: f64) -> f64 {
    if spacing == 0.0 {
        return film.over_dielectric(lambda, c, nb);
    }
    let (c1, nf) = (c.clamp(1e-6, 1.0), film.ior);
    let s2 = 1.0 - c1 * c1;
    let (c2, c3) = ((1.0 - s2 / (nf * nf)).max(0.0).sqrt(), (1.0 - s2 / (nb * nb)).max(0.0).sqrt());
    let pol = [
        ((c1 - nf * c2) / (c1 + nf * c2), (nf * c2 - nb * c3) / (nf * c2 + nb * c3)),
        ((nf * c1 - c2) / (nf * c1 + c2), (nb * c2 - nf * c3) / (nb * c2 + nf * c3)),
    ];
    let delta = 4.0 * std::f64::consts::PI * film.thickness_nm * nf * c2 / lambda;
    let w_band = delta * 0.5 * spacing / lambda;
    let x = ((w_band / std::f64::consts::PI - 0.25) / 0.25).clamp(0.0, 1.0);
    let w = w_band * x * x * (3.0 - 2.0 * x);
    let sinc = if w < 1e-4 { 1.0 } else { w.sin() / w };
    let r: f64 = pol
        .iter()
        .map(|&(a, b)| {
            let v = a * b * sinc;
            1.0 - (1.0 - a * a) * (1.0 - b * b) * (1.0 - v * v)
                / (1.0 - a * a * b * b)
                / (1.0 + v * v + 2.0 * v * delta.cos())
        })
        .sum();
    (0.5 * r).clamp(0.0, 1.0)
}

/// Radiance over E at wavelength λ of a filmed surface of reflectance ρ(λ); the film over a
/// node's band of width `spacing` ([`band`]).
#[allow(clippy::too_many_arguments)]
fn filmed_value(
    rho: f64,
    lambda: f64,
    metallic: f64,
    film: &Iridescence,
    ior: f32,
    (kd, ks, vh): (f64, f64, f64),
    spacing: f64,
) -> f64 {
    let f = scene::film::Film { thickness_nm: f64::from(film.thickness_max), ior: f64::from(film.ior) };
    let w = f64::from(film.factor);
    let fres = (1.0 - vh).powi(5);
    let f0 = f64::from(scene::dielectric_f0(ior));
    let fd = (f0 + (1.0 - f0) * fres) * (1.0 - w) + w * band(&f, lambda, vh, f64::from(ior), spacing);
    let fm = (rho + (1.0 - rho) * fres) * (1.0 - w)
        + w * band(&f, lambda, vh, scene::film::ior_from_f0(rho), spacing);
    let spec = (1.0 - metallic) * fd + metallic * fm;
    kd * (1.0 - metallic) / std::f64::consts::PI * (1.0 - fd) * rho + ks * spec
}

#[test]
fn filmed_patches_match_the_cpu_per_node_in_spectral_and_naive_modes() {
    let chart = Chart::colorchecker();
    let f11 = color::illuminant::by_name("F11").unwrap();
    let table = table();
    let mut r = renderer();
    r.resize(W, H).unwrap();
    for metallic in [0.0f32, 1.0] {
        r.set_scene(&filmed_chart(&chart, metallic, true)).unwrap();
        for (rule, n) in
            [(Quadrature::Prefiltered, 16), (Quadrature::Midpoint, 8), (Quadrature::Prefiltered, 7)]
        {
            let spectral = render_hdr(&mut r, &settings(Mode::Spectral, n, rule));
            let naive = render_hdr(&mut r, &settings(Mode::Naive, n, rule));
            let cpu = CpuSpectral::new(n, rule, &f11, 1.5);
            // The spectral mode's nodes carry the film's mean over their band; the naive
            // mode's its value at the node.
            let spacing = color::WavelengthRange::VISIBLE.width() / n as f64;
            let (mut worst, mut worst_naive, mut compared) = (0.0f64, 0.0f64, 0);
            for y in 0..H {
                for x in 0..W {
                    let (p, d) = pixel_to_chart(x, y, W, H);
                    let Some(patch) = chart.patch_at(p, MARGIN) else { continue };
                    let i = (y * W + x) as usize;
                    let film = film_of(patch);
                    let t = terms(d);
                    let m = f64::from(metallic);
                    let poly = table.fetch(chart.colours[patch].map(f64::from));
                    let want = cpu.shade_values(|l| {
                        filmed_value(poly.to_f32_poly_eval(l), l, m, &film, ior_of(patch), t, spacing)
                    });
                    let boxed =
                        color::upsample::boxes::BoxSpectrum { rgb: chart.colours[patch].map(f64::from) };
                    let want_naive =
                        cpu.shade_values(|l| filmed_value(boxed.eval(l), l, m, &film, ior_of(patch), t, 0.0));
                    // The HDR target is f16 (2⁻¹⁰ relative, rounded toward zero on lavapipe):
                    // 1e-3 absolute below 1, relative above (a bare metal's highlight is ~2).
                    for c in 0..3 {
                        worst = worst.max((spectral[i][c] - want[c]).abs() / want[c].abs().max(1.0));
                        worst_naive = worst_naive
                            .max((naive[i][c] - want_naive[c]).abs() / want_naive[c].abs().max(1.0));
                    }
                    compared += 1;
                }
            }
            println!(
                "films, metallic {metallic}, {rule} N={n}: |GPU − CPU| max {worst:.2e} (naive {worst_naive:.2e}) over {compared} pixels"
            );
            assert!(compared > 1000);
            assert!(
                worst < 1e-3,
                "metallic {metallic} {rule} N={n}: filmed spectral GPU vs CPU differ by {worst}"
            );
            // The naive mode's box spectrum is of the G-buffer's f16 base colour (2⁻¹⁰ relative
            // on lavapipe, which truncates), and a metal's Fresnel term is that colour: one more
            // f16 step than the spectral mode (whose coefficients come from the exact colour).
            assert!(
                worst_naive < 2e-3,
                "metallic {metallic} {rule} N={n}: filmed naive GPU vs CPU differ by {worst_naive}"
            );
        }
    }
}

#[test]
fn films_change_every_mode_and_a_zero_weight_film_is_none() {
    let chart = Chart::colorchecker();
    let mut r = renderer();
    r.resize(W, H).unwrap();
    for metallic in [0.0f32, 1.0] {
        let mut plain_scene = filmed_chart(&chart, metallic, false);
        for (i, m) in plain_scene.materials.iter_mut().enumerate() {
            m.ior = ior_of(i);
        }
        let mut zero = filmed_chart(&chart, metallic, true);
        for m in &mut zero.materials {
            m.iridescence.as_mut().unwrap().factor = 0.0;
        }
        for mode in [Mode::Rgb, Mode::Spectral, Mode::Naive] {
            let s = settings(mode, 16, Quadrature::Prefiltered);
            r.set_scene(&plain_scene).unwrap();
            let plain = render_hdr(&mut r, &s);
            r.set_scene(&zero).unwrap();
            assert_eq!(render_hdr(&mut r, &s), plain, "{mode:?}: a film of weight 0 changed the image");
            r.set_scene(&filmed_chart(&chart, metallic, true)).unwrap();
            let filmed = render_hdr(&mut r, &s);
            let mut de = Vec::new();
            for y in 0..H {
                for x in 0..W {
                    let (p, _) = pixel_to_chart(x, y, W, H);
                    if chart.patch_at(p, MARGIN).is_some() {
                        let i = (y * W + x) as usize;
                        // Finite; not necessarily inside sRGB (a metal's film under F11 is not).
                        assert!(filmed[i].iter().all(|c| c.is_finite()), "{mode:?}: {:?}", filmed[i]);
                        de.push(color::ciede2000(lab(filmed[i]), lab(plain[i])));
                    }
                }
            }
            let (mean, _) = stats(de);
            println!("metallic {metallic} {mode:?}: ΔE(filmed, plain) mean {mean:.2}");
            assert!(mean > 2.0, "{mode:?} metallic {metallic}: films changed the image by only ΔE {mean}");
        }
    }
}

/// The spectral capture takes the general node loop (groups outermost, each light's terms kept,
/// as the underwater and RGB-medium hooks do): it draws a filmed chart lit by a light and the
/// environment as the plain loop does; and the environment's film (Fresnel at n·v) changes the
/// image in every mode, finitely.
#[test]
fn films_under_the_environment_and_through_the_general_node_loop() {
    let chart = Chart::colorchecker();
    let mut r = renderer();
    r.resize(W, H).unwrap();
    r.set_environment(Some(&scene::Environment::default_sky()));
    for metallic in [0.0f32, 1.0] {
        let filmed = filmed_chart(&chart, metallic, true);
        let plain_scene = filmed_chart(&chart, metallic, false);
        let s = settings(Mode::Spectral, 8, Quadrature::Prefiltered);
        r.set_scene(&filmed).unwrap();
        let plain_loop = render_hdr(&mut r, &s);
        r.set_spectral_capture(true);
        let general = render_hdr(&mut r, &s);
        let captured = r.read_spectral_capture().expect("the frame took the capture's loop");
        assert!(captured.data.iter().any(|&v| v > 0.0), "the capture wrote nothing");
        r.set_spectral_capture(false);
        let mut worst = 0.0f64;
        for (a, b) in plain_loop.iter().zip(&general) {
            for c in 0..3 {
                worst = worst.max((a[c] - b[c]).abs() / a[c].abs().max(1.0));
            }
        }
        println!("metallic {metallic}: filmed, with environment: capture loop vs plain loop max {worst:.2e}");
        assert!(worst < 2e-3, "metallic {metallic}: the general node loop draws films differently ({worst})");
        for mode in [Mode::Rgb, Mode::Spectral, Mode::Naive] {
            let s = settings(mode, 8, Quadrature::Prefiltered);
            r.set_scene(&plain_scene).unwrap();
            let plain = render_hdr(&mut r, &s);
            r.set_scene(&filmed).unwrap();
            let with = render_hdr(&mut r, &s);
            assert!(with.iter().flatten().all(|c| c.is_finite()), "{mode:?}: a non-finite pixel");
            let de: Vec<f64> =
                plain.iter().zip(&with).map(|(a, b)| color::ciede2000(lab(*a), lab(*b))).collect();
            let (mean, _) = stats(de);
            println!("metallic {metallic} {mode:?} + environment: ΔE(filmed, plain) mean {mean:.2}");
            assert!(mean > 1.0, "{mode:?}: under the environment films changed the image by only ΔE {mean}");
        }
    }
}

/// The film's textures: the iridescence texture's R scales the weight and the thickness
/// texture's G places the thickness between minimum and maximum. A 2×1 nearest-sampled texture
/// (left texel R 1, G 0; right R 128/255, G 1) on every patch draws its left half as a film of
/// weight 1 at the minimum thickness and its right half as one of weight 128/255 at the maximum,
/// each equal to the same film given by factors alone.
#[test]
fn film_textures_pick_the_weight_and_the_thickness() {
    use scene::{Filter, Sampler, Texture, TextureRef, Wrap};
    let chart = Chart::colorchecker();
    let (t_min, t_max) = (250.0f32, 650.0f32);
    let with = |films: &dyn Fn(usize) -> Iridescence| {
        let mut s = filmed_chart(&chart, 0.0, false);
        for (i, m) in s.materials.iter_mut().enumerate() {
            m.metallic = if i % 2 == 0 { 0.0 } else { 1.0 };
            m.iridescence = Some(films(i));
        }
        s
    };
    let plain = |factor: f32, thickness: f32| {
        move |i: usize| Iridescence {
            factor,
            texture: None,
            ior: 1.3 + 0.1 * (i % 3) as f32,
            thickness_min: 0.0,
            thickness_max: thickness,
            thickness_texture: None,
        }
    };
    let mut textured = with(&|i| Iridescence {
        texture: Some(TextureRef::new(0)),
        thickness_min: t_min,
        thickness_texture: Some(TextureRef::new(0)),
        ..plain(1.0, t_max)(i)
    });
    let nearest = Sampler {
        wrap_s: Wrap::ClampToEdge,
        wrap_t: Wrap::ClampToEdge,
        mag: Filter::Nearest,
        min: Filter::Nearest,
        mipmaps: false,
    };
    textured.textures.push(Texture {
        name: "film 2x1".into(),
        width: 2,
        height: 1,
        rgba8: vec![255, 0, 0, 255, 128, 255, 0, 255],
        srgb: false,
        sampler: nearest,
    });
    let left = with(&plain(1.0, t_min));
    let right = with(&plain(128.0 / 255.0, t_max));
    let mut r = renderer();
    r.resize(W, H).unwrap();
    for mode in [Mode::Rgb, Mode::Spectral, Mode::Naive] {
        let s = settings(mode, 8, Quadrature::Prefiltered);
        let mut image = |scene: &Scene| {
            r.set_scene(scene).unwrap();
            render_hdr(&mut r, &s)
        };
        let (t, a, b) = (image(&textured), image(&left), image(&right));
        let (mut worst, mut halves) = (0.0f64, [0usize; 2]);
        for y in 0..H {
            for x in 0..W {
                let (p, _) = pixel_to_chart(x, y, W, H);
                let Some(patch) = chart.patch_at(p, MARGIN) else { continue };
                // u across the patch; keep clear of the texel edge in its middle.
                let u = p.x - chart.origin(patch % chart.cols, patch / chart.cols).x;
                if (u - 0.5).abs() < 0.1 {
                    continue;
                }
                let i = (y * W + x) as usize;
                let want = if u < 0.5 { a[i] } else { b[i] };
                halves[usize::from(u >= 0.5)] += 1;
                for c in 0..3 {
                    worst = worst.max((t[i][c] - want[c]).abs() / want[c].abs().max(1.0));
                }
            }
        }
        println!(
            "{mode:?}: textured film vs the films of its texels: max {worst:.2e} over {halves:?} pixels"
        );
        assert!(halves[0] > 300 && halves[1] > 300, "{halves:?}");
        assert!(worst < 2e-3, "{mode:?}: the film textures give {worst} off the films they stand for");
    }
}
