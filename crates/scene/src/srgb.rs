//! The sRGB colour space (IEC 61966-2-1): the RGB that glTF colours are in.
//!
//! Built-in scenes need it to turn measured spectra into the 8-bit texels and linear factors an
//! RGB renderer sees, and lights need it to give a spectrum its RGB stand-in. The matrices and
//! transfer function are `color::colorspace`'s; this module adds the 8-bit helpers scenes need.

use color::colorspace::{RgbColorSpace, srgb_decode, srgb_encode};
use glam::{DMat3, DVec3, Vec3};

/// Linear sRGB → CIE XYZ (Y of white = 1).
pub fn rgb_to_xyz_matrix() -> DMat3 {
    RgbColorSpace::srgb().to_xyz
}

/// CIE XYZ → linear sRGB.
pub fn xyz_to_rgb_matrix() -> DMat3 {
    RgbColorSpace::srgb().from_xyz
}

/// Linear sRGB of an XYZ triple (may be negative or above 1 for out-of-gamut colours).
pub fn xyz_to_linear(xyz: [f64; 3]) -> DVec3 {
    xyz_to_rgb_matrix() * DVec3::from_array(xyz)
}

/// Relative luminance Y of a linear sRGB colour ([`RgbColorSpace::luminance`]).
pub fn luminance(rgb: Vec3) -> f64 {
    RgbColorSpace::srgb().luminance(rgb.as_dvec3().to_array())
}

/// The sRGB transfer function (linear → encoded).
pub fn encode(c: f64) -> f64 {
    srgb_encode(c)
}

/// The inverse sRGB transfer function (encoded → linear).
pub fn decode(c: f64) -> f64 {
    srgb_decode(c)
}

/// 8-bit sRGB of a linear colour: clipped to [0, 1] (the gamut of an 8-bit texture), encoded,
/// rounded.
pub fn linear_to_srgb8(rgb: DVec3) -> [u8; 3] {
    rgb.to_array().map(|c| (encode(c.clamp(0.0, 1.0)) * 255.0).round() as u8)
}

/// Linear value of an 8-bit sRGB colour.
pub fn srgb8_to_linear(rgb8: [u8; 3]) -> Vec3 {
    Vec3::from_array(rgb8.map(|c| decode(c as f64 / 255.0) as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    // colour-science 0.4: colour.models.RGB_COLOURSPACE_sRGB.matrix_RGB_to_XYZ, printed with
    // 4 decimals (the IEC standard's own rounding).
    #[test]
    fn matrix_matches_the_standard() {
        let m = rgb_to_xyz_matrix();
        let want = [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]];
        for (r, row) in want.iter().enumerate() {
            for (c, w) in row.iter().enumerate() {
                assert!((m.row(r)[c] - w).abs() < 1e-4, "row {r} col {c}: {} vs {w}", m.row(r)[c]);
            }
        }
        let back = xyz_to_rgb_matrix() * m;
        assert!(back.abs_diff_eq(DMat3::IDENTITY, 1e-12));
    }

    #[test]
    fn transfer_function_round_trips_and_hits_known_points() {
        assert!((encode(0.18) - 0.461_356).abs() < 1e-5);
        assert_eq!(linear_to_srgb8(DVec3::ONE), [255; 3]);
        assert_eq!(linear_to_srgb8(DVec3::new(-0.2, 0.0, 2.0)), [0, 0, 255]);
        for v in 0..=255u8 {
            let lin = srgb8_to_linear([v; 3]);
            assert_eq!(linear_to_srgb8(lin.as_dvec3()), [v; 3]);
        }
    }
}
