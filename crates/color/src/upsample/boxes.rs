//! The simplest baseline: each RGB channel becomes a box over its own band of wavelengths.
//!
//! The three bands partition the whole spectrum, so RGB (1, 1, 1) is the constant 1 and white
//! round-trips exactly under any illuminant; greys are exact too. Saturated colours are not
//! (a box is not a colour-matching-function inverse), which is the point of the comparison.
//! The band edges are `pub` because the GPU shader evaluates the same boxes.

/// Blue band: below this wavelength (nm).
pub const BOX_BLUE_GREEN_NM: f64 = 490.0;
/// Red band: at and above this wavelength (nm); green lies between the two edges.
pub const BOX_GREEN_RED_NM: f64 = 585.0;

/// A box-basis reflectance: the RGB itself, read per band.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BoxSpectrum {
    pub rgb: [f64; 3],
}

impl BoxSpectrum {
    /// Value at `lambda` nm: blue below [`BOX_BLUE_GREEN_NM`], red from [`BOX_GREEN_RED_NM`],
    /// green between (at every wavelength, including outside the visible range).
    #[inline]
    pub fn eval(&self, lambda: f64) -> f64 {
        if lambda < BOX_BLUE_GREEN_NM {
            self.rgb[2]
        } else if lambda < BOX_GREEN_RED_NM {
            self.rgb[1]
        } else {
            self.rgb[0]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_partition_the_spectrum() {
        let s = BoxSpectrum { rgb: [0.1, 0.2, 0.3] };
        assert_eq!(s.eval(360.0), 0.3);
        assert_eq!(s.eval(BOX_BLUE_GREEN_NM), 0.2);
        assert_eq!(s.eval(BOX_GREEN_RED_NM - 1e-9), 0.2);
        assert_eq!(s.eval(BOX_GREEN_RED_NM), 0.1);
        assert_eq!(s.eval(830.0), 0.1);
        let w = BoxSpectrum { rgb: [1.0; 3] };
        assert!((360..=830).all(|l| w.eval(l as f64) == 1.0));
    }
}
