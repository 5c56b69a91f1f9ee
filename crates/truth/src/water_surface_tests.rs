//! Transport through the water surface against closed forms and quadrature: the sky seen through
//! Snell's window (T·n²·L_air·e^{−a·z}), total internal reflection, Fresnel reflection inside the
//! window, and a white Lambertian floor lit by the sky alone (with the floor ↔ surface
//! inter-reflections summed as a geometric series). Each drops a factor and the test fails: n²
//! (×1.8), T (≈ 2–7 %), e^{−a·z} (×1.4–1.8), TIR (the floor case's K term, ≈ 16 %).

use super::*;
use crate::integrator::Integrator;
use crate::medium::{Medium, Phase, Region};
use crate::rng::Sampler;
use crate::spectral::Wavelengths;
use crate::testing::{quad, scene_with};
use crate::upsample::GreyOnly;
use crate::world::World;
use color::{Spectrum, WavelengthRange};
use glam::Vec4;
use scene::sky::SKY_STAND_IN;
use scene::{Emission, Light, LightKind, Material, Scene};
use std::f64::consts::PI;

const N: f64 = 1.34;
/// Sky irradiance just below the surface: `E_SKY` × D65 (tracer units, white D65).
const E_SKY: f32 = 2.0;
const WL: [f32; 4] = [420.0, 510.0, 590.0, 680.0];
const DOWN: Vec3 = Vec3::NEG_Y;

fn d65() -> Spectrum {
    color::illuminant::by_name("D65").unwrap()
}

/// The stand-in light scene::sky makes, built directly: irradiance E_SKY·D65 straight down.
fn sky_light() -> Light {
    Light {
        name: "sky".into(),
        kind: LightKind::Directional { direction: -Vec3::Y },
        emission: Emission { rgb: Vec3::ONE, intensity: E_SKY, spectrum: Some(d65()) },
        stands_in_for: Some(SKY_STAND_IN),
    }
}

/// Water between y = −50 and the surface at `top`, ±200 units sideways.
fn water(a: f64, top: f32) -> Medium {
    Medium {
        sigma_a: Spectrum::Constant(a),
        sigma_s: Spectrum::Constant(0.0),
        phase: Phase::Isotropic,
        region: Region::Box { min: Vec3::new(-200.0, -50.0, -200.0), max: Vec3::new(200.0, top, 200.0) },
        surface_ior: Some(N as f32),
    }
}

/// L_air(λ) at the test wavelengths: E_sky / (π·T̄), by hand.
fn l_air() -> Vec4 {
    let tbar = mean_transmittance(N);
    Vec4::from_array(WL.map(|l| (E_SKY as f64 * d65().eval(l as f64) / (PI * tbar)) as f32))
}

/// Mean and standard error per lane of `n` one-path estimates from `o` along `d`, the hero
/// lane chosen uniformly (as the renderer does) so spectral MIS is unbiased.
fn estimate(world: &World, o: Vec3, d: Vec3, n: usize) -> (Vec4, Vec4) {
    let integ = Integrator { world, direct_only: false, max_depth: 1000, lambert: true };
    let (mut s, mut s2) = ([0.0f64; 4], [0.0f64; 4]);
    for i in 0..n {
        let mut rng = Sampler::new(11, i as u64);
        let k = ((rng.uniform() * 4.0) as usize).min(3);
        let wl = Wavelengths(Vec4::from_array(std::array::from_fn(|j| WL[(j + k) % 4])));
        let r = integ.radiance(o, d, &wl, &mut rng);
        for j in 0..4 {
            let v = r[(j + 4 - k) % 4] as f64;
            s[j] += v;
            s2[j] += v * v;
        }
    }
    let m = s.map(|v| v / n as f64);
    let se: [f64; 4] =
        std::array::from_fn(|j| ((s2[j] / n as f64 - m[j] * m[j]).max(0.0) / (n as f64 - 1.0)).sqrt());
    (Vec4::from_array(m.map(|v| v as f32)), Vec4::from_array(se.map(|v| v as f32)))
}

fn assert_close(got: (Vec4, Vec4), want: Vec4, what: &str) {
    for j in 0..4 {
        let tol = 5.0 * got.1[j] + 2e-5 * want[j].abs();
        assert!(
            (got.0[j] - want[j]).abs() <= tol,
            "{what}, {} nm: got {} ± {}, want {}",
            WL[j],
            got.0[j],
            got.1[j],
            want[j]
        );
    }
}

fn world<'s>(scene: &'s Scene, m: &Medium) -> World<'s> {
    World::new(scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, Some(m)).unwrap()
}

/// A camera in clear water looking up through Snell's window sees L_air·T(θ)·n², in absorbing
/// water times e^{−a·z/cosθ}; the floor far below is black, so the Fresnel-reflected part adds
/// nothing.
#[test]
fn looking_up_sees_the_sky_times_t_n2_and_beer() {
    let black = Material { base_color: Vec4::new(0.0, 0.0, 0.0, 1.0), ..Material::default() };
    let scene =
        scene_with(vec![quad(Vec3::new(0.0, -40.0, 0.0), Vec3::Y, 150.0, 0)], vec![black], vec![sky_light()]);
    let z = 3.0f32;
    for (a, theta_deg) in [(0.0, 0.0f64), (0.0, 30.0), (0.0, 45.0), (0.2, 0.0), (0.2, 40.0)] {
        let m = water(a, z);
        let w = world(&scene, &m);
        let th = theta_deg.to_radians();
        let d = Vec3::new(th.sin() as f32, th.cos() as f32, 0.0);
        let t = transmittance_up(th.cos(), N);
        let beer = (-a * z as f64 / th.cos()).exp();
        let want = l_air() * (t * N * N * beer) as f32;
        // Without absorption the estimate is deterministic: one path suffices and SE = 0.
        let n = if a == 0.0 { 64 } else { 40_000 };
        assert_close(estimate(&w, Vec3::ZERO, d, n), want, &format!("a={a}, θ={theta_deg}°"));
    }
}

/// Outside Snell's window the surface is a perfect mirror (TIR); inside it, it reflects R(θ).
/// Under a black sky above an emissive floor, a camera looking up at 60° (beyond the critical
/// 48.3°) sees exactly the floor's emission; at 40° it sees T·n²·L_air + R·Le.
#[test]
fn total_internal_reflection_and_fresnel_reflection_show_the_floor() {
    let glow = Material {
        base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
        emissive: Vec3::splat(0.5),
        ..Material::default()
    };
    let floor = vec![quad(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, 150.0, 0)];
    // The floor's emission, seen straight down with no surface on the way.
    let dark = scene_with(floor.clone(), vec![glow.clone()], vec![]);
    let m = water(0.0, 2.0);
    let le = estimate(&world(&dark, &m), Vec3::ZERO, DOWN, 16).0;
    assert!(le.min_element() > 0.1, "{le}");

    let th = 60f64.to_radians();
    let d = Vec3::new(th.sin() as f32, th.cos() as f32, 0.0);
    assert_close(estimate(&world(&dark, &m), Vec3::ZERO, d, 16), le, "TIR at 60°");

    let lit = scene_with(floor, vec![glow], vec![sky_light()]);
    let th = 40f64.to_radians();
    let d = Vec3::new(th.sin() as f32, th.cos() as f32, 0.0);
    let t = transmittance_up(th.cos(), N);
    let want = l_air() * (t * N * N) as f32 + le * (1.0 - t) as f32;
    assert_close(estimate(&world(&lit, &m), Vec3::ZERO, d, 200_000), want, "inside the window at 40°");
}

/// Midpoint rule over μ ∈ [lo, 1] with `k` cells.
fn integrate(lo: f64, k: usize, f: impl Fn(f64) -> f64) -> f64 {
    let h = (1.0 - lo) / k as f64;
    (0..k).map(|i| f(lo + (i as f64 + 0.5) * h)).sum::<f64>() * h
}

/// A white Lambertian floor h below the surface in absorbing water, lit by the sky alone. Its
/// radiance L_f is uniform (an infinite plane under a uniform sky), so
///
/// L_f = (1/π)·(E_d + L_f·K),  E_d = 2π∫_{μc}^1 L_air·T·n²·e^{−a·h/μ} μ dμ,
/// K = 2π∫_0^1 R(μ)·e^{−2a·h/μ} μ dμ (R = 1 outside the window),
///
/// and a camera a distance d above it looking down sees L_f·e^{−a·d}.
#[test]
fn white_floor_under_the_sky_matches_quadrature() {
    let (a, h, d) = (0.3f64, 1.0f64, 0.5f64);
    let white = Material { base_color: Vec4::ONE, ..Material::default() };
    let scene = scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 190.0, 0)], vec![white], vec![sky_light()]);
    let m = water(a, h as f32);
    let w = world(&scene, &m);
    let got = estimate(&w, Vec3::new(0.0, d as f32, 0.0), DOWN, 60_000);

    let mu_c = (1.0 - 1.0 / (N * N)).sqrt();
    let ed =
        2.0 * PI * N * N * integrate(mu_c, 200_000, |mu| transmittance_up(mu, N) * (-a * h / mu).exp() * mu);
    let k = 2.0
        * PI
        * integrate(0.0, 200_000, |mu| (1.0 - transmittance_up(mu, N)) * (-2.0 * a * h / mu).exp() * mu);
    let lf = (ed / PI) / (1.0 - k / PI);
    let want = l_air() * (lf * (-a * d).exp()) as f32;
    assert!(k / PI > 0.1, "the TIR term must matter for this test to catch its loss: K/π = {}", k / PI);
    for j in 0..4 {
        eprintln!(
            "white floor, {} nm: path traced {:.4} ± {:.4}, quadrature {:.4} (first bounce alone {:.4}, K/π {:.4})",
            WL[j],
            got.0[j],
            got.1[j],
            want[j],
            ed / PI * l_air()[j] as f64 * (-a * d).exp(),
            k / PI
        );
    }
    assert_close(got, want, "white floor under the sky");
}

/// A sky with nowhere to be seen, and a sky the scene asks for without its stand-in, are errors.
#[test]
fn sky_needs_a_surface_and_a_stand_in() {
    let scene = scene_with(vec![], vec![], vec![sky_light()]);
    let no_surface = Medium { surface_ior: None, ..water(0.1, 1.0) };
    let e = World::new(&scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, Some(&no_surface)).err().unwrap();
    assert!(e.to_string().contains("no water surface"), "{e}");
    let e = World::new(&scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, None).err().unwrap();
    assert!(e.to_string().contains("no water surface"), "{e}");
    let mut asks = scene_with(vec![], vec![], vec![]);
    asks.water = Some(scene::WaterSettings {
        water_type: "II".into(),
        depth: 1.0,
        sun_direction: Vec3::Y,
        scale: 1.0,
        sky: 0.2,
    });
    let e =
        World::new(&asks, &GreyOnly, &d65(), WavelengthRange::VISIBLE, Some(&water(0.1, 1.0))).err().unwrap();
    assert!(e.to_string().contains("stand-in"), "{e}");
}
