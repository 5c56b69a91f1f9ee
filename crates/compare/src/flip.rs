//! FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"):
//! NVIDIA's perceptual difference of rendered images, as LDR-FLIP, through the `nv-flip` crate,
//! which compiles the reference C++ implementation (BSD-3-Clause) it vendors.
//!
//! LDR-FLIP compares display-encoded sRGB images in [0, 1]: our linear images are clamped and
//! encoded to 8-bit sRGB exactly as a PNG output is ([`crate::io::to_display`]), so FLIP of two
//! images read from PNG sees the files' own codes. HDR-FLIP (tone mapping over a range of
//! exposures) is not offered: `nv-flip` wraps LDR-FLIP only.

use crate::error::{CompareError, Result};
use crate::image::Image;

/// Pixels per degree of visual angle of the reference implementation's default viewing setup
/// (a 0.7 m wide 4K monitor at 0.7 m).
pub const DEFAULT_PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// A per-pixel FLIP error map, values in [0, 1], row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipMap {
    pub width: u32,
    pub height: u32,
    pub values: Vec<f32>,
}

impl FlipMap {
    /// Mean FLIP over the image, the number the reference tool reports as "Mean".
    pub fn mean(&self) -> f64 {
        self.values.iter().map(|&v| f64::from(v)).sum::<f64>() / self.values.len().max(1) as f64
    }

    /// The map coloured with the reference implementation's magma lookup table, as RGB8.
    pub fn magma(&self) -> Vec<u8> {
        let map = nv_flip::FlipImageFloat::with_data(self.width, self.height, &self.values);
        map.apply_color_lut(&nv_flip::magma_lut()).to_vec()
    }

    /// Writes the magma-coloured map as PNG, atomically.
    pub fn save_png(&self, path: &std::path::Path) -> Result<()> {
        let img = image::RgbImage::from_raw(self.width, self.height, self.magma())
            .expect("the lookup gives three bytes a pixel");
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, image::ImageFormat::Png).map_err(|e| CompareError::Encode {
            path: path.into(),
            format: "PNG",
            reason: e.to_string(),
        })?;
        crate::atomic::write_atomic(path, &buf.into_inner())
    }
}

fn srgb8(image: &Image) -> Vec<u8> {
    image.data.iter().flat_map(|p| p.map(|v| (crate::io::to_display(v) * 255.0).round() as u8)).collect()
}

/// LDR-FLIP of `test` against `reference` (same size, finite pixels) at `pixels_per_degree`.
pub fn ldr_flip(reference: &Image, test: &Image, pixels_per_degree: f32) -> Result<FlipMap> {
    reference.validate()?;
    test.validate()?;
    if reference.size() != test.size() {
        return Err(CompareError::SizeMismatch { reference: reference.size(), test: test.size() });
    }
    reference.check_finite("reference image")?;
    test.check_finite("test image")?;
    if !(pixels_per_degree.is_finite() && pixels_per_degree > 0.0) {
        return Err(CompareError::InvalidOption(format!(
            "pixels per degree must be a positive number, got {pixels_per_degree}"
        )));
    }
    let (w, h) = reference.size();
    let r = nv_flip::FlipImageRgb8::with_data(w, h, &srgb8(reference));
    let t = nv_flip::FlipImageRgb8::with_data(w, h, &srgb8(test));
    let map = nv_flip::flip(r, t, pixels_per_degree);
    Ok(FlipMap { width: w, height: h, values: map.to_vec() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_zero_flip_and_errors_are_named() {
        let a = Image::from_fn(16, 8, |x, y| [x as f32 / 16.0, y as f32 / 8.0, 0.3]).unwrap();
        let m = ldr_flip(&a, &a, DEFAULT_PIXELS_PER_DEGREE).unwrap();
        assert_eq!(m.mean(), 0.0);
        assert_eq!(m.magma().len(), 16 * 8 * 3);
        let b = Image::filled(8, 8, [0.5; 3]).unwrap();
        assert!(matches!(ldr_flip(&a, &b, 67.0), Err(CompareError::SizeMismatch { .. })));
        let mut c = a.clone();
        c.get_mut(3, 2)[0] = f32::NAN;
        let e = ldr_flip(&a, &c, 67.0).unwrap_err().to_string();
        assert!(e.contains("test image") && e.contains("(3, 2)"), "{e}");
        assert!(ldr_flip(&a, &a, 0.0).is_err());
    }
}
