//! The diffuse sky under water, as the rasteriser sees it: one stand-in directional light per sun,
//! straight down, carrying [`WaterSettings::sky`] × that sun's downwelling irradiance.
//!
//! Definition shared by both renderers: the sky's downwelling irradiance just below the surface
//! is `sky` × the sun's there — the sun's emission × the cosine of its (already refracted)
//! direction to the downward vertical — with the sun's spectrum (a real sky is bluer; both
//! renderers make the same simplification, so it does not count against either).
//!
//! - The real-time underwater hooks sum every directional light's emission × cosine into E0 and
//!   light surfaces with every light, so a light propagating along −Y with irradiance
//!   `sky·E_sun` adds exactly the sky's E0. What it gets wrong on surfaces: a zenith light
//!   lights a surface ∝ max(n_y, 0), so a vertical face gets nothing where Snell's window gives
//!   it ≈ 19 % of the sky's E0 just below the surface, and faces turned down stay black; and its
//!   shadow map hides the whole sky behind any occluder straight above (an object's shadow is
//!   hard and complete, where the real sky is only partly blocked).
//! - The path tracer skips it as a light (it is a stand-in, [`SKY_STAND_IN`]) and instead lights
//!   the scene through the water surface with a uniform sky whose radiance reproduces that same
//!   irradiance below the surface (`truth::water_surface`).
//!
//! The stand-ins are derived data: loaders and built-ins call [`sync`] after setting the water,
//! and the exporter leaves them out (the file's `water.sky` recreates them on load).

use crate::{Emission, Light, LightKind, Scene};
use glam::Vec3;

/// `Light::stands_in_for` of a sky stand-in. No mesh has this index, so renderers that skip a
/// stand-in's own mesh (shadow maps) skip nothing, and the path tracer ignores the light.
pub const SKY_STAND_IN: usize = usize::MAX;

/// Whether `l` is a sky stand-in made by [`stand_ins`].
pub fn is_stand_in(l: &Light) -> bool {
    l.stands_in_for == Some(SKY_STAND_IN)
}

/// The suns: directional lights that stand in for nothing.
fn suns(lights: &[Light]) -> impl Iterator<Item = &Light> {
    lights.iter().filter(|l| l.stands_in_for.is_none() && matches!(l.kind, LightKind::Directional { .. }))
}

/// One stand-in per sun in `lights` with positive downwelling irradiance, for a sky of `sky`
/// × the sun (none when `sky` is 0). Its emission is the sun's scaled by `sky · cos θ`, θ the
/// angle between the sun's propagation direction and straight down, so the sun's spectrum
/// (if it has one) is kept exactly.
pub fn stand_ins(lights: &[Light], sky: f32) -> Vec<Light> {
    if sky <= 0.0 {
        return Vec::new();
    }
    suns(lights)
        .filter_map(|sun| {
            let LightKind::Directional { direction } = sun.kind else { return None };
            let cos = (-direction.y).max(0.0);
            let k = sky * cos;
            (k > 0.0).then(|| Light {
                name: format!("sky (stand-in, {sky} × '{}')", sun.name),
                kind: LightKind::Directional { direction: Vec3::NEG_Y },
                emission: Emission {
                    rgb: sun.emission.rgb,
                    intensity: sun.emission.intensity * k,
                    spectrum: sun.emission.spectrum.as_ref().map(|s| s.scaled(k as f64)),
                },
                stands_in_for: Some(SKY_STAND_IN),
            })
        })
        .collect()
}

/// A sky asked for with no sun to scale it by; the caller places it at `water.sky`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "sky = {sky} is a multiple of the sun's irradiance, but no directional light shines down into the water"
)]
pub struct NoSunError {
    pub sky: f32,
}

/// Replaces the scene's sky stand-ins by those its water settings call for (idempotent).
/// Errors when a sky is asked for but no sun lights the water from above (there would be
/// nothing to scale).
pub fn sync(scene: &mut Scene) -> Result<(), NoSunError> {
    scene.lights.retain(|l| !is_stand_in(l));
    let sky = scene.water.as_ref().map_or(0.0, |w| w.sky);
    let new = stand_ins(&scene.lights, sky);
    if sky > 0.0 && new.is_empty() {
        return Err(NoSunError { sky });
    }
    scene.lights.extend(new);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emission::spectrum_luminance;

    #[test]
    fn stand_in_carries_sky_times_the_suns_downwelling_irradiance() {
        let mut s = crate::builtin("underwater").unwrap();
        let sky = s.water.as_ref().unwrap().sky;
        assert!(sky > 0.0);
        let sun = s.lights.iter().find(|l| !is_stand_in(l)).unwrap().clone();
        let LightKind::Directional { direction } = sun.kind else { panic!() };
        let made: Vec<_> = s.lights.iter().filter(|l| is_stand_in(l)).cloned().collect();
        assert_eq!(made.len(), 1);
        let st = &made[0];
        assert!(matches!(st.kind, LightKind::Directional { direction } if direction == Vec3::NEG_Y));
        let want = sky as f64 * -direction.y as f64;
        let (a, b) = (spectrum_luminance(st.emission.spectrum.as_ref().unwrap()), sun.emission.xyz()[1]);
        assert!((a / b - want).abs() < 1e-6, "{a} / {b} vs {want}");
        assert!((st.emission.intensity / sun.emission.intensity - want as f32).abs() < 1e-6);
        // Same shape: the ratio is the same at every wavelength.
        let (ss, su) = (st.emission.spectrum.as_ref().unwrap(), sun.emission.spectrum.as_ref().unwrap());
        for l in [400.0, 550.0, 700.0] {
            assert!((ss.eval(l) / su.eval(l) - want).abs() < 1e-6 * want);
        }
        // Idempotent, and gone with the sky.
        sync(&mut s).unwrap();
        assert_eq!(s.lights.iter().filter(|l| is_stand_in(l)).count(), 1);
        s.water.as_mut().unwrap().sky = 0.0;
        sync(&mut s).unwrap();
        assert!(s.lights.iter().all(|l| !is_stand_in(l)));
    }

    #[test]
    fn a_sky_without_a_sun_is_an_error() {
        let mut s = crate::builtin("underwater").unwrap();
        s.lights.clear();
        let e = sync(&mut s).unwrap_err().to_string();
        assert!(e.contains("no directional light"), "{e}");
    }
}
