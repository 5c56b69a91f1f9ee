//! Spectral quadrature: how a renderer turns N reflectance values at its wavelength nodes into
//! tristimulus values under a light, without the light's lines aliasing.
//!
//! A renderer evaluates the reflectance ρ at N nodes λᵢ and needs
//! `XYZ = ∫ ρ(λ)·E(λ)·x̄(λ) dλ` for each light E. Two rules are offered:
//!
//! - [`Quadrature::Midpoint`] (the paper's): `XYZ ≈ Σᵢ ρ(λᵢ)·E(λᵢ)·x̄(λᵢ)·Δλ`. The light and
//!   the observer are *point sampled*, so a line spectrum (F11's mercury lines, an LED peak)
//!   counts fully when a node lands on it and not at all when it falls between nodes: the
//!   result jumps with N.
//! - [`Quadrature::Prefiltered`]: ρ is smooth (a sigmoid of a quadratic), so it is represented
//!   by its interpolant through the nodes, ρ(λ) ≈ Σᵢ ρ(λᵢ)·φᵢ(λ), and everything known in
//!   advance is integrated densely against the cardinal functions φᵢ:
//!   `Wᵢ = ∫ φᵢ(λ)·E(λ)·x̄(λ) dλ`, so that `XYZ = Σᵢ ρ(λᵢ)·Wᵢ` exactly for any ρ in the
//!   interpolation space. Every line of E is counted once, whatever N is; the error left is the
//!   interpolation error of the smooth ρ. The per-node cost on the GPU is the same as the
//!   midpoint rule's (one weight per node and channel), only the weights differ.
//!
//! The basis is the cubic Catmull–Rom interpolant on the equally spaced nodes (local: four
//! nodes per wavelength; reproduces quadratics; the cardinals sum to one, so a constant
//! spectrum — and therefore the white, and every term that does not depend on ρ — is integrated
//! exactly). Why not linear or a global spline: `cargo run --release -p color --example
//! quadrature_study` measures midpoint, linear, Catmull–Rom and a not-a-knot cubic spline on
//! random upsampled reflectances under spiky and smooth lights; docs/quadrature.md has the table.

use crate::error::{ColorError, Result};
use crate::observer::Observer;
use crate::wavelengths::WavelengthRange;

/// Spacing (nm) of the dense grid the prefiltered weights are integrated on. Measured spectra
/// are piecewise linear at 1 or 5 nm; a 0.25 nm midpoint rule integrates their products with
/// the cubic cardinals to well below 1e-5 relative.
pub const DENSE_STEP_NM: f64 = 0.25;

/// Node count from which Catmull–Rom's ghost nodes are extrapolated quadratically.
const QUADRATIC_GHOSTS_FROM: usize = 6;

/// How node values are integrated; see the module documentation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Quadrature {
    /// Point sampling of light × observer at the nodes (the paper's midpoint Riemann sum).
    Midpoint,
    /// Light × observer integrated densely against the cardinal functions of the Catmull–Rom
    /// interpolant through the nodes.
    #[default]
    Prefiltered,
}

impl Quadrature {
    pub const NAMES: &'static [&'static str] = &["midpoint", "prefiltered"];
    pub const ALL: [Quadrature; 2] = [Quadrature::Midpoint, Quadrature::Prefiltered];

    pub fn parse(s: &str) -> Result<Self> {
        match s.to_ascii_lowercase().as_str() {
            "midpoint" | "point" => Ok(Quadrature::Midpoint),
            "prefiltered" | "prefilter" => Ok(Quadrature::Prefiltered),
            _ => {
                Err(ColorError::Unknown { kind: "quadrature", name: s.into(), known: Self::NAMES.join(", ") })
            }
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Quadrature::Midpoint => "midpoint",
            Quadrature::Prefiltered => "prefiltered",
        }
    }
}

impl std::fmt::Display for Quadrature {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// An interpolation of node values, as the linear map from N node values to a value at λ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Basis {
    /// Piecewise linear (hat cardinals), extrapolated linearly beyond the end nodes.
    Linear,
    /// Uniform Catmull–Rom cubic with quadratically extrapolated ghost nodes.
    CatmullRom,
    /// Global not-a-knot cubic spline (N ≥ 4; fewer nodes fall back to Catmull–Rom).
    Spline,
}

/// N equally spaced nodes `λᵢ = min + (i + u)·Δ`, Δ = width / N, u ∈ [0, 1) (u = ½ puts them at
/// the bin centres, as the midpoint rule does; other u shift the whole grid, for jitter).
#[derive(Clone, Debug, PartialEq)]
pub struct Nodes {
    pub range: WavelengthRange,
    pub offset: f64,
    pub lambda: Vec<f64>,
    pub spacing: f64,
}

impl Nodes {
    pub fn new(range: WavelengthRange, n: usize, offset: f64) -> Result<Self> {
        if n == 0 {
            return Err(ColorError::NoSamples);
        }
        if !(0.0..1.0).contains(&offset) {
            return Err(ColorError::BadSpectrum(format!("node offset must be in [0, 1), got {offset}")));
        }
        let spacing = range.width() / n as f64;
        let lambda = (0..n).map(|i| range.min + (i as f64 + offset) * spacing).collect();
        Ok(Nodes { range, offset, lambda, spacing })
    }

    pub fn len(&self) -> usize {
        self.lambda.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lambda.is_empty()
    }

    /// The dense midpoint grid over the range that prefiltered weights are integrated on.
    pub fn dense_grid(&self) -> (Vec<f64>, f64) {
        let m = (self.range.width() / DENSE_STEP_NM).ceil().max(1.0) as usize;
        let d = self.range.width() / m as f64;
        ((0..m).map(|k| self.range.min + (k as f64 + 0.5) * d).collect(), d)
    }

    /// The nonzero cardinal values φᵢ(λ) of `basis` at λ, as (i, φᵢ) pairs, appended to `out`.
    pub fn cardinals(&self, basis: Basis, lambda: f64, out: &mut Vec<(usize, f64)>) {
        let n = self.len();
        if n == 1 {
            out.push((0, 1.0));
            return;
        }
        // Position in node units and the segment [j, j + 1] it belongs to (the end segments
        // are extended beyond the end nodes).
        let x = (lambda - self.lambda[0]) / self.spacing;
        let j = (x.floor().max(0.0) as usize).min(n - 2);
        let t = x - j as f64;
        match basis {
            Basis::Linear => {
                out.push((j, 1.0 - t));
                out.push((j + 1, t));
            }
            Basis::CatmullRom | Basis::Spline => {
                // Catmull–Rom on p[j−1..=j+2]; a missing end node is extrapolated, quadratically
                // (3·p[0] − 3·p[1] + p[2]) from six nodes on, so that quadratics stay exact up to
                // the range ends, else linearly (a parabola through nodes 60–90 nm apart
                // overshoots: N = 4 loses 0.3 ΔE in the quadrature study); the ghost's weight is
                // spread over the nodes it is made of.
                let ghost: &[(usize, f64)] = if n >= QUADRATIC_GHOSTS_FROM {
                    &[(0, 3.0), (1, -3.0), (2, 1.0)]
                } else {
                    &[(0, 2.0), (1, -1.0)]
                };
                let t2 = t * t;
                let t3 = t2 * t;
                let w = [
                    0.5 * (-t3 + 2.0 * t2 - t),
                    0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
                    0.5 * (-3.0 * t3 + 4.0 * t2 + t),
                    0.5 * (t3 - t2),
                ];
                let mut add = |i: isize, v: f64| {
                    if i < 0 {
                        out.extend(ghost.iter().map(|&(k, g)| (k, g * v)));
                    } else if i as usize >= n {
                        out.extend(ghost.iter().map(|&(k, g)| (n - 1 - k, g * v)));
                    } else {
                        out.push((i as usize, v));
                    }
                };
                for (k, &wk) in w.iter().enumerate() {
                    add(j as isize - 1 + k as isize, wk);
                }
            }
        }
    }

    /// The dense matrix Φ[k][i] = φᵢ(μₖ) of `basis` on `grid`.
    pub fn cardinal_matrix(&self, basis: Basis, grid: &[f64]) -> Vec<Vec<f64>> {
        let n = self.len();
        if basis == Basis::Spline && n >= 4 {
            return spline_cardinals(&self.lambda, grid);
        }
        let mut row = Vec::with_capacity(8);
        grid.iter()
            .map(|&l| {
                row.clear();
                self.cardinals(basis, l, &mut row);
                let mut dense = vec![0.0; n];
                for &(i, v) in &row {
                    dense[i] += v;
                }
                dense
            })
            .collect()
    }
}

/// Cardinal functions of the not-a-knot cubic spline through `nodes`, on `grid`: column i is the
/// spline through the unit vector eᵢ (solved densely: N ≤ 256, done once per setting).
fn spline_cardinals(nodes: &[f64], grid: &[f64]) -> Vec<Vec<f64>> {
    let n = nodes.len();
    let mut out = vec![vec![0.0; n]; grid.len()];
    for i in 0..n {
        let mut y = vec![0.0; n];
        y[i] = 1.0;
        let m = not_a_knot_second_derivatives(nodes, &y);
        for (k, &l) in grid.iter().enumerate() {
            out[k][i] = eval_spline(nodes, &y, &m, l);
        }
    }
    out
}

/// Second derivatives of the not-a-knot cubic spline through (x, y) (dense Gaussian
/// elimination on the N×N system; fine for the sizes here).
fn not_a_knot_second_derivatives(x: &[f64], y: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mut a = vec![vec![0.0; n + 1]; n];
    let h: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    // Not-a-knot: the third derivative is continuous at x[1] and x[n−2].
    a[0][0] = h[1];
    a[0][1] = -(h[0] + h[1]);
    a[0][2] = h[0];
    for i in 1..n - 1 {
        a[i][i - 1] = h[i - 1];
        a[i][i] = 2.0 * (h[i - 1] + h[i]);
        a[i][i + 1] = h[i];
        a[i][n] = 6.0 * ((y[i + 1] - y[i]) / h[i] - (y[i] - y[i - 1]) / h[i - 1]);
    }
    a[n - 1][n - 3] = h[n - 2];
    a[n - 1][n - 2] = -(h[n - 3] + h[n - 2]);
    a[n - 1][n - 1] = h[n - 3];
    for c in 0..n {
        let p = (c..n).max_by(|&r, &s| a[r][c].abs().total_cmp(&a[s][c].abs())).unwrap_or(c);
        a.swap(c, p);
        let d = a[c][c];
        if d.abs() < 1e-300 {
            continue;
        }
        let pivot = a[c].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != c && row[c] != 0.0 {
                let f = row[c] / d;
                row.iter_mut().zip(&pivot).skip(c).for_each(|(v, p)| *v -= f * p);
            }
        }
    }
    (0..n).map(|i| if a[i][i] != 0.0 { a[i][n] / a[i][i] } else { 0.0 }).collect()
}

fn eval_spline(x: &[f64], y: &[f64], m: &[f64], l: f64) -> f64 {
    let n = x.len();
    let j = x.partition_point(|&v| v <= l).clamp(1, n - 1) - 1;
    let h = x[j + 1] - x[j];
    let a = (x[j + 1] - l) / h;
    let b = (l - x[j]) / h;
    a * y[j] + b * y[j + 1] + ((a * a * a - a) * m[j] + (b * b * b - b) * m[j + 1]) * h * h / 6.0
}

/// Node weights for one rule, range, node grid and observer: for an emission spectrum E,
/// `weights(E)[i][c]` is what node i's reflectance is multiplied by to give channel c, so that
/// `XYZ = Σᵢ ρᵢ·Wᵢ` ([`integrate_nodes`]). Unnormalised: the caller divides by the white's Y.
#[derive(Clone, Debug)]
pub struct NodeQuadrature {
    pub rule: Quadrature,
    pub nodes: Nodes,
    /// Midpoint: the observer at the nodes × Δ. Prefiltered: the observer at the dense grid × δ.
    observer_dense: Vec<[f64; 3]>,
    grid: Vec<f64>,
    /// Prefiltered: for each dense point, its nonzero cardinals.
    cardinals: Vec<Vec<(usize, f64)>>,
}

impl NodeQuadrature {
    /// The renderer's quadrature: Catmull–Rom cardinals for the prefiltered rule.
    pub fn new(rule: Quadrature, nodes: Nodes, observer: &Observer) -> Self {
        Self::with_basis(rule, nodes, observer, Basis::CatmullRom)
    }

    /// Any basis, for studies; the renderer uses [`Self::new`].
    pub fn with_basis(rule: Quadrature, nodes: Nodes, observer: &Observer, basis: Basis) -> Self {
        match rule {
            Quadrature::Midpoint => {
                let d = nodes.spacing;
                let observer_dense = nodes.lambda.iter().map(|&l| observer.eval(l).map(|c| c * d)).collect();
                NodeQuadrature {
                    rule,
                    grid: nodes.lambda.clone(),
                    nodes,
                    observer_dense,
                    cardinals: Vec::new(),
                }
            }
            Quadrature::Prefiltered => {
                let (grid, d) = nodes.dense_grid();
                let observer_dense = grid.iter().map(|&l| observer.eval(l).map(|c| c * d)).collect();
                let cardinals = if basis == Basis::Spline && nodes.len() >= 4 {
                    nodes
                        .cardinal_matrix(basis, &grid)
                        .into_iter()
                        .map(|row| row.into_iter().enumerate().filter(|(_, v)| *v != 0.0).collect())
                        .collect()
                } else {
                    grid.iter()
                        .map(|&l| {
                            let mut row = Vec::with_capacity(8);
                            nodes.cardinals(basis, l, &mut row);
                            row
                        })
                        .collect()
                };
                NodeQuadrature { rule, nodes, observer_dense, grid, cardinals }
            }
        }
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The node weights Wᵢ of an emission spectrum E (unnormalised).
    pub fn weights(&self, emission: impl Fn(f64) -> f64) -> Vec<[f64; 3]> {
        let mut w = vec![[0.0; 3]; self.len()];
        match self.rule {
            Quadrature::Midpoint => {
                for ((wi, &l), o) in w.iter_mut().zip(&self.grid).zip(&self.observer_dense) {
                    let e = emission(l);
                    *wi = o.map(|c| c * e);
                }
            }
            Quadrature::Prefiltered => {
                for ((&l, o), row) in self.grid.iter().zip(&self.observer_dense).zip(&self.cardinals) {
                    let e = emission(l);
                    if e == 0.0 {
                        continue;
                    }
                    let f = o.map(|c| c * e);
                    for &(i, phi) in row {
                        for c in 0..3 {
                            w[i][c] += phi * f[c];
                        }
                    }
                }
            }
        }
        w
    }

    /// ∫ E(λ)·x̄(λ) dλ as this rule sees it (the weights of a constant reflectance 1).
    pub fn total(&self, emission: impl Fn(f64) -> f64) -> [f64; 3] {
        sum_weights(&self.weights(emission))
    }
}

/// XYZ = Σᵢ ρᵢ·Wᵢ.
pub fn integrate_nodes(weights: &[[f64; 3]], node_values: &[f64]) -> [f64; 3] {
    debug_assert_eq!(weights.len(), node_values.len());
    let mut xyz = [0.0; 3];
    for (w, v) in weights.iter().zip(node_values) {
        for c in 0..3 {
            xyz[c] += v * w[c];
        }
    }
    xyz
}

/// Σᵢ Wᵢ: the integral of the light itself (a reflectance of one).
pub fn sum_weights(weights: &[[f64; 3]]) -> [f64; 3] {
    weights.iter().fold([0.0; 3], |acc, w| [acc[0] + w[0], acc[1] + w[1], acc[2] + w[2]])
}

/// Dense reference: `∫ ρ(λ)·E(λ)·x̄(λ) dλ` on the same 0.25 nm grid the prefiltered weights use.
pub fn dense_integral(range: WavelengthRange, observer: &Observer, f: impl Fn(f64) -> f64) -> [f64; 3] {
    let m = (range.width() / DENSE_STEP_NM).ceil().max(1.0) as usize;
    let d = range.width() / m as f64;
    let mut xyz = [0.0; 3];
    for k in 0..m {
        let l = range.min + (k as f64 + 0.5) * d;
        let v = f(l);
        if v == 0.0 {
            continue;
        }
        let o = observer.eval(l);
        for c in 0..3 {
            xyz[c] += v * o[c] * d;
        }
    }
    xyz
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::illuminant;

    fn visible_nodes(n: usize) -> Nodes {
        Nodes::new(WavelengthRange::VISIBLE, n, 0.5).unwrap()
    }

    #[test]
    fn cardinals_sum_to_one_and_interpolate_nodes() {
        for basis in [Basis::Linear, Basis::CatmullRom, Basis::Spline] {
            for n in [1, 2, 3, 4, 7, 16] {
                let nodes = visible_nodes(n);
                let (grid, _) = nodes.dense_grid();
                let phi = nodes.cardinal_matrix(basis, &grid);
                for row in &phi {
                    let s: f64 = row.iter().sum();
                    assert!((s - 1.0).abs() < 1e-9, "{basis:?} N={n}: Σφ = {s}");
                }
                let at_nodes = nodes.cardinal_matrix(basis, &nodes.lambda);
                for (i, row) in at_nodes.iter().enumerate() {
                    for (j, v) in row.iter().enumerate() {
                        let want = if i == j { 1.0 } else { 0.0 };
                        assert!((v - want).abs() < 1e-9, "{basis:?} N={n}: φ{j}(λ{i}) = {v}");
                    }
                }
            }
        }
    }

    #[test]
    fn catmull_rom_reproduces_quadratics_and_spline_cubics() {
        let nodes = visible_nodes(9);
        let q = |l: f64| 0.3 + 1e-3 * (l - 500.0) - 2e-6 * (l - 500.0).powi(2);
        let c = |l: f64| q(l) + 3e-9 * (l - 450.0).powi(3);
        let (grid, _) = nodes.dense_grid();
        for (basis, f, tol) in
            [(Basis::CatmullRom, &q as &dyn Fn(f64) -> f64, 1e-9), (Basis::Spline, &c, 1e-9)]
        {
            let vals: Vec<f64> = nodes.lambda.iter().map(|&l| f(l)).collect();
            for (row, &l) in nodes.cardinal_matrix(basis, &grid).iter().zip(&grid) {
                let v: f64 = row.iter().zip(&vals).map(|(p, y)| p * y).sum();
                assert!((v - f(l)).abs() < tol, "{basis:?} at {l}: {v} vs {}", f(l));
            }
        }
    }

    #[test]
    fn prefiltered_integrates_a_constant_exactly_and_counts_every_line() {
        let obs = Observer::cie1931();
        let f11 = illuminant::by_name("F11").unwrap();
        let r = WavelengthRange::VISIBLE;
        let want = dense_integral(r, &obs, |l| f11.eval(l));
        for n in [1, 3, 4, 8, 12, 16, 18, 32, 64] {
            let q = NodeQuadrature::new(Quadrature::Prefiltered, visible_nodes(n), &obs);
            let got = q.total(|l| f11.eval(l));
            for c in 0..3 {
                assert!((got[c] - want[c]).abs() < 1e-9 * want[1], "N={n} channel {c}: {got:?} vs {want:?}");
            }
        }
        // The midpoint rule's white under F11 swings with N: that is the aliasing.
        let mid: Vec<f64> = [8, 16, 18]
            .iter()
            .map(|&n| {
                NodeQuadrature::new(Quadrature::Midpoint, visible_nodes(n), &obs).total(|l| f11.eval(l))[1]
            })
            .collect();
        let spread = mid.iter().fold(0.0f64, |m, v| m.max((v / want[1] - 1.0).abs()));
        assert!(spread > 0.05, "midpoint totals {mid:?} vs {}", want[1]);
    }

    #[test]
    fn midpoint_weights_are_point_samples() {
        let obs = Observer::cie1931();
        let nodes = visible_nodes(5);
        let q = NodeQuadrature::new(Quadrature::Midpoint, nodes.clone(), &obs);
        let w = q.weights(|l| l / 100.0);
        for (wi, &l) in w.iter().zip(&nodes.lambda) {
            let o = obs.eval(l);
            for c in 0..3 {
                assert!((wi[c] - o[c] * l / 100.0 * 70.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn parse_names() {
        assert_eq!(Quadrature::parse("Midpoint").unwrap(), Quadrature::Midpoint);
        assert_eq!(Quadrature::parse("prefiltered").unwrap(), Quadrature::Prefiltered);
        assert!(Quadrature::parse("gauss").unwrap_err().to_string().contains("gauss"));
        assert!(Nodes::new(WavelengthRange::VISIBLE, 0, 0.5).is_err());
        assert!(Nodes::new(WavelengthRange::VISIBLE, 4, 1.0).is_err());
    }
}
