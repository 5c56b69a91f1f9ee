//! Ground truth for the underwater model: the same water as `scene::water::WaterMedium`, as a
//! homogeneous participating medium that the path tracer solves with full multiple scattering.
//!
//! Shared with the real-time model: absorption a(λ) and scattering b(λ) of the Jerlov type, the
//! camera depth, metres per scene unit, the scene's (already refracted) directional sun, a flat
//! surface with no sky drawn above it, index-matched objects.
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
use scene::water::WaterMedium;

/// Mean cosine of Petzold's average-particle phase function.
pub const PETZOLD_G: f32 = 0.924;

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
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use color::WavelengthRange;
    use color::water::WaterType;

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
