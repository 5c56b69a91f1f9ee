//! See-through materials in the path tracer against analytic values: a glass sphere in a
//! white furnace returns the furnace's radiance (energy kept, with and without dispersion);
//! a glass slab in front of an emitter transmits the two-interface Fresnel value with its
//! internal reflections, (1 − R)²τ / (1 − R²τ²) with τ the volume's Beer transmittance; with
//! direct light only, the first pass alone; a prism refracts each wavelength by Snell's law
//! with the dispersion extension's index.

use crate::dielectric::{Dielectric, refract};
use crate::integrator::Integrator;
use crate::rng::Sampler;
use crate::sampling::Frame;
use crate::spectral::{Wavelengths, XyzSensor};
use crate::testing::{quad, scene_with, sphere};
use crate::upsample::GreyOnly;
use crate::world::World;
use color::{Observer, Spectrum, WavelengthRange};
use glam::{Vec3, Vec4};
use scene::transmission::{Transmission, Volume, fresnel_dielectric};
use scene::{Material, SpectralReflectance};

fn d65() -> Spectrum {
    color::illuminant::by_name("D65").unwrap()
}

fn glass(ior: f32, roughness: f32, volume: Option<Volume>, dispersion: f32) -> Material {
    Material {
        base_color: Vec4::ONE,
        spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(1.0))),
        metallic: 0.0,
        roughness,
        ior,
        transmission: Some(Transmission { factor: 1.0, texture: None, volume, dispersion }),
        ..Default::default()
    }
}

fn clear(thickness: f32) -> Volume {
    Volume {
        thickness,
        thickness_texture: None,
        attenuation_color: [1.0; 3],
        attenuation_distance: f32::INFINITY,
    }
}

/// Mean per lane over `n` paths with a uniformly chosen hero lane (as the renderer's hero
/// wavelengths are), in the order of `wl`.
fn mean_radiance(integ: &Integrator, o: Vec3, dirs: &[Vec3], wl: &Wavelengths, n: usize) -> (Vec4, Vec4) {
    let mut rng = Sampler::new(11, 0);
    let (mut s, mut s2) = ([0.0f64; 4], [0.0f64; 4]);
    for i in 0..n {
        let k = ((rng.uniform() * 4.0) as usize).min(3);
        let rotated = Wavelengths(Vec4::from_array(std::array::from_fn(|j| wl.0[(j + k) % 4])));
        let r = integ.radiance(o, dirs[i % dirs.len()], &rotated, &mut rng);
        for j in 0..4 {
            let v = f64::from(r[(j + 4 - k) % 4]);
            s[j] += v;
            s2[j] += v * v;
        }
    }
    let n = n as f64;
    let mean: [f64; 4] = s.map(|v| v / n);
    let se: [f64; 4] = std::array::from_fn(|j| ((s2[j] / n - mean[j] * mean[j]).max(0.0) / (n - 1.0)).sqrt());
    (Vec4::from_array(mean.map(|v| v as f32)), Vec4::from_array(se.map(|v| v as f32)))
}

/// A clear glass sphere (smooth and rough, index 1.5, with and without a strong dispersion, and
/// rough at index 1.0: index-matched, invisible) in a uniform white environment: every path
/// that leaves brings back the environment's radiance, so the sphere must look like the
/// environment (a furnace) to within 1 %.
#[test]
fn a_glass_sphere_in_a_furnace_keeps_energy() {
    let range = WavelengthRange::VISIBLE;
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.4);
    let env = Vec4::from_array(wl.0.to_array().map(|l| d65().eval(f64::from(l)) as f32));
    // The last case with a thin film (KHR_materials_iridescence), which a clear film keeps
    // energy through: what it does not reflect it transmits, inside and out.
    for (ior, roughness, dispersion, filmed) in [
        (1.5, 0.0, 0.0, false),
        (1.5, 0.2, 0.0, false),
        (1.5, 0.0, 2.0, false),
        (1.0, 0.3, 0.0, false),
        (1.5, 0.1, 0.0, true),
    ] {
        let mut material = glass(ior, roughness, Some(clear(2.0)), dispersion);
        if filmed {
            material.iridescence = Some(scene::Iridescence {
                factor: 1.0,
                texture: None,
                ior: 1.33,
                thickness_min: 100.0,
                thickness_max: 400.0,
                thickness_texture: None,
            });
        }
        let scene = scene_with(vec![sphere(Vec3::ZERO, 1.0, 96, 0)], vec![material], vec![]);
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap().with_environment(&d65());
        let integ = Integrator { world: &world, direct_only: false, max_depth: 1000, lambert: false };
        // Rays at the sphere over its whole disc, from the centre to the grazing edge.
        let o = Vec3::new(0.0, 0.0, 4.0);
        let dirs: Vec<Vec3> = (0..64)
            .map(|i| (Vec3::new(0.95 * (i as f32 / 63.0), 0.013 * i as f32, 0.0) - o).normalize())
            .collect();
        let (m, se) = mean_radiance(&integ, o, &dirs, &wl, 40_000);
        for j in 0..4 {
            let rel = (m[j] / env[j] - 1.0).abs();
            assert!(
                rel <= 0.01 && (m[j] - env[j]).abs() <= 5.0 * se[j] + 0.005 * env[j],
                "η {ior}, roughness {roughness}, dispersion {dispersion}, film {filmed}, lane {j}: {} ± {} vs {} ({:.2} %)",
                m[j],
                se[j],
                env[j],
                100.0 * rel
            );
        }
    }
}

/// A glass slab (two parallel faces 0.1 apart, index 1.5) between the camera and a black
/// emitter, seen at normal incidence: L = Le·(1 − R)²τ / (1 − R²τ²) with R the exact Fresnel
/// reflectance and τ = c^(t/d) the volume's transmittance per pass (grey here); with direct light
/// only the internal reflections are bounces, so L = Le·(1 − R)²τ.
#[test]
fn a_glass_slab_transmits_the_two_interface_fresnel_value() {
    let range = WavelengthRange::VISIBLE;
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.6);
    let le = 2.0f32;
    // Single-sided too: "the doubleSided property has no effect on volume boundaries"
    // (KHR_materials_volume); culled back faces kept the ray inside (0.42 for 0.92).
    for (ior, c, direct_only, double_sided) in [
        (1.5f32, 1.0f32, false, true),
        (1.5, 0.4, false, true),
        (2.0, 0.7, false, true),
        (1.5, 0.4, true, true),
        (1.5, 1.0, false, false),
        (1.5, 0.4, false, false),
    ] {
        let t = 0.1f32;
        let (distance, color) = if c < 1.0 { (0.25, [c; 3]) } else { (f32::INFINITY, [1.0; 3]) };
        let volume = Volume {
            thickness: t,
            thickness_texture: None,
            attenuation_color: color,
            attenuation_distance: distance,
        };
        let emitter = Material {
            base_color: Vec4::new(0.0, 0.0, 0.0, 1.0),
            emissive: Vec3::splat(le),
            emission_spectrum: Some(Spectrum::Constant(f64::from(le))),
            ..Default::default()
        };
        let scene = scene_with(
            vec![
                quad(Vec3::new(0.0, 0.0, t * 0.5), Vec3::Z, 50.0, 0),
                quad(Vec3::new(0.0, 0.0, -t * 0.5), -Vec3::Z, 50.0, 0),
                quad(Vec3::new(0.0, 0.0, -1.0), Vec3::Z, 50.0, 1),
            ],
            vec![Material { double_sided, ..glass(ior, 0.0, Some(volume), 0.0) }, emitter],
            vec![],
        );
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let integ = Integrator { world: &world, direct_only, max_depth: 1000, lambert: false };
        let (m, se) = mean_radiance(&integ, Vec3::new(0.0, 0.0, 2.0), &[-Vec3::Z], &wl, 20_000);
        let r = fresnel_dielectric(1.0, f64::from(ior));
        let tau = f64::from(c).powf(f64::from(t / distance));
        let want = if direct_only {
            (1.0 - r).powi(2) * tau
        } else {
            (1.0 - r).powi(2) * tau / (1.0 - r * r * tau * tau)
        };
        for j in 0..4 {
            // The emission in tracer units at this lane: what a direct view of the emitter gives.
            let bare = integ_emitter(&world, &wl, j);
            let got = f64::from(m[j]) / bare;
            assert!(
                (got - want).abs() <= 0.005 * want + 5.0 * f64::from(se[j]) / bare,
                "η {ior}, c {c}, direct only {direct_only}, double-sided {double_sided}, lane {j}: {got:.5} vs {want:.5}"
            );
        }
    }
}

/// The emitter's radiance at lane `j` of `wl`, seen directly (tracer units).
fn integ_emitter(world: &World, wl: &Wavelengths, j: usize) -> f64 {
    let integ = Integrator { world, direct_only: false, max_depth: 2, lambert: false };
    let mut rng = Sampler::new(1, 1);
    // From just in front of the emitter, looking at it: nothing between.
    f64::from(integ.radiance(Vec3::new(0.0, 0.0, -0.9), -Vec3::Z, wl, &mut rng)[j])
}

/// A 60° prism of dispersive glass (index 1.6 at the d line, dispersion 1, an Abbe number of
/// 20): a ray entering one face at 50° leaves the other at the angle Snell's law gives with
/// the extension's index at each wavelength, to 0.1° — through the path tracer's own sampling
/// of its two smooth interfaces (the median of sampled refractions, GGX's tail aside).
#[test]
fn a_prism_refracts_each_wavelength_by_snells_law() {
    let t = Transmission { factor: 1.0, texture: None, volume: Some(clear(1.0)), dispersion: 1.0 };
    let apex = 60f32.to_radians();
    let theta1 = 50f32.to_radians();
    // Faces in the xz-plane: outward normals at ∓30° from −x (the base is along −z).
    let n1 = Vec3::new(-(apex / 2.0).cos(), 0.0, (apex / 2.0).sin());
    let n2 = Vec3::new((apex / 2.0).cos(), 0.0, (apex / 2.0).sin());
    // The incoming ray, at θ1 to the first face's normal, heading into the prism.
    let d_in = {
        let f = Frame::from_normal(n1);
        let local = Vec3::new(theta1.sin(), 0.0, -theta1.cos());
        let w = f.to_world(local);
        // Keep it in the xz-plane, bending towards the base.
        Vec3::new(w.x, 0.0, w.z).normalize()
    };
    let mut deviations = Vec::new();
    for lambda in [420.0f64, 486.13, 587.56, 656.27, 700.0] {
        let n = t.ior_at(1.6, lambda) as f32;
        let through = |d: Vec3, normal: Vec3, eta: f32, rng: &mut Sampler| -> Vec3 {
            // Sampled at the smallest roughness; the median over many samples.
            let f = Frame::from_normal(normal);
            let b =
                Dielectric { tint: Vec4::ONE, alpha: crate::bsdf::MIN_ALPHA, eta, thin: false, film: None };
            let mut xs = Vec::new();
            for _ in 0..2001 {
                if let Some(s) = b.sample(f.to_local(-d), rng.uniform(), rng.next2())
                    && s.transmitted
                {
                    xs.push(f.to_world(s.wi));
                }
            }
            xs.sort_by(|a, b| a.x.total_cmp(&b.x));
            let exact = f.to_world(refract(f.to_local(-d), Vec3::Z, eta).unwrap());
            let m = xs[xs.len() / 2];
            assert!((m - exact).length() < 2e-3, "λ {lambda}: median {m} vs refraction {exact}");
            m
        };
        let mut rng = Sampler::new(2, 3);
        let inside = through(d_in, n1, n, &mut rng);
        // Leaving by the second face: the inside frame's normal is the inward one.
        let out = through(inside, -n2, 1.0 / n, &mut rng);
        // Snell at both faces in the plane: θ2 = asin(sin θ1 / n), θ3 = A − θ2, θ4 = asin(n sin θ3).
        let theta2 = (theta1.sin() / n).asin();
        let theta4 = (n * (apex - theta2).sin()).asin();
        let got = out.dot(n2).clamp(-1.0, 1.0).acos();
        assert!(
            (got - theta4).abs().to_degrees() < 0.1,
            "λ {lambda} nm (n = {n}): exit at {:.3}°, Snell {:.3}°",
            got.to_degrees(),
            theta4.to_degrees()
        );
        deviations.push(got);
    }
    // Blue leaves more steeply than red: the colours spread.
    assert!(deviations[0] > deviations[4] + 1f32.to_radians(), "{deviations:?}");
}
