//! What a renderer's tristimulus values are shown as: one convention, called by the real-time
//! renderer (with its node quadrature's response to the white), the path tracer (with its
//! sensor's) and `compare` (with a spectral image's), so that the three agree for every
//! observer.
//!
//! - A CIE observer gives CIE XYZ, each of X, Y and Z scaled so that the renderer's own value
//!   of the white lands on sRGB's white, then shown through the sRGB matrix without chromatic
//!   adaptation (the scene white is taken to be sRGB's D65). Over 380–730 nm with many nodes the
//!   scale is within 2e-3 of 1 (the white outside the range, the illuminant against sRGB's
//!   rounded chromaticity); at few nodes or a narrowed range the integral of the white is tinted
//!   by the quadrature or the truncation, and without the scale every pixel would carry that
//!   tint, differently in each renderer (their integrals differ), where the scene has none.
//! - Any other observer (a camera, cones, an animal) is white balanced: each channel divided by
//!   its response to the white (von Kries), so the white is (1, 1, 1). The balanced triple is
//!   then shown as linear display RGB ([`CameraView::Balanced`], what the sensor separates), or
//!   through the camera's least-squares matrix to CIE 1931 XYZ over the ColorChecker under the
//!   white ([`Observer::fit_to_xyz`]) and the sRGB matrix ([`CameraView::Display`],
//!   `--camera-to-display`: roughly what the camera's photograph looks like).

use glam::{DMat3, DVec3};

use crate::error::{ColorError, Result};
use crate::observer::{Observer, ObserverKind};
use crate::spectrum::Spectrum;

/// How a non-CIE observer's balanced channels reach the display (CIE observers ignore it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CameraView {
    /// The balanced channels as linear display RGB: white → (1, 1, 1).
    #[default]
    Balanced,
    /// The balanced channels through the camera → XYZ matrix fitted over the ColorChecker
    /// under the white, then XYZ → linear sRGB.
    Display,
}

impl CameraView {
    /// The view `--camera-to-display` asks for.
    pub fn from_flag(camera_to_display: bool) -> Self {
        if camera_to_display { CameraView::Display } else { CameraView::Balanced }
    }

    /// How records and reports name it.
    pub fn name(self) -> &'static str {
        match self {
            CameraView::Balanced => "balanced",
            CameraView::Display => "camera-to-display",
        }
    }
}

/// The 3×3 matrix from `observer`'s tristimulus values to linear sRGB. `white_response`: the
/// renderer's value of the white (its channels' response to the white spectrum, as the renderer
/// integrates it); `white`: that spectrum, under which [`CameraView::Display`]'s matrix is
/// fitted. Errors name the observer: a channel that does not see the white, or channels the
/// chart cannot tell apart (a dichromat's repeated receptor) with `Display`.
pub fn to_linear_srgb(
    observer: &Observer,
    white_response: [f64; 3],
    white: &Spectrum,
    view: CameraView,
) -> Result<DMat3> {
    let srgb = crate::RgbColorSpace::srgb();
    if observer.kind() == ObserverKind::CieXyz {
        // A channel the range leaves (almost) blind to the white (z̄ above 650 nm) is left as it
        // is: nothing in the frame reaches it either, and a tiny divisor would only amplify noise.
        let target = srgb.white_xyz();
        let correction = DVec3::from_array(std::array::from_fn(|c| {
            if white_response[c] > 1e-12 { target[c] / white_response[c] } else { 1.0 }
        }));
        return Ok(srgb.from_xyz * DMat3::from_diagonal(correction));
    }
    if white_response.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(ColorError::BadSpectrum(format!(
            "observer '{}' has a zero or invalid response to the white ({white_response:?})",
            observer.name
        )));
    }
    let balance = DMat3::from_diagonal(DVec3::from(white_response.map(|w| 1.0 / w)));
    Ok(match view {
        CameraView::Balanced => balance,
        CameraView::Display => {
            let (to_xyz, _) = observer.fit_to_xyz(white)?;
            srgb.from_xyz * to_xyz * balance
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::illuminant;

    fn d65() -> Spectrum {
        illuminant::by_name("D65").unwrap()
    }

    /// A CIE observer's XYZ goes through sRGB's matrix (from the primaries' chromaticities,
    /// not from us) after the diagonal that puts the renderer's white on sRGB's white, in both
    /// views: the white's own response shows as (1, 1, 1), a white already at sRGB's white
    /// XYZ is shown by the bare matrix, and a tinted white's tint is taken out of every colour.
    #[test]
    fn cie_observers_are_xyz_through_srgb_balanced_to_the_white_whatever_the_view() {
        let srgb = crate::RgbColorSpace::srgb();
        let exact = srgb.white_xyz();
        for view in [CameraView::Balanced, CameraView::Display] {
            let m = to_linear_srgb(&Observer::cie1931(), exact, &d65(), view).unwrap();
            assert!((m - srgb.from_xyz).to_cols_array().iter().all(|d| d.abs() < 1e-15), "{m}");
            let tinted = [0.9, 1.0, 1.1];
            let m = to_linear_srgb(&Observer::cie1964(), tinted, &d65(), view).unwrap();
            let white = m * DVec3::from(tinted);
            assert!((white - DVec3::ONE).abs().max_element() < 1e-12, "{white}");
            let grey = m * (DVec3::from(tinted) * 0.18);
            assert!((grey - DVec3::splat(0.18)).abs().max_element() < 1e-12, "{grey}");
        }
        // A channel blind to the white is left unscaled rather than divided by nothing.
        let m =
            to_linear_srgb(&Observer::cie1931(), [exact[0], 1.0, 0.0], &d65(), CameraView::Balanced).unwrap();
        assert!(m.is_finite() && (m.z_axis - srgb.from_xyz.z_axis).abs().max_element() < 1e-15, "{m}");
    }

    /// Both views keep the white white: balanced exactly, the fitted matrix to the fit's
    /// residual (the white patch is one of the chart's 24).
    #[test]
    fn the_white_is_white_in_both_views() {
        let cam = Observer::nikon_d5100();
        let w = d65();
        let resp = cam.white_balance(&w);
        let b = to_linear_srgb(&cam, resp, &w, CameraView::Balanced).unwrap() * DVec3::from(resp);
        assert!((b - DVec3::ONE).abs().max_element() < 1e-12, "{b}");
        let d = to_linear_srgb(&cam, resp, &w, CameraView::Display).unwrap() * DVec3::from(resp);
        assert!((d - DVec3::ONE).abs().max_element() < 0.03, "{d}");
    }

    /// The ACES RICD is an exact linear transform of CIE 1931: through its fitted matrix it
    /// shows what CIE 1931 shows.
    #[test]
    fn an_observer_that_is_a_transform_of_xyz_displays_as_xyz() {
        let w = d65();
        let ricd = Observer::aces_ricd();
        let cie = Observer::cie1931();
        let m = to_linear_srgb(&ricd, ricd.white_balance(&w), &w, CameraView::Display).unwrap();
        let yw = cie.white_balance(&w)[1];
        for patch in crate::data::colorchecker::SPECTRA.iter().take(6) {
            let r = Spectrum::from_table(patch);
            let shown = m * DVec3::from(ricd.response(&r, &w));
            let want = crate::RgbColorSpace::srgb().from_xyz * (DVec3::from(cie.response(&r, &w)) / yw);
            assert!((shown - want).abs().max_element() < 1e-6, "{shown} vs {want}");
        }
    }

    #[test]
    fn a_channel_blind_to_the_white_and_a_dichromat_in_display_are_errors() {
        let w = d65();
        let cam = Observer::nikon_d5100();
        let e = to_linear_srgb(&cam, [1.0, 0.0, 1.0], &w, CameraView::Balanced).unwrap_err().to_string();
        assert!(e.contains("nikon_d5100") && e.contains("white"), "{e}");
        let dog = Observer::dog();
        let e = to_linear_srgb(&dog, dog.white_balance(&w), &w, CameraView::Display).unwrap_err().to_string();
        assert!(e.contains("dog"), "{e}");
        assert!(to_linear_srgb(&dog, dog.white_balance(&w), &w, CameraView::Balanced).is_ok());
    }
}
