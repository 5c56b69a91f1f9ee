//! An RGB medium (issue 18) in the path tracer, against closed forms of the same upsampled
//! spectra: pure absorption (a white Lambertian wall seen through it) and single scattering of
//! a point light.

use crate::integrator::Integrator;
use crate::medium::{Medium, Phase, phase_eval};
use crate::render::{Settings, render};
use crate::rng::Sampler;
use crate::spectral::Wavelengths;
use crate::testing::{quad, scene_with};
use crate::upsample::GreyOnly;
use crate::world::World;
use color::upsample::medium::Attenuation;
use color::{Observer, RgbColorSpace, SpectralIntegrator, Spectrum, WavelengthRange};
use glam::{Vec3, Vec4};
use scene::medium::RgbMedium;
use scene::{Emission, Light, LightKind, Material};

fn d65() -> Spectrum {
    color::illuminant::by_name("D65").unwrap()
}

fn point_light(position: Vec3, intensity: f32) -> Light {
    Light {
        name: "lamp".into(),
        kind: LightKind::Point { position, range: None },
        emission: Emission { rgb: Vec3::ONE, intensity, spectrum: Some(d65()) },
        stands_in_for: None,
    }
}

/// A white Lambertian wall `d` units in front of the camera, lit by a point light at the
/// camera, seen through an absorbing RGB medium: light travels 2d, so each pixel is the clear
/// image times exp(−2·σ_a(λ)·d), and the image's linear sRGB over the clear one's is, per
/// channel, the RGB of that transmittance under D65. The tracer (direct lighting, 8×8 pixels
/// of a narrow view, 512 spp) must match it to Monte-Carlo noise, for every upsampling method;
/// the default method's colour must also stay within the measured box-basis bound (max
/// ΔE2000 10.4 over 0.1–10 mfp, docs/rgb-media.md) of the RGB renderer's exp(−2·σ_rgb·d).
#[test]
fn white_wall_through_an_absorbing_rgb_medium_matches_the_transmittance() {
    let table = color::upsample::table("srgb").expect("the sRGB table");
    let d = 2.0f32;
    let mut scene = scene_with(
        vec![quad(Vec3::new(0.0, 0.0, -d), Vec3::Z, 5.0, 0)],
        vec![Material::default()],
        vec![point_light(Vec3::ZERO, 10.0)],
    );
    scene.camera.yfov = 0.02;
    let range = WavelengthRange::VISIBLE;
    let srgb = RgbColorSpace::srgb();
    let integ = SpectralIntegrator::reference(&Observer::cie1931(), &d65(), range).unwrap();
    let absorption = [0.45, 0.2, 0.08];
    let clear = {
        let st = Settings { direct_only: true, lambert: true, ..Settings::new(8, 8, 512).unwrap() };
        render(&scene, &GreyOnly, &st, &Default::default(), &|_| {}).unwrap()
    };
    let clear_rgb = clear.to_rgb(&srgb);
    for method in [Attenuation::DEFAULT, Attenuation::TRANSMITTANCE, Attenuation::Unbounded] {
        let rgb_medium = RgbMedium::new(absorption, [0.0; 3], 0.0, 1.0, method).unwrap();
        let medium = Medium::from_rgb(&rgb_medium, &table).unwrap();
        assert_eq!(medium.sigma_s.max_value(360.0, 830.0), 0.0, "absorbing only");
        let st = Settings {
            direct_only: true,
            lambert: true,
            medium: Some(medium.clone()),
            ..Settings::new(8, 8, 512).unwrap()
        };
        let img = render(&scene, &GreyOnly, &st, &Default::default(), &|_| {}).unwrap();
        let rgb = img.to_rgb(&srgb);
        let t = |l: f64| (-2.0 * d as f64 * medium.sigma_a.eval(l)).exp();
        let want = {
            let a = srgb.xyz_to_rgb(integ.integrate(t));
            let w = srgb.xyz_to_rgb(integ.white());
            [0, 1, 2].map(|c| a[c] / w[c])
        };
        let mut got = [0.0f64; 3];
        for c in 0..3 {
            // Per-pixel ratios to the clear image (same pixels, same light falloff).
            let r: Vec<f64> = rgb.iter().zip(&clear_rgb).map(|(p, q)| p[c] as f64 / q[c] as f64).collect();
            let n = r.len() as f64;
            let mean = r.iter().sum::<f64>() / n;
            let se = (r.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0) / n).sqrt();
            got[c] = mean;
            assert!(
                (mean - want[c]).abs() <= 5.0 * se + 1e-3,
                "{method:?}, channel {c}: traced {mean} ± {se}, transmittance {}",
                want[c]
            );
        }
        if method == Attenuation::DEFAULT {
            let target = absorption.map(|s| (-2.0 * d as f64 * s).exp());
            let lab = |x: [f64; 3]| color::xyz_to_lab(srgb.rgb_to_xyz(x), srgb.white_xyz());
            let de = color::ciede2000(lab(target), lab(got));
            assert!(de < 10.4, "ΔE2000 {de} from exp(−2σd) = {target:?}: got {got:?}");
        }
    }
}

/// Single scattering of a point light at height h above a level camera ray, in a coloured RGB
/// medium filling the scene, has a closed form per wavelength:
/// L(λ) = ∫₀^∞ σ_s(λ)·p(cos θ(t))·I(λ)·e^{−σ_t(λ)·(t + r(t))}/r(t)² dt, r = √(t² + h²),
/// cos θ = −t/r (the light's propagation against the way to the camera). The tracer (direct
/// lighting only, hero wavelength rotated so spectral MIS is unbiased) must reproduce it at four
/// wavelengths to Monte-Carlo accuracy.
#[test]
fn single_scattering_of_a_point_light_in_an_rgb_medium_matches_closed_form() {
    let table = color::upsample::table("srgb").expect("the sRGB table");
    let h = 1.0f32;
    let intensity = 5.0;
    // Geometry (black) far behind, so only the medium is seen.
    let black = Material { base_color: Vec4::new(0.0, 0.0, 0.0, 1.0), ..Default::default() };
    let scene = scene_with(
        vec![quad(Vec3::new(200.0, 0.0, 0.0), -Vec3::X, 500.0, 0)],
        vec![black],
        vec![point_light(Vec3::new(0.0, h, 0.0), intensity)],
    );
    let rgb_medium = RgbMedium::from_json_str(
        r#"{"absorption": [0.3, 0.1, 0.05], "scattering": [0.2, 0.35, 0.6], "g": 0.4, "scale": 0.5}"#,
    )
    .unwrap();
    let medium = Medium::from_rgb(&rgb_medium, &table).unwrap();
    let range = WavelengthRange::VISIBLE;
    let world = World::new(&scene, &GreyOnly, &d65(), range, Some(&medium)).unwrap();
    let integ = Integrator { world: &world, direct_only: true, max_depth: 10, lambert: true };
    let wl = Wavelengths(Vec4::new(450.0, 520.0, 580.0, 650.0));
    let dir = Vec3::X;
    let n = 40_000u64;
    let (mut sum, mut sum2) = (Vec4::ZERO, Vec4::ZERO);
    for i in 0..n {
        let mut rng = Sampler::new(11, i);
        let k = ((rng.uniform() * 4.0) as usize).min(3);
        let rotated = Wavelengths(Vec4::from_array(std::array::from_fn(|j| wl.0[(j + k) % 4])));
        let r = integ.radiance(Vec3::ZERO, dir, &rotated, &mut rng);
        let v = Vec4::from_array(std::array::from_fn(|j| r[(j + 4 - k) % 4]));
        sum += v;
        sum2 += v * v;
    }
    let mean = sum / n as f32;
    let se = ((sum2 / n as f32 - mean * mean).max(Vec4::ZERO) / (n - 1) as f32).powf(0.5);
    let Phase::HenyeyGreenstein { .. } = medium.phase else { panic!("g = 0.4 is Henyey–Greenstein") };
    for j in 0..4 {
        let l = wl.0[j] as f64;
        let (ss, st) = (medium.sigma_s.eval(l), medium.sigma_a.eval(l) + medium.sigma_s.eval(l));
        // Scale 0.5 m per unit: per-unit coefficients are half the per-metre ones.
        assert!(ss > 0.0 && st < 0.5 * 0.95, "λ {l}: σs {ss}, σt {st}");
        let steps = 400_000;
        let t_max = 150.0;
        let dt = t_max / steps as f64;
        let want: f64 = (0..steps)
            .map(|i| {
                let t = (i as f64 + 0.5) * dt;
                let r = (t * t + (h * h) as f64).sqrt();
                let p = phase_eval(medium.phase, (-t / r) as f32) as f64;
                ss * p * intensity as f64 * d65().eval(l) * (-st * (t + r)).exp() / (r * r) * dt
            })
            .sum();
        let got = mean[j] as f64;
        assert!(
            (got - want).abs() <= 5.0 * se[j] as f64 + 1e-3 * want,
            "λ {l}: traced {got} ± {}, closed form {want}",
            se[j]
        );
    }
}
