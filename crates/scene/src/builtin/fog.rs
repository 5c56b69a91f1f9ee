//! `fog` and `tinted-fog`: the Cornell box filled with an RGB medium ([`crate::medium`]), with
//! a lantern (a 2700 K point light) hanging in the fog beside the ceiling lamp, so that light
//! scattered around a source inside the medium can be seen. For the RGB-media work (issue 18):
//! both renderers draw the medium (`spectra truth`, `spectra render`; docs/rgb-media.md).
//!
//! `fog` is a white fog (grey coefficients: every upsampling gives a flat spectrum, so RGB and
//! spectral rendering agree on its colour); `tinted-fog` a smoky fog that absorbs blue more
//! than red, where they do not.

use color::Spectrum;
use color::upsample::medium::Attenuation;
use glam::Vec3;

use super::{cornell, light_emission};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::medium::RgbMedium;
use crate::{Light, LightKind, Scene};

/// Where the lantern hangs (m): in front of the tall block, halfway up the box.
pub const LANTERN: Vec3 = Vec3::new(-0.12, 0.40, 0.16);
/// The lantern's luminous intensity, in the units of the Cornell lamp's stand-in (0.55).
pub const LANTERN_INTENSITY: f32 = 0.12;

/// The media, per metre: mean free paths of 1.2–1.6 m, so the back wall (1.36 m from the
/// camera) is seen through an optical depth of about one.
pub fn medium(tinted: bool) -> RgbMedium {
    let (absorption, scattering, g) =
        if tinted { ([0.1, 0.25, 0.6], [0.5, 0.5, 0.5], 0.4) } else { ([0.02; 3], [0.6; 3], 0.6) };
    RgbMedium::new(absorption, scattering, g, 1.0, Attenuation::DEFAULT).expect("valid built-in medium")
}

pub(crate) fn build(ctx: &Ctx, tinted: bool) -> Result<Scene, SceneError> {
    let mut s = cornell::build(ctx)?;
    let warm = Spectrum::blackbody(2700.0).map_err(|e| ctx.invalid("lantern", e.to_string()))?;
    s.lights.push(Light {
        name: "lantern (point, 2700 K)".into(),
        kind: LightKind::Point { position: LANTERN, range: None },
        emission: light_emission(ctx, "lantern", &warm, LANTERN_INTENSITY)?,
        stands_in_for: None,
    });
    s.medium = Some(medium(tinted));
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fog_scenes_carry_their_medium_and_the_lantern() {
        for (name, tinted) in [("fog", false), ("tinted-fog", true)] {
            let s = crate::builtin(name).unwrap();
            let m = s.medium.as_ref().expect("a medium");
            assert_eq!(*m, medium(tinted));
            let grey = m.absorption.iter().all(|&a| a == m.absorption[0]);
            assert_eq!(grey, !tinted, "{name}");
            assert!(
                s.lights
                    .iter()
                    .any(|l| matches!(l.kind, LightKind::Point { position, .. } if position == LANTERN))
            );
            assert!(s.water.is_none());
        }
    }
}
