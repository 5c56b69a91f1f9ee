//! `KHR_materials_specular` in the path tracer (`crate::bsdf::SpecularLanes`): the BRDF against
//! the extension's formula written out in f64, its sampling against its own value and pdf,
//! furnaces of a black dielectric (the weight scales the reflection; a coloured F0 colour
//! colours it as its upsampled spectrum, in RGB as its RGB), the diffuse's neutral share
//! under a coloured F0 (F0c_max), the textures, and renders without the extension unchanged
//! to the bit.

use super::tests::{assert_within, d65, estimate, radiance_any_hero, with_env};
use super::*;
use crate::bsdf::SpecularLanes;
use crate::material::TexCoords;
use crate::render::{Settings, render};
use crate::spectral::XyzSensor;
use crate::testing::{quad, scene_with, sphere};
use crate::upsample::GreyOnly;
use color::upsample::CoeffTable;
use color::{Observer, RgbColorSpace, Spectrum, WavelengthRange};
use glam::Vec2;
use scene::specular::Specular;
use scene::{Camera, Emission, Light, LightKind, Material, SpectralReflectance, Texture, TextureRef};
use std::f64::consts::PI;

fn specular(factor: f32, color: Vec3) -> Specular {
    Specular { factor, texture: None, color, color_texture: None }
}

fn dir(theta: f32, phi: f32) -> Vec3 {
    Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

fn srgb_table() -> std::sync::Arc<CoeffTable> {
    color::upsample::table("srgb").expect("the sRGB table")
}

/// The extension's f in f64, apart from the tracer's code: GGX D, glTF's height-correlated
/// Smith V, and with `sp` = (s, F0c per lane, F0c_max)
/// f = (1 − F_dmax)·base·(1 − m)/π + [(1 − m)·F_d + m·F_m]·D·V; without it the plain glTF
/// BRDF, (1 − Schlick(F0(η)))·base·(1 − m)/π + Schlick(lerp(F0(η), base, m))·D·V (the
/// normative mix: the diffuse loses the dielectric's Fresnel term only).
fn reference(
    base: [f64; 4],
    m: f64,
    alpha: f64,
    ior: f64,
    sp: Option<(f64, [f64; 4], f64)>,
    wo: [f64; 3],
    wi: [f64; 3],
) -> [f64; 4] {
    let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
    let hl = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    let h = h.map(|x| x / hl);
    let vh = (wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2]).abs();
    let x = (1.0 - vh).max(0.0).powi(5);
    let a2 = alpha * alpha;
    let t = h[2] * h[2] * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * t * t);
    let (nv, nl) = (wo[2], wi[2]);
    let v = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
    let f0_eta = ((ior - 1.0) / (ior + 1.0)).powi(2);
    std::array::from_fn(|i| {
        let b = base[i];
        let fm = b + (1.0 - b) * x;
        let (spec, lost) = match sp {
            Some((s, f0c, f0max)) => {
                let fd = s * (f0c[i] + (1.0 - f0c[i]) * x);
                let fdmax = s * (f0max + (1.0 - f0max) * x);
                ((1.0 - m) * fd + m * fm, fdmax)
            }
            None => {
                let f0 = f0_eta * (1.0 - m) + b * m;
                (f0 + (1.0 - f0) * x, f0_eta + (1.0 - f0_eta) * x)
            }
        };
        (1.0 - lost) * b * (1.0 - m) / PI + spec * d * v
    })
}

fn v64(v: Vec3) -> [f64; 3] {
    v.to_array().map(f64::from)
}

fn l64(v: Vec4) -> [f64; 4] {
    v.to_array().map(f64::from)
}

/// What `Brdf::eval` computed before the extension, operation for operation in f32.
fn eval_before_specular(b: &Brdf, wo: Vec3, wi: Vec3) -> Vec4 {
    use std::f32::consts::{FRAC_1_PI, PI};
    let (n_v, n_l) = (wo.z, wi.z);
    if n_v <= 0.0 || n_l <= 0.0 {
        return Vec4::ZERO;
    }
    let h = (wo + wi).normalize();
    let v_h = wo.dot(h).abs();
    let f0 = Vec4::splat(scene::dielectric_f0(b.ior) * (1.0 - b.metallic)) + b.base * b.metallic;
    let fr = f0 + (Vec4::ONE - f0) * (1.0 - v_h).max(0.0).powi(5);
    let diffuse = (Vec4::ONE - fr) * b.base * ((1.0 - b.metallic) * FRAC_1_PI);
    let a2 = b.alpha * b.alpha;
    let t = h.z * h.z * (a2 - 1.0) + 1.0;
    let d = a2 / (PI * t * t);
    let gv = n_l * (n_v * n_v * (1.0 - a2) + a2).sqrt();
    let gl = n_v * (n_l * n_l * (1.0 - a2) + a2).sqrt();
    let vis = if gv + gl > 0.0 { 0.5 / (gv + gl) } else { 0.0 };
    diffuse + fr * (d * vis)
}

/// `Brdf::eval` with a specular is the extension's formula (f64, 1e-5 relative) for weights,
/// F0 colours (grey, coloured, clamped at 1), metallic, roughness, indices and directions; the
/// same BRDF read without the extension (weight 1, the index's grey F0) is within round-off of
/// the plain one; and without a specular (`None`) every value at metallic 0 or 1 is the one
/// before the extension to the bit.
#[test]
fn the_brdf_is_the_extensions_formula() {
    let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
    let dirs =
        [(dir(0.2, 0.0), dir(0.5, 2.5)), (dir(0.9, 0.3), dir(1.2, 3.0)), (dir(1.3, 0.0), dir(0.4, 1.0))];
    type Case = (f32, Vec4, f32, f32, f32, f32);
    // (s, F0c per lane, F0c_max, metallic, roughness, η)
    let cases: [Case; 6] = [
        (1.0, Vec4::splat(0.04), 0.04, 0.0, 0.5, 1.5),
        (0.5, Vec4::new(0.9, 0.6, 0.2, 0.05), 0.95, 0.0, 0.4, 1.5),
        (0.25, Vec4::new(0.1, 0.3, 0.5, 0.7), 0.72, 0.3, 0.7, 1.8),
        (0.8, Vec4::ONE, 1.0, 0.0, 0.3, 1.33),
        (0.0, Vec4::splat(0.2), 0.2, 0.6, 0.5, 1.5),
        (1.0, Vec4::new(0.3, 0.1, 0.02, 0.0), 0.35, 1.0, 0.25, 1.5),
    ];
    let mut worst = 0.0f64;
    for (s, f0, f0_max, m, r, ior) in cases {
        let plain = Brdf::new(base, m, r).with_ior(ior);
        let sp = SpecularLanes { weight: s, f0, f0_max };
        let b = plain.with_specular(Some(sp));
        for (wo, wi) in dirs {
            let got = b.eval(wo, wi);
            let want = reference(
                l64(base),
                m.into(),
                b.alpha.into(),
                ior.into(),
                Some((s.into(), l64(f0), f0_max.into())),
                v64(wo),
                v64(wi),
            );
            for i in 0..4 {
                let e = (f64::from(got[i]) - want[i]).abs() / want[i].max(1e-3);
                worst = worst.max(e);
                assert!(e < 1e-5, "s {s} F0c {f0} m {m} r {r}, lane {i}: {} vs {}", got[i], want[i]);
            }
            // Without the extension, the formula and the BRDF are the plain glTF one's.
            let want = reference(l64(base), m.into(), b.alpha.into(), ior.into(), None, v64(wo), v64(wi));
            let got = plain.eval(wo, wi);
            for i in 0..4 {
                assert!((f64::from(got[i]) - want[i]).abs() <= 1e-5 * want[i].max(1e-3), "plain lane {i}");
            }
            // Bit for bit the arithmetic before the extension where that had the normative
            // mix already (m = 0 and 1; partial metals' diffuse changed with it).
            if m == 0.0 || m == 1.0 {
                assert_eq!(
                    plain.with_specular(None).eval(wo, wi).to_array(),
                    eval_before_specular(&plain, wo, wi).to_array()
                );
            }
            let f0_eta = scene::dielectric_f0(ior);
            let default = plain.with_specular(Some(SpecularLanes {
                weight: 1.0,
                f0: Vec4::splat(f0_eta),
                f0_max: f0_eta,
            }));
            assert!((default.eval(wo, wi) - got).abs().max_element() <= 2e-6 * got.max_element());
        }
    }
    println!("specular BRDF vs the f64 formula: worst relative error {worst:.2e}");
    // The weight scales the dielectric's specular lobe: a black dielectric reflects s × itself.
    let black = |s: f32| {
        Brdf::new(Vec4::ZERO, 0.0, 0.4)
            .with_specular(Some(SpecularLanes { weight: s, f0: Vec4::splat(0.04), f0_max: 0.04 }))
            .eval(dirs[1].0, dirs[1].1)
    };
    assert!((black(0.3) - black(1.0) * 0.3).abs().max_element() <= 1e-6 * black(1.0).x);
    // Lambert and films take no specular.
    let sp = Some(SpecularLanes { weight: 0.5, f0: Vec4::splat(0.5), f0_max: 0.5 });
    assert!(Brdf::lambertian(base).with_specular(sp).specular.is_none());
}

/// F0c per lane: a grey F0 colour is the constant (the table is not asked), a coloured one the
/// table's reflectance at each lane, as the base colour's; F0c_max is the RGB's largest channel.
#[test]
fn the_f0_colour_is_upsampled_as_a_reflectance() {
    struct Refuses;
    impl crate::RgbToSpectrum for Refuses {
        fn coefficients(&self, rgb: [f32; 3]) -> [f32; 3] {
            panic!("asked to upsample {rgb:?}")
        }
    }
    let l = Vec4::new(420.0, 500.0, 580.0, 660.0);
    let grey = SpecularLanes::new(0.7, Vec3::splat(0.0371), &Refuses, l);
    assert_eq!((grey.weight, grey.f0, grey.f0_max), (0.7, Vec4::splat(0.0371), 0.0371));
    let table = srgb_table();
    let rgb = Vec3::new(0.8, 0.48, 0.08);
    let c = SpecularLanes::new(1.0, rgb, table.as_ref(), l);
    assert_eq!(c.f0, crate::upsample::reflectance(table.as_ref(), rgb.to_array(), l));
    assert_eq!(c.f0_max, 0.8);
    let s = table.fetch([0.8, 0.48, 0.08]);
    for i in 0..4 {
        assert!((f64::from(c.f0[i]) - s.eval(f64::from(l[i]))).abs() < 1e-4, "lane {i}");
    }
    assert!(c.f0.x < 0.25 && c.f0.w > 0.6, "not yellow-orange: {}", c.f0);
}

/// The tracer's BRDF with a specular samples what it evaluates: its pdf integrates (by
/// quadrature) to the fraction of samples returned, and the sampler's mean of f·cos/pdf is the
/// quadrature's ∫ f·cos (the pattern of `bsdf`'s own test). The albedo is not the plain BRDF's,
/// and at weight 0 a dielectric is Lambert.
#[test]
fn sampling_with_a_specular_matches_its_value_and_pdf() {
    let base = Vec4::new(0.8, 0.6, 0.3, 0.9);
    for (s, f0, f0_max, m, r) in [
        (0.3f32, Vec4::new(0.9, 0.5, 0.1, 0.02), 0.95f32, 0.0f32, 0.4f32),
        (1.0, Vec4::ONE, 1.0, 0.0, 0.2),
        (0.6, Vec4::new(0.2, 0.4, 0.6, 0.8), 0.8, 0.5, 0.6),
        (0.0, Vec4::splat(0.04), 0.04, 0.0, 0.5),
    ] {
        let plain = Brdf::new(base, m, r);
        let b = plain.with_specular(Some(SpecularLanes { weight: s, f0, f0_max }));
        for theta in [0.4f32, 1.2] {
            let wo = dir(theta, 0.0);
            let (nt, np) = (800, 400);
            let (mut ip, mut ialb, mut iplain) = (0.0f64, Vec4::ZERO, Vec4::ZERO);
            for i in 0..nt {
                let c0 = (i as f32 + 0.5) / nt as f32;
                for j in 0..np {
                    let wi = dir(c0.acos(), 2.0 * std::f32::consts::PI * (j as f32 + 0.5) / np as f32);
                    let dw = (1.0 / nt as f32) * (2.0 * std::f32::consts::PI / np as f32);
                    ip += f64::from(b.pdf(wo, wi) * dw);
                    ialb += b.eval(wo, wi) * wi.z * dw;
                    iplain += plain.eval(wo, wi) * wi.z * dw;
                }
            }
            let mut rng = Sampler::new(3, 2);
            let n = 200_000;
            let (mut est, mut returned) = (Vec4::ZERO, 0);
            for _ in 0..n {
                if let Some(x) = b.sample(wo, rng.uniform(), rng.next2()) {
                    assert_eq!((x.f, x.pdf), (b.eval(wo, x.wi), b.pdf(wo, x.wi)));
                    est += x.f * x.wi.z / x.pdf;
                    returned += 1;
                }
            }
            est /= n as f32;
            let frac = returned as f64 / n as f64;
            let what = format!("s {s} F0c {f0} m {m} r {r} θ {theta}");
            println!("{what}: ∫pdf {ip:.4} vs returned {frac:.4}; ∫f·cos {ialb} vs sampled {est}");
            assert!(ip <= 1.0 + 1e-3 && (ip - frac).abs() < 0.01, "{what}: ∫pdf = {ip}, sampled {frac}");
            assert!((est - ialb).abs().max_element() < 0.01, "{what}: {est} vs {ialb}");
            // The extension changes the albedo; at weight 0 a dielectric is its Lambertian base.
            assert!((ialb - iplain).abs().max_element() > 0.005, "{what}: {ialb} as without the extension");
            if s == 0.0 && m == 0.0 {
                assert!((ialb - base).abs().max_element() < 1e-3, "{what}: {ialb} vs the base {base}");
            }
            // The coat's sampling weighs against this: the albedo's lane mean, near the quadrature.
            let a = b.albedo_estimate(wo.z);
            assert!(a > 0.0 && a.is_finite());
        }
    }
}

/// [`estimate`] with its own stream `seed`: pixels estimated with one stream each are
/// independent trials.
fn estimate_seeded(n: usize, seed: u64, mut f: impl FnMut(&mut Sampler) -> Vec4) -> (Vec4, Vec4) {
    let mut rng = Sampler::new(42, seed);
    estimate(n, |_| f(&mut rng))
}

/// ∫ D·V·cos θ_i dω_i and ∫ (1 − |v·h|)⁵·D·V·cos θ_i dω_i at cos θ_o = `c` (f64 midpoint
/// quadrature over half the circle, twice): a black dielectric with a specular reflects
/// s·(F0c·A0 + (1 − F0c)·A1) of a uniform surround.
fn lobe_albedos(alpha: f64, c: f64) -> (f64, f64) {
    let a2 = alpha * alpha;
    let so = (1.0 - c * c).max(0.0).sqrt();
    let (nt, np) = (600, 200);
    let (mut a0, mut a1) = (0.0, 0.0);
    for i in 0..nt {
        let ci = (i as f64 + 0.5) / nt as f64;
        let si = (1.0 - ci * ci).sqrt();
        for j in 0..np {
            let phi = PI * (j as f64 + 0.5) / np as f64;
            let h = [so + si * phi.cos(), si * phi.sin(), c + ci];
            let hl = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            let (nh, vh) = (h[2] / hl, (so * h[0] + c * h[2]) / hl);
            let t = nh * nh * (a2 - 1.0) + 1.0;
            let d = a2 / (PI * t * t);
            let v = 0.5 / (ci * (c * c * (1.0 - a2) + a2).sqrt() + c * (ci * ci * (1.0 - a2) + a2).sqrt());
            a0 += d * v * ci;
            a1 += (1.0 - vh).max(0.0).powi(5) * d * v * ci;
        }
    }
    let k = (2.0 * PI / np as f64) / nt as f64;
    (a0 * k, a1 * k)
}

/// Furnace: a black dielectric sphere (base 0, roughness 0.4; convex, so every reflection
/// escapes) in a uniform white surround, specular weight s and colour `color` (η 1.5). At each
/// pixel centre the radiance is Le·s·(F0c(λ)·A0 + (1 − F0c(λ))·A1) at its facet's cos
/// (quadrature, [`lobe_albedos`]), F0c(λ) the table's reflectance for the F0 colour; 2000 paths
/// per pixel (a stream of its own each: independent trials), within 5 standard errors per lane. Returns the mean over the pixels of the
/// radiance over Le (the four lanes) and the lanes' wavelengths.
fn black_sphere_furnace(
    s: f32,
    color: Vec3,
    up: &dyn crate::RgbToSpectrum,
    f0c: impl Fn(f64) -> f64,
) -> (Vec4, Vec4) {
    let roughness = 0.4f32;
    let mat = Material {
        roughness,
        spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(0.0))),
        specular: Some(specular(s, color)),
        ..Default::default()
    };
    let mut scene = with_env(
        scene_with(vec![sphere(Vec3::ZERO, 1.0, 48, 0)], vec![mat], vec![]),
        scene::Environment::uniform(Vec3::ONE),
    );
    scene.camera = Camera::look_at(Vec3::new(0.0, 0.6, 3.0), Vec3::ZERO, Vec3::Y, 0.7);
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, up, &d65(), range, None).unwrap();
    let integ = Integrator { world: &world, direct_only: false, max_depth: 100, lambert: false };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.3);
    // The surround's radiance as the tracer upsamples an RGB emitter (D65, to the table's fit).
    let le = world.units.rgb(Vec3::ONE, up, wl.0);
    let f0c: [f64; 4] = std::array::from_fn(|i| f0c(f64::from(wl.0[i])));
    let (w, h) = (8u32, 8u32);
    let cam = crate::camera::RayCamera::new(&scene.camera, w, h);
    let (mut n, mut sum, mut worst) = (0, Vec4::ZERO, 0.0f32);
    for i in 0..w * h {
        let r = cam.ray(Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5));
        let Some(hit) = world.geometry.intersect(r.o, r.d, f32::INFINITY) else { continue };
        let cos = f64::from(world.surface(&hit).ng.dot(-r.d));
        let (a0, a1) = lobe_albedos(f64::from(roughness * roughness), cos);
        let a = Vec4::from_array(std::array::from_fn(|k| {
            (f64::from(s) * (f0c[k] * a0 + (1.0 - f0c[k]) * a1)) as f32
        }));
        let (m, se) =
            estimate_seeded(2000, u64::from(i), |rng| radiance_any_hero(&integ, r.o, r.d, &wl, rng));
        assert_within(m, se, le * a, &format!("s {s} colour {color}, pixel {i}, cos {cos:.3}"));
        worst = worst.max(((m - le * a).abs() / se.max(Vec4::splat(1e-12))).max_element());
        sum += m / le;
        n += 1;
    }
    println!(
        "black sphere furnace, s {s}, colour {color}: {n} pixels, worst lane {worst:.2} standard errors"
    );
    assert!(n > 30, "{n} pixels on the sphere");
    (sum / n as f32, wl.0)
}

/// The weight scales a black dielectric's whole reflection: s = 0.5 and 0.2 reflect that share
/// of s = 1, pixel by pixel against the quadrature (grey F0c 0.04 of η 1.5), and s = 0
/// reflects nothing. Ignoring the extension would reflect the s = 1 furnace at every weight.
#[test]
fn the_weight_scales_a_black_dielectrics_reflection() {
    let (full, _) = black_sphere_furnace(1.0, Vec3::ONE, &GreyOnly, |_| 0.04);
    for s in [0.5f32, 0.2] {
        let (got, _) = black_sphere_furnace(s, Vec3::ONE, &GreyOnly, |_| 0.04);
        println!(
            "black dielectric furnace, s {s}: {:.5} of s = 1 (lane means {got} vs {full})",
            got.x / full.x
        );
    }
    assert_eq!(black_sphere_furnace(0.0, Vec3::ONE, &GreyOnly, |_| 0.04).0, Vec4::ZERO);
}

/// A yellow-orange F0 colour on a black base: colour (20, 12, 2) makes F0c = min(0.04·colour, 1)
/// = (0.8, 0.48, 0.08), upsampled by the sRGB table; pixel by pixel the lanes follow its
/// spectrum (blue lanes far below the red), and a colour beyond the clamp (25, 25, 0) reflects as
/// F0c (1, 1, 0).
#[test]
fn a_coloured_f0_colours_a_black_dielectrics_reflection() {
    let table = srgb_table();
    for (color, f0) in
        [(Vec3::new(20.0, 12.0, 2.0), [0.8, 0.48, 0.08]), (Vec3::new(25.0, 25.0, 0.0), [1.0, 1.0, 0.0])]
    {
        let spectrum = table.fetch(f0);
        let (got, l) = black_sphere_furnace(1.0, color, table.as_ref(), |l| spectrum.eval(l));
        println!("black dielectric furnace, F0c {f0:?}: lanes {l} nm, means {got}");
        let lane = |x: f32| l.to_array().iter().position(|&y| y == x).unwrap();
        let (blue, red) = (got[lane(l.min_element())], got[lane(l.max_element())]);
        assert!(blue < 0.5 * red, "{got} at {l}");
    }
}

/// The same in the truth's RGB output: a black dielectric plane seen at 45° in a uniform white
/// surround (narrow field of view: one angle), rendered and converted to linear sRGB, reflects
/// per channel s·(A1 + (A0 − A1)·F0c), the F0 colour's RGB (the table reproduces an in-gamut
/// reflectance's RGB; 1 % allowed for its fit), within 5 standard errors over the pixels. With
/// the white F0 the channels are equal; with (0.8, 0.48, 0.08) blue is a fraction of red.
#[test]
fn a_coloured_f0_colours_the_rgb_render_as_its_rgb() {
    let table = srgb_table();
    let roughness = 0.4f32;
    let theta = 45f32.to_radians();
    let (a0, a1) = lobe_albedos(f64::from(roughness * roughness), f64::from(theta.cos()));
    let srgb = RgbColorSpace::srgb();
    for (s, color) in [(1.0f32, Vec3::ONE), (0.6, Vec3::new(20.0, 12.0, 2.0))] {
        let mat = Material {
            roughness,
            spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(0.0))),
            specular: Some(specular(s, color)),
            ..Default::default()
        };
        let mut scene = with_env(
            scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 4.0, 0)], vec![mat], vec![]),
            scene::Environment::uniform(Vec3::ONE),
        );
        let eye = Vec3::new(0.0, theta.cos(), theta.sin()) * 3.0;
        scene.camera = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.01);
        let st = Settings { seed: 7, ..Settings::new(16, 16, 64).unwrap() };
        let img = render(&scene, table.as_ref(), &st, &Default::default(), &|_| {}).unwrap();
        let rgb = img.to_rgb(&srgb);
        let f0 = scene::specular::f0_color(0.04, color);
        for c in 0..3 {
            let v: Vec<f64> = rgb.iter().map(|p| f64::from(p[c])).collect();
            let n = v.len() as f64;
            let mean = v.iter().sum::<f64>() / n;
            let se = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
            let want = f64::from(s) * (a1 + (a0 - a1) * f64::from(f0[c]));
            println!("plane, s {s}, F0c {f0}: channel {c} {mean:.5} ± {se:.5}, want {want:.5}");
            assert!(
                (mean - want).abs() <= 5.0 * se + 0.01 * want,
                "s {s} colour {color}, channel {c}: {mean} vs {want}"
            );
        }
    }
}

/// F0c_max: a white base (0.9) with weight 1 and a red F0 colour (colour (20, 0, 0): F0c =
/// (0.8, 0, 0)) under a point light overhead, seen at 60° (direct light; every path the same).
/// Per lane against the same plane without the extension (same light and geometry, so the
/// ratio is f_specular/f_plain), the diffuse part (1 − F_dmax)·0.9/π is the same at every lane —
/// neutral, as F_dmax uses the RGB's largest channel — while a diffuse share taken per lane,
/// 1 − F_d(λ), would be cyan (5 times brighter at the blue and green lanes, near 0 at the red).
#[test]
fn the_diffuse_share_of_a_coloured_f0_stays_neutral() {
    let table = srgb_table();
    let roughness = 0.3f32;
    let render_plane = |sp: Option<Specular>| {
        let mat = Material {
            roughness,
            spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(0.9))),
            specular: sp,
            ..Default::default()
        };
        let light = Light {
            name: "p".into(),
            kind: LightKind::Point { position: Vec3::new(0.0, 1.0, 0.0), range: None },
            emission: Emission { rgb: Vec3::ONE, intensity: 1.0, spectrum: None },
            stands_in_for: None,
        };
        let scene = scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 4.0, 0)], vec![mat], vec![light]);
        let world = World::new(&scene, table.as_ref(), &d65(), WavelengthRange::VISIBLE, None).unwrap();
        let integ = Integrator { world: &world, direct_only: true, max_depth: 10, lambert: false };
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), world.units.range).sample(0.2);
        let wo = Vec3::new(60f32.to_radians().sin(), 60f32.to_radians().cos(), 0.0);
        let mut rng = Sampler::new(1, 0);
        let r = integ.radiance(wo * 2.0, -wo, &wl, &mut rng);
        assert_eq!(r, integ.radiance(wo * 2.0, -wo, &wl, &mut rng), "not deterministic");
        (r, wl)
    };
    let (plain, wl) = render_plane(None);
    let (red, wl2) = render_plane(Some(specular(1.0, Vec3::new(20.0, 0.0, 0.0))));
    assert_eq!(wl.0, wl2.0);
    let spectrum = table.fetch([0.8, 0.0, 0.0]);
    let f0c: [f64; 4] = std::array::from_fn(|i| spectrum.eval(f64::from(wl.0[i])));
    let alpha = f64::from(roughness * roughness);
    let (wo, wi) = ([60f64.to_radians().sin(), 0.0, 60f64.to_radians().cos()], [0.0, 0.0, 1.0]);
    let f_plain = reference([0.9; 4], 0.0, alpha, 1.5, None, wo, wi);
    let f_red = reference([0.9; 4], 0.0, alpha, 1.5, Some((1.0, f0c, 0.8)), wo, wi);
    // The specular lobe alone (base 0), to take from the measured f.
    let lobe = reference([0.0; 4], 0.0, alpha, 1.5, Some((1.0, f0c, 0.8)), wo, wi);
    let mut diffuse = [0.0f64; 4];
    for i in 0..4 {
        let ratio = f64::from(red[i]) / f64::from(plain[i]);
        let want = f_red[i] / f_plain[i];
        assert!((ratio - want).abs() < 1e-4 * want, "lane {i} ({} nm): {ratio} vs {want}", wl.0[i]);
        diffuse[i] = ratio * f_plain[i] - lobe[i];
    }
    let h = 0.5 * (1.0 + 60f64.to_radians().cos()).sqrt() * std::f64::consts::SQRT_2;
    let x = (1.0 - h).powi(5);
    let neutral = (1.0 - (0.8 + 0.2 * x)) * 0.9 / PI;
    let per_lane: [f64; 4] = std::array::from_fn(|i| (1.0 - (f0c[i] + (1.0 - f0c[i]) * x)) * 0.9 / PI);
    println!(
        "white base, red F0c: lanes {:?} nm, F0c {f0c:.3?}; diffuse {diffuse:.5?} (neutral {neutral:.5}; a per-lane share would be {per_lane:.5?})",
        wl.0.to_array()
    );
    for (i, d) in diffuse.iter().enumerate() {
        assert!((d - neutral).abs() < 1e-4 * neutral, "lane {i}: diffuse {d} vs {neutral}");
    }
    assert!(
        per_lane.iter().fold(0.0f64, |a, &b| a.max(b)) > 1.5 * neutral,
        "the test cannot tell: {per_lane:?}"
    );
}

/// The textures are read as the clear coat's are: the weight from the specular texture's A
/// (linear), the colour from the colour texture's RGB (sRGB-decoded), times the factors.
#[test]
fn the_textures_scale_weight_and_colour() {
    let tex = |rgba: [u8; 4], srgb: bool| Texture {
        sampler: Default::default(),
        name: "t".into(),
        width: 1,
        height: 1,
        rgba8: rgba.to_vec(),
        srgb,
    };
    let r = |index| Some(TextureRef { index, tex_coord: 0, transform: None });
    let m = Material {
        ior: 1.8,
        specular: Some(Specular {
            factor: 0.8,
            texture: r(0),
            color: Vec3::new(4.0, 2.0, 1.0),
            color_texture: r(1),
        }),
        ..Default::default()
    };
    let textures = [tex([10, 20, 30, 128], false), tex([255, 128, 64, 7], true)];
    let (w, f0) = material::specular(&m, &textures, &TexCoords::one(Vec2::splat(0.5))).unwrap();
    assert!((w - 0.8 * 128.0 / 255.0).abs() < 1e-6, "{w}");
    let dec = |v: u8| crate::texture::srgb_decode(f32::from(v) / 255.0);
    let want =
        (Vec3::new(4.0 * dec(255), 2.0 * dec(128), dec(64)) * scene::dielectric_f0(1.8)).min(Vec3::ONE);
    assert!((f0 - want).abs().max_element() < 1e-6, "{f0} vs {want}");
    assert_eq!(
        material::specular(&Material { unlit: true, ..m.clone() }, &textures, &TexCoords::default()),
        None
    );
    assert_eq!(material::specular(&Material::default(), &textures, &TexCoords::default()), None);
}

/// The extension tests' sphere on a floor (`testing::two_materials_on_floor`), the floor of
/// index 1.8; `sp` on both materials.
fn two_material_scene(sp: Option<Specular>) -> scene::Scene {
    let mut s = crate::testing::two_materials_on_floor(|m| m.specular = sp.clone());
    s.materials[1].ior = 1.8;
    s
}

/// The extension at its defaults' values (weight 1, white) is the BRDF without it up to
/// round-off (that renders without it are the bits they were is checked on the built-ins and by
/// `spectra eval --quick`'s results, not pinned here). `--lambert` ignores the
/// extension entirely, as it ignores films and coats; without it a weight of 0.3 shows.
#[test]
fn without_the_extension_renders_are_unchanged() {
    let plain = crate::testing::small_render(&two_material_scene(None), false);
    assert_eq!(plain.dropped, 0);
    let default = crate::testing::small_render(&two_material_scene(Some(specular(1.0, Vec3::ONE))), false);
    let (a, b) = (plain.mean(), default.mean());
    println!("defaults' values: image mean {b:?} vs {a:?}");
    assert!((0..3).all(|c| (a[c] - b[c]).abs() <= 1e-3 * a[c]), "{b:?} vs {a:?}");
    let weak = two_material_scene(Some(specular(0.3, Vec3::new(1.0, 0.5, 2.0))));
    assert!(
        crate::testing::small_render(&weak, true).xyz
            == crate::testing::small_render(&two_material_scene(None), true).xyz
    );
    assert!(crate::testing::small_render(&weak, false).xyz != plain.xyz);
}
