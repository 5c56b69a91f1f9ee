//! `KHR_materials_sheen`: a layer of fibres (velvet, cloth) over the whole material. This module
//! is the extension's math in one place; both renderers will call it (the path tracer directly,
//! the real-time renderer with [`albedo_table`] uploaded as a texture and the formulas below
//! ported to its shader), so that the two draw the same sheen.
//!
//! f = sheenColor·f_sheen + f_base·s,  f_sheen = D(n·h)·V(n·l, n·v),
//! s = min(1 − max3(sheenColor)·E(n·v), 1 − max3(sheenColor)·E(n·l))   (clamped to [0, 1]),
//!
//! with, as the ratified extension writes them (Conty Estevez & Kulla 2017, "Charlie"):
//!
//! - D(n·h) = (2 + 1/α)·(sin²θ_h)^(1/(2α)) / (2π), α = sheenRoughness² (the ratified text's
//!   `alphaG = sheenRoughness * sheenRoughness`, "the mapping r = sheenRoughness^2"; the
//!   experimental draft used sheenRoughness unsquared). D is normalised, ∫D·(n·h) dω_h = 1.
//! - V = 1 / ((1 + Λ(n·v) + Λ(n·l))·4·(n·v)·(n·l)), with the fitted
//!   Λ(x) = exp(l(x)) for x < 0.5, exp(2·l(0.5) − l(1 − x)) otherwise,
//!   l(x) = a/(1 + b·x^c) + d·x + e, each coefficient mix(at α = 1, at α = 0, (1 − α)²).
//!   V is not clamped to 1 (some implementations do; the extension does not).
//! - E(μ) = ∫ D·V·(n·l) dω_l over the hemisphere, at n·v = μ: the sheen's directional albedo
//!   with a white colour, which the base loses (albedo scaling).
//!
//! The lobe's α is raised to [`MIN_ALPHA`] = 0.07 (sheenRoughness to [`MIN_ROUGHNESS`] = √0.07
//! ≈ 0.265) in every function here and in the table, so that both renderers draw the same
//! lobe: D is a delta at α = 0, and just below α = 0.07 the fitted Λ starts letting E exceed 1
//! at grazing views (1.03 at α = 0.06, 2.9 at α = 0.0049, which a clamp of sheenRoughness at
//! 0.07 would allow), which no albedo scaling can pay for. The extension's default roughness, 0, draws as 0.265.
//! With the clamp E < 0.99 for n·v ≥ 10⁻⁵ (0.988 the table's largest value); closer to grazing
//! it grows without bound (Λ(0) is finite, so V·n·l ~ 1/n·v), over a range of view directions
//! no renderer resolves.
//!
//! E comes from a table ([`albedo_table`], 64 √μ × 32 roughness nodes): each value the integral
//! by Gauss–Legendre quadrature in f64, within 4·10⁻⁶ of twice the points and 10⁻⁵ of an
//! independent midpoint rule and Monte Carlo estimate (the tests), built in ≈ 20 ms; looked up
//! bilinearly ([`albedo`]), within 6·10⁻³ of the integral from the first column on (the tests
//! measure 5.1·10⁻³, at the smallest roughness and n·v ≈ 5·10⁻⁴).
//! With it, a white sheen over a white Lambertian base reflects at most 1 at the table's
//! nodes and 1.0036 between them.

use std::f64::consts::PI;
use std::sync::OnceLock;

use crate::TextureRef;
use glam::Vec3;

/// A material's sheen, as the extension gives it; the values at a point are the factors times
/// the textures' channels ([`Sheen::color_at`], [`Sheen::roughness_at`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Sheen {
    /// `sheenColorFactor`, linear RGB in [0, 1]; zero turns the whole layer off.
    pub color: Vec3,
    /// `sheenColorTexture` (sRGB): its RGB multiplies `color`.
    pub color_texture: Option<TextureRef>,
    /// `sheenRoughnessFactor` in [0, 1] (perceptual: α = roughness², at least
    /// [`MIN_ROUGHNESS`]² where the lobe is drawn).
    pub roughness: f32,
    /// `sheenRoughnessTexture`: its A channel multiplies `roughness`.
    pub roughness_texture: Option<TextureRef>,
}

impl Sheen {
    /// The sheen colour at a point whose `sheenColorTexture` reads `rgb` (linear).
    pub fn color_at(&self, rgb: Option<Vec3>) -> Vec3 {
        self.color * rgb.unwrap_or(Vec3::ONE)
    }

    /// The sheen roughness at a point whose `sheenRoughnessTexture` reads `a` (A channel, 0–1),
    /// as the extension defines it; the functions here raise it to [`MIN_ROUGHNESS`].
    pub fn roughness_at(&self, a: Option<f32>) -> f32 {
        (self.roughness * a.unwrap_or(1.0)).clamp(0.0, 1.0)
    }

    /// Whether the layer is off: the extension disables it when `sheenColorFactor` is zero,
    /// whatever the texture holds.
    pub fn is_off(&self) -> bool {
        self.color == Vec3::ZERO
    }
}

/// Smallest α drawn. The Charlie lobe with the fitted Λ reflects more than it receives at
/// grazing views below it (E(μ) peaks at 1.03 for α = 0.06, 1.19 for 0.04, 2.9 for 0.0049, at
/// μ ≈ 0.001–0.003; 0.984 for 0.07), so sharper sheens draw as this one, in every function here
/// and in the table.
pub const MIN_ALPHA: f64 = 0.07;

/// The sheen roughness of [`MIN_ALPHA`], √0.07: lower values, the extension's default 0
/// included, draw as this one.
pub const MIN_ROUGHNESS: f64 = 0.264_575_131_106_459_1;

/// The roughness the lobe is drawn with: `roughness` raised to [`MIN_ROUGHNESS`] and capped
/// at 1 (NaN gives the minimum, so that a bad texel draws something finite).
pub fn clamp_roughness(roughness: f64) -> f64 {
    clamp_to_one(roughness, MIN_ROUGHNESS)
}

/// `x` clamped to [lo, 1], NaN to lo.
fn clamp_to_one(x: f64, lo: f64) -> f64 {
    if x.is_nan() { lo } else { x.clamp(lo, 1.0) }
}

/// α = roughness², the ratified extension's mapping, raised to [`MIN_ALPHA`].
pub fn alpha_g(roughness: f64) -> f64 {
    let r = clamp_to_one(roughness, 0.0);
    (r * r).max(MIN_ALPHA)
}

/// The Charlie distribution D at `n_dot_h`, for the sheen roughness `roughness`.
pub fn charlie_d(roughness: f64, n_dot_h: f64) -> f64 {
    d_alpha(alpha_g(roughness), n_dot_h)
}

fn d_alpha(alpha: f64, n_dot_h: f64) -> f64 {
    let sin2 = (1.0 - n_dot_h * n_dot_h).max(0.0);
    let inv = 1.0 / alpha;
    (2.0 + inv) * sin2.powf(0.5 * inv) / (2.0 * PI)
}

/// Conty & Kulla's fitted l(x) at α, coefficients mixed by (1 − α)² between their α = 1 and
/// α = 0 fits, as the extension writes it.
fn l_fit(x: f64, alpha: f64) -> f64 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |at_one: f64, at_zero: f64| at_one * (1.0 - t) + at_zero * t;
    let a = mix(21.5473, 25.3245);
    let b = mix(3.82987, 3.32435);
    let c = mix(0.19823, 0.16801);
    let d = mix(-1.97760, -1.27393);
    let e = mix(-4.32054, -4.85967);
    a / (1.0 + b * x.powf(c)) + d * x + e
}

fn lambda_alpha(cos: f64, alpha: f64) -> f64 {
    // Directions below the horizon have no sheen; clamping keeps x^c real there.
    let x = clamp_to_one(cos, 0.0);
    if x < 0.5 { l_fit(x, alpha).exp() } else { (2.0 * l_fit(0.5, alpha) - l_fit(1.0 - x, alpha)).exp() }
}

/// The Charlie Λ at `cos` = n·ω (clamped to [0, 1]) for the sheen roughness `roughness`.
pub fn charlie_lambda(cos: f64, roughness: f64) -> f64 {
    lambda_alpha(cos, alpha_g(roughness))
}

/// The Charlie visibility V = G / (4·n·l·n·v); 0 when either direction is at or below the
/// horizon, where V·n·l would tend to 1/(4·n·v·(1 + Λ(n·v) + Λ(0))), Λ(0) > 3·10⁷.
pub fn visibility(n_dot_l: f64, n_dot_v: f64, roughness: f64) -> f64 {
    v_alpha(n_dot_l, n_dot_v, alpha_g(roughness))
}

fn v_alpha(n_dot_l: f64, n_dot_v: f64, alpha: f64) -> f64 {
    if n_dot_l <= 0.0 || n_dot_v <= 0.0 {
        return 0.0;
    }
    // Sums and products grouped so that swapping l and v gives the same bits.
    let lambdas = lambda_alpha(n_dot_v, alpha) + lambda_alpha(n_dot_l, alpha);
    1.0 / ((1.0 + lambdas) * (4.0 * (n_dot_v * n_dot_l)))
}

/// The sheen BRDF with a white colour, D·V (the extension's Fresnel is 1); times sheenColor it
/// is f_sheen.
pub fn brdf(n_dot_l: f64, n_dot_v: f64, n_dot_h: f64, roughness: f64) -> f64 {
    let alpha = alpha_g(roughness);
    d_alpha(alpha, n_dot_h) * v_alpha(n_dot_l, n_dot_v, alpha)
}

/// [`brdf`] in f32 (computed in f64 and rounded, so that it agrees with the f64 one).
pub fn brdf_f32(n_dot_l: f32, n_dot_v: f32, n_dot_h: f32, roughness: f32) -> f32 {
    brdf(n_dot_l.into(), n_dot_v.into(), n_dot_h.into(), roughness.into()) as f32
}

/// The base layer's share s = min(1 − c·E(n·v), 1 − c·E(n·l)) in [0, 1], with `max_color` =
/// c = max3(sheenColor) and `e_v`, `e_l` the sheen's albedos ([`albedo`]) at n·v and n·l. A
/// zero colour gives exactly 1.
pub fn albedo_scaling(max_color: f64, e_v: f64, e_l: f64) -> f64 {
    (1.0 - max_color * e_v).min(1.0 - max_color * e_l).clamp(0.0, 1.0)
}

/// [`albedo_scaling`] in f32.
pub fn albedo_scaling_f32(max_color: f32, e_v: f32, e_l: f32) -> f32 {
    (1.0 - max_color * e_v).min(1.0 - max_color * e_l).clamp(0.0, 1.0)
}

/// The sheen's directional albedo E(μ) at `mu` = n·v for the sheen roughness `roughness`: the
/// bilinear lookup in [`albedo_table`] (its doc says how).
pub fn albedo(mu: f64, roughness: f64) -> f64 {
    albedo_table().lookup(mu, roughness)
}

/// [`albedo`] in f32.
pub fn albedo_f32(mu: f32, roughness: f32) -> f32 {
    albedo(mu.into(), roughness.into()) as f32
}

/// E(μ) by quadrature, without the table: what each table entry holds, at any point (about
/// 2000 evaluations of the lobe; for checks, not for shading).
pub fn albedo_integral(mu: f64, roughness: f64) -> f64 {
    let q = Quadrature::new(QUAD_U, QUAD_PHI);
    let alpha = alpha_g(roughness);
    let mu = clamp_to_one(mu, 0.0);
    let mut ln_sin2 = vec![0.0; q.u.len() * q.phi.len()];
    fill_ln_sin2(mu, &q, &mut ln_sin2);
    let lambda_u: Vec<f64> = q.u.iter().map(|&(u, _)| lambda_alpha(u, alpha)).collect();
    integrate(mu, alpha, &q, &ln_sin2, &lambda_u)
}

/// Columns of the table, along s = √μ.
pub const TABLE_MU: usize = 64;
/// Rows of the table, along the sheen roughness from [`MIN_ROUGHNESS`] to 1.
pub const TABLE_ROUGHNESS: usize = 32;

/// E(μ, roughness) on a grid of nodes, stored row-major with μ fastest: `values[j·n_mu + i]` is
/// E at μ_i = s_i², s_i = (i + 1)/n_mu, and roughness r_j = r₀ + (1 − r₀)·j/(n_roughness − 1),
/// r₀ = [`MIN_ROUGHNESS`]. The μ axis is √μ because the sheen lives at grazing views, where E
/// changes fastest (the first column is μ = 2.4·10⁻⁴, the last μ = 1); the roughness axis
/// ends on the clamp and on 1 so that both are nodes.
///
/// As a texture (width n_mu, height n_roughness, texel (i, j) = `values[j·n_mu + i]`), with a
/// linear filter and clamp-to-edge addressing, it is sampled at
/// u = √(n·v) − 0.5/n_mu and v = (x·(n_roughness − 1) + 0.5)/n_roughness,
/// x = ([`clamp_roughness`]\(sheenRoughness) − r₀)/(1 − r₀), which is exactly
/// [`AlbedoTable::lookup`] (up to the sampler's filter precision). Below the first column the
/// lookup holds E(2.4·10⁻⁴), above the true E there but for the roughness interpolation's
/// error (E dips toward μ ≈ 10⁻⁴ before it rises again below 10⁻⁵).
#[derive(Clone, Debug, PartialEq)]
pub struct AlbedoTable {
    n_mu: usize,
    n_roughness: usize,
    values: Vec<f64>,
}

impl AlbedoTable {
    /// Columns, along s = √μ (the texture's width).
    pub fn n_mu(&self) -> usize {
        self.n_mu
    }

    /// Rows, along roughness (the texture's height).
    pub fn n_roughness(&self) -> usize {
        self.n_roughness
    }

    /// μ at column `i`: ((i + 1)/n_mu)².
    pub fn mu(&self, i: usize) -> f64 {
        column_mu(i, self.n_mu)
    }

    /// The roughness at row `j`: from [`MIN_ROUGHNESS`] at row 0 to 1 at the last.
    pub fn roughness(&self, j: usize) -> f64 {
        row_roughness(j, self.n_roughness)
    }

    /// Every value, row-major with μ fastest.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// [`AlbedoTable::values`] rounded to f32, for an upload.
    pub fn values_f32(&self) -> Vec<f32> {
        self.values.iter().map(|&v| v as f32).collect()
    }

    /// E at column `i` (μ), row `j` (roughness).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.values[j * self.n_mu + i]
    }

    /// Bilinear interpolation between the nodes in (√μ, clamped roughness), clamped to the
    /// outer ones, as a texture sampler's linear filter with clamp-to-edge.
    pub fn lookup(&self, mu: f64, roughness: f64) -> f64 {
        let (i0, i1, s) = cell(clamp_to_one(mu, 0.0).sqrt() * self.n_mu as f64 - 1.0, self.n_mu);
        let x = (clamp_roughness(roughness) - MIN_ROUGHNESS) / (1.0 - MIN_ROUGHNESS);
        let (j0, j1, t) = cell(x * (self.n_roughness - 1) as f64, self.n_roughness);
        let row = |j| self.get(i0, j) * (1.0 - s) + self.get(i1, j) * s;
        row(j0) * (1.0 - t) + row(j1) * t
    }
}

fn column_mu(i: usize, n: usize) -> f64 {
    let s = (i + 1) as f64 / n as f64;
    s * s
}

fn row_roughness(j: usize, n: usize) -> f64 {
    if j + 1 == n { 1.0 } else { MIN_ROUGHNESS + (1.0 - MIN_ROUGHNESS) * j as f64 / (n - 1) as f64 }
}

/// The two nodes around the fractional index `p` on `n` nodes (clamped to them) and the weight
/// of the second.
fn cell(p: f64, n: usize) -> (usize, usize, f64) {
    let p = p.max(0.0).min((n - 1) as f64);
    let i0 = (p.floor() as usize).min(n - 1);
    let i1 = (i0 + 1).min(n - 1);
    (i0, i1, p - i0 as f64)
}

/// The albedo table, built on first use (a few milliseconds).
pub fn albedo_table() -> &'static AlbedoTable {
    static TABLE: OnceLock<AlbedoTable> = OnceLock::new();
    TABLE.get_or_init(|| build_table(TABLE_MU, TABLE_ROUGHNESS, &Quadrature::new(QUAD_U, QUAD_PHI)))
}

/// Gauss–Legendre points per panel of n·l, and over the azimuth: within 3·10⁻⁶ of twice as
/// many everywhere on the table (a test checks 10⁻⁵).
const QUAD_U: usize = 16;
const QUAD_PHI: usize = 32;

/// Where the n·l axis is split: Λ changes formula at 0.5 (its second derivative jumps there),
/// and x^c (c ≈ 0.2) is steep near grazing, so the panels narrow toward 0.
const U_PANELS: [f64; 5] = [0.0, 0.01, 0.1, 0.5, 1.0];

/// Nodes and weights of E's quadrature over the hemisphere, in (u = n·l, φ): dω = du dφ.
struct Quadrature {
    /// (u, weight) over [0, 1].
    u: Vec<(f64, f64)>,
    /// (cos φ, weight) over [0, π], weights doubled for the mirror half (the integrand is even
    /// in φ about the plane of n and v).
    phi: Vec<(f64, f64)>,
}

impl Quadrature {
    fn new(per_panel: usize, n_phi: usize) -> Self {
        let g = gauss_legendre(per_panel);
        let mut u = Vec::with_capacity(per_panel * (U_PANELS.len() - 1));
        for w in U_PANELS.windows(2) {
            let (lo, hi) = (w[0], w[1]);
            u.extend(g.iter().map(|&(x, wt)| (lo + (hi - lo) * 0.5 * (x + 1.0), (hi - lo) * 0.5 * wt)));
        }
        let phi = gauss_legendre(n_phi)
            .into_iter()
            .map(|(x, wt)| ((PI * 0.5 * (x + 1.0)).cos(), PI * wt))
            .collect();
        Quadrature { u, phi }
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1] (n ≥ 1), by Newton's iteration on Pₙ.
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                // Pₙ(x) and Pₙ₋₁(x) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-15 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

fn build_table(n_mu: usize, n_roughness: usize, q: &Quadrature) -> AlbedoTable {
    let mut values = vec![0.0; n_mu * n_roughness];
    // ln(sin²θ_h) on the quadrature's nodes is the same for every roughness at one μ: D is
    // then one exp per node.
    let mut ln_sin2 = vec![0.0; q.u.len() * q.phi.len()];
    let alphas: Vec<f64> = (0..n_roughness).map(|j| alpha_g(row_roughness(j, n_roughness))).collect();
    let lambdas: Vec<Vec<f64>> =
        alphas.iter().map(|&a| q.u.iter().map(|&(u, _)| lambda_alpha(u, a)).collect()).collect();
    for i in 0..n_mu {
        let mu = column_mu(i, n_mu);
        fill_ln_sin2(mu, q, &mut ln_sin2);
        for j in 0..n_roughness {
            values[j * n_mu + i] = integrate(mu, alphas[j], q, &ln_sin2, &lambdas[j]);
        }
    }
    AlbedoTable { n_mu, n_roughness, values }
}

fn fill_ln_sin2(mu: f64, q: &Quadrature, out: &mut [f64]) {
    let sin_v = (1.0 - mu * mu).max(0.0).sqrt();
    for (k, &(u, _)) in q.u.iter().enumerate() {
        let sin_l = (1.0 - u * u).max(0.0).sqrt();
        for (m, &(cos_phi, _)) in q.phi.iter().enumerate() {
            // |v + l|² = 2 + 2·v·l, and n·(v + l) = μ + u.
            let len2 = 2.0 + 2.0 * (mu * u + sin_v * sin_l * cos_phi);
            let nh2 = (mu + u) * (mu + u) / len2;
            out[k * q.phi.len() + m] = (1.0 - nh2).max(0.0).ln();
        }
    }
}

/// E(μ) = ∫∫ D·V·u du dφ, where V·u = 1 / ((1 + Λ(μ) + Λ(u))·4μ): finite at u = 0.
fn integrate(mu: f64, alpha: f64, q: &Quadrature, ln_sin2: &[f64], lambda_u: &[f64]) -> f64 {
    if mu <= 0.0 {
        return 0.0;
    }
    let k = 0.5 / alpha;
    let norm = (2.0 + 1.0 / alpha) / (2.0 * PI);
    let lambda_v = lambda_alpha(mu, alpha);
    let n_phi = q.phi.len();
    let mut sum = 0.0;
    for (idx, &(_, wu)) in q.u.iter().enumerate() {
        let row = &ln_sin2[idx * n_phi..(idx + 1) * n_phi];
        let d: f64 = row.iter().zip(&q.phi).map(|(&ls, &(_, wp))| wp * (k * ls).exp()).sum();
        sum += wu * d / ((1.0 + (lambda_v + lambda_u[idx])) * (4.0 * mu));
    }
    norm * sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// ∫ f(l) dω over the upper hemisphere by the midpoint rule in (θ, φ), φ over the whole
    /// circle: a different rule, variable and geometry from the table's Gauss–Legendre in
    /// (n·l, φ) on half the circle.
    fn midpoint_hemisphere(n_theta: usize, n_phi: usize, f: impl Fn(DVec3) -> f64) -> f64 {
        let (dt, dp) = (0.5 * PI / n_theta as f64, 2.0 * PI / n_phi as f64);
        let mut sum = 0.0;
        for it in 0..n_theta {
            let (st, ct) = ((it as f64 + 0.5) * dt).sin_cos();
            let mut ring = 0.0;
            for ip in 0..n_phi {
                let (sp, cp) = ((ip as f64 + 0.5) * dp).sin_cos();
                ring += f(DVec3::new(st * cp, st * sp, ct));
            }
            sum += ring * st;
        }
        sum * dt * dp
    }

    fn view(mu: f64) -> DVec3 {
        DVec3::new((1.0 - mu * mu).sqrt(), 0.0, mu)
    }

    /// E by the midpoint rule, h built from the vectors.
    fn midpoint_albedo(mu: f64, roughness: f64, n_theta: usize, n_phi: usize) -> f64 {
        let v = view(mu);
        midpoint_hemisphere(n_theta, n_phi, |l| brdf(l.z, mu, (v + l).normalize().z, roughness) * l.z)
    }

    /// A small deterministic generator (SplitMix64) for the Monte Carlo reference.
    struct SplitMix(u64);
    impl SplitMix {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn sheen_parameters_follow_the_factors_and_textures() {
        let s = Sheen {
            color: Vec3::new(0.5, 1.0, 0.25),
            color_texture: None,
            roughness: 0.5,
            roughness_texture: None,
        };
        assert_eq!(s.color_at(None), s.color);
        assert_eq!(s.color_at(Some(Vec3::new(0.5, 0.5, 1.0))), Vec3::new(0.25, 0.5, 0.25));
        assert_eq!(s.roughness_at(None), 0.5);
        assert_eq!(s.roughness_at(Some(0.5)), 0.25);
        assert!(!s.is_off());
        let off = Sheen { color: Vec3::ZERO, color_texture: Some(TextureRef::new(0)), ..s.clone() };
        assert!(off.is_off());
        assert!(Sheen { color: Vec3::new(-0.0, 0.0, 0.0), ..s }.is_off());
    }

    #[test]
    fn roughness_is_squared_and_clamped_alike_everywhere() {
        assert!((MIN_ROUGHNESS * MIN_ROUGHNESS - MIN_ALPHA).abs() < 1e-16);
        assert_eq!(alpha_g(0.5), 0.25);
        assert_eq!(alpha_g(1.0), 1.0);
        assert_eq!(alpha_g(2.0), 1.0);
        for r in [0.0, 0.07, 0.2, f64::NAN, -1.0] {
            assert_eq!(alpha_g(r), MIN_ALPHA, "{r}");
            assert_eq!(clamp_roughness(r), MIN_ROUGHNESS, "{r}");
            assert_eq!(charlie_d(r, 0.3), charlie_d(MIN_ROUGHNESS, 0.3));
            assert_eq!(visibility(0.3, 0.6, r), visibility(0.6, 0.3, MIN_ROUGHNESS));
            assert_eq!(albedo(0.4, r), albedo(0.4, MIN_ROUGHNESS));
        }
        // D written out by hand at α = 1 and α = 0.25 (roughness 0.5): (2 + 1/α)·sin^(1/α)/2π.
        assert!((charlie_d(1.0, 0.0) - 3.0 / (2.0 * PI)).abs() < 1e-15);
        let sin = 0.6f64;
        assert!((charlie_d(0.5, 0.8) - 6.0 * sin.powi(4) / (2.0 * PI)).abs() < 1e-15);
        assert_eq!(visibility(0.0, 0.5, 0.5), 0.0);
        assert_eq!(visibility(0.5, -0.1, 0.5), 0.0);
        let (l, v, h) = (0.3f32, 0.7f32, 0.2f32);
        let f = brdf(l.into(), v.into(), h.into(), 0.6);
        assert_eq!(brdf_f32(l, v, h, 0.6), f as f32);
        assert_eq!(f, charlie_d(0.6, h.into()) * visibility(l.into(), v.into(), 0.6));
    }

    /// ∫ D(h)·(n·h) dω_h = 2π ∫₀^{π/2} D(cos θ) cos θ sin θ dθ = 1, by the midpoint rule on
    /// 20 000 intervals of θ (D depends on θ_h alone).
    #[test]
    fn charlie_d_is_normalised() {
        let n = 20_000;
        let dt = 0.5 * PI / n as f64;
        let mut worst: f64 = 0.0;
        // Through the public roughness (0.07 and 0.1 draw at the clamp, α = 0.07) and at the
        // formula's own α, below the clamp too.
        let cases = [0.07, 0.1, 0.3, 0.5, 1.0].map(alpha_g).into_iter().chain([0.0049, 0.02, 0.25, 0.5]);
        for alpha in cases {
            let integral: f64 = (0..n)
                .map(|i| {
                    let (s, c) = ((i as f64 + 0.5) * dt).sin_cos();
                    d_alpha(alpha, c) * c * s
                })
                .sum::<f64>()
                * dt
                * 2.0
                * PI;
            eprintln!("α = {alpha}: ∫D·cos = {integral:.12}");
            worst = worst.max((integral - 1.0).abs());
        }
        eprintln!("worst normalisation error {worst:.2e}");
        assert!(worst < 1e-7, "{worst}");
    }

    #[test]
    fn lambda_is_continuous_at_one_half_and_visibility_symmetric() {
        let mut worst_jump: f64 = 0.0;
        let mut worst_slope: f64 = 0.0;
        for r in [0.0, 0.3, 0.5, 0.7, 1.0] {
            // Value: the lower branch just below 0.5 against the upper one at 0.5.
            let below = charlie_lambda(0.5 - 1e-12, r);
            let at = charlie_lambda(0.5, r);
            worst_jump = worst_jump.max((below / at - 1.0).abs());
            // Slope: one-sided differences on each branch.
            let h = 1e-5;
            let left = (charlie_lambda(0.5 - 1e-12, r) - charlie_lambda(0.5 - h, r)) / h;
            let right = (charlie_lambda(0.5 + h, r) - at) / h;
            worst_slope = worst_slope.max((left / right - 1.0).abs());
            // Λ falls from grazing to normal incidence, and is positive.
            let mut prev = f64::INFINITY;
            for k in 0..=100 {
                let lam = charlie_lambda(k as f64 / 100.0, r);
                assert!(lam > 0.0 && lam < prev, "Λ({}) = {lam} at roughness {r}", k as f64 / 100.0);
                prev = lam;
            }
        }
        eprintln!("Λ at 0.5: relative jump {worst_jump:.1e}, slopes differ by {worst_slope:.1e}");
        assert!(worst_jump < 1e-10, "{worst_jump}");
        assert!(worst_slope < 1e-3, "{worst_slope}");
        for r in [0.0, 0.4, 1.0] {
            for a in 1..=20 {
                for b in 1..=20 {
                    let (l, v) = (a as f64 / 20.0, b as f64 / 20.0);
                    assert_eq!(visibility(l, v, r), visibility(v, l, r));
                    // G = V·4·n·l·n·v is a fraction.
                    let g = visibility(l, v, r) * 4.0 * l * v;
                    assert!(g > 0.0 && g <= 1.0, "{g}");
                }
            }
        }
    }

    /// The table's quadrature against twice the points in both variables.
    #[test]
    fn albedo_table_converges() {
        let t = std::time::Instant::now();
        let built = build_table(TABLE_MU, TABLE_ROUGHNESS, &Quadrature::new(QUAD_U, QUAD_PHI));
        eprintln!("table built in {:?} (this profile)", t.elapsed());
        let table = albedo_table();
        assert_eq!(table, &built);
        let fine = build_table(TABLE_MU, TABLE_ROUGHNESS, &Quadrature::new(2 * QUAD_U, 2 * QUAD_PHI));
        let worst = table.values().iter().zip(fine.values()).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        eprintln!("table vs twice the quadrature points: worst {worst:.2e}");
        assert!(worst < 1e-5, "{worst}");
        assert_eq!((table.n_mu(), table.n_roughness()), (TABLE_MU, TABLE_ROUGHNESS));
        assert_eq!(table.values().len(), TABLE_MU * TABLE_ROUGHNESS);
        assert_eq!(table.values_f32()[5], table.get(5, 0) as f32);
        // The lookup at a node is the node.
        assert_eq!(table.lookup(table.mu(10), table.roughness(20)), table.get(10, 20));
        assert!((table.mu(0) - (1.0f64 / 64.0).powi(2)).abs() < 1e-18);
        assert_eq!((table.mu(TABLE_MU - 1), table.roughness(TABLE_ROUGHNESS - 1)), (1.0, 1.0));
        assert_eq!(table.roughness(0), MIN_ROUGHNESS);
        assert_eq!(table.lookup(1.0, 1.0), table.get(TABLE_MU - 1, TABLE_ROUGHNESS - 1));
        assert_eq!(table.lookup(0.5, 0.0), table.lookup(0.5, MIN_ROUGHNESS));
    }

    /// E by quadrature and by the table against a midpoint rule in (θ, φ), Richardson-
    /// extrapolated from 400 × 800 and 800 × 1600 cells (its error is O(h²): near grazing the
    /// finer grid alone is 10⁻⁴ off), at points off the table's nodes.
    #[test]
    fn albedo_matches_an_independent_midpoint_rule() {
        let points =
            [(0.003, 0.1), (0.02, 0.3), (0.13, 0.85), (0.27, 0.4), (0.5, 0.6), (0.77, 0.33), (0.95, 1.0)];
        let (mut worst_integral, mut worst_lookup): (f64, f64) = (0.0, 0.0);
        for (mu, r) in points {
            let reference =
                (4.0 * midpoint_albedo(mu, r, 800, 1600) - midpoint_albedo(mu, r, 400, 800)) / 3.0;
            let integral = albedo_integral(mu, r);
            let lookup = albedo(mu, r);
            eprintln!("E({mu}, {r}): midpoint {reference:.6}, quadrature {integral:.6}, table {lookup:.6}");
            worst_integral = worst_integral.max((integral - reference).abs());
            worst_lookup = worst_lookup.max((lookup - reference).abs());
        }
        eprintln!("worst: quadrature {worst_integral:.2e}, table lookup {worst_lookup:.2e}");
        assert!(worst_integral < 2e-5, "{worst_integral}");
        assert!(worst_lookup < 5e-3, "{worst_lookup}");
    }

    /// The bilinear lookup against the quadrature (checked above against the midpoint rule) on
    /// a scan off the nodes, n·v from 10⁻⁴ to 1, log-spaced. Below the first column
    /// (μ < 2.4·10⁻⁴) the lookup holds that column's value, above the true E there, so that
    /// range is held to the underestimate bound only (the one the energy balance needs).
    #[test]
    fn albedo_lookup_error_is_bounded() {
        let first = albedo_table().mu(0);
        let (mut worst, mut at) = (0.0, (0.0, 0.0));
        let (mut worst_under, mut worst_below): (f64, f64) = (0.0, 0.0);
        for a in 0..160 {
            let mu = 1e-4f64.powf(1.0 - (a as f64 + 0.37) / 160.0);
            for b in 0..24 {
                let r = (b as f64 + 0.21) / 24.0;
                let err = albedo(mu, r) - albedo_integral(mu, r);
                if mu < first {
                    worst_below = worst_below.max(err);
                } else if err.abs() > worst {
                    (worst, at) = (err.abs(), (mu, r));
                }
                worst_under = worst_under.max(-err);
            }
        }
        eprintln!(
            "lookup error from the first column on: worst {worst:.2e} at (μ, roughness) = {at:?}, \
             worst underestimate (whole scan) {worst_under:.2e}; below the first column: overestimates up to {worst_below:.2e}"
        );
        assert!(worst < 6e-3, "{worst}");
        assert!(worst_under < 6e-3, "{worst_under}");
    }

    /// E is a fraction everywhere on the grid, and grows toward grazing views (from μ = 0.01;
    /// it falls again below μ ≈ 0.003 where Λ stops growing as fast as 1/μ). A few nodes
    /// against stratified Monte Carlo (512 × 512 strata in (n·l, φ), one jittered sample each,
    /// fixed seed): yet another estimator of the same integral.
    #[test]
    fn albedo_is_a_fraction_and_grows_toward_grazing() {
        let t = albedo_table();
        let max = t.values().iter().copied().fold(0.0, f64::max);
        let min = t.values().iter().copied().fold(1.0, f64::min);
        eprintln!("table range [{min:.3e}, {max:.6}]");
        assert!(min > 0.0 && max < 0.99, "{min} {max}");
        for j in 0..t.n_roughness() {
            for i in 0..t.n_mu() - 1 {
                if t.mu(i) >= 0.01 {
                    assert!(t.get(i + 1, j) < t.get(i, j), "row {j} at column {i}");
                }
            }
        }
        let mut rng = SplitMix(0x5eed);
        let n = 512;
        let mut worst: f64 = 0.0;
        for (i, j) in [(1, 0), (6, 3), (12, 12), (25, 20), (40, 31), (63, 16)] {
            let (mu, r) = (t.mu(i), t.roughness(j));
            let v = view(mu);
            let mut sum = 0.0;
            for a in 0..n {
                for b in 0..n {
                    let u = (a as f64 + rng.next()) / n as f64;
                    let phi = 2.0 * PI * (b as f64 + rng.next()) / n as f64;
                    let s = (1.0 - u * u).sqrt();
                    let l = DVec3::new(s * phi.cos(), s * phi.sin(), u);
                    sum += brdf(u, mu, (v + l).normalize().z, r) * u;
                }
            }
            // Uniform over the hemisphere: pdf 1/2π.
            let mc = sum * 2.0 * PI / (n * n) as f64;
            eprintln!("E({mu:.5}, {r:.4}): table {:.6}, Monte Carlo {mc:.6}", t.get(i, j));
            worst = worst.max((mc - t.get(i, j)).abs());
        }
        eprintln!("table vs Monte Carlo: worst {worst:.2e}");
        assert!(worst < 1e-4, "{worst}");
    }

    #[test]
    fn albedo_scaling_takes_the_smaller_share() {
        assert_eq!(albedo_scaling(0.0, 0.7, 0.2), 1.0);
        assert_eq!(albedo_scaling_f32(0.0, 0.7, 0.2), 1.0);
        assert_eq!(albedo_scaling(1.0, 0.25, 0.5), 0.5);
        assert_eq!(albedo_scaling(0.5, 0.5, 0.25), 0.75);
        assert_eq!(albedo_scaling(0.5, 0.25, 0.5), 0.75);
        assert_eq!(albedo_scaling(2.0, 0.75, 0.1), 0.0);
        assert_eq!(albedo_scaling(1.0, -0.5, -0.5), 1.0);
        assert_eq!(albedo_scaling_f32(1.0, 0.25, 0.5), 0.5);
        // A black sheen leaves the base exactly as it is, whatever the albedos.
        for e in [0.0, 0.3, 0.99, 1.0] {
            assert_eq!(albedo_scaling(0.0, e, albedo(0.01, 0.3)), 1.0);
        }
    }

    /// A white sheen over a white Lambertian base, with the albedo scaling from the table:
    /// ∫ (f_sheen + s·1/π)·n·l dω = E(μ) + 2∫₀¹ s(μ, u)·u du (the base term does not depend on
    /// the azimuth), E by quadrature and the u-integral by the midpoint rule on 4000 cells.
    /// At the table's nodes the lookup is exact and the total at most 1; between them it is
    /// over 1 by at most the lookup's underestimate of E(μ).
    #[test]
    fn white_sheen_over_white_lambertian_conserves_energy() {
        let t = albedo_table();
        let n = 4000;
        let total = |mu: f64, r: f64| {
            let e_v = albedo(mu, r);
            let base: f64 = (0..n)
                .map(|k| {
                    let u = (k as f64 + 0.5) / n as f64;
                    albedo_scaling(1.0, e_v, albedo(u, r)) * u
                })
                .sum::<f64>()
                * 2.0
                / n as f64;
            albedo_integral(mu, r) + base
        };
        let (mut on, mut on_at) = (0.0, (0.0, 0.0));
        let (mut off, mut off_at) = (0.0, (0.0, 0.0));
        for j in 0..t.n_roughness() {
            let r = t.roughness(j);
            for i in 0..t.n_mu() {
                let e = total(t.mu(i), r);
                if e > on {
                    (on, on_at) = (e, (t.mu(i), r));
                }
                // Halfway between columns (in √μ), and between rows.
                let s = (i as f64 + 0.5) / t.n_mu() as f64;
                let r_mid = (r + 0.5 * (1.0 - MIN_ROUGHNESS) / (t.n_roughness() - 1) as f64).min(1.0);
                let e = total(s * s, r_mid);
                if e > off {
                    (off, off_at) = (e, (s * s, r_mid));
                }
            }
        }
        eprintln!("worst total albedo: {on:.8} at nodes {on_at:?}, {off:.6} between them {off_at:?}");
        assert!(on <= 1.0 + 1e-4, "{on}");
        assert!(off <= 1.0 + 8e-3, "{off}");
    }
}
