//! Analytic checks of the estimator: furnaces (a uniform radiance field must be reproduced)
//! and single delta lights (closed-form direct lighting).

use super::*;
use crate::bsdf::Brdf;
use crate::medium::{Medium, Region};
use crate::spectral::Wavelengths;
use crate::spectral::XyzSensor;
use crate::testing::{quad, scene_with};
use crate::upsample::GreyOnly;
use color::{Observer, Spectrum, WavelengthRange};
use scene::{Emission, Light, LightKind, Material, SpectralReflectance};

pub(super) fn d65() -> Spectrum {
    color::illuminant::by_name("D65").unwrap()
}

/// One path with a uniformly chosen hero lane, results in the order of `wl`. The renderer
/// gets this for free (the hero wavelength is uniform over the range); a test that fixes the
/// wavelengths must randomise the hero itself, or spectral MIS is not unbiased.
pub(super) fn radiance_any_hero(
    integ: &Integrator,
    o: Vec3,
    d: Vec3,
    wl: &Wavelengths,
    rng: &mut Sampler,
) -> Vec4 {
    let k = ((rng.uniform() * 4.0) as usize).min(3);
    let rotated = Wavelengths(Vec4::from_array(std::array::from_fn(|i| wl.0[(i + k) % 4])));
    let r = integ.radiance(o, d, &rotated, rng);
    Vec4::from_array(std::array::from_fn(|j| r[(j + 4 - k) % 4]))
}

pub(super) fn spectrum_at(s: &Spectrum, wl: &Wavelengths) -> Vec4 {
    Vec4::from_array(wl.0.to_array().map(|l| s.eval(l as f64) as f32))
}

/// Mean and standard error of `n` independent one-path estimates per lane.
pub(super) fn estimate(n: usize, mut f: impl FnMut(&mut Sampler) -> Vec4) -> (Vec4, Vec4) {
    let mut rng = Sampler::new(42, 0);
    let (mut s, mut s2) = ([0.0f64; 4], [0.0f64; 4]);
    for _ in 0..n {
        let v = f(&mut rng).to_array();
        for i in 0..4 {
            s[i] += v[i] as f64;
            s2[i] += v[i] as f64 * v[i] as f64;
        }
    }
    let n = n as f64;
    let mean = s.map(|v| v / n);
    let se: [f64; 4] = std::array::from_fn(|i| ((s2[i] / n - mean[i] * mean[i]).max(0.0) / (n - 1.0)).sqrt());
    (Vec4::from_array(mean.map(|v| v as f32)), Vec4::from_array(se.map(|v| v as f32)))
}

pub(super) fn assert_within(mean: Vec4, se: Vec4, want: Vec4, what: &str) {
    for i in 0..4 {
        // 5 standard errors (p ≈ 6e-7 per lane if unbiased) plus float round-off.
        let tol = 5.0 * se[i] + 1e-4 * want[i].abs();
        assert!(
            (mean[i] - want[i]).abs() <= tol,
            "{what}, lane {i}: got {} ± {}, want {}",
            mean[i],
            se[i],
            want[i]
        );
    }
}

/// Volume white furnace: a box of purely scattering medium (albedo 1) whose σs varies
/// strongly with wavelength, under uniform background emission. Radiance everywhere, in every
/// direction, must equal the emission at every wavelength: this exercises free-flight
/// sampling with spectral MIS, phase sampling, multiple scattering and Russian roulette.
#[test]
fn volume_furnace_returns_the_emission() {
    let scene = scene_with(vec![], vec![], vec![]);
    let env = color::illuminant::by_name("F11").unwrap();
    let medium = Medium {
        sigma_a: Spectrum::Constant(0.0),
        sigma_s: Spectrum::piecewise(vec![380.0, 500.0, 730.0], vec![6.0, 0.5, 2.0]).unwrap(),
        phase: Phase::HenyeyGreenstein { g: 0.6 },
        region: Region::Box { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) },
        surface_ior: None,
    };
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, Some(&medium)).unwrap().with_environment(&env);
    let integ = Integrator { world: &world, direct_only: false, max_depth: 100_000, lambert: false };
    let sensor = XyzSensor::new(&Observer::cie1931(), &d65(), range);
    for u in [0.05, 0.4, 0.77] {
        let wl = sensor.sample(u);
        let (m, se) = estimate(20_000, |rng| {
            radiance_any_hero(
                &integ,
                Vec3::new(0.2, -0.3, 0.1),
                Vec3::new(0.3, 0.5, -0.8).normalize(),
                &wl,
                rng,
            )
        });
        assert_within(m, se, spectrum_at(&env, &wl), &format!("volume furnace at λ = {}", wl.0));
    }
}

/// Beer–Lambert through an absorbing slab: L = E(λ)·exp(−σa(λ)·length), per wavelength.
#[test]
fn absorbing_box_follows_beer_lambert() {
    let scene = scene_with(vec![], vec![], vec![]);
    let sigma_a = Spectrum::piecewise(vec![380.0, 730.0], vec![0.1, 3.0]).unwrap();
    let medium = Medium {
        sigma_a: sigma_a.clone(),
        sigma_s: Spectrum::Constant(0.0),
        phase: Phase::Isotropic,
        region: Region::Box { min: Vec3::new(-1.0, -5.0, -5.0), max: Vec3::new(0.5, 5.0, 5.0) },
        surface_ior: None,
    };
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, Some(&medium)).unwrap().with_environment(&d65());
    let integ = Integrator { world: &world, direct_only: false, max_depth: 10, lambert: false };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.2);
    let (m, se) =
        estimate(20_000, |rng| radiance_any_hero(&integ, Vec3::new(-3.0, 0.0, 0.0), Vec3::X, &wl, rng));
    let want = spectrum_at(&d65(), &wl)
        * Vec4::from_array(spectrum_at(&sigma_a, &wl).to_array().map(|s| (-1.5 * s).exp()));
    assert_within(m, se, want, "absorbing slab");
}

/// Directional albedo of the glTF BRDF at `wo` by quadrature (independent of the sampler).
fn albedo(b: &Brdf, wo: Vec3) -> Vec4 {
    crate::testing::hemisphere_albedo(b, wo, 2000, 1000)
}

/// Surface white furnace: a glTF-material quad under uniform background emission reflects
/// E(λ)·A(wo, λ), with A the BRDF's directional albedo computed by quadrature. Covers the
/// diffuse and GGX lobes and their sampling, with a measured (spectrally varying) base colour.
/// (Base colour 1 and a Lambertian BRDF would reflect exactly E; glTF's BRDF is not Lambertian,
/// hence the albedo.)
#[test]
fn surface_furnace_returns_emission_times_albedo() {
    let base = Spectrum::piecewise(vec![380.0, 550.0, 730.0], vec![1.0, 0.3, 0.8]).unwrap();
    let env = color::illuminant::by_name("A").unwrap();
    for (metallic, roughness) in [(0.0, 1.0), (0.0, 0.3), (1.0, 0.5), (1.0, 0.25)] {
        let mat = Material {
            metallic,
            roughness,
            spectral: Some(SpectralReflectance::Uniform(base.clone())),
            ..Default::default()
        };
        let scene = scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 0.5, 0)], vec![mat], vec![]);
        let range = WavelengthRange::VISIBLE;
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap().with_environment(&env);
        let integ = Integrator { world: &world, direct_only: false, max_depth: 1000, lambert: false };
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.3);
        let d = Vec3::new(0.4, -1.0, 0.2).normalize();
        let o = -d * 1.5;
        let brdf = Brdf::new(spectrum_at(&base, &wl), metallic, roughness);
        let want = spectrum_at(&env, &wl) * albedo(&brdf, Vec3::new(-d.x, -d.z, -d.y));
        let (m, se) = estimate(20_000, |rng| integ.radiance(o, d, &wl, rng));
        assert_within(m, se, want, &format!("surface furnace metallic {metallic} roughness {roughness}"));
    }
}

/// A point light above a quad: L = f(wo, wi)·I(λ)·cosθ/d², exactly (no randomness involved).
#[test]
fn point_and_spot_lights_give_closed_form_direct_light() {
    let white = Material {
        spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(0.7))),
        ..Default::default()
    };
    let lp = Vec3::new(0.3, 2.0, -0.1);
    let kinds = [
        LightKind::Point { position: lp, range: None },
        LightKind::Spot {
            position: lp,
            direction: Vec3::new(0.0, -1.0, 0.0),
            inner_cone: 0.3,
            outer_cone: 0.6,
            range: None,
        },
        LightKind::Directional { direction: -lp.normalize() },
    ];
    for kind in kinds {
        let light = Light {
            name: "l".into(),
            kind: kind.clone(),
            emission: Emission { rgb: Vec3::ONE, intensity: 5.0, spectrum: Some(d65()) },
            stands_in_for: None,
        };
        let scene = scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 1.0, 0)], vec![white.clone()], vec![light]);
        let range = WavelengthRange::VISIBLE;
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let integ = Integrator { world: &world, direct_only: true, max_depth: 10, lambert: false };
        let sensor = XyzSensor::new(&Observer::cie1931(), &d65(), range);
        let wl = sensor.sample(0.6);
        let o = Vec3::new(-1.0, 1.0, 0.5);
        let d = (Vec3::ZERO - o).normalize();
        let mut rng = Sampler::new(1, 1);
        let got = integ.radiance(o, d, &wl, &mut rng);
        let wi = lp.normalize();
        let brdf = Brdf::new(Vec4::splat(0.7), 0.0, 1.0);
        let f = brdf.eval(Vec3::new(-d.x, -d.z, -d.y), Vec3::new(wi.x, wi.z, wi.y));
        let falloff = match kind {
            LightKind::Point { .. } => 1.0 / lp.length_squared(),
            LightKind::Spot { .. } => {
                let t = ((wi.y - 0.6f32.cos()) / (0.3f32.cos() - 0.6f32.cos())).clamp(0.0, 1.0);
                t * t / lp.length_squared()
            }
            LightKind::Directional { .. } => 1.0,
        };
        // Luminance-matched D65 of intensity 5 is 5·D65 in tracer units.
        let want =
            f * wi.y * falloff * 5.0 * Vec4::from_array(wl.0.to_array().map(|l| d65().eval(l as f64) as f32));
        assert!((got - want).abs().max_element() <= 2e-3 * want.max_element(), "{kind:?}: {got} vs {want}");
    }
}

/// The closed-enclosure furnace: every wall of a box emits Le and reflects diffusely with
/// albedo ρ(λ) (Lambert mode). The radiance field is uniform, L = Le + ρ·L, so everywhere
/// and in every direction L(λ) = Le(λ)/(1 − ρ(λ)): the geometric series of all bounces, which
/// checks NEE + MIS on area lights at every vertex and Russian roulette.
#[test]
fn emitting_enclosure_sums_all_bounces() {
    let rho = Spectrum::piecewise(vec![380.0, 550.0, 730.0], vec![0.5, 0.8, 0.3]).unwrap();
    let wall = Material {
        emissive: Vec3::splat(0.6),
        spectral: Some(SpectralReflectance::Uniform(rho.clone())),
        ..Default::default()
    };
    let scene = scene_with(vec![crate::testing::inward_box(1.0, 0)], vec![wall], vec![]);
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
    let integ = Integrator { world: &world, direct_only: false, max_depth: 100_000, lambert: true };
    let sensor = XyzSensor::new(&Observer::cie1931(), &d65(), range);
    for u in [0.1, 0.45] {
        let wl = sensor.sample(u);
        let le = world.units.rgb(Vec3::splat(0.6), &GreyOnly, wl.0);
        let want = le / (Vec4::ONE - spectrum_at(&rho, &wl));
        let (m, se) = estimate(20_000, |rng| {
            integ.radiance(Vec3::new(0.3, 0.1, -0.2), Vec3::new(-0.5, 0.7, 0.2).normalize(), &wl, rng)
        });
        assert_within(m, se, want, &format!("emitting enclosure at λ = {}", wl.0));
    }
}

/// Direct light from an area light seen at a grazing angle, against a deterministic
/// quadrature of ∫ Le·ρ/π·cosθ·cosθ'/r² dA over the lamp. Regression test: shadow rays aimed at
/// the exact light point once hit the light itself when they left the receiver obliquely.
#[test]
fn oblique_area_light_matches_quadrature() {
    let lamp = Material { emissive: Vec3::splat(5.0), ..Default::default() };
    let floor = Material {
        spectral: Some(SpectralReflectance::Uniform(Spectrum::Constant(0.5))),
        ..Default::default()
    };
    let (c, h) = (Vec3::new(0.0, 1.0, 0.0), 0.2);
    let scene = scene_with(
        vec![quad(c, -Vec3::Y, h, 0), quad(Vec3::ZERO, Vec3::Y, 10.0, 1)],
        vec![lamp, floor],
        vec![],
    );
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
    let integ = Integrator { world: &world, direct_only: true, max_depth: 10, lambert: true };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.5);
    let p = Vec3::new(2.5, 0.0, 0.3);
    let o = p + Vec3::new(0.3, 0.5, 0.1);
    let n = 400;
    let mut e = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let q = c + Vec3::new(
                -h + 2.0 * h * (i as f32 + 0.5) / n as f32,
                0.0,
                -h + 2.0 * h * (j as f32 + 0.5) / n as f32,
            );
            let v = q - p;
            let r2 = v.length_squared();
            let cos_r = v.y / r2.sqrt();
            e += (cos_r * cos_r / r2) as f64 * (2.0 * h as f64 / n as f64).powi(2);
        }
    }
    let le = world.units.rgb(Vec3::splat(5.0), &GreyOnly, wl.0);
    let want = le * (0.5 / std::f32::consts::PI) * e as f32;
    let (m, se) = estimate(20_000, |rng| integ.radiance(o, (p - o).normalize(), &wl, rng));
    assert_within(m, se, want, "oblique area light");
}

// ---- The environment map (`crate::env_map`): NEE ∝ luminance, MIS with the BRDF/phase. ----

pub(super) fn with_env(mut scene: scene::Scene, env: scene::Environment) -> scene::Scene {
    scene.environment = Some(env);
    scene
}

/// White furnace with the environment map, through the whole renderer: a white Lambertian
/// sphere (convex, so every reflected direction escapes) inside a uniform environment of RGB
/// radiance 1 (= the scene white, Y = 1). Every pixel, sphere or background, has Y = 1, for
/// direct lighting and for all bounces alike.
#[test]
fn env_furnace_white_sphere_renders_one() {
    use crate::render::{Settings, render};
    let mut scene = with_env(
        scene_with(vec![crate::testing::sphere(Vec3::ZERO, 1.0, 48, 0)], vec![Material::default()], vec![]),
        scene::Environment::uniform(Vec3::ONE),
    );
    scene.camera = scene::Camera::look_at(Vec3::new(0.0, 0.6, 3.0), Vec3::ZERO, Vec3::Y, 0.8);
    let (w, h) = (24u32, 24u32);
    let world = World::new(&scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, None).unwrap();
    let cam = crate::camera::RayCamera::new(&scene.camera, w, h);
    let on_sphere: Vec<bool> = (0..w * h)
        .map(|i| {
            let px = glam::Vec2::new((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            let r = cam.ray(px);
            world.geometry.intersect(r.o, r.d, f32::INFINITY).is_some()
        })
        .collect();
    let n_sphere = on_sphere.iter().filter(|&&b| b).count();
    assert!(n_sphere > 100 && n_sphere < 400, "{n_sphere} sphere pixels");
    for direct_only in [false, true] {
        let st = Settings { direct_only, lambert: true, seed: 3, ..Settings::new(w, h, 32).unwrap() };
        let img =
            render(&scene, &GreyOnly, &st, &std::sync::atomic::AtomicBool::new(false), &|_| {}).unwrap();
        assert_eq!(img.dropped, 0);
        let (mut sphere, mut worst) = (0.0f64, 0.0f32);
        for (i, p) in img.xyz.iter().enumerate() {
            worst = worst.max((p[1] - 1.0).abs());
            if on_sphere[i] {
                sphere += p[1] as f64 / n_sphere as f64;
            }
        }
        println!(
            "env furnace (direct only: {direct_only}): sphere mean Y {sphere:.5}, image mean Y {:.5}, \
             worst pixel |Y − 1| {worst:.4}",
            img.mean()[1]
        );
        assert!((sphere - 1.0).abs() < 0.01, "sphere mean Y {sphere}");
        assert!((img.mean()[1] - 1.0).abs() < 0.01, "image mean Y {}", img.mean()[1]);
        // MIS of uniform-sphere NEE with cosine sampling leaves ~5 % noise per pixel at 32 spp.
        assert!(worst < 0.25, "a pixel is {worst} from 1");
    }
}

/// The furnace where bounces matter: a white Lambertian sphere (radius 1, centre 2 above the
/// point looked at) over a wide white floor, in the uniform environment. With all bounces the
/// floor point has L = Le (white furnace); with direct light only it has Le·(1 − F), F = (r/h)²
/// = 1/4 the view factor of the sphere from a floor element below its centre.
#[test]
fn env_furnace_with_interreflection_and_direct_view_factor() {
    let scene = with_env(
        scene_with(
            vec![
                crate::testing::sphere(Vec3::new(0.0, 2.0, 0.0), 1.0, 128, 0),
                quad(Vec3::ZERO, Vec3::Y, 50.0, 0),
            ],
            vec![Material::default()],
            vec![],
        ),
        scene::Environment::uniform(Vec3::ONE),
    );
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.35);
    let o = Vec3::new(3.0, 1.0, 0.0);
    let d = (Vec3::ZERO - o).normalize();
    let le = spectrum_at(&d65(), &wl);
    for (direct_only, want) in [(false, 1.0), (true, 0.75)] {
        let integ = Integrator { world: &world, direct_only, max_depth: 100_000, lambert: true };
        let (m, se) = estimate(20_000, |rng| integ.radiance(o, d, &wl, rng));
        println!(
            "floor below the sphere, direct only {direct_only}: {:.5} ± {:.5} (want {want})",
            mean(m / le),
            mean(se / le)
        );
        // The tessellated sphere's view factor is within 0.1 % of the round one's.
        assert_within(m, se + le * 1e-3, le * want, &format!("direct only {direct_only}"));
        assert!((mean(m / le) - want).abs() < 0.01 * want);
    }
}

/// The glTF BRDF (diffuse and GGX lobes) under the uniform environment map reflects
/// Le·A(wo), as with the uniform background: MIS between environment NEE and GGX sampling.
#[test]
fn env_surface_furnace_returns_emission_times_albedo() {
    for (metallic, roughness) in [(0.0, 1.0), (1.0, 0.25)] {
        let mat = Material { metallic, roughness, ..Default::default() };
        let scene = with_env(
            scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 0.5, 0)], vec![mat], vec![]),
            scene::Environment::uniform(Vec3::ONE),
        );
        let range = WavelengthRange::VISIBLE;
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let integ = Integrator { world: &world, direct_only: false, max_depth: 1000, lambert: false };
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.6);
        let d = Vec3::new(0.4, -1.0, 0.2).normalize();
        let brdf = Brdf::new(Vec4::ONE, metallic, roughness);
        let want = spectrum_at(&d65(), &wl) * albedo(&brdf, Vec3::new(-d.x, -d.z, -d.y));
        let (m, se) = estimate(20_000, |rng| integ.radiance(-d * 1.5, d, &wl, rng));
        assert_within(m, se, want, &format!("env surface furnace metallic {metallic} roughness {roughness}"));
    }
}

/// The sky with a small sun: 64×32, sky radiance 0.2, one texel 5000 at 45° elevation. A
/// white Lambertian floor reflects L = E/π, E = Σ_texels L·Δφ·(cos²θ₀ − cos²θ₁)/2 over the upper
/// hemisphere (exact for the piecewise-constant map). The integrator's estimate (environment
/// NEE + BRDF sampling, MIS) and a cosine-sampling-only estimate both find it, and the first
/// has a far smaller variance.
#[test]
fn env_importance_sampling_beats_cosine_sampling_on_a_sunny_sky() {
    let (w, h) = (64u32, 32u32);
    let mut texels = vec![Vec3::splat(0.2); (w * h) as usize];
    let sun = (8 * w + 40) as usize;
    texels[sun] = Vec3::splat(5000.0);
    let env = scene::Environment::from_rgb("sunny", w, h, texels).unwrap();
    let scene = with_env(
        scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 50.0, 0)], vec![Material::default()], vec![]),
        env,
    );
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
    let env = scene.environment.as_ref().unwrap();
    let pi = std::f64::consts::PI;
    let exact: f64 = (0..h / 2)
        .map(|y| {
            let (c0, c1) = ((pi * y as f64 / h as f64).cos(), (pi * (y + 1) as f64 / h as f64).cos());
            let row: f64 = (0..w).map(|x| env.texels[(y * w + x) as usize].x as f64).sum();
            row * (2.0 * pi / w as f64) * (c0 * c0 - c1 * c1) / 2.0
        })
        .sum::<f64>()
        / pi;
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.5);
    let le1 = spectrum_at(&d65(), &wl);
    let want = le1 * exact as f32;
    let integ = Integrator { world: &world, direct_only: true, max_depth: 10, lambert: true };
    let o = Vec3::new(0.3, 1.0, 0.4);
    let d = -o.normalize();
    let n = 20_000;
    let (ma, sa) = estimate(n, |rng| integ.radiance(o, d, &wl, rng));
    // Cosine sampling alone: for a white Lambertian, f·cos/pdf = 1, so the estimate is the
    // radiance found along the sampled direction.
    let map = world.env_map.as_ref().unwrap();
    let frame = crate::sampling::Frame::from_normal(Vec3::Y);
    let (mb, sb) = estimate(n, |rng| {
        map.radiance(frame.to_world(crate::sampling::cosine_hemisphere(rng.next2())), wl.0)
    });
    let var = |se: Vec4| mean(se * se) * n as f32;
    let ratio = var(sb) / var(sa);
    println!(
        "sunny sky, L/Le: exact {exact:.4}; env NEE + MIS {:.4} ± {:.4}; cosine only {:.4} ± {:.4}; \
         variance ratio {ratio:.0}",
        mean(ma / le1),
        mean(sa / le1),
        mean(mb / le1),
        mean(sb / le1)
    );
    assert_within(ma, sa, want, "env NEE + MIS");
    assert_within(mb, sb, want, "cosine sampling");
    for i in 0..4 {
        assert!((ma[i] - mb[i]).abs() <= 5.0 * (sa[i] * sa[i] + sb[i] * sb[i]).sqrt(), "lane {i}");
    }
    assert!(ratio > 5.0, "variance only {ratio}× lower with environment sampling");
}

/// Environment NEE through a medium: a white Lambertian floor under an absorbing slab 1 unit
/// deep (σa(λ) varying), in the uniform environment. The floor point receives
/// L = Le·2·E₃(σa) (E₃ the exponential integral: ∫ cos·e^{−σa/cos} dω/π over the hemisphere),
/// and the camera inside the slab sees it through e^{−σa·s} more.
#[test]
fn env_light_through_an_absorbing_slab() {
    let sigma_a = Spectrum::piecewise(vec![380.0, 730.0], vec![0.2, 1.5]).unwrap();
    let medium = Medium {
        sigma_a: sigma_a.clone(),
        sigma_s: Spectrum::Constant(0.0),
        phase: Phase::Isotropic,
        region: Region::Box { min: Vec3::new(-60.0, -1.0, -60.0), max: Vec3::new(60.0, 1.0, 60.0) },
        surface_ior: None,
    };
    let scene = with_env(
        scene_with(vec![quad(Vec3::ZERO, Vec3::Y, 50.0, 0)], vec![Material::default()], vec![]),
        scene::Environment::uniform(Vec3::ONE),
    );
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, Some(&medium)).unwrap();
    let integ = Integrator { world: &world, direct_only: false, max_depth: 100, lambert: true };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.15);
    let o = Vec3::new(0.3, 0.5, 0.2);
    let e3 = |s: f64| {
        let n = 100_000;
        (0..n).map(|i| (i as f64 + 0.5) / n as f64).map(|mu| mu * (-s / mu).exp()).sum::<f64>() / n as f64
    };
    let sig = spectrum_at(&sigma_a, &wl);
    let want = spectrum_at(&d65(), &wl)
        * Vec4::from_array(sig.to_array().map(|s| (2.0 * e3(s as f64)) as f32 * (-s * o.length()).exp()));
    let (m, se) = estimate(20_000, |rng| radiance_any_hero(&integ, o, -o.normalize(), &wl, rng));
    assert_within(m, se, want, "environment through an absorbing slab");
}

/// The smallest maps the scene accepts light a scene without panicking, also in a medium.
#[test]
fn env_tiny_maps_render() {
    use crate::render::{Settings, render};
    for (w, h) in [(1u32, 1u32), (2, 1), (3, 1)] {
        let env =
            scene::Environment::from_rgb("tiny", w, h, vec![Vec3::new(0.5, 1.0, 2.0); (w * h) as usize])
                .unwrap();
        let mut scene = with_env(
            scene_with(
                vec![crate::testing::sphere(Vec3::ZERO, 1.0, 8, 0)],
                vec![Material::default()],
                vec![],
            ),
            env,
        );
        scene.camera = scene::Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 0.8);
        for medium in [
            None,
            Some(Medium {
                sigma_a: Spectrum::Constant(0.1),
                sigma_s: Spectrum::Constant(0.3),
                phase: Phase::HenyeyGreenstein { g: 0.5 },
                region: Region::Box { min: Vec3::splat(-2.0), max: Vec3::splat(2.0) },
                surface_ior: None,
            }),
        ] {
            let st = Settings { medium, ..Settings::new(4, 4, 4).unwrap() };
            let img =
                render(&scene, &GreyOnly, &st, &std::sync::atomic::AtomicBool::new(false), &|_| {}).unwrap();
            assert!(
                img.dropped == 0 && img.mean()[1] > 0.0,
                "{w}×{h}: {} dropped, mean {:?}",
                img.dropped,
                img.mean()
            );
        }
    }
}

/// A water surface shows the water settings' sky only; an environment map under it is refused.
#[test]
fn env_map_under_a_water_surface_is_refused() {
    let scene = with_env(scene_with(vec![], vec![], vec![]), scene::Environment::uniform(Vec3::ONE));
    let medium = Medium {
        sigma_a: Spectrum::Constant(0.1),
        sigma_s: Spectrum::Constant(0.0),
        phase: Phase::Isotropic,
        region: Region::Box { min: Vec3::splat(-5.0), max: Vec3::splat(1.0) },
        surface_ior: Some(1.34),
    };
    let e = World::new(&scene, &GreyOnly, &d65(), WavelengthRange::VISIBLE, Some(&medium)).err().unwrap();
    assert!(e.to_string().contains("environment map"), "{e}");
}

/// The volume furnace lit by the environment map instead of the uniform background: NEE of
/// the map from medium vertices (with transmittance to infinity) and MIS against HG sampling.
#[test]
fn env_volume_furnace_returns_the_emission() {
    let scene = with_env(scene_with(vec![], vec![], vec![]), scene::Environment::uniform(Vec3::ONE));
    let medium = Medium {
        sigma_a: Spectrum::Constant(0.0),
        sigma_s: Spectrum::piecewise(vec![380.0, 500.0, 730.0], vec![6.0, 0.5, 2.0]).unwrap(),
        phase: Phase::HenyeyGreenstein { g: 0.6 },
        region: Region::Box { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) },
        surface_ior: None,
    };
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, Some(&medium)).unwrap();
    let integ = Integrator { world: &world, direct_only: false, max_depth: 100_000, lambert: false };
    let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.4);
    let (m, se) = estimate(20_000, |rng| {
        radiance_any_hero(&integ, Vec3::new(0.2, -0.3, 0.1), Vec3::new(0.3, 0.5, -0.8).normalize(), &wl, rng)
    });
    assert_within(m, se, spectrum_at(&d65(), &wl), "volume furnace under the environment map");
}

/// Fresnel reflectance of unpolarised light at a smooth interface from air into index `n`,
/// written out here (Born & Wolf) rather than taken from the tracer.
fn fresnel_from_air(cos_i: f64, n: f64) -> f64 {
    let sin_t = (1.0 - cos_i * cos_i).sqrt() / n;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    let rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Direct light that arrives through glass: a mirror floor under a smooth glass sheet (thin
/// walled) or slab (a volume 0.2 thick), in a uniform white sky, seen from between the two.
/// The mirror reflects the view up through the glass: one bounce, so direct light. Refractions
/// are not bounces, so the direct-only path follows the refraction out to the sky: Le·(1 − F)
/// through the sheet (its transmission is 1 − F, straight on), Le·(1 − F)² through the slab
/// (in and out at the same angle outside, internal reflections being bounces). The shadow ray
/// of light sampling stops at glass, so this was black when the path ended at its bounce.
#[test]
fn direct_light_through_glass_after_the_bounce() {
    use scene::transmission::{Transmission, Volume};
    let glass = |volume: Option<Volume>| Material {
        roughness: 0.0,
        metallic: 0.0,
        ior: 1.5,
        double_sided: true,
        transmission: Some(Transmission { factor: 1.0, texture: None, volume, dispersion: 0.0 }),
        ..Default::default()
    };
    let mirror = Material { metallic: 1.0, roughness: 0.0, ..Default::default() };
    let slab = Volume {
        thickness: 0.2,
        thickness_texture: None,
        attenuation_color: [1.0; 3],
        attenuation_distance: f32::INFINITY,
    };
    let cases = [
        ("sheet", vec![quad(Vec3::new(0.0, 1.0, 0.0), Vec3::Y, 50.0, 1)], glass(None), 1),
        (
            "slab",
            vec![
                quad(Vec3::new(0.0, 1.2, 0.0), Vec3::Y, 50.0, 1),
                quad(Vec3::new(0.0, 1.0, 0.0), -Vec3::Y, 50.0, 1),
            ],
            glass(Some(slab)),
            2,
        ),
    ];
    for (name, mut meshes, material, interfaces) in cases {
        meshes.push(quad(Vec3::ZERO, Vec3::Y, 50.0, 0));
        let scene = with_env(
            scene_with(meshes, vec![mirror.clone(), material], vec![]),
            scene::Environment::uniform(Vec3::ONE),
        );
        let range = WavelengthRange::VISIBLE;
        let world = World::new(&scene, &GreyOnly, &d65(), range, None).unwrap();
        let wl = XyzSensor::new(&Observer::cie1931(), &d65(), range).sample(0.35);
        let le = spectrum_at(&d65(), &wl);
        for theta in [0.2f32, 0.9] {
            let d = Vec3::new(theta.sin(), -theta.cos(), 0.0);
            let o = Vec3::new(0.0, 0.5, 0.0) - d * 0.5;
            let t = 1.0 - fresnel_from_air(f64::from(theta.cos()), 1.5);
            let want = t.powi(interfaces) as f32;
            let integ = Integrator { world: &world, direct_only: true, max_depth: 100, lambert: false };
            let (m, se) = estimate(40_000, |rng| radiance_any_hero(&integ, o, d, &wl, rng));
            println!("{name}, θ = {theta}: {:.5} ± {:.5} (want {want:.5})", mean(m / le), mean(se / le));
            // The mirror's GGX lobe at the smallest roughness is ~10⁻³ wide and reflects a
            // little under 1: 0.5 % of slack.
            assert!((mean(m / le) - want).abs() < 0.005 + 5.0 * mean(se / le), "{name}, θ = {theta}");
        }
    }
}
