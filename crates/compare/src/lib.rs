//! Image comparison for spectra: image I/O (EXR, PNG, spectral EXR), per-pixel error metrics
//! (CIEDE2000, MAE, FLIP), and ΔE heat maps with a readable colour bar.
//!
//! Everything here works on [`Image`], linear sRGB (Rec. 709 primaries, D65 white) pixels, the
//! type the GPU renderer and the CPU ground-truth tracer both hand to the binary. The metric
//! maps ([`DiffMaps`]) and heat maps ([`Heatmap`]) are plain values so a report generator can
//! reuse them without going through files.
//!
//! Depends on `color` only.

pub mod atomic;
pub mod diff;
pub mod error;
pub mod flip;
pub mod font;
pub mod frame;
pub mod heatmap;
pub mod image;
pub mod io;
pub mod spectral;

pub use diff::{DiffMaps, DiffOptions, DiffSummary};
pub use error::{CompareError, Result};
pub use frame::{ExrFrame, Placement, Region, align, read_exr_frame, read_exr_frame_and_size};
pub use heatmap::{ColorMap, Heatmap, HeatmapOptions};
pub use image::Image;
pub use io::{
    ExrPrecision, PngBitDepth, WriteOptions, decode_image, decode_image_placed, encode_exr_framed,
    encode_image, read_image, read_image_placed, write_exr_framed, write_image,
};
pub use spectral::{
    SpectralImage, SpectralKind, encode_spectral_exr_framed, read_spectral_exr, write_spectral_exr,
    write_spectral_exr_framed,
};
