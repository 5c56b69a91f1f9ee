//! Per-pixel differences between a reference and a test image, and their summary statistics.
//!
//! Colour difference is CIEDE2000 on CIELAB computed from linear sRGB: RGB → XYZ with the
//! matrix derived from the Rec. 709 primaries and the D65 chromaticity (0.3127, 0.3290)
//! ([`color::RgbColorSpace::srgb`]), then XYZ → L*a*b* relative to D65 scaled to luminance
//! `white_luminance`. With the default `white_luminance = 1`, an image value of (1, 1, 1) has
//! L* = 100; HDR renders can pass the luminance that should count as diffuse white.
//!
//! MAE is reported twice: on the linear values and on display-encoded sRGB (linear clamped to
//! [0, 1], then the sRGB transfer curve — what an 8-bit PNG of the image shows, before
//! quantisation). Per pixel it is the mean over the three channels, so the mean of the
//! per-pixel values is the usual image MAE over pixels and channels.

use color::RgbColorSpace;
use color::error::show as short;
use color::metrics::Stats;
use rayon::prelude::*;

use crate::error::{CompareError, Result};
use crate::image::Image;
use crate::io::to_display;

/// The smallest white luminance accepted (see [`DiffMaps::compute`]).
pub const MIN_WHITE_LUMINANCE: f64 = 1e-20;
/// The largest white luminance accepted.
pub const MAX_WHITE_LUMINANCE: f64 = 1e20;

/// Choices that change the metric values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffOptions {
    /// Luminance Y (in image units) of the reference white for CIELAB. Default 1.
    pub white_luminance: f64,
}

impl Default for DiffOptions {
    fn default() -> Self {
        DiffOptions { white_luminance: 1.0 }
    }
}

/// XYZ of the CIELAB reference white: D65 (x, y) = (0.3127, 0.3290) with Y = `luminance`.
pub fn reference_white(luminance: f64) -> [f64; 3] {
    RgbColorSpace::srgb().white_xyz().map(|v| v * luminance)
}

/// Converts linear sRGB to CIELAB relative to `white` (see [`reference_white`]).
pub fn linear_srgb_to_lab(space: &RgbColorSpace, rgb: [f32; 3], white: [f64; 3]) -> [f64; 3] {
    color::xyz_to_lab(space.rgb_to_xyz(rgb.map(f64::from)), white)
}

/// Per-pixel error maps, row-major like [`Image::data`].
#[derive(Clone, Debug, PartialEq)]
pub struct DiffMaps {
    pub width: u32,
    pub height: u32,
    pub options: DiffOptions,
    /// CIEDE2000 between reference and test.
    pub delta_e2000: Vec<f64>,
    /// Mean over channels of |reference − test|, linear values.
    pub abs_linear: Vec<f64>,
    /// Mean over channels of |reference − test|, display-encoded sRGB values in [0, 1].
    pub abs_srgb: Vec<f64>,
}

/// Summary of a comparison: the statistics of each per-pixel map.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct DiffSummary {
    pub width: u32,
    pub height: u32,
    pub white_luminance: f64,
    pub delta_e2000: Stats,
    pub mae_linear: Stats,
    pub mae_srgb: Stats,
}

impl DiffMaps {
    /// Computes all per-pixel maps.
    ///
    /// Errors: images of different sizes (both sizes in the message), a NaN/∞ pixel in either
    /// (named "reference"/"test" with its coordinates), a non-positive or non-finite white.
    /// Pixel values (finite f32, ≤ 3.4·10³⁸) over the white then stay far from f64 overflow.
    pub fn compute(reference: &Image, test: &Image, options: DiffOptions) -> Result<DiffMaps> {
        reference.validate()?;
        test.validate()?;
        if reference.size() != test.size() {
            return Err(CompareError::SizeMismatch { reference: reference.size(), test: test.size() });
        }
        reference.check_finite("reference")?;
        test.check_finite("test")?;
        let y = options.white_luminance;
        // Not just positive: a subnormal white (1e-310) turns every pixel's L* infinite and
        // ΔE NaN.
        if !(MIN_WHITE_LUMINANCE..=MAX_WHITE_LUMINANCE).contains(&y) {
            return Err(CompareError::InvalidOption(format!(
                "white luminance must be between {} and {}, got {}",
                short(MIN_WHITE_LUMINANCE),
                short(MAX_WHITE_LUMINANCE),
                short(y)
            )));
        }
        let space = RgbColorSpace::srgb();
        let white = reference_white(y);
        let per_pixel: Vec<(f64, f64, f64)> = reference
            .data
            .par_iter()
            .zip(&test.data)
            .map(|(r, t)| {
                let de = color::ciede2000(
                    linear_srgb_to_lab(&space, *r, white),
                    linear_srgb_to_lab(&space, *t, white),
                );
                let lin = (0..3).map(|k| (f64::from(r[k]) - f64::from(t[k])).abs()).sum::<f64>() / 3.0;
                let disp = (0..3).map(|k| (to_display(r[k]) - to_display(t[k])).abs()).sum::<f64>() / 3.0;
                (de, lin, disp)
            })
            .collect();
        let mut maps = DiffMaps {
            width: reference.width,
            height: reference.height,
            options,
            delta_e2000: Vec::with_capacity(per_pixel.len()),
            abs_linear: Vec::with_capacity(per_pixel.len()),
            abs_srgb: Vec::with_capacity(per_pixel.len()),
        };
        for (de, lin, disp) in per_pixel {
            maps.delta_e2000.push(de);
            maps.abs_linear.push(lin);
            maps.abs_srgb.push(disp);
        }
        Ok(maps)
    }

    /// Mean, median, p95, p99 and max of each map (nearest-rank percentiles).
    pub fn summary(&self) -> DiffSummary {
        // Inputs were checked finite and the image is non-empty, so every value is finite.
        let stats = |v: &[f64]| Stats::of(v).expect("finite, non-empty per-pixel values");
        DiffSummary {
            width: self.width,
            height: self.height,
            white_luminance: self.options.white_luminance,
            delta_e2000: stats(&self.delta_e2000),
            mae_linear: stats(&self.abs_linear),
            mae_srgb: stats(&self.abs_srgb),
        }
    }
}

impl DiffMaps {
    /// Per-pixel values as CSV: header `x,y,delta_e2000,abs_linear,abs_srgb`, one row per pixel
    /// in row-major order, numbers in Rust's shortest round-trip form (parsing them gives back
    /// the exact f64), for scripts that check the metric pixel by pixel.
    pub fn to_csv(&self) -> String {
        let mut out = String::with_capacity(self.delta_e2000.len() * 64 + 64);
        out.push_str("x,y,delta_e2000,abs_linear,abs_srgb\n");
        let w = self.width as usize;
        for (i, ((de, lin), disp)) in
            self.delta_e2000.iter().zip(&self.abs_linear).zip(&self.abs_srgb).enumerate()
        {
            out.push_str(&format!("{},{},{de},{lin},{disp}\n", i % w, i / w));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: u32, h: u32) -> Image {
        Image::from_fn(w, h, |x, y| [x as f32 / w as f32, y as f32 / h as f32, 0.25]).unwrap()
    }

    #[test]
    fn identical_images_are_zero() {
        let a = gradient(7, 5);
        let s = DiffMaps::compute(&a, &a.clone(), DiffOptions::default()).unwrap().summary();
        for st in [s.delta_e2000, s.mae_linear, s.mae_srgb] {
            assert_eq!((st.mean, st.median, st.p95, st.p99, st.max), (0.0, 0.0, 0.0, 0.0, 0.0));
        }
    }

    #[test]
    fn single_pixel_change_by_hand() {
        // 4×5 = 20 pixels of mid grey; one pixel changes by (+0.3, 0, −0.15).
        let a = Image::filled(4, 5, [0.2, 0.2, 0.2]).unwrap();
        let mut b = a.clone();
        *b.get_mut(1, 3) = [0.5, 0.2, 0.05];
        let m = DiffMaps::compute(&a, &b, DiffOptions::default()).unwrap();
        let s = m.summary();
        // That pixel's channel mean is (0.3 + 0 + 0.15) / 3 = 0.15; over 20 pixels 0.0075.
        assert!((m.abs_linear[3 * 4 + 1] - 0.15).abs() < 1e-7);
        assert!((s.mae_linear.mean - 0.0075).abs() < 1e-8, "{}", s.mae_linear.mean);
        assert!((s.mae_linear.max - 0.15).abs() < 1e-7);
        // One changed pixel in 20: it sits above the 95th percentile (rank 19), so p95 = 0.
        assert_eq!((s.mae_linear.median, s.mae_linear.p95), (0.0, 0.0));
        // Display-encoded: |enc(0.5) − enc(0.2)| + 0 + |enc(0.05) − enc(0.2)|, sRGB values
        // enc(0.5) = 0.7353570, enc(0.2) = 0.4845292, enc(0.05) = 0.2478005 (IEC 61966-2-1).
        let disp = ((0.735_357_0 - 0.484_529_2) + (0.484_529_2 - 0.247_800_5)) / 3.0;
        assert!((m.abs_srgb[13] - disp).abs() < 1e-6, "{} vs {disp}", m.abs_srgb[13]);
        assert!((s.mae_srgb.mean - disp / 20.0).abs() < 1e-7);
        // Only that pixel has a colour difference, and the overall MAE agrees with color::metrics::mae.
        assert_eq!(m.delta_e2000.iter().filter(|&&d| d > 0.0).count(), 1);
        assert!(m.delta_e2000[13] > 1.0);
        let to64 = |im: &Image| im.data.iter().map(|p| p.map(f64::from)).collect::<Vec<_>>();
        let mae = color::metrics::mae(&to64(&a), &to64(&b)).unwrap();
        assert!((mae - s.mae_linear.mean).abs() < 1e-15);
    }

    #[test]
    fn white_is_l100_and_white_luminance_scales() {
        let space = RgbColorSpace::srgb();
        let lab = linear_srgb_to_lab(&space, [1.0; 3], reference_white(1.0));
        assert!((lab[0] - 100.0).abs() < 1e-5 && lab[1].abs() < 1e-5 && lab[2].abs() < 1e-5, "{lab:?}");
        let lab = linear_srgb_to_lab(&space, [4.0; 3], reference_white(4.0));
        assert!((lab[0] - 100.0).abs() < 1e-5, "{lab:?}");
        // Scaling both images and the white together leaves ΔE unchanged.
        let a = gradient(6, 4);
        let b = Image::from_fn(6, 4, |x, y| [0.3, x as f32 / 6.0, y as f32 / 4.0]).unwrap();
        let scale = |im: &Image| {
            Image::new(im.width, im.height, im.data.iter().map(|p| p.map(|v| v * 4.0)).collect()).unwrap()
        };
        let d1 = DiffMaps::compute(&a, &b, DiffOptions::default()).unwrap();
        let d4 = DiffMaps::compute(&scale(&a), &scale(&b), DiffOptions { white_luminance: 4.0 }).unwrap();
        for (p, q) in d1.delta_e2000.iter().zip(&d4.delta_e2000) {
            assert!((p - q).abs() < 1e-9, "{p} vs {q}");
        }
    }

    #[test]
    fn known_lab_difference() {
        // sRGB red (1,0,0) vs green (0,1,0), D65 white Y = 1: colour-science 0.4.7 with the
        // derived sRGB matrix gives Lab (53.2371156, 80.0901135, 67.2032635) and
        // (87.7355191, −86.1815969, 83.1866203), CIEDE2000 between them 86.6078144.
        let a = Image::filled(1, 1, [1.0, 0.0, 0.0]).unwrap();
        let b = Image::filled(1, 1, [0.0, 1.0, 0.0]).unwrap();
        let space = RgbColorSpace::srgb();
        let lab = linear_srgb_to_lab(&space, [1.0, 0.0, 0.0], reference_white(1.0));
        for (v, e) in lab.iter().zip([53.237_115_6, 80.090_113_5, 67.203_263_5]) {
            assert!((v - e).abs() < 1e-6, "{lab:?}");
        }
        let d = DiffMaps::compute(&a, &b, DiffOptions::default()).unwrap().delta_e2000[0];
        assert!((d - 86.607_814_4).abs() < 1e-6, "{d}");
    }

    #[test]
    fn csv_round_trips_exactly() {
        let a = gradient(3, 2);
        let b = Image::from_fn(3, 2, |x, y| [0.1 * x as f32, 0.7, 0.2 * y as f32]).unwrap();
        let m = DiffMaps::compute(&a, &b, DiffOptions::default()).unwrap();
        let csv = m.to_csv();
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(rows[0], "x,y,delta_e2000,abs_linear,abs_srgb");
        assert_eq!(rows.len(), 7);
        let f: Vec<&str> = rows[5].split(',').collect();
        assert_eq!((f[0], f[1]), ("1", "1"));
        assert_eq!(f[2].parse::<f64>().unwrap(), m.delta_e2000[4]);
        assert_eq!(f[3].parse::<f64>().unwrap(), m.abs_linear[4]);
        assert_eq!(f[4].parse::<f64>().unwrap(), m.abs_srgb[4]);
    }

    #[test]
    fn errors_are_clear() {
        let a = gradient(4, 3);
        let e = DiffMaps::compute(&a, &gradient(3, 4), DiffOptions::default()).unwrap_err().to_string();
        assert!(e.contains("4×3") && e.contains("3×4"), "{e}");
        let mut nan = a.clone();
        nan.get_mut(2, 1)[0] = f32::INFINITY;
        let e = DiffMaps::compute(&a, &nan, DiffOptions::default()).unwrap_err().to_string();
        assert!(e.contains("test") && e.contains("(2, 1)"), "{e}");
        let e = DiffMaps::compute(&a, &a, DiffOptions { white_luminance: 0.0 }).unwrap_err().to_string();
        assert!(e.contains("white luminance"), "{e}");
        // A subnormal white used to reach the summary as NaN ΔE and panic there.
        for y in [1e-310, 1e-21, 1e21, f64::INFINITY] {
            let e = DiffMaps::compute(&a, &a, DiffOptions { white_luminance: y }).unwrap_err().to_string();
            assert!(e.contains("white luminance") && e.contains("1e-20"), "{e}");
        }
        // The extremes accepted stay finite with the largest and smallest pixel values.
        let mut b = a.clone();
        b.get_mut(0, 0)[1] = f32::MAX;
        b.get_mut(1, 0)[2] = f32::MIN_POSITIVE;
        for y in [MIN_WHITE_LUMINANCE, MAX_WHITE_LUMINANCE] {
            let s = DiffMaps::compute(&a, &b, DiffOptions { white_luminance: y }).unwrap().summary();
            assert!(s.delta_e2000.max.is_finite() && s.mae_linear.max.is_finite(), "{y}");
        }
    }
}
