//! RGB → spectrum upsampling (Jakob & Hanika 2019, "A Low-Dimensional Function Space for
//! Efficient Spectral Upsampling"), its pbrt-style variants, and the baselines the paper
//! compares against.
//!
//! - [`SigmoidPolynomial`]: the spectral model, scalar `f64` and `f32` 4/8-wide evaluation.
//! - [`CoeffTable`]: rgb2spec's `.coeff` tables (read, write, `fetch`).
//! - [`fit_table`] / [`fit_default`]: the fitter; [`refine`]: interpolation-aware refinement.
//! - [`table()`]: the renderer's entry point — a cached, shared table per colour space.
//! - [`variants`]: unbounded RGB and illuminant spectra (pbrt-v4); [`smits`], [`boxes`]:
//!   baselines; [`Upsampler`] / [`Method`]: one interface over all three methods.
//! - [`roundtrip`]: RGB → spectrum → Lab accuracy, as measured for the acceptance figures.
//! - [`medium`]: RGB participating-medium coefficients → spectra (attenuation round trip).

// Numeric kernels index several parallel arrays with one counter, and `!(a > b)` is how the
// validation code makes NaN fail a check; both lints would make this code harder to read.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod adversarial;
pub mod boxes;
pub mod cache;
pub mod fit;
pub mod medium;
pub mod method;
pub mod refine;
pub mod roundtrip;
pub mod sigmoid;
pub mod smits;
pub mod table;
pub mod throughput;
pub mod variants;

use std::sync::atomic::AtomicBool;

use crate::progress::Progress;

pub use cache::{TABLE_RES, table, table_for};
pub use fit::{FitOptions, fit_table, fit_table_with};
pub use method::{Method, Reflectance, Upsampler, upsampler};
pub use sigmoid::SigmoidPolynomial;
pub use table::CoeffTable;

use crate::colorspace::RgbColorSpace;
use crate::error::Result;

/// The process's cancellation token ([`crate::cancel::token`]): long fits poll it and stop
/// without writing anything. The program, not this library, installs the Ctrl-C handler.
pub fn interrupt_flag() -> &'static AtomicBool {
    crate::cancel::token()
}

/// The fit behind the default tables: [`TABLE_RES`]³ nodes on [`fit::spectra_scale`]'s
/// brightness grid, then one sweep of [`refine`] (interpolation-aware). This is what [`table()`]
/// caches and `spectra lut` writes.
pub fn fit_default(space: &RgbColorSpace, progress: &dyn Progress) -> Result<CoeffTable> {
    fit_default_res(space, TABLE_RES, progress)
}

/// [`fit_default`] at another resolution.
pub fn fit_default_res(space: &RgbColorSpace, res: usize, progress: &dyn Progress) -> Result<CoeffTable> {
    let mut t = fit_table_with(space, &FitOptions::spectra(res), progress, interrupt_flag())?;
    let model = fit::LabModel::new(space)?;
    progress.stage(Some(&format!("refining the {} table for interpolation", space.name)), 0);
    refine::refine_table(&mut t, &model, &refine::RefineOptions::default(), progress, interrupt_flag())?;
    Ok(t)
}
