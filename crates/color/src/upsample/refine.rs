//! Interpolation-aware refinement of a fitted table.
//!
//! A node-exact fit reproduces every grid colour, but a renderer never looks up grid colours:
//! it interpolates the coefficients trilinearly, and the sigmoid is far from linear in them
//! where the spectra are extreme (saturated colours next to a zero channel, near-whites).
//! There, the colour between two exact nodes can be off by ΔE ≈ 0.5.
//!
//! This pass re-fits each node that borders a poor cell so that the *interpolated* table is
//! accurate across all eight cells around it: Gauss–Newton on the Lab residuals of sample
//! points in those cells ([`RefineOptions::samples_per_axis`]³ per cell, plus the node itself), where a sample's
//! coefficients are the trilinear blend of its cell's corners and so depend on the node with
//! the sample's interpolation weight. Nodes are visited in eight parity classes: two nodes of
//! the same parity never share a cell, so each class updates in parallel and the sweep is an
//! exact block Gauss–Seidel. Each step is accepted only if it lowers the node's objective, so
//! the pass never makes the sampled error worse.
//!
//! The file format and `rgb2spec_fetch` are unchanged: only the stored numbers differ.

use std::sync::atomic::{AtomicBool, Ordering};

use indicatif::ProgressBar;
use rayon::prelude::*;

use crate::error::{ColorError, Result};
use crate::upsample::fit::{LabModel, is_grey_node, nm_to_normalised, normalised_to_nm};
use crate::upsample::table::{CoeffTable, z_weight};

/// Knobs of [`refine_table`].
#[derive(Clone, Debug)]
pub struct RefineOptions {
    /// Full passes over the table.
    pub sweeps: usize,
    /// A cell is poor when the ΔE*ab at any of its probe points exceeds this.
    pub threshold: f64,
    /// Cells whose centre is off by more than this are not refined: their colours are (almost
    /// always) outside what any reflectance can reach — wide-gamut primaries beyond the
    /// object-colour solid — and no choice of coefficients helps. Without this cut, P3 and
    /// Rec.2020 tables spend minutes on hopeless nodes.
    pub give_up: f64,
    /// Gauss–Newton steps per node per sweep.
    pub steps: usize,
    /// Sample points per axis inside each cell (at (m + ½)/n); 1 = cell centres only.
    pub samples_per_axis: usize,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions { sweeps: 1, threshold: 0.02, give_up: 2.0, steps: 2, samples_per_axis: 1 }
    }
}

struct Grid<'a> {
    res: usize,
    scale: &'a [f64],
    scale32: &'a [f32],
}

impl Grid<'_> {
    /// Interpolation fractions of the point at fractions `f` of cell k: the brightness weight is
    /// [`z_weight`]'s, exactly as [`CoeffTable::fetch`] blends the corners.
    fn wf(&self, k: usize, f: [f64; 3]) -> [f64; 3] {
        let z = self.scale[k] + (self.scale[k + 1] - self.scale[k]) * f[2];
        [f[0], f[1], z_weight(z as f32, self.scale32[k], self.scale32[k + 1]) as f64]
    }

    /// RGB at fractional grid coordinates inside cell (l, k, j, i).
    fn rgb(&self, l: usize, k: usize, j: usize, i: usize, f: [f64; 3]) -> [f64; 3] {
        let z = self.scale[k] + (self.scale[k + 1] - self.scale[k]) * f[2];
        let n = (self.res - 1) as f64;
        let mut rgb = [0.0; 3];
        rgb[l] = z;
        rgb[(l + 1) % 3] = (i as f64 + f[0]) / n * z;
        rgb[(l + 2) % 3] = (j as f64 + f[1]) / n * z;
        rgb
    }
}

fn node_index(res: usize, l: usize, k: usize, j: usize, i: usize) -> usize {
    ((l * res + k) * res + j) * res + i
}

/// Trilinear weights of the 8 corners (di, dj, dk ∈ {0, 1}, index di + 2dj + 4dk).
fn weights(f: [f64; 3]) -> [f64; 8] {
    let mut w = [0.0; 8];
    for (c, wc) in w.iter_mut().enumerate() {
        let (di, dj, dk) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
        *wc = (if di == 1 { f[0] } else { 1.0 - f[0] })
            * (if dj == 1 { f[1] } else { 1.0 - f[1] })
            * (if dk == 1 { f[2] } else { 1.0 - f[2] });
    }
    w
}

fn lab_err(model: &LabModel, target: [f64; 3], a: [f64; 3]) -> f64 {
    let lab = model.lab_of_xyz(model.xyz(a));
    ((lab[0] - target[0]).powi(2) + (lab[1] - target[1]).powi(2) + (lab[2] - target[2]).powi(2)).sqrt()
}

/// Refines `table` in place for `model`'s colour space. Returns the number of node updates.
pub fn refine_table(
    table: &mut CoeffTable,
    model: &LabModel,
    opt: &RefineOptions,
    progress: &ProgressBar,
    cancel: &AtomicBool,
) -> Result<usize> {
    let res = table.res;
    let scale: Vec<f64> = table.scale.iter().map(|&s| s as f64).collect();
    let grid = Grid { res, scale: &scale, scale32: &table.scale };
    // Work in normalised coefficients (trilinear interpolation commutes with the linear map).
    let mut a: Vec<[f64; 3]> = table
        .data
        .chunks_exact(3)
        .map(|c| nm_to_normalised([c[0] as f64, c[1] as f64, c[2] as f64]))
        .collect();
    let ncell = 3 * (res - 1).pow(3);
    let n_off = opt.samples_per_axis.max(1);
    let offs: Vec<f64> = (0..n_off).map(|m| (m as f64 + 0.5) / n_off as f64).collect();
    let mut updates = 0;
    progress.set_length((opt.sweeps * 9) as u64);
    for _ in 0..opt.sweeps {
        // 1. Probe every cell at its centre and mark the nodes around poor cells.
        let poor: Vec<bool> = (0..ncell)
            .into_par_iter()
            .map(|c| {
                let r1 = res - 1;
                let (i, j, k, l) = (c % r1, c / r1 % r1, c / r1 / r1 % r1, c / r1.pow(3));
                let f = [0.5; 3];
                let w = weights(grid.wf(k, f));
                let mut ac = [0.0; 3];
                for (cn, wc) in w.iter().enumerate() {
                    let n = node_index(res, l, k + (cn >> 2 & 1), j + (cn >> 1 & 1), i + (cn & 1));
                    for m in 0..3 {
                        ac[m] += wc * a[n][m];
                    }
                }
                let e = lab_err(model, model.target_lab(grid.rgb(l, k, j, i, f)), ac);
                e > opt.threshold && e <= opt.give_up
            })
            .collect();
        progress.inc(1);
        if cancel.load(Ordering::Relaxed) {
            return Err(ColorError::Table("refinement interrupted; nothing was written".into()));
        }
        let r1 = res - 1;
        let cell_poor = |l: usize, k: usize, j: usize, i: usize| poor[((l * r1 + k) * r1 + j) * r1 + i];
        // 2. Eight parity classes, each updated in parallel.
        for parity in 0..8 {
            let (pi, pj, pk) = (parity & 1, (parity >> 1) & 1, (parity >> 2) & 1);
            let mut nodes = Vec::new();
            for l in 0..3 {
                for k in (pk..res).step_by(2) {
                    for j in (pj..res).step_by(2) {
                        for i in (pi..res).step_by(2) {
                            // Adjacent cells: corner offsets 0/1 on each axis.
                            let mut any = false;
                            for c in 0..8 {
                                let (di, dj, dk) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
                                if i >= di && j >= dj && k >= dk && i - di < r1 && j - dj < r1 && k - dk < r1
                                {
                                    any |= cell_poor(l, k - dk, j - dj, i - di);
                                }
                            }
                            // Greys stay the exact flat spectra `pin_grey_nodes` set.
                            if any && !is_grey_node(res, &table.scale, k, j, i) {
                                nodes.push((l, k, j, i));
                            }
                        }
                    }
                }
            }
            let new: Vec<(usize, [f64; 3])> = nodes
                .par_iter()
                .map(|&(l, k, j, i)| {
                    let me = node_index(res, l, k, j, i);
                    // Samples: (target Lab, weight of this node, the other corners' blend).
                    let mut samples: Vec<([f64; 3], f64, [f64; 3])> = Vec::with_capacity(8 * 8 + 1);
                    samples.push((
                        model.target_lab(crate::upsample::fit::node_rgb(res, &scale, l, k, j, i)),
                        1.0,
                        [0.0; 3],
                    ));
                    for c in 0..8 {
                        let (di, dj, dk) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
                        if !(i >= di && j >= dj && k >= dk && i - di < r1 && j - dj < r1 && k - dk < r1) {
                            continue;
                        }
                        let (ci, cj, ck) = (i - di, j - dj, k - dk);
                        for &fz in &offs {
                            for &fy in &offs {
                                for &fx in &offs {
                                    let f = [fx, fy, fz];
                                    let w = weights(grid.wf(ck, f));
                                    let mut rest = [0.0; 3];
                                    let mut wme = 0.0;
                                    for (cn, wc) in w.iter().enumerate() {
                                        let n = node_index(
                                            res,
                                            l,
                                            ck + (cn >> 2 & 1),
                                            cj + (cn >> 1 & 1),
                                            ci + (cn & 1),
                                        );
                                        if n == me {
                                            wme = *wc;
                                        } else {
                                            for m in 0..3 {
                                                rest[m] += wc * a[n][m];
                                            }
                                        }
                                    }
                                    samples.push((model.target_lab(grid.rgb(l, ck, cj, ci, f)), wme, rest));
                                }
                            }
                        }
                    }
                    let blend = |x: [f64; 3], s: &([f64; 3], f64, [f64; 3])| {
                        [s.2[0] + s.1 * x[0], s.2[1] + s.1 * x[1], s.2[2] + s.1 * x[2]]
                    };
                    let objective = |x: [f64; 3]| {
                        samples.iter().map(|s| lab_err(model, s.0, blend(x, s)).powi(2)).sum::<f64>()
                    };
                    let mut x = a[me];
                    let mut fx = objective(x);
                    for _ in 0..opt.steps {
                        let mut h = [[0.0; 3]; 3];
                        let mut g = [0.0; 3];
                        for s in &samples {
                            let (lab, jac) = model.lab_jac_pub(blend(x, s));
                            let r = [lab[0] - s.0[0], lab[1] - s.0[1], lab[2] - s.0[2]];
                            for p in 0..3 {
                                for q in 0..3 {
                                    let mut acc = 0.0;
                                    for row in 0..3 {
                                        acc += jac[row][p] * jac[row][q];
                                    }
                                    h[p][q] += s.1 * s.1 * acc;
                                }
                                let mut acc = 0.0;
                                for row in 0..3 {
                                    acc += jac[row][p] * r[row];
                                }
                                g[p] += s.1 * acc;
                            }
                        }
                        let mut damping = 1e-9;
                        let mut accepted = false;
                        for _ in 0..3 {
                            let mut hd = h;
                            for p in 0..3 {
                                hd[p][p] *= 1.0 + damping;
                            }
                            let Some(step) = crate::upsample::fit::solve3_pub(hd, g) else { break };
                            let cand = [x[0] - step[0], x[1] - step[1], x[2] - step[2]];
                            let fc = objective(cand);
                            if fc < fx {
                                x = cand;
                                fx = fc;
                                accepted = true;
                                break;
                            }
                            damping = if damping < 1e-3 { 1e-2 } else { damping * 10.0 };
                        }
                        if !accepted {
                            break;
                        }
                    }
                    (me, x)
                })
                .collect();
            updates += new.len();
            for (n, x) in new {
                a[n] = x;
            }
            progress.inc(1);
            if cancel.load(Ordering::Relaxed) {
                return Err(ColorError::Table("refinement interrupted; nothing was written".into()));
            }
        }
    }
    for (n, x) in a.iter().enumerate() {
        let c = normalised_to_nm(*x);
        for m in 0..3 {
            table.data[3 * n + m] = c[m] as f32;
        }
    }
    table.validate("refined table")?;
    Ok(updates)
}
