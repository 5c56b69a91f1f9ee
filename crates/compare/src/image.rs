//! The image type exchanged between renderer, ground truth and comparison.

use crate::error::{CompareError, Result};

/// A linear-light image in sRGB primaries (Rec. 709 primaries, D65 white): `(1, 1, 1)` is the
/// white of the scene's exposure, values above 1 and below 0 are allowed (HDR, out of gamut).
///
/// Pixels are stored row-major, top row first, `data[y * width + x]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub data: Vec<[f32; 3]>,
}

impl Image {
    /// Wraps pixel data, checking that `data.len() == width * height` and the image is not empty.
    pub fn new(width: u32, height: u32, data: Vec<[f32; 3]>) -> Result<Image> {
        let image = Image { width, height, data };
        image.validate()?;
        Ok(image)
    }

    /// Checks the invariants [`Image::new`] establishes (the fields are public, so an image
    /// built by hand may break them): no zero dimension, `data.len() == width * height`.
    pub fn validate(&self) -> Result<()> {
        let (width, height) = (self.width, self.height);
        if width == 0 || height == 0 {
            return Err(CompareError::InvalidImage(format!("{width}×{height} has no pixels")));
        }
        let expected = width as usize * height as usize;
        if self.data.len() != expected {
            return Err(CompareError::InvalidImage(format!(
                "{width}×{height} needs {expected} pixels, got {}",
                self.data.len()
            )));
        }
        Ok(())
    }

    /// An image of one colour.
    pub fn filled(width: u32, height: u32, rgb: [f32; 3]) -> Result<Image> {
        Image::new(width, height, vec![rgb; width as usize * height as usize])
    }

    /// Builds an image from a function of the pixel coordinates.
    pub fn from_fn(width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> Result<Image> {
        let data = (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
        Image::new(width, height, data)
    }

    /// Builds an image from interleaved samples with `channels` per pixel (3 for RGB, 4 for
    /// RGBA as GPU read-backs deliver them; channels past the third are dropped).
    pub fn from_interleaved(width: u32, height: u32, samples: &[f32], channels: usize) -> Result<Image> {
        if channels < 3 {
            return Err(CompareError::InvalidImage(format!(
                "{channels} channels per pixel; need at least 3"
            )));
        }
        if samples.len() != width as usize * height as usize * channels {
            return Err(CompareError::InvalidImage(format!(
                "{width}×{height} with {channels} channels needs {} samples, got {}",
                width as usize * height as usize * channels,
                samples.len()
            )));
        }
        Image::new(width, height, samples.chunks_exact(channels).map(|p| [p[0], p[1], p[2]]).collect())
    }

    /// The pixel at column `x`, row `y` (panics out of range, like slice indexing).
    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.data[self.index(x, y)]
    }

    /// Mutable access to the pixel at column `x`, row `y`.
    pub fn get_mut(&mut self, x: u32, y: u32) -> &mut [f32; 3] {
        let i = self.index(x, y);
        &mut self.data[i]
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside {}×{}", self.width, self.height);
        y as usize * self.width as usize + x as usize
    }

    /// `(width, height)`.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The image averaged over `n`×`n` pixel blocks (partial blocks at the right and bottom
    /// edges are dropped). Used to compare against a Monte-Carlo reference whose per-pixel
    /// noise would otherwise dominate the error: averaging n² pixels cuts the noise by n.
    pub fn block_mean(&self, n: u32) -> Result<Image> {
        let (w, h) = (self.width / n.max(1), self.height / n.max(1));
        if n == 0 || w == 0 || h == 0 {
            return Err(CompareError::InvalidOption(format!(
                "block size {n} does not fit a {}×{} image",
                self.width, self.height
            )));
        }
        let k = 1.0 / (n * n) as f64;
        Image::from_fn(w, h, |bx, by| {
            let mut sum = [0.0f64; 3];
            for y in by * n..(by + 1) * n {
                for x in bx * n..(bx + 1) * n {
                    let p = self.get(x, y);
                    (0..3).for_each(|c| sum[c] += p[c] as f64);
                }
            }
            sum.map(|v| (v * k) as f32)
        })
    }

    /// The first pixel holding NaN or ±∞, as `(x, y, value)`.
    pub fn first_non_finite(&self) -> Option<(u32, u32, [f32; 3])> {
        let i = self.data.iter().position(|p| p.iter().any(|v| !v.is_finite()))?;
        let w = self.width as usize;
        Some(((i % w) as u32, (i / w) as u32, self.data[i]))
    }

    /// Fails with [`CompareError::NonFinite`] naming `what` if any pixel is NaN or infinite.
    pub fn check_finite(&self, what: &str) -> Result<()> {
        match self.first_non_finite() {
            None => Ok(()),
            Some((x, y, value)) => Err(CompareError::NonFinite { what: what.into(), x, y, value }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_mean_averages_whole_blocks() {
        let img = Image::from_fn(5, 4, |x, y| [x as f32, y as f32, (x * y) as f32]).unwrap();
        let b = img.block_mean(2).unwrap();
        assert_eq!(b.size(), (2, 2));
        // Block (1, 1) covers x 2..4, y 2..4: means 2.5, 2.5 and (4 + 6 + 6 + 9) / 4.
        assert_eq!(b.get(1, 1), [2.5, 2.5, 6.25]);
        assert_eq!(b.get(0, 0), [0.5, 0.5, 0.25]);
        assert!(img.block_mean(0).is_err() && img.block_mean(5).is_err());
        assert_eq!(img.block_mean(1).unwrap(), img);
    }

    #[test]
    fn new_checks_length_and_emptiness() {
        assert!(Image::new(2, 2, vec![[0.0; 3]; 4]).is_ok());
        let e = Image::new(2, 3, vec![[0.0; 3]; 4]).unwrap_err().to_string();
        assert!(e.contains("2×3") && e.contains("6") && e.contains("4"), "{e}");
        assert!(Image::new(0, 5, vec![]).is_err());
    }

    #[test]
    fn row_major_layout() {
        let im = Image::from_fn(3, 2, |x, y| [x as f32, y as f32, 0.0]).unwrap();
        assert_eq!(im.data[4], [1.0, 1.0, 0.0]);
        assert_eq!(im.get(2, 1), [2.0, 1.0, 0.0]);
    }

    #[test]
    fn from_interleaved_rgba() {
        let s = [1.0, 2.0, 3.0, 9.0, 4.0, 5.0, 6.0, 9.0];
        assert_eq!(
            Image::from_interleaved(2, 1, &s, 4).unwrap().data,
            vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]
        );
        assert!(Image::from_interleaved(2, 2, &s, 4).is_err());
        assert!(Image::from_interleaved(4, 1, &s, 2).is_err());
    }

    #[test]
    fn finds_non_finite() {
        let mut im = Image::filled(4, 3, [0.5; 3]).unwrap();
        assert!(im.check_finite("x").is_ok());
        im.get_mut(3, 2)[1] = f32::NAN;
        assert_eq!(im.first_non_finite().map(|t| (t.0, t.1)), Some((3, 2)));
        let e = im.check_finite("test.exr").unwrap_err().to_string();
        assert!(e.contains("test.exr") && e.contains("(3, 2)"), "{e}");
    }
}
