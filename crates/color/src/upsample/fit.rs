//! Fitting Jakob–Hanika coefficient tables: Gauss–Newton on the CIELAB residual.
//!
//! For every grid node the target is the node's RGB colour converted to CIELAB (relative to the
//! colour space's white), and the model is the sigmoid polynomial's reflectance integrated
//! against CIE 1931 2° under the space's illuminant on the 1 nm grid 360–830 nm (relative to the
//! white of a perfect reflector on the same grid, so that reflectance 1 is exactly L* = 100
//! and RGB (1, 1, 1) is its target). The round-trip evaluation uses this very integrator, so
//! the fit minimises exactly what is measured.
//!
//! What makes it fast compared with rgb2spec_opt (same method, same grid):
//! - the Jacobian is analytic: one pass over the wavelengths gives XYZ and ∂XYZ/∂c (rgb2spec
//!   re-integrates three more times for finite differences);
//! - the observer × illuminant × Δλ weights are precomputed once, and the pass runs four
//!   wavelengths at a time in `f64x4`;
//! - each node is warm-started from its neighbour along the brightness sweep and stops as soon
//!   as the Lab residual is below [`FitOptions::tolerance`] (typically 1–3 iterations).
//!
//! The polynomial is fitted in the normalised variable t = (λ − 360)/470 ∈ [0, 1], which keeps
//! the 3 × 3 systems well conditioned, and converted to nanometre coefficients at the end.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::progress::Progress;
use rayon::prelude::*;
use wide::f64x4;

use crate::colorspace::RgbColorSpace;
use crate::error::{ColorError, Result};
use crate::lab::xyz_to_lab;
use crate::observer::Observer;
use crate::upsample::table::CoeffTable;
use crate::wavelengths::WavelengthRange;
use crate::xyz::SpectralIntegrator;

/// Start and width of the normalised wavelength variable t = (λ − T0) / TW.
const T0: f64 = 360.0;
const TW: f64 = 470.0;

/// `smoothstep(x) = x²(3 − 2x)`.
pub fn smoothstep(x: f64) -> f64 {
    x * x * (3.0 - 2.0 * x)
}

/// rgb2spec's brightness grid: `smoothstep(smoothstep(k / (res − 1)))`, dense near 0 and 1.
pub fn rgb2spec_scale(res: usize) -> Vec<f64> {
    (0..res).map(|k| smoothstep(smoothstep(k as f64 / (res - 1) as f64))).collect()
}

/// spectra's brightness grid: a single `smoothstep(k / (res − 1))`. rgb2spec's double smoothstep
/// spends most nodes within 1 % of black and white and leaves mid-tones coarse (Δz ≈ 0.036 at
/// res 64); on 10⁵ random sRGB colours the single smoothstep lowers the round-trip mean ΔE2000
/// from 0.011 to 0.008 and p99 from 0.050 to 0.042 at the same memory (measured with
/// `cargo run --release -p color --example fit`).
pub fn spectra_scale(res: usize) -> Vec<f64> {
    (0..res).map(|k| smoothstep(k as f64 / (res - 1) as f64)).collect()
}

/// How far [`spectra_chroma`] pulls the chroma nodes towards 0 and towards 1: the first and the
/// last cell are 1 − this of a uniform cell.
pub const CHROMA_PULL: f64 = 0.5;

/// spectra's chroma grid: node i at the channel ratio t − p·t(1 − t)³ + p·t³(1 − t),
/// p = [`CHROMA_PULL`], t = i/(res − 1). The cells next to a zero channel (ratio 0) and next to a
/// second largest channel (ratio 1) are half as wide as rgb2spec's uniform ones, those in the
/// middle 25 % wider (slope 1 − p(1 − t)²(1 − 4t) + p·t²(3 − 4t), 0.5 … 1.25). The interpolation
/// error concentrates at both ends, where the spectra are extreme and the coefficients move
/// fastest: on the sRGB 64³ table with the uniform grid the worst colours were all in the corner
/// cell of the red table, (0.839, 0.0055, 0.0060) at ΔE2000 0.161; pulled towards 0 only
/// (t − p·t(1 − t)³) they were light yellows with red ≈ green, (0.984, 1, 0.336) at 0.081; with
/// both ends 0.059 (docs/upsampling.md, "Chroma grid"). Same memory: only the node positions move.
pub fn spectra_chroma(res: usize) -> Vec<f64> {
    (0..res)
        .map(|i| {
            let t = i as f64 / (res - 1) as f64;
            t - CHROMA_PULL * t * (1.0 - t).powi(3) + CHROMA_PULL * t.powi(3) * (1.0 - t)
        })
        .collect()
}

/// rgb2spec's chroma grid, i/(res − 1), in f64.
pub fn uniform_chroma(res: usize) -> Vec<f64> {
    (0..res).map(|i| i as f64 / (res - 1) as f64).collect()
}

/// Knobs of [`fit_table_with`].
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Grid points per axis.
    pub res: usize,
    /// Brightness grid (the largest channel's value at each k); strictly increasing in [0, 1],
    /// `res` entries. Defaults to [`rgb2spec_scale`].
    pub scale: Vec<f64>,
    /// Chroma grid (the channel ratio at each i or j); strictly increasing from 0 to 1, `res`
    /// entries. [`uniform_chroma`] for rgb2spec, [`spectra_chroma`] for spectra's tables.
    pub chroma: Vec<f64>,
    /// Stop a node's iteration once the Lab residual norm is below this.
    pub tolerance: f64,
    /// Iteration cap per node.
    pub max_iter: usize,
    /// Largest coefficient magnitude in the normalised variable. rgb2spec clamps at 200, which
    /// is too tight for dark saturated colours: e.g. sRGB (0, 0.00075, 0) then misses its
    /// target by ΔE2000 ≈ 13. spectra uses 10⁴, which every node but black (unreachable: a
    /// sigmoid is never exactly 0) stays inside.
    pub max_coeff: f64,
}

impl FitOptions {
    /// rgb2spec's grid ([`rgb2spec_scale`]) and coefficient clamp, for like-for-like comparisons.
    pub fn new(res: usize) -> Self {
        FitOptions {
            res,
            scale: rgb2spec_scale(res),
            chroma: uniform_chroma(res),
            tolerance: 1e-6,
            max_iter: 40,
            max_coeff: 200.0,
        }
    }

    /// spectra's default grids ([`spectra_scale`], [`spectra_chroma`]).
    pub fn spectra(res: usize) -> Self {
        FitOptions {
            scale: spectra_scale(res),
            chroma: spectra_chroma(res),
            max_coeff: 1e4,
            ..Self::new(res)
        }
    }
}

/// Converts normalised-variable coefficients (of t = (λ − 360)/470) to nanometre coefficients.
pub fn normalised_to_nm(a: [f64; 3]) -> [f64; 3] {
    let [a2, a1, a0] = a;
    [a2 / (TW * TW), a1 / TW - 2.0 * a2 * T0 / (TW * TW), a2 * T0 * T0 / (TW * TW) - a1 * T0 / TW + a0]
}

/// Converts nanometre coefficients back to the normalised variable.
pub fn nm_to_normalised(c: [f64; 3]) -> [f64; 3] {
    // x = c0 λ² + c1 λ + c2 with λ = T0 + TW t.
    [c[0] * TW * TW, (2.0 * c[0] * T0 + c[1]) * TW, (c[0] * T0 + c[1]) * T0 + c[2]]
}

/// The spectral model of one colour space, ready to evaluate Lab and its Jacobian.
#[derive(Clone, Debug)]
pub struct LabModel {
    /// Normalised wavelengths, padded to a multiple of 4 (padding has zero weight).
    t: Vec<f64>,
    /// Observer × illuminant × Δλ weights, one array per channel, padded.
    w: [Vec<f64>; 3],
    /// XYZ of the perfect reflector on this grid (the spectrum side's Lab white).
    pub white: [f64; 3],
    /// The colour space (its white is the target side's Lab white).
    pub space: RgbColorSpace,
}

/// XYZ of a coefficient set and its derivatives with respect to the three coefficients.
struct XyzJac {
    xyz: [f64; 3],
    /// `d[m][ch]` = ∂XYZ[ch]/∂a_m for the normalised coefficients (a2, a1, a0).
    d: [[f64; 3]; 3],
}

impl LabModel {
    /// The model on the 1 nm grid 360–830 nm, CIE 1931 2°, under the space's illuminant.
    pub fn new(space: &RgbColorSpace) -> Result<Self> {
        let integ =
            SpectralIntegrator::reference(&Observer::cie1931(), &space.illuminant(), WavelengthRange::FULL)?;
        Ok(Self::from_integrator(space, &integ))
    }

    /// The model on any integrator's wavelengths and weights.
    pub fn from_integrator(space: &RgbColorSpace, integ: &SpectralIntegrator) -> Self {
        let n = integ.lambda.len().div_ceil(4) * 4;
        let mut t = vec![0.0; n];
        let mut w = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        for (i, (&l, wi)) in integ.lambda.iter().zip(&integ.weights).enumerate() {
            t[i] = (l - T0) / TW;
            for ch in 0..3 {
                w[ch][i] = wi[ch];
            }
        }
        LabModel { t, w, white: integ.white(), space: space.clone() }
    }

    /// The XYZ weight of each wavelength (padding excluded): the generators of the
    /// object-colour solid on this grid.
    pub fn generators(&self) -> Vec<[f64; 3]> {
        (0..self.t.len()).map(|i| [self.w[0][i], self.w[1][i], self.w[2][i]]).collect()
    }

    /// Target Lab of a linear RGB colour, relative to the space's white.
    pub fn target_lab(&self, rgb: [f64; 3]) -> [f64; 3] {
        xyz_to_lab(self.space.rgb_to_xyz(rgb), self.space.white_xyz())
    }

    /// XYZ of the reflectance with normalised coefficients `a` (the pass of [`Self::xyz_jac`]
    /// without the derivatives, a third of its work: the refinement and the checkers call it
    /// millions of times).
    pub fn xyz(&self, a: [f64; 3]) -> [f64; 3] {
        let (a2, a1, a0) = (f64x4::splat(a[0]), f64x4::splat(a[1]), f64x4::splat(a[2]));
        let one = f64x4::ONE;
        let half = f64x4::HALF;
        let mut acc = [f64x4::ZERO; 3];
        for i in (0..self.t.len()).step_by(4) {
            let t = f64x4::from(<[f64; 4]>::try_from(&self.t[i..i + 4]).unwrap());
            let x = a2.mul_add(t, a1).mul_add(t, a0);
            let s = (half * x).mul_add(one / x.mul_add(x, one).sqrt(), half);
            for ch in 0..3 {
                let w = f64x4::from(<[f64; 4]>::try_from(&self.w[ch][i..i + 4]).unwrap());
                acc[ch] = s.mul_add(w, acc[ch]);
            }
        }
        acc.map(|v| v.reduce_add())
    }

    /// XYZ of any reflectance function of λ (nm) on this model's grid.
    pub fn xyz_of(&self, f: impl Fn(f64) -> f64) -> [f64; 3] {
        let mut xyz = [0.0; 3];
        for i in 0..self.t.len() {
            let v = f(T0 + TW * self.t[i]);
            for ch in 0..3 {
                xyz[ch] += v * self.w[ch][i];
            }
        }
        xyz
    }

    /// Lab (relative to the grid's white) of an XYZ computed on this grid.
    pub fn lab_of_xyz(&self, xyz: [f64; 3]) -> [f64; 3] {
        xyz_to_lab(xyz, self.white)
    }

    /// Lab of the reflectance with nanometre coefficients `c` (relative to the grid's white).
    pub fn lab_of_nm(&self, c: [f64; 3]) -> [f64; 3] {
        xyz_to_lab(self.xyz(nm_to_normalised(c)), self.white)
    }

    fn xyz_jac(&self, a: [f64; 3]) -> XyzJac {
        let (a2, a1, a0) = (f64x4::splat(a[0]), f64x4::splat(a[1]), f64x4::splat(a[2]));
        let one = f64x4::ONE;
        let half = f64x4::HALF;
        let mut acc = [f64x4::ZERO; 3];
        let mut dacc = [[f64x4::ZERO; 3]; 3];
        for i in (0..self.t.len()).step_by(4) {
            let t = f64x4::from(<[f64; 4]>::try_from(&self.t[i..i + 4]).unwrap());
            let x = a2.mul_add(t, a1).mul_add(t, a0);
            let q = x.mul_add(x, one);
            let r = one / q.sqrt(); // (1 + x²)^(−½)
            let s = (half * x).mul_add(r, half);
            let ds = half * r * r * r; // d s / d x
            let g = [ds * t * t, ds * t, ds];
            for ch in 0..3 {
                let w = f64x4::from(<[f64; 4]>::try_from(&self.w[ch][i..i + 4]).unwrap());
                acc[ch] = s.mul_add(w, acc[ch]);
                for m in 0..3 {
                    dacc[m][ch] = g[m].mul_add(w, dacc[m][ch]);
                }
            }
        }
        XyzJac { xyz: acc.map(|v| v.reduce_add()), d: dacc.map(|r| r.map(|v| v.reduce_add())) }
    }

    /// Lab and ∂Lab/∂a (rows: L, a, b; columns: a2, a1, a0).
    fn lab_jac(&self, a: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        let XyzJac { xyz, d } = self.xyz_jac(a);
        const EPS: f64 = 216.0 / 24389.0;
        const KAPPA: f64 = 24389.0 / 27.0;
        let mut f = [0.0; 3];
        let mut df = [0.0; 3]; // d f(X/Xn) / dX
        for ch in 0..3 {
            let u = xyz[ch] / self.white[ch];
            if u > EPS {
                f[ch] = u.cbrt();
                df[ch] = 1.0 / (3.0 * f[ch] * f[ch] * self.white[ch]);
            } else {
                f[ch] = (KAPPA * u + 16.0) / 116.0;
                df[ch] = KAPPA / (116.0 * self.white[ch]);
            }
        }
        let lab = [116.0 * f[1] - 16.0, 500.0 * (f[0] - f[1]), 200.0 * (f[1] - f[2])];
        let mut j = [[0.0; 3]; 3];
        for m in 0..3 {
            let dfx = df[0] * d[m][0];
            let dfy = df[1] * d[m][1];
            let dfz = df[2] * d[m][2];
            j[0][m] = 116.0 * dfy;
            j[1][m] = 500.0 * (dfx - dfy);
            j[2][m] = 200.0 * (dfy - dfz);
        }
        (lab, j)
    }

    /// Lab and ∂Lab/∂a at normalised coefficients `a` (rows L, a, b; columns a2, a1, a0).
    pub fn lab_jac_pub(&self, a: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
        self.lab_jac(a)
    }

    /// Newton iterations from `a` (normalised coefficients) towards `target` Lab. Returns the
    /// last residual norm computed (ΔE*ab): after an unchecked last step ([`EARLY_STOP`]) the one
    /// before it, an upper bound.
    pub fn solve(&self, target: [f64; 3], a: &mut [f64; 3], opt: &FitOptions) -> f64 {
        let mut best = f64::INFINITY;
        for _ in 0..opt.max_iter {
            let (lab, j) = self.lab_jac(*a);
            let r = [lab[0] - target[0], lab[1] - target[1], lab[2] - target[2]];
            let norm = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
            best = norm;
            if norm < opt.tolerance {
                break;
            }
            let Some(step) = solve3(j, r) else { break };
            for m in 0..3 {
                a[m] -= step[m];
            }
            // Newton converges quadratically: from a residual this small the step lands far
            // below `tolerance`, so checking that would cost one more XYZ + Jacobian pass (a
            // third of a node's work with warm starts) for nothing.
            if norm < EARLY_STOP * opt.tolerance.sqrt() {
                break;
            }
            let mx = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if !mx.is_finite() {
                *a = [0.0; 3];
                break;
            }
            if mx > opt.max_coeff {
                for v in a.iter_mut() {
                    *v *= opt.max_coeff / mx;
                }
            }
        }
        best
    }
}

/// [`LabModel::solve`] takes a last step without checking it once the residual is below this
/// times √tolerance (10⁻⁴ at the default 10⁻⁶).
const EARLY_STOP: f64 = 0.1;

/// Solves the 3 × 3 system `j · x = r`; `None` when singular.
pub fn solve3_pub(j: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    solve3(j, r)
}

/// Solves the 3 × 3 system `j · x = r` by Cramer's rule; `None` when singular.
fn solve3(j: [[f64; 3]; 3], r: [f64; 3]) -> Option<[f64; 3]> {
    let det3 = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det3(j);
    if !(d.abs() > 1e-300) || !d.is_finite() {
        return None;
    }
    let mut x = [0.0; 3];
    for (c, xc) in x.iter_mut().enumerate() {
        let mut m = j;
        for row in 0..3 {
            m[row][c] = r[row];
        }
        *xc = det3(m) / d;
    }
    Some(x)
}

/// The RGB colour of node (l, k, j, i): largest channel `l` = `scale[k]`, the two others
/// `i/(res−1)` and `j/(res−1)` of it.
pub fn node_rgb(scale: &[f64], chroma: &[f64], l: usize, k: usize, j: usize, i: usize) -> [f64; 3] {
    let z = scale[k];
    let mut rgb = [0.0; 3];
    rgb[l] = z;
    rgb[(l + 1) % 3] = chroma[i] * z;
    rgb[(l + 2) % 3] = chroma[j] * z;
    rgb
}

/// Fits a `res`³ table for `space` with rgb2spec's grid, showing progress on `progress`.
/// Stops early when [`crate::upsample::interrupt_flag`] is set (Ctrl-C once
/// the program installed a handler that calls [`crate::cancel::cancel`]).
pub fn fit_table(space: &RgbColorSpace, res: usize, progress: &dyn Progress) -> Result<CoeffTable> {
    fit_table_with(space, &FitOptions::new(res), progress, crate::upsample::interrupt_flag())
}

/// [`fit_table`] with explicit options and cancellation flag. Returns
/// a [`ColorError::Table`] ("fit interrupted; nothing was written") when `cancel` becomes true.
pub fn fit_table_with(
    space: &RgbColorSpace,
    opt: &FitOptions,
    progress: &dyn Progress,
    cancel: &AtomicBool,
) -> Result<CoeffTable> {
    let res = opt.res;
    if !(2..=crate::upsample::table::MAX_RES).contains(&res) {
        return Err(ColorError::Table(format!(
            "table resolution {res} is outside 2..={}",
            crate::upsample::table::MAX_RES
        )));
    }
    if opt.scale.len() != res
        || opt.scale.windows(2).any(|w| !(w[1] > w[0]))
        || opt.scale[0] < 0.0
        || opt.scale[res - 1] > 1.0
    {
        return Err(ColorError::Table(format!("brightness grid must be {res} increasing values in [0, 1]")));
    }
    if opt.chroma.len() != res
        || opt.chroma.windows(2).any(|w| !(w[1] > w[0]))
        || opt.chroma[0] != 0.0
        || opt.chroma[res - 1] != 1.0
    {
        return Err(ColorError::Table(format!("chroma grid must be {res} increasing values from 0 to 1")));
    }
    let model = LabModel::new(space)?;
    progress.stage(None, (3 * res) as u64);
    let start = res / 5;
    // One task per (l, j) row: sweeps every i column in k from `start` up, then down, each
    // node warm-started from the previous one.
    let rows: Vec<Option<Vec<[f64; 3]>>> = (0..3 * res)
        .into_par_iter()
        .map(|lj| {
            let (l, j) = (lj / res, lj % res);
            let mut out = vec![[0.0; 3]; res * res]; // [k][i]
            for i in 0..res {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                for dir in [1i64, -1] {
                    let mut a = [0.0; 3];
                    let mut prev: Option<[f64; 3]> = None;
                    let mut k = if dir > 0 { start as i64 } else { start as i64 - 1 };
                    while (0..res as i64).contains(&k) {
                        let ku = k as usize;
                        let rgb = node_rgb(&opt.scale, &opt.chroma, l, ku, j, i);
                        solve_node(&model, rgb, prev, &mut a, opt);
                        out[ku * res + i] = normalised_to_nm(a);
                        prev = Some(rgb);
                        k += dir;
                    }
                }
            }
            progress.inc(1);
            Some(out)
        })
        .collect();
    if cancel.load(Ordering::Relaxed) {
        return Err(ColorError::Table("fit interrupted; nothing was written".into()));
    }
    let mut table = CoeffTable {
        res,
        scale: opt.scale.iter().map(|&s| s as f32).collect(),
        chroma: opt.chroma.iter().map(|&c| c as f32).collect(),
        data: vec![0.0; CoeffTable::data_len(res)],
    };
    for (lj, row) in rows.into_iter().enumerate() {
        let (l, j) = (lj / res, lj % res);
        let row = row.expect("checked for cancellation above");
        for k in 0..res {
            for i in 0..res {
                let o = table.index(l, k, j, i);
                let c = row[k * res + i];
                for m in 0..3 {
                    table.data[o + m] = c[m] as f32;
                }
            }
        }
    }
    pin_grey_nodes(&mut table);
    progress.finish();
    table.validate("fitted table")?;
    Ok(table)
}

/// A node's Lab residual above which its warm-started solve is taken to have failed (the fitted
/// nodes of the default tables are far below it).
const NODE_RETRY_RESIDUAL: f64 = 1e-3;

/// Fits node colour `rgb` into `a`, warm-started from the previous node's coefficients (`a` on
/// entry; `prev_rgb` its colour). Where that start is too far — a coarse grid's brightness step
/// on a dark saturated blue sent Newton to the coefficient clamp, and every later node of the
/// row started from there (a 32³ table returned (0, 0, 0.01) as (0.72, −0.05, 0.03)) — it
/// walks from the previous colour to this one in small steps, and tries a cold start; the best
/// of the three is kept.
fn solve_node(
    model: &LabModel,
    rgb: [f64; 3],
    prev_rgb: Option<[f64; 3]>,
    a: &mut [f64; 3],
    opt: &FitOptions,
) {
    let start = *a;
    let target = model.target_lab(rgb);
    let mut best = model.solve(target, a, opt);
    if !(best > NODE_RETRY_RESIDUAL) {
        return;
    }
    if let Some(p) = prev_rgb {
        let mut b = start;
        const STEPS: usize = 16;
        for s in 1..STEPS {
            let t = s as f64 / STEPS as f64;
            let mid = std::array::from_fn(|c| p[c] + (rgb[c] - p[c]) * t);
            model.solve(model.target_lab(mid), &mut b, opt);
        }
        let r = model.solve(target, &mut b, opt);
        if r < best {
            best = r;
            *a = b;
        }
    }
    let mut cold = [0.0; 3];
    let r = model.solve(target, &mut cold, opt);
    if r < best {
        *a = cold;
    }
}

/// Whether node (k, j, i) is a grey (all three channels equal, black included), for the
/// brightness grid `scale`.
pub fn is_grey_node(res: usize, scale: &[f32], k: usize, j: usize, i: usize) -> bool {
    scale[k] == 0.0 || (i == res - 1 && j == res - 1)
}

/// Sets every grey node to the flat reflectance `σ⁻¹(z)` (clamped at [`table::Z_LO`] and
/// [`table::Z_HI`]). The flat spectrum is the exact solution, but Newton on black (no sigmoid
/// reaches 0) and white (none reaches 1) runs off towards the coefficient clamp and stops
/// wherever it is: exact black then came back at ΔE2000 ≈ 24 in the Rec.2020 and ACEScg tables.
/// Flat greys at the σ⁻¹ levels are also what makes [`table::z_weight`] reproduce every grey
/// between two levels.
///
/// [`table::Z_LO`]: crate::upsample::table::Z_LO
/// [`table::Z_HI`]: crate::upsample::table::Z_HI
/// [`table::z_weight`]: crate::upsample::table::z_weight
pub fn pin_grey_nodes(table: &mut CoeffTable) {
    let res = table.res;
    for l in 0..3 {
        for k in 0..res {
            for j in 0..res {
                for i in 0..res {
                    if is_grey_node(res, &table.scale, k, j, i) {
                        let o = table.index(l, k, j, i);
                        let c0 = crate::upsample::table::z_logit(table.scale[k]);
                        table.data[o..o + 3].copy_from_slice(&[0.0, 0.0, c0]);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::upsample::sigmoid::SigmoidPolynomial;

    #[test]
    fn coefficient_conversion_round_trips() {
        let a = [3.0, -7.5, 1.25];
        let c = normalised_to_nm(a);
        for l in [360.0, 512.3, 830.0] {
            let t = (l - T0) / TW;
            let want = (a[0] * t + a[1]) * t + a[2];
            assert!((SigmoidPolynomial { c }.poly(l) - want).abs() < 1e-9);
        }
        let back = nm_to_normalised(c);
        for m in 0..3 {
            assert!((back[m] - a[m]).abs() < 1e-9);
        }
    }

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        let m = LabModel::new(&RgbColorSpace::srgb()).unwrap();
        let a = [-3.0, 2.5, -0.4];
        let (lab, j) = m.lab_jac(a);
        let (x0, x1) = (m.xyz(a), m.xyz_jac(a).xyz);
        assert!((0..3).all(|c| (x0[c] - x1[c]).abs() < 1e-12 * x1[c].abs().max(1.0)), "{x0:?} vs {x1:?}");
        for k in 0..3 {
            let mut ap = a;
            ap[k] += 1e-6;
            let (labp, _) = m.lab_jac(ap);
            for row in 0..3 {
                let fd = (labp[row] - lab[row]) / 1e-6;
                assert!(
                    (fd - j[row][k]).abs() < 1e-3 * (1.0 + fd.abs()),
                    "row {row} col {k}: {fd} vs {}",
                    j[row][k]
                );
            }
        }
    }

    #[test]
    fn solve_reaches_in_gamut_targets() {
        let space = RgbColorSpace::srgb();
        let m = LabModel::new(&space).unwrap();
        let opt = FitOptions::new(8);
        for rgb in [[0.5, 0.5, 0.5], [0.8, 0.2, 0.1], [0.05, 0.3, 0.9], [0.9, 0.9, 0.2]] {
            let mut a = [0.0; 3];
            m.solve(m.target_lab(rgb), &mut a, &opt);
            let (lab, t) = (m.lab_of_xyz(m.xyz(a)), m.target_lab(rgb));
            let r = ((lab[0] - t[0]).powi(2) + (lab[1] - t[1]).powi(2) + (lab[2] - t[2]).powi(2)).sqrt();
            assert!(r < 1e-6, "{rgb:?}: residual {r}");
        }
    }

    /// Every fitted node of a coarse table reproduces its own colour: at 8³–32³ the warm start
    /// from the previous brightness ran off to the coefficient clamp on dark saturated blues and
    /// reds (2–42 nodes off by ΔE2000 44–100 against colour-science), and the rest of the row
    /// started from there.
    #[test]
    fn coarse_tables_fit_every_node() {
        let space = RgbColorSpace::srgb();
        let m = LabModel::new(&space).unwrap();
        for res in [8, 16, 32] {
            let opt = FitOptions::spectra(res);
            let t = fit_table_with(&space, &opt, &crate::progress::Silent, &AtomicBool::new(false)).unwrap();
            let mut worst = (0.0f64, [0.0; 3]);
            for l in 0..3 {
                for k in 0..res {
                    for j in 0..res {
                        for i in 0..res {
                            let o = t.index(l, k, j, i);
                            let c = [0, 1, 2].map(|n| f64::from(t.data[o + n]));
                            let rgb = node_rgb(&opt.scale, &opt.chroma, l, k, j, i);
                            let (lab, want) = (m.lab_of_xyz(m.xyz(nm_to_normalised(c))), m.target_lab(rgb));
                            let r = (0..3).map(|n| (lab[n] - want[n]).powi(2)).sum::<f64>().sqrt();
                            if r > worst.0 {
                                worst = (r, rgb);
                            }
                        }
                    }
                }
            }
            eprintln!("{res}³: worst node {:?}, Lab residual {:.3}", worst.1, worst.0);
            assert!(worst.0 < 1.0, "{res}³: node {:?} off by {}", worst.1, worst.0);
        }
    }
}
