//! Interpolation-aware refinement of a fitted table.
//!
//! A node-exact fit reproduces every grid colour, but a renderer never looks up grid colours:
//! it interpolates the coefficients trilinearly, and the sigmoid is far from linear in them
//! where the spectra are extreme (saturated colours next to a zero channel, near-whites).
//! There, the colour between two exact nodes can be off by ΔE ≈ 0.5.
//!
//! This pass re-fits each node that borders a poor cell so that the *interpolated* table is
//! accurate across all eight cells around it: Gauss–Newton on the Lab residuals of sample
//! points in those cells ([`RefineOptions::samples_per_axis`]³ per cell, plus the cell's faces
//! that bound the table — a zero channel, a second channel equal to the largest, z = 1 — plus
//! the node itself), where a sample's coefficients are the blend of its cell's corners with
//! the fetch's weights ([`chroma_weight`], [`z_weight`]) and so depend on the node with the
//! sample's interpolation weight. Colours the table misses by more than ΔE*ab 2 (wide gamuts:
//! outside the object-colour solid, or beyond the model) are left out of the objective, so the
//! nodes next to them serve the reachable colours of their cells. Nodes are visited in eight parity classes: two nodes of
//! the same parity never share a cell, so each class updates in parallel and the sweep is an
//! exact block Gauss–Seidel. Each step is accepted only if it lowers the node's objective, so
//! the pass never makes the sampled error worse.
//!
//! The file format is unchanged: only the stored numbers differ.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::progress::Progress;
use rayon::prelude::*;

use crate::error::{ColorError, Result};
use crate::upsample::adversarial::ObjectSolid;
use crate::upsample::fit::{LabModel, is_grey_node, nm_to_normalised, normalised_to_nm};
use crate::upsample::table::{CoeffTable, chroma_weight, z_weight};

/// Knobs of [`refine_table`].
#[derive(Clone, Debug)]
pub struct RefineOptions {
    /// Full passes over the table.
    pub sweeps: usize,
    /// A cell is poor when the ΔE*ab at any of its probe points exceeds this.
    pub threshold: f64,
    /// Sample points (and nodes' own colours) off by more than this (ΔE*ab) leave the
    /// objective: they are wide-gamut colours no reflectance has (outside the object-colour
    /// solid) or beyond what a sigmoid reaches, and a least-squares fit that keeps them trades
    /// the reachable colours of their cells for them. Without them, the nodes next to such
    /// colours are fitted for the reachable colours of their cells instead of staying where
    /// Newton stopped (which spoiled saturated sRGB reds in P3: ΔE2000 3.06 before, 0.36 now).
    pub give_up: f64,
    /// Keep samples worse than `give_up` if they lie inside the object-colour solid
    /// ([`ObjectSolid`]). Off by default: measured on the 64³ tables, the sRGB colours inside
    /// P3 / Rec.2020 / ACEScg then reach 2.33 / 0.79 / 4.3 instead of 0.36 / 0.49 / 1.77
    /// (docs/upsampling.md), because colours just inside the solid that the model misses by
    /// ΔE 10–40 dominate the squares.
    pub keep_solid: bool,
    /// Gauss–Newton steps per node per sweep. One: a second step changed the sRGB 64³ table's
    /// adversarial max from 0.161 to 0.159 and its uniform mean not at all, for 50 % more time.
    pub steps: usize,
    /// Scale σ (ΔE*ab) of the robust (Cauchy) loss σ²·ln(1 + e²/σ²) that replaces e², so that
    /// samples off by much more than σ (colours next to the object-colour solid's boundary, in
    /// wide gamuts) stop dominating a node's objective; `f64::INFINITY` is least squares. 1:
    /// the sRGB colours inside P3 / Rec.2020 / ACEScg went from ΔE2000 0.209 / 0.306 / 0.300 to
    /// 0.117 / 0.287 / 0.267, sRGB's own adversarial max stayed 0.059; σ = 0.3 gave P3 0.151 but
    /// sRGB 0.093 (docs/upsampling.md).
    pub robust: f64,
    /// Weight of a node's own colour in its objective, relative to one sample point. 1: a
    /// weight of 4 made both sRGB (0.059 → 0.063) and the sRGB colours in P3 (0.117 → 0.166) worse.
    pub own_weight: f64,
    /// A step is refused if it leaves the node's own colour off by more than this (ΔE*ab) and
    /// by more than before. The objective trades a node's own colour for its cells' samples, and
    /// next to black in wide gamuts (coefficients in the hundreds, colours at the solid's
    /// boundary) that went far: Rec.2020 nodes at z = 0.003 ended 0.39 off, and sRGB
    /// (0.0016, 0.0002, 0.00004) between them at 0.287, where the unrefined table gave 0.078.
    /// 0.3: Rec.2020 0.287 → 0.132, sRGB unchanged; 0.1: Rec.2020 0.180, but sRGB 0.128 (its
    /// darkest corner cells need the move). `f64::INFINITY`: no cap.
    pub own_cap: f64,
    /// Sample points per axis inside each cell (at (m + ½)/n), 1 or 2 (larger values are
    /// taken as 2); boundary cells add their boundary face ([`Grid::cell_points`]).
    pub samples_per_axis: usize,
}

impl Default for RefineOptions {
    fn default() -> Self {
        RefineOptions {
            sweeps: 1,
            threshold: 0.02,
            give_up: 2.0,
            steps: 1,
            samples_per_axis: 1,
            keep_solid: false,
            robust: 1.0,
            own_weight: 1.0,
            own_cap: 0.3,
        }
    }
}

struct Grid<'a> {
    res: usize,
    scale: &'a [f64],
    scale32: &'a [f32],
    chroma: &'a [f64],
    chroma32: &'a [f32],
    /// Interior sample fractions per axis.
    offs: Vec<f64>,
}

impl Grid<'_> {
    /// The sample points of cell (k, j, i), as fractions: the interior lattice `offs`³, extended
    /// on each axis by the cell's face where that face is a boundary of the table — the cube's
    /// faces (a zero channel: f = 0 on the first cell), the planes where a second channel equals
    /// the largest (f = 1 on the last cell), and the top face z = 1. Colours there are extreme
    /// (a channel exactly 0), the interpolation error peaks there, and a centre-only objective
    /// never sees them: the worst sRGB colours of the centre-only refinement were on the red
    /// face, (0.762, 0, 0.0064) at ΔE2000 0.44. Black (k = 0) is pinned and has no free node.
    /// At most (n + 2)³ ≤ 64 points for n ≤ 2, so a `u64` mask can select among them.
    fn cell_points(&self, k: usize, j: usize, i: usize) -> Vec<[f64; 3]> {
        let last = self.res - 2;
        let axis = |c: usize, lower: bool| {
            let mut v = self.offs.clone();
            if lower && c == 0 {
                v.push(0.0);
            }
            if c == last {
                v.push(1.0);
            }
            v
        };
        let (ax, ay, az) = (axis(i, true), axis(j, true), axis(k, false));
        let mut out = Vec::with_capacity(ax.len() * ay.len() * az.len());
        for &fz in &az {
            for &fy in &ay {
                for &fx in &ax {
                    out.push([fx, fy, fz]);
                }
            }
        }
        out
    }

    /// Interpolation weights of the point at fractions `f` of cell (k, j, i): [`chroma_weight`]
    /// and [`z_weight`], exactly as [`CoeffTable::fetch`] blends the corners.
    fn wf(&self, k: usize, j: usize, i: usize, f: [f64; 3]) -> [f64; 3] {
        let z = self.scale[k] + (self.scale[k + 1] - self.scale[k]) * f[2];
        let (x, y) = (self.ratio(i, f[0]) as f32, self.ratio(j, f[1]) as f32);
        let c = self.chroma32;
        [
            chroma_weight(x, c[i], c[i + 1], y) as f64,
            chroma_weight(y, c[j], c[j + 1], x) as f64,
            z_weight(z as f32, self.scale32[k], self.scale32[k + 1]) as f64,
        ]
    }

    /// RGB at fractional grid coordinates inside cell (l, k, j, i).
    fn rgb(&self, l: usize, k: usize, j: usize, i: usize, f: [f64; 3]) -> [f64; 3] {
        let z = self.scale[k] + (self.scale[k + 1] - self.scale[k]) * f[2];
        let mut rgb = [0.0; 3];
        rgb[l] = z;
        rgb[(l + 1) % 3] = self.ratio(i, f[0]) * z;
        rgb[(l + 2) % 3] = self.ratio(j, f[1]) * z;
        rgb
    }

    /// Channel ratio at fraction `f` of chroma cell `i`.
    fn ratio(&self, i: usize, f: f64) -> f64 {
        self.chroma[i] + (self.chroma[i + 1] - self.chroma[i]) * f
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

/// Blends the corner coefficients of cell (l, k, j, i) at interpolation weights `w`; the
/// weight of node `me` is returned separately and its coefficients left out, so a sample's
/// coefficients are `rest + w_me · a[me]`.
fn blend_without(
    a: &[[f64; 3]],
    res: usize,
    cell: (usize, usize, usize, usize),
    w: &[f64; 8],
    me: Option<usize>,
) -> ([f64; 3], f64) {
    let (l, k, j, i) = cell;
    let mut rest = [0.0; 3];
    let mut wme = 0.0;
    for (cn, wc) in w.iter().enumerate() {
        let n = node_index(res, l, k + (cn >> 2 & 1), j + (cn >> 1 & 1), i + (cn & 1));
        if Some(n) == me {
            wme = *wc;
        } else {
            for m in 0..3 {
                rest[m] += wc * a[n][m];
            }
        }
    }
    (rest, wme)
}

/// Refines `table` in place for `model`'s colour space. Returns the number of node updates.
pub fn refine_table(
    table: &mut CoeffTable,
    model: &LabModel,
    opt: &RefineOptions,
    progress: &dyn Progress,
    cancel: &AtomicBool,
) -> Result<usize> {
    let res = table.res;
    let scale: Vec<f64> = table.scale.iter().map(|&s| s as f64).collect();
    let n_off = opt.samples_per_axis.clamp(1, 2);
    let offs: Vec<f64> = (0..n_off).map(|m| (m as f64 + 0.5) / n_off as f64).collect();
    let chroma: Vec<f64> = table.chroma.iter().map(|&c| c as f64).collect();
    let grid =
        Grid { res, scale: &scale, scale32: &table.scale, chroma: &chroma, chroma32: &table.chroma, offs };
    let solid = opt.keep_solid.then(|| ObjectSolid::new(model));
    // A colour is in the objective if the table already comes within `give_up` of it (or, with
    // `keep_solid`, if a reflectance in [0, 1] can have it at all; the membership test — 110 k
    // facets — only runs for the former's failures).
    let reachable =
        |rgb: [f64; 3], err: f64| err <= opt.give_up || solid.as_ref().is_some_and(|s| s.margin(rgb) >= 0.0);
    // Work in normalised coefficients (trilinear interpolation commutes with the linear map).
    let mut a: Vec<[f64; 3]> = table
        .data
        .chunks_exact(3)
        .map(|c| nm_to_normalised([c[0] as f64, c[1] as f64, c[2] as f64]))
        .collect();
    let r1 = res - 1;
    let ncell = 3 * r1.pow(3);
    let mut updates = 0;
    progress.stage(None, (opt.sweeps * 9) as u64);
    for _ in 0..opt.sweeps {
        // 1. Probe every cell at its sample points: which points are reachable (a bit mask over
        //    `cell_points`) and whether any reachable one is poor.
        let cells: Vec<(bool, u64)> = (0..ncell)
            .into_par_iter()
            .map(|c| {
                let (i, j, k, l) = (c % r1, c / r1 % r1, c / r1 / r1 % r1, c / r1.pow(3));
                let mut poor = false;
                let mut mask = 0u64;
                for (p, f) in grid.cell_points(k, j, i).into_iter().enumerate() {
                    let (ac, _) = blend_without(&a, res, (l, k, j, i), &weights(grid.wf(k, j, i, f)), None);
                    let rgb = grid.rgb(l, k, j, i, f);
                    let e = lab_err(model, model.target_lab(rgb), ac);
                    if reachable(rgb, e) {
                        mask |= 1 << p;
                        poor |= e > opt.threshold;
                    }
                }
                (poor, mask)
            })
            .collect();
        progress.inc(1);
        if cancel.load(Ordering::Relaxed) {
            return Err(ColorError::Table("refinement interrupted; nothing was written".into()));
        }
        let cell_at = |l: usize, k: usize, j: usize, i: usize| cells[((l * r1 + k) * r1 + j) * r1 + i];
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
                                    any |= cell_at(l, k - dk, j - dj, i - di).0;
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
                    // Samples: (target Lab, weight of this node, the other corners' blend, weight
                    // of the sample in the objective).
                    let mut samples: Vec<([f64; 3], f64, [f64; 3], f64)> = Vec::with_capacity(8 * 8 + 1);
                    let own = crate::upsample::fit::node_rgb(&scale, &chroma, l, k, j, i);
                    let own_lab = model.target_lab(own);
                    // An unreachable node's own colour would pull it back to where Newton gave
                    // up; without it the node serves the reachable colours of its cells.
                    if reachable(own, lab_err(model, own_lab, a[me])) {
                        samples.push((own_lab, 1.0, [0.0; 3], opt.own_weight));
                    }
                    for c in 0..8 {
                        let (di, dj, dk) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
                        if !(i >= di && j >= dj && k >= dk && i - di < r1 && j - dj < r1 && k - dk < r1) {
                            continue;
                        }
                        let (ci, cj, ck) = (i - di, j - dj, k - dk);
                        let mask = cell_at(l, ck, cj, ci).1;
                        for (p, f) in grid.cell_points(ck, cj, ci).into_iter().enumerate() {
                            if mask >> p & 1 == 0 {
                                continue;
                            }
                            let w = weights(grid.wf(ck, cj, ci, f));
                            let (rest, wme) = blend_without(&a, res, (l, ck, cj, ci), &w, Some(me));
                            if wme > 0.0 {
                                samples.push((model.target_lab(grid.rgb(l, ck, cj, ci, f)), wme, rest, 1.0));
                            }
                        }
                    }
                    if samples.is_empty() {
                        return (me, a[me]);
                    }
                    let blend = |x: [f64; 3], s: &([f64; 3], f64, [f64; 3], f64)| {
                        [s.2[0] + s.1 * x[0], s.2[1] + s.1 * x[1], s.2[2] + s.1 * x[2]]
                    };
                    let sigma2 = opt.robust * opt.robust;
                    let loss = |e2: f64| if sigma2.is_finite() { sigma2 * (e2 / sigma2).ln_1p() } else { e2 };
                    let objective = |x: [f64; 3]| {
                        samples
                            .iter()
                            .map(|s| s.3 * loss(lab_err(model, s.0, blend(x, s)).powi(2)))
                            .sum::<f64>()
                    };
                    let mut x = a[me];
                    for _ in 0..opt.steps {
                        let mut h = [[0.0; 3]; 3];
                        let mut g = [0.0; 3];
                        // The objective at x comes with the Jacobian pass (no separate pass).
                        let mut fx = 0.0;
                        for s in &samples {
                            let (lab, jac) = model.lab_jac_pub(blend(x, s));
                            let r = [lab[0] - s.0[0], lab[1] - s.0[1], lab[2] - s.0[2]];
                            let e2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
                            fx += s.3 * loss(e2);
                            // Iteratively reweighted: the loss's slope at e² scales the sample.
                            let om = s.3 * if sigma2.is_finite() { 1.0 / (1.0 + e2 / sigma2) } else { 1.0 };
                            for p in 0..3 {
                                for q in 0..3 {
                                    let mut acc = 0.0;
                                    for row in 0..3 {
                                        acc += jac[row][p] * jac[row][q];
                                    }
                                    h[p][q] += om * s.1 * s.1 * acc;
                                }
                                let mut acc = 0.0;
                                for row in 0..3 {
                                    acc += jac[row][p] * r[row];
                                }
                                g[p] += om * s.1 * acc;
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
                            let own_ok = !opt.own_cap.is_finite() || {
                                let e = lab_err(model, own_lab, cand);
                                e <= opt.own_cap || e <= lab_err(model, own_lab, x)
                            };
                            if fc < fx && own_ok {
                                x = cand;
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
