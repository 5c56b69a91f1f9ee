//! FLIP (Andersson et al. 2020, "FLIP: A Difference Evaluator for Alternating Images"; HDR-FLIP,
//! Andersson et al. 2021): NVIDIA's perceptual difference of rendered images, computed by NVIDIA's
//! own reference implementation (flip/FLIP.h of `flip-evaluator` 1.7, BSD-3-Clause, compiled by
//! build.rs) through the small C ABI in flip/flip_capi.cpp. Nothing of FLIP is re-implemented
//! here: this module only validates inputs and prepares them the way the reference's Python
//! `evaluate` does, so the maps and means are the reference's.
//!
//! - LDR-FLIP compares display-encoded sRGB images in [0, 1]: our linear images are clamped and
//!   encoded to 8-bit (or, for 16-bit files, 16-bit; [`ldr_flip_at_depths`]) sRGB exactly as a
//!   PNG output is ([`crate::io::to_display`]), so FLIP of two images read from PNG sees the
//!   files' own codes, and FLIP decodes them with its own function.
//! - HDR-FLIP takes linear images, exposes them over a range of exposures, tone maps each (ACES
//!   by default), and keeps each pixel's worst LDR-FLIP. Without user exposures the range comes
//!   from the reference image as in the reference tool: from its brightest pixel to its median
//!   luminance.

use crate::error::{CompareError, Result};
use crate::image::Image;

unsafe extern "C" {
    fn spectra_flip_exposures(
        reference: *const f32,
        width: i32,
        height: i32,
        tonemapper: i32,
        start: *mut f32,
        stop: *mut f32,
    ) -> i32;
    fn spectra_flip_evaluate(
        reference: *const f32,
        test: *const f32,
        width: i32,
        height: i32,
        use_hdr: i32,
        srgb_input: i32,
        ppd: f32,
        start_exposure: f32,
        stop_exposure: f32,
        num_exposures: i32,
        tonemapper: i32,
        map_out: *mut f32,
        mean_out: *mut f32,
        num_exposures_used: *mut i32,
    ) -> i32;
    fn spectra_flip_magma(values: *const f32, count: i32, rgb_out: *mut f32);
}

/// Pixels per degree of visual angle of the reference implementation's default viewing setup
/// (a 0.7 m wide 4K monitor at 0.7 m): 0.7 · 3840 / 0.7 · π / 180, in f32 as FLIP.h computes it
/// (its π, 3.14159265358979f, is the same f32).
pub const DEFAULT_PIXELS_PER_DEGREE: f32 = 0.7 * (3840.0 / 0.7) * (std::f32::consts::PI / 180.0);

/// HDR-FLIP's tone mapper (the reference's `--tone-mapper`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ToneMapper {
    Reinhard,
    #[default]
    Aces,
    Hable,
}

impl ToneMapper {
    /// By the reference tool's names: `aces`, `reinhard`, `hable`.
    pub fn by_name(name: &str) -> Result<ToneMapper> {
        match name.to_ascii_lowercase().as_str() {
            "aces" => Ok(ToneMapper::Aces),
            "reinhard" => Ok(ToneMapper::Reinhard),
            "hable" => Ok(ToneMapper::Hable),
            _ => Err(CompareError::InvalidOption(format!(
                "tone mapper {name:?}: FLIP has aces (default), reinhard and hable"
            ))),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ToneMapper::Reinhard => "reinhard",
            ToneMapper::Aces => "aces",
            ToneMapper::Hable => "hable",
        }
    }

    fn code(self) -> i32 {
        match self {
            ToneMapper::Reinhard => 0,
            ToneMapper::Aces => 1,
            ToneMapper::Hable => 2,
        }
    }
}

/// Pixels per degree accepted (FLIP's default, 67, is a 4K monitor at 0.7 m): FLIP's filter
/// kernels grow with it, so 1000 is seconds on a megapixel image where 1e9 ran for minutes, and
/// below 1 they are narrower than a pixel.
pub const PPD_RANGE: (f32, f32) = (1.0, 1000.0);
/// HDR-FLIP exposures accepted, in stops (2^±64 keeps any finite f16 or sane f32 radiance
/// finite).
pub const EXPOSURE_RANGE: (f32, f32) = (-64.0, 64.0);
/// Widest exposure span: FLIP evaluates ⌈stop − start⌉ exposures when not told how many.
pub const MAX_EXPOSURE_SPAN: f32 = 64.0;

/// HDR-FLIP settings; `None` means the reference implementation's default.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdrOptions {
    /// First exposure (log2 stops); default from the reference image's brightest pixel.
    pub start_exposure: Option<f32>,
    /// Last exposure; default from the reference image's median luminance.
    pub stop_exposure: Option<f32>,
    /// Number of exposures; default ⌈stop − start⌉, at least 2.
    pub exposures: Option<u32>,
    pub tone_mapper: ToneMapper,
}

/// The exposures HDR-FLIP used.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Exposures {
    pub start: f32,
    pub stop: f32,
    pub count: u32,
    pub tone_mapper: &'static str,
}

/// A per-pixel FLIP error map, values in [0, 1], row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct FlipMap {
    pub width: u32,
    pub height: u32,
    pub values: Vec<f32>,
    /// The mean as the reference computes it (a running f32 sum), so it equals the number the
    /// reference tool prints.
    mean: f32,
    /// For HDR-FLIP, the exposures used; `None` for LDR-FLIP.
    pub exposures: Option<Exposures>,
}

impl FlipMap {
    /// Mean FLIP over the image, the number the reference tool reports as "Mean".
    pub fn mean(&self) -> f64 {
        f64::from(self.mean)
    }

    /// The map coloured with the reference implementation's magma lookup table, as RGB8 (the
    /// reference tool's PNG rounding).
    pub fn magma(&self) -> Vec<u8> {
        let mut rgb = vec![0f32; self.values.len() * 3];
        // SAFETY: `values` has `len` floats and `rgb` three times as many, as the callee reads
        // and writes; the count fits an i32 (checked when the map was made).
        unsafe { spectra_flip_magma(self.values.as_ptr(), self.values.len() as i32, rgb.as_mut_ptr()) };
        rgb.iter().map(|&c| (255.0 * c.clamp(0.0, 1.0) + 0.5) as u8).collect()
    }

    /// Writes the magma-coloured map as PNG, atomically.
    pub fn save_png(&self, path: &std::path::Path) -> Result<()> {
        crate::atomic::write_atomic(path, &self.to_png(path)?)
    }

    /// The PNG [`FlipMap::save_png`] writes to `path` (named in errors), for staging beside a
    /// command's other outputs.
    pub fn to_png(&self, path: &std::path::Path) -> Result<Vec<u8>> {
        let img = image::RgbImage::from_raw(self.width, self.height, self.magma())
            .expect("the lookup gives three bytes a pixel");
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, image::ImageFormat::Png).map_err(|e| CompareError::Encode {
            path: path.into(),
            format: "PNG",
            reason: e.to_string(),
        })?;
        Ok(buf.into_inner())
    }
}

/// Checks what FLIP needs of a pair and returns the size as the C side's ints.
fn check_pair(reference: &Image, test: &Image, pixels_per_degree: f32) -> Result<(i32, i32)> {
    reference.validate()?;
    test.validate()?;
    if reference.size() != test.size() {
        return Err(CompareError::SizeMismatch { reference: reference.size(), test: test.size() });
    }
    reference.check_finite("reference image")?;
    test.check_finite("test image")?;
    if !(PPD_RANGE.0..=PPD_RANGE.1).contains(&pixels_per_degree) {
        return Err(CompareError::InvalidOption(format!(
            "pixels per degree must be between {} and {} (FLIP's filters grow with it: 1e9 ran for minutes), got {pixels_per_degree}",
            PPD_RANGE.0, PPD_RANGE.1
        )));
    }
    let (w, h) = reference.size();
    // FLIP.h indexes with int: keep 3 · pixels within i32.
    if u64::from(w) * u64::from(h) * 3 > i32::MAX as u64 {
        return Err(CompareError::InvalidImage(format!("{w}×{h} is too large for FLIP")));
    }
    Ok((w as i32, h as i32))
}

#[allow(clippy::too_many_arguments)]
fn evaluate(
    reference: &[f32],
    test: &[f32],
    (w, h): (i32, i32),
    hdr: bool,
    srgb: bool,
    ppd: f32,
    (start, stop, count): (f32, f32, i32),
    tone_mapper: ToneMapper,
) -> Result<FlipMap> {
    let mut values = vec![0f32; (w as usize) * (h as usize)];
    let (mut mean, mut used) = (0f32, 0i32);
    // SAFETY: both inputs hold 3·w·h floats and `values` w·h, as the callee reads and writes;
    // the callee catches every C++ exception, and the exposures were validated so FLIP.h never
    // reaches its exit() on start > stop.
    let rc = unsafe {
        spectra_flip_evaluate(
            reference.as_ptr(),
            test.as_ptr(),
            w,
            h,
            i32::from(hdr),
            i32::from(srgb),
            ppd,
            start,
            stop,
            count,
            tone_mapper.code(),
            values.as_mut_ptr(),
            &mut mean,
            &mut used,
        )
    };
    if rc != 0 {
        return Err(CompareError::InvalidImage(format!("FLIP failed on a {w}×{h} image (out of memory?)")));
    }
    let exposures =
        hdr.then(|| Exposures { start, stop, count: used as u32, tone_mapper: tone_mapper.name() });
    Ok(FlipMap { width: w as u32, height: h as u32, values, mean, exposures })
}

/// LDR-FLIP of `test` against `reference` (same size, finite pixels) at `pixels_per_degree`,
/// each as an 8-bit PNG of it holds it.
pub fn ldr_flip(reference: &Image, test: &Image, pixels_per_degree: f32) -> Result<FlipMap> {
    ldr_flip_at_depths(reference, test, pixels_per_degree, (8, 8))
}

/// [`ldr_flip`] with each image's codes at its own bit depth (`bits`: the reference's and the
/// test's, 8 or 16, as read from PNGs of those depths; [`crate::io::png_bit_depth`]), so that
/// FLIP sees a 16-bit file's own codes, as the reference tool does.
pub fn ldr_flip_at_depths(
    reference: &Image,
    test: &Image,
    pixels_per_degree: f32,
    bits: (u8, u8),
) -> Result<FlipMap> {
    let size = check_pair(reference, test, pixels_per_degree)?;
    // Codes as a PNG holds them, given to FLIP as code / (2^bits − 1) like the reference's loader.
    let codes = |img: &Image, bits: u8| -> Vec<f32> {
        let top = if bits > 8 { 65535.0 } else { 255.0 };
        img.data
            .iter()
            .flat_map(|p| p.map(|v| ((crate::io::to_display(v) * top).round() as f32) / top as f32))
            .collect()
    };
    evaluate(
        &codes(reference, bits.0),
        &codes(test, bits.1),
        size,
        false,
        true,
        pixels_per_degree,
        (0.0, 0.0, -1),
        ToneMapper::Aces,
    )
}

/// HDR-FLIP of the linear images `test` against `reference` (same size, finite pixels).
/// Negative values (linear sRGB outside the gamut) are taken as 0: FLIP expects non-negative
/// radiance, and a display cannot show less than black.
pub fn hdr_flip(
    reference: &Image,
    test: &Image,
    pixels_per_degree: f32,
    opts: &HdrOptions,
) -> Result<FlipMap> {
    let size = check_pair(reference, test, pixels_per_degree)?;
    let linear = |img: &Image| -> Vec<f32> { img.data.iter().flat_map(|p| p.map(|v| v.max(0.0))).collect() };
    let (r, t) = (linear(reference), linear(test));
    let (mut start, mut stop) = (f32::INFINITY, f32::INFINITY);
    if opts.start_exposure.is_none() || opts.stop_exposure.is_none() {
        // SAFETY: `r` holds 3·w·h floats; the callee catches every C++ exception.
        let rc = unsafe {
            spectra_flip_exposures(r.as_ptr(), size.0, size.1, opts.tone_mapper.code(), &mut start, &mut stop)
        };
        if rc != 0 {
            return Err(CompareError::InvalidImage("FLIP could not compute the exposure range".into()));
        }
        if !(start.is_finite() && stop.is_finite()) {
            return Err(CompareError::InvalidOption(
                "HDR-FLIP: the reference image is black, so FLIP cannot choose its exposure range; \
                 give the exposure range (`spectra diff --flip-start-exposure S --flip-stop-exposure E`) \
                 or use LDR-FLIP"
                    .into(),
            ));
        }
    }
    let start = opts.start_exposure.unwrap_or(start);
    let stop = opts.stop_exposure.unwrap_or(stop);
    if !(start.is_finite() && stop.is_finite() && start <= stop) {
        return Err(CompareError::InvalidOption(format!(
            "HDR-FLIP exposures: the start ({start}) must not exceed the stop ({stop}), both finite"
        )));
    }
    // 2^±1e30 overflows into garbage and ⌈stop − start⌉ exposures of 2·10⁵ run for minutes.
    let (lo, hi) = EXPOSURE_RANGE;
    if start < lo || stop > hi || stop - start > MAX_EXPOSURE_SPAN {
        return Err(CompareError::InvalidOption(format!(
            "HDR-FLIP exposures {start}…{stop}: each must lie within {lo}…{hi} stops and the span be at most \
             {MAX_EXPOSURE_SPAN} stops{}",
            if opts.start_exposure.is_none() || opts.stop_exposure.is_none() {
                " (FLIP chose them from the reference image; give --flip-start-exposure and --flip-stop-exposure)"
            } else {
                ""
            }
        )));
    }
    let count = match opts.exposures {
        None => -1,
        Some(n) if (2..=1000).contains(&n) => n as i32,
        Some(n) => {
            return Err(CompareError::InvalidOption(format!(
                "HDR-FLIP: the number of exposures must be 2 to 1000, got {n}"
            )));
        }
    };
    evaluate(&r, &t, size, true, false, pixels_per_degree, (start, stop, count), opts.tone_mapper)
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
        let h = hdr_flip(&a, &a, DEFAULT_PIXELS_PER_DEGREE, &HdrOptions::default()).unwrap();
        assert_eq!(h.mean(), 0.0);
        assert!(h.exposures.unwrap().count >= 2);
        let b = Image::filled(8, 8, [0.5; 3]).unwrap();
        assert!(matches!(ldr_flip(&a, &b, 67.0), Err(CompareError::SizeMismatch { .. })));
        let mut c = a.clone();
        c.get_mut(3, 2)[0] = f32::NAN;
        let e = ldr_flip(&a, &c, 67.0).unwrap_err().to_string();
        assert!(e.contains("test image") && e.contains("(3, 2)"), "{e}");
        assert!(ldr_flip(&a, &a, 0.0).is_err());
        assert!(hdr_flip(&a, &c, 67.0, &HdrOptions::default()).is_err());
    }

    #[test]
    fn hdr_options_that_would_stop_flip_are_refused() {
        let a = Image::from_fn(16, 8, |x, _| [x as f32, 0.5, 0.2]).unwrap();
        let b = Image::from_fn(16, 8, |x, _| [x as f32 * 1.1, 0.5, 0.2]).unwrap();
        let backwards =
            HdrOptions { start_exposure: Some(1.0), stop_exposure: Some(-1.0), ..Default::default() };
        let e = hdr_flip(&a, &b, 67.0, &backwards).unwrap_err().to_string();
        assert!(e.contains("start") && e.contains("stop"), "{e}");
        let one = HdrOptions { exposures: Some(1), ..Default::default() };
        assert!(hdr_flip(&a, &b, 67.0, &one).unwrap_err().to_string().contains("number of exposures"));
        let black = Image::filled(16, 8, [0.0; 3]).unwrap();
        let e = hdr_flip(&black, &b, 67.0, &HdrOptions::default()).unwrap_err().to_string();
        assert!(e.contains("black"), "{e}");
        // With exposures given, a black reference is measurable.
        let given = HdrOptions { start_exposure: Some(-2.0), stop_exposure: Some(1.0), ..Default::default() };
        let m = hdr_flip(&black, &b, 67.0, &given).unwrap();
        assert!(m.mean() > 0.0);
        assert_eq!(m.exposures.unwrap().count, 3);
        assert!(ToneMapper::by_name("filmic").is_err());
    }
}
