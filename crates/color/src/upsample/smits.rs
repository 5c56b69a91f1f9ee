//! Smits 1999, "An RGB-to-Spectrum Conversion for Reflectances" (journal of graphics tools 4(4)):
//! a reflectance is built from seven basis spectra (white, cyan, magenta, yellow, red, green,
//! blue) sampled in 10 equal bins over 380–720 nm, choosing the basis by channel ordering.
//!
//! The values are Table 1 of the paper, the table colour-science ships as
//! `colour.recovery.datasets.smits1999` (no script here compares the two yet). Spectra are
//! piecewise constant over the bins and keep their edge value outside 380–720 nm, so white stays
//! white over the whole observer range. The basis was derived for sRGB-like primaries; it is
//! applied to the RGB of any space as given.

/// First and last wavelength of the Smits basis (nm).
pub const SMITS_RANGE: (f64, f64) = (380.0, 720.0);

/// The seven basis spectra, 10 bins each, from Smits 1999 Table 1.
pub mod basis {
    pub const WHITE: [f64; 10] =
        [1.0000, 1.0000, 0.9999, 0.9993, 0.9992, 0.9998, 1.0000, 1.0000, 1.0000, 1.0000];
    pub const CYAN: [f64; 10] =
        [0.9710, 0.9426, 1.0007, 1.0007, 1.0007, 1.0007, 0.1564, 0.0000, 0.0000, 0.0000];
    pub const MAGENTA: [f64; 10] =
        [1.0000, 1.0000, 0.9685, 0.2229, 0.0000, 0.0458, 0.8369, 1.0000, 1.0000, 0.9959];
    pub const YELLOW: [f64; 10] =
        [0.0001, 0.0000, 0.1088, 0.6651, 1.0000, 1.0000, 0.9996, 0.9586, 0.9685, 0.9840];
    pub const RED: [f64; 10] =
        [0.1012, 0.0515, 0.0000, 0.0000, 0.0000, 0.0000, 0.8325, 1.0149, 1.0149, 1.0149];
    pub const GREEN: [f64; 10] =
        [0.0000, 0.0000, 0.0273, 0.7937, 1.0000, 0.9418, 0.1719, 0.0000, 0.0000, 0.0025];
    pub const BLUE: [f64; 10] =
        [1.0000, 1.0000, 0.8916, 0.3323, 0.0000, 0.0000, 0.0003, 0.0369, 0.0483, 0.0496];
}

/// A Smits reflectance: one value per bin.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SmitsSpectrum {
    pub bins: [f64; 10],
}

impl SmitsSpectrum {
    /// Smits' construction for linear RGB (components assumed finite and non-negative).
    pub fn from_rgb(rgb: [f64; 3]) -> Self {
        use basis::*;
        let [r, g, b] = rgb;
        let mut s = [0.0; 10];
        let mut add = |k: f64, v: &[f64; 10]| {
            for (o, x) in s.iter_mut().zip(v) {
                *o += k * x;
            }
        };
        if r <= g && r <= b {
            add(r, &WHITE);
            if g <= b {
                add(g - r, &CYAN);
                add(b - g, &BLUE);
            } else {
                add(b - r, &CYAN);
                add(g - b, &GREEN);
            }
        } else if g <= r && g <= b {
            add(g, &WHITE);
            if r <= b {
                add(r - g, &MAGENTA);
                add(b - r, &BLUE);
            } else {
                add(b - g, &MAGENTA);
                add(r - b, &RED);
            }
        } else {
            add(b, &WHITE);
            if r <= g {
                add(r - b, &YELLOW);
                add(g - r, &GREEN);
            } else {
                add(g - b, &YELLOW);
                add(r - g, &RED);
            }
        }
        SmitsSpectrum { bins: s }
    }

    /// Value at `lambda` nm: the bin containing it (edge bins extend beyond 380–720 nm).
    pub fn eval(&self, lambda: f64) -> f64 {
        let (lo, hi) = SMITS_RANGE;
        let t = ((lambda - lo) / (hi - lo) * 10.0).floor();
        let i = if t.is_nan() { 0 } else { t.clamp(0.0, 9.0) as usize };
        self.bins[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primaries_and_white_select_their_basis() {
        assert_eq!(SmitsSpectrum::from_rgb([1.0, 1.0, 1.0]).bins, basis::WHITE);
        assert_eq!(SmitsSpectrum::from_rgb([1.0, 0.0, 0.0]).bins, basis::RED);
        assert_eq!(SmitsSpectrum::from_rgb([0.0, 1.0, 1.0]).bins, basis::CYAN);
        let s = SmitsSpectrum::from_rgb([0.2, 0.5, 0.9]); // white 0.2 + cyan 0.3 + blue 0.4
        assert!((s.bins[0] - (0.2 + 0.3 * 0.9710 + 0.4)).abs() < 1e-12);
        assert_eq!(s.eval(380.0), s.bins[0]);
        assert_eq!(s.eval(300.0), s.bins[0]);
        assert_eq!(s.eval(719.9), s.bins[9]);
        assert_eq!(s.eval(800.0), s.bins[9]);
        assert_eq!(s.eval(414.0 + 1e-9), s.bins[1]);
    }
}
