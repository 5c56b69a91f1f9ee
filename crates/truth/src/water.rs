//! Ground truth for the underwater model: the same water as `scene::water::WaterMedium`, as a
//! homogeneous participating medium that the path tracer solves with full multiple scattering.
//!
//! Shared with the real-time model: absorption a(λ) and scattering b(λ) of the Jerlov type, the
//! camera depth, metres per scene unit, the scene's (already refracted) directional sun, the sky's
//! downwelling irradiance below the surface (`scene::sky`: `water.sky` × the sun's, the sun's
//! spectrum), a flat surface, index-matched objects.
//!
//! The slab's top face is the water surface ([`crate::water_surface`], n = [`WATER_IOR`]): paths
//! going up see a uniform sky through Snell's window with exact Fresnel transmission and the n²
//! radiance law, and are reflected (Fresnel inside the window, totally outside it).
//!
//! Different, on purpose (this is what the real-time model approximates):
//! - the phase function is forward peaked — Henyey–Greenstein with g = [`PETZOLD_G`], the mean
//!   cosine of Petzold's average particle phase function (Mobley 1994, *Light and Water*,
//!   §3.8; Haltrin 2002) — instead of isotropic;
//! - the sun's light is attenuated by the beam coefficient c along its refracted path from the
//!   surface and re-gains what forward scattering keeps in the beam, so the downwelling
//!   attenuation is an *outcome* of a and b here, where the real-time model takes the measured
//!   Kd of the type;
//! - light scatters any number of times, where the real-time model counts one isotropic event
//!   of the Kd-attenuated diffuse field.
//!
//! The water fills a slab from far below the sea floor up to the surface, `depth / scale` scene
//! units above the camera, and ±[`HALF_WIDTH`] units sideways (wide enough that no path leaves
//! it sideways in practice: even the clearest water's c ≥ 0.02 /m gives e^{−c·L} < 1e-40).

use crate::medium::{Medium, Phase, Region};
use glam::Vec3;
pub use scene::water::PETZOLD_G;
use scene::water::{WATER_IOR, WaterMedium};

/// Half the sideways extent of the water slab, and its depth below the camera, in metres.
pub const HALF_WIDTH: f32 = 5000.0;

/// The participating medium for `water` around a camera at `camera` (world position, scene
/// units). Coefficients are converted from per metre to per scene unit.
pub fn medium(water: &WaterMedium, camera: Vec3) -> Medium {
    let k = water.scale;
    let surface = camera.y + (water.depth / k) as f32;
    let half = HALF_WIDTH / k as f32;
    Medium {
        sigma_a: water.properties.a.scaled(k),
        sigma_s: water.properties.b.scaled(k),
        phase: Phase::HenyeyGreenstein { g: PETZOLD_G },
        region: Region::Box {
            min: Vec3::new(camera.x - half, camera.y - half, camera.z - half),
            max: Vec3::new(camera.x + half, surface, camera.z + half),
        },
        surface_ior: Some(WATER_IOR as f32),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::Integrator;
    use crate::medium::phase_eval;
    use crate::rng::Sampler;
    use crate::spectral::Wavelengths;
    use crate::testing::{quad, scene_with};
    use crate::upsample::GreyOnly;
    use crate::world::World;
    use color::WavelengthRange;
    use color::water::WaterType;
    use glam::Vec4;
    use scene::{Emission, Light, LightKind, Material};

    /// Single scattering of the sun along a level ray in the slab has a closed form: every point
    /// is s = (surface − y)/ω_sun,y from the surface along the sun, so
    /// L(λ) = b·p(cos)·E(λ)·e^{−c·s}/c. The path tracer (direct lighting only, hero wavelength
    /// rotated so spectral MIS is unbiased) must reproduce it to Monte-Carlo accuracy; this
    /// checks the slab's surface height, the per-unit coefficients and the sun's attenuation.
    #[test]
    fn level_ray_single_scattering_matches_closed_form() {
        let d65 = color::illuminant::by_name("D65").unwrap();
        let prop = Vec3::new(0.3, -0.9, 0.1).normalize();
        let light = Light {
            name: "sun".into(),
            kind: LightKind::Directional { direction: prop },
            emission: Emission { rgb: Vec3::ONE, intensity: 5.0, spectrum: Some(d65.clone()) },
            stands_in_for: None,
        };
        // Geometry far below, never hit by the level ray.
        let scene = scene_with(
            vec![quad(Vec3::new(0.0, -500.0, 0.0), Vec3::Y, 1.0, 0)],
            vec![Material::default()],
            vec![light],
        );
        let water = WaterMedium::new(WaterType::parse("II").unwrap(), 3.0, Vec3::Y, 0.5).unwrap();
        let camera = Vec3::new(0.0, 1.0, 0.0);
        let m = medium(&water, camera);
        let range = WavelengthRange::VISIBLE;
        let world = World::new(&scene, &GreyOnly, &d65, range, Some(&m)).unwrap();
        let integ = Integrator { world: &world, direct_only: true, max_depth: 10, lambert: false };
        let wl = Wavelengths(Vec4::new(450.0, 520.0, 580.0, 650.0));
        let d = Vec3::new(1.0, 0.0, 0.3).normalize();
        let n = 40_000u64;
        let mut sum = Vec4::ZERO;
        for i in 0..n {
            let mut rng = Sampler::new(7, i);
            let k = ((rng.uniform() * 4.0) as usize).min(3);
            let rotated = Wavelengths(Vec4::from_array(std::array::from_fn(|j| wl.0[(j + k) % 4])));
            let r = integ.radiance(camera, d, &rotated, &mut rng);
            sum += Vec4::from_array(std::array::from_fn(|j| r[(j + 4 - k) % 4]));
        }
        let got = sum / n as f32;
        // 3 m at 0.5 m per unit: the surface is 6 units above the camera.
        let s_units = 6.0 / (-prop.y) as f64;
        let cos = d.dot(-prop);
        let p = phase_eval(Phase::HenyeyGreenstein { g: PETZOLD_G }, cos) as f64;
        for j in 0..4 {
            let l = wl.0[j] as f64;
            let [_, b, c, _] = water.properties.at(l);
            let (b, c) = (b * 0.5, c * 0.5);
            let want = b * p * 5.0 * d65.eval(l) * (-c * s_units).exp() / c;
            let rel = (got[j] as f64 - want).abs() / want;
            assert!(rel < 0.03, "λ={l}: path traced {} vs closed form {want} ({rel:.3})", got[j]);
        }
    }

    #[test]
    fn slab_reaches_the_surface_and_coefficients_are_per_scene_unit() {
        let w = WaterMedium::new(WaterType::parse("II").unwrap(), 8.0, Vec3::Y, 0.5).unwrap();
        let m = medium(&w, Vec3::new(1.0, 2.0, 3.0));
        m.validate(WavelengthRange::VISIBLE).unwrap();
        let Region::Box { min, max } = m.region else { panic!("a box") };
        // 8 m at 0.5 m per unit is 16 units above the camera.
        assert_eq!(max.y, 18.0);
        assert!(min.y < -1000.0 && max.x > 1000.0);
        let [a, b, _, _] = w.properties.at(500.0);
        assert!((m.sigma_a.eval(500.0) - a * 0.5).abs() < 1e-12);
        assert!((m.sigma_s.eval(500.0) - b * 0.5).abs() < 1e-12);
    }
}
