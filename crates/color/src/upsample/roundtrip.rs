//! Round-trip accuracy: RGB → spectrum → XYZ → Lab, compared with the RGB's own Lab by CIEDE2000.
//!
//! The spectrum side integrates CIE 1931 2° on the 1 nm grid 360–830 nm under the space's
//! illuminant, relative to the perfect reflector's white on that grid; the RGB side is the
//! space's matrix relative to the space's white. Colours are uniform in the linear RGB cube
//! (a fixed seed, so runs are reproducible).

use rayon::prelude::*;

use crate::colorspace::RgbColorSpace;
use crate::delta_e::ciede2000;
use crate::error::{ColorError, Result};
use crate::metrics::Stats;
use crate::upsample::fit::{LabModel, nm_to_normalised};
use crate::upsample::table::CoeffTable;

/// Summary of a round trip over many colours.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RoundTrip {
    pub colours: usize,
    pub stats: Stats,
    /// The colour with the largest error.
    pub worst_rgb: [f64; 3],
}

/// SplitMix64: a tiny, well-mixed deterministic generator (no need for a crate here).
pub fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// `n` colours uniform in the linear unit cube.
pub fn random_colours(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut s = seed;
    (0..n).map(|_| [(); 3].map(|_| (splitmix64(&mut s) >> 11) as f64 / (1u64 << 53) as f64)).collect()
}

/// ΔE2000 of every colour, with `xyz_of(rgb)` giving the spectrum's XYZ on `model`'s grid.
pub fn delta_e_all(
    model: &LabModel,
    colours: &[[f64; 3]],
    xyz_of: impl Fn([f64; 3]) -> [f64; 3] + Sync,
) -> Vec<f64> {
    colours.par_iter().map(|&rgb| ciede2000(model.target_lab(rgb), model.lab_of_xyz(xyz_of(rgb)))).collect()
}

/// Summarises per-colour errors.
pub fn summarise(colours: &[[f64; 3]], de: &[f64]) -> Result<RoundTrip> {
    let stats =
        Stats::of(de).ok_or_else(|| ColorError::Table("round trip produced no finite errors".into()))?;
    let worst = de.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1)).map(|(i, _)| i).unwrap_or(0);
    Ok(RoundTrip { colours: colours.len(), stats, worst_rgb: colours[worst] })
}

/// Round trip through `table` exactly as a renderer uses it: trilinear fetch, then evaluate.
pub fn roundtrip_table(table: &CoeffTable, space: &RgbColorSpace, n: usize, seed: u64) -> Result<RoundTrip> {
    if n == 0 {
        return Err(ColorError::NoSamples);
    }
    let model = LabModel::new(space)?;
    let colours = random_colours(n, seed);
    let de = delta_e_all(&model, &colours, |rgb| model.xyz(nm_to_normalised(table.fetch(rgb).c)));
    summarise(&colours, &de)
}

/// Round trip of any [`crate::upsample::Upsampler`] (for the Jakob method this is the same as
/// [`roundtrip_table`] on its table).
pub fn roundtrip_upsampler(
    up: &dyn crate::upsample::Upsampler,
    space: &RgbColorSpace,
    n: usize,
    seed: u64,
) -> Result<RoundTrip> {
    if n == 0 {
        return Err(ColorError::NoSamples);
    }
    let model = LabModel::new(space)?;
    let colours = random_colours(n, seed);
    let de = delta_e_all(&model, &colours, |rgb| match up.reflectance(rgb) {
        Ok(s) => model.xyz_of(|l| s.eval(l)),
        Err(_) => [f64::NAN; 3],
    });
    summarise(&colours, &de)
}

/// The colour a reflectance round-trips to: its Lab (relative to the grid's white) taken back to
/// XYZ relative to the space's white, then to linear RGB. Also returns the ΔE2000 from `rgb`.
pub fn round_trip_rgb(model: &LabModel, rgb: [f64; 3], f: impl Fn(f64) -> f64) -> ([f64; 3], f64) {
    let lab = model.lab_of_xyz(model.xyz_of(f));
    let back = model.space.xyz_to_rgb(crate::lab::lab_to_xyz(lab, model.space.white_xyz()));
    (back, ciede2000(model.target_lab(rgb), lab))
}
