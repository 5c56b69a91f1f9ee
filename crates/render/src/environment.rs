//! The environment light in real time: how an equirectangular RGB environment
//! ([`scene::Environment`]) is lit with inside the same spectral loop and quadrature as the
//! punctual lights.
//!
//! # Representation: K basis spectra × K coefficient maps
//!
//! Each texel's radiance is upsampled as an illuminant, `L_t(λ) = s_t·ρ_t(λ)·W(λ)` (the variant
//! every RGB light uses), which is not linear in RGB, so the N node weights of a texel cannot be
//! mixed from three fixed spectra. Instead the smooth parts `x_t(λ) = s_t·ρ_t(λ)` of all texels are
//! reduced to [`K`] basis spectra `φ_j` by a principal-component analysis (uncentred, weighted by
//! solid angle and by the observer × white), and each texel keeps its K coefficients:
//! `L_t(λ) ≈ Σ_j α_tj·φ_j(λ)·W(λ)`. Everything after that is linear, so it commutes with
//! filtering: the coefficient maps are prefiltered (GGX lobes by roughness into mip levels;
//! a cosine lobe into an irradiance map) exactly as RGB maps are, and the shader turns a filtered
//! coefficient vector into node weights with the basis's node weights `B_j = weights(φ_j·W)`
//! (prefiltered or midpoint quadrature, like any light). The truncation error is measured when the
//! basis is built ([`SpectralBasis::residual`]: the largest relative error of a texel's shape);
//! an environment whose texels all have one colour (the default sky) is captured exactly. The PCA
//! is fitted to the texels' shapes (each normalised to unit length), not their energy, so a sun
//! that holds most of the power does not take every component from the sky.
//!
//! RGB mode uses the texels' RGB as its three coefficients. Naive mode uses the same RGB
//! coefficients with the box spectra `band_c(λ)·W(λ)` as basis: exact, since box upsampling is
//! linear.
//!
//! # Specular: split sum (Karis 2013)
//!
//! `∫ L(l)·f(l, v)·cos dl ≈ L_pref(r, roughness) · (F0·A + B)` with `L_pref` the radiance
//! convolved with the GGX lobe around the mirror direction (n = v = r), one mip level per
//! roughness step, and (A, B) the [`brdf_lut`] of the glTF BRDF's D·V (height-correlated Smith).
//!
//! # Diffuse
//!
//! `E(n) = ∫ L(l)·max(n·l, 0) dl` exactly for the coefficient maps, on a 64×32 map sampled
//! bilinearly by the normal.
//!
//! # Not modelled
//!
//! The environment is not shadowed in real time: every point sees the whole environment (the
//! path tracer traces shadow rays), so concave parts are brighter than in truth.

use std::f32::consts::PI;

use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;
use scene::Environment;

/// Number of basis spectra (one rgba texture of coefficients).
pub const K: usize = 4;
/// Width of the finest (mirror) level on the GPU; larger environments are box-filtered down.
pub const GPU_WIDTH: u32 = 512;
/// Mip levels of the radiance map: level m is prefiltered for roughness m / (LEVELS − 1).
pub const LEVELS: u32 = 6;
/// Narrowest finest level: smaller environments are enlarged (nearest texel, the same function)
/// so that every mip level exists.
pub const GPU_MIN_WIDTH: u32 = 2 << LEVELS;
/// Width of the irradiance map.
pub const IRRADIANCE_WIDTH: u32 = 64;
/// Resolution of the split-sum table (n·v × roughness).
pub const LUT_SIZE: u32 = 32;

/// The smooth parts' sample grid: 360–830 nm at 5 nm.
const GRID_MIN: f64 = 360.0;
const GRID_STEP: f64 = 5.0;
const GRID_N: usize = 95;

/// An image of K-vectors (coefficients), equirectangular, row 0 at +Y.
#[derive(Clone, Debug)]
pub struct Map {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec4>,
}

impl Map {
    fn row_solid_angle(&self, y: u32) -> f32 {
        let t0 = PI * y as f32 / self.height as f32;
        let t1 = PI * (y + 1) as f32 / self.height as f32;
        2.0 * PI / self.width as f32 * (t0.cos() - t1.cos())
    }

    /// Unrotated direction of texel centre (x, y) (the convention of `scene::environment`).
    fn direction(&self, x: u32, y: u32) -> Vec3 {
        let uv = Vec2::new((x as f32 + 0.5) / self.width as f32, (y as f32 + 0.5) / self.height as f32);
        let (theta, phi) = (PI * uv.y, 2.0 * PI * (uv.x - 0.5));
        Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
    }

    /// Solid-angle-weighted 2×2 (or 2×1 at odd heights) box reduction: keeps ∫ over the sphere.
    fn half(&self) -> Map {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let mut texels = vec![Vec4::ZERO; (w * h) as usize];
        for y in 0..h {
            for x in 0..w {
                let (mut sum, mut ws) = (Vec4::ZERO, 0.0);
                for sy in (2 * y)..(2 * y + 2).min(self.height) {
                    let s = self.row_solid_angle(sy);
                    for sx in (2 * x)..(2 * x + 2).min(self.width) {
                        sum += self.texels[(sy * self.width + sx) as usize] * s;
                        ws += s;
                    }
                }
                texels[(y * w + x) as usize] = sum / ws;
            }
        }
        Map { width: w, height: h, texels }
    }

    /// Nearest-neighbour enlargement to at least `width` (the same piecewise-constant function,
    /// sampled finely enough for a quadrature over it).
    fn enlarged_to(&self, width: u32) -> Map {
        let f = width.div_ceil(self.width).max(1);
        if f == 1 {
            return self.clone();
        }
        let (w, h) = (self.width * f, self.height * f);
        let texels =
            (0..w * h).map(|i| self.texels[((i / w / f) * self.width + (i % w) / f) as usize]).collect();
        Map { width: w, height: h, texels }
    }

    fn reduced_to(&self, width: u32) -> Map {
        let mut m = self.clone();
        while m.width > width {
            m = m.half();
        }
        m
    }
}

/// The GPU-ready maps of one environment in one coefficient space.
#[derive(Clone, Debug)]
pub struct EnvMaps {
    /// `LEVELS` levels, level 0 the mirror image, each half the previous size.
    pub radiance: Vec<Map>,
    pub irradiance: Map,
}

/// The K basis spectra's smooth parts φ_j on the 5 nm grid (the spectrum is φ_j(λ)·W(λ)).
#[derive(Clone, Debug)]
pub struct SpectralBasis {
    pub phi: Vec<[f64; GRID_N]>,
    /// The largest relative error of a texel's spectral shape after projection on the K
    /// components, ‖x − Σⱼ αⱼφⱼ‖ / ‖x‖ in the observer-weighted norm (0 = every texel exact).
    pub residual: f64,
    /// How many leading components any texel uses (1..=K): the ones after are zero in every
    /// texel (set so where they held less than [`UNUSED_COMPONENT`] of the first's largest
    /// coefficient), and the shader need not weigh them per node (`ENV_BASES`). One for an
    /// environment of one spectral shape, such as the default sky and ground.
    pub used: usize,
}

/// A trailing component whose largest coefficient is below this share of the first
/// component's is numerical noise of a rank-deficient PCA (the default environment's leave
/// ~10⁻¹⁶): it is dropped. 10⁻⁶ is far below what the half-float maps resolve (2⁻¹¹ of a
/// texel's value), so dropping it changes no stored texel's meaning.
pub const UNUSED_COMPONENT: f64 = 1e-6;

impl SpectralBasis {
    /// φ_j(λ), linear between grid points, 0 outside 360–830 nm.
    pub fn eval(&self, j: usize, l: f64) -> f64 {
        let x = (l - GRID_MIN) / GRID_STEP;
        if !(0.0..=(GRID_N - 1) as f64).contains(&x) {
            return 0.0;
        }
        let i = (x as usize).min(GRID_N - 2);
        let t = x - i as f64;
        self.phi[j][i] * (1.0 - t) + self.phi[j][i + 1] * t
    }
}

fn grid(i: usize) -> f64 {
    GRID_MIN + GRID_STEP * i as f64
}

/// The environment's texels (intensity not applied: the shader multiplies it) as an RGB map
/// at most [`GPU_WIDTH`] wide, rotation ignored (the shader rotates the lookup).
pub fn rgb_map(env: &Environment) -> Map {
    let m = Map {
        width: env.width,
        height: env.height,
        texels: env.texels.iter().map(|t| t.extend(0.0)).collect(),
    };
    m.reduced_to(GPU_WIDTH).enlarged_to(GPU_MIN_WIDTH)
}

/// PCA of the illuminant-upsampled texels of `rgb` (an [`rgb_map`]); returns the basis and the
/// coefficient map.
pub fn spectral_basis(rgb: &Map, table: &color::upsample::CoeffTable) -> (SpectralBasis, Map) {
    let white = color::RgbColorSpace::srgb().illuminant();
    let obs = color::Observer::cie1931();
    // Weight of each grid sample in the error metric: what the observer sees of it under the
    // white. A small floor keeps the basis defined where the observer is ~0.
    let w: Vec<f64> = (0..GRID_N)
        .map(|i| {
            let l = grid(i);
            let b = obs.eval(l);
            white.eval(l) * (b[0] + b[1] + b[2])
        })
        .collect();
    let wmax = w.iter().cloned().fold(0.0, f64::max);
    let sw: Vec<f64> = w.iter().map(|&v| (v + 1e-4 * wmax).sqrt()).collect();
    // x̃_t = √w · s·ρ_t, per texel, and the weighted second moment C = Σ Ω x̃ x̃ᵀ.
    let samples: Vec<[f64; GRID_N]> = rgb
        .texels
        .par_iter()
        .map(|t| {
            let (s, poly) =
                crate::spectral_data::illuminant_coeffs([t.x as f64, t.y as f64, t.z as f64], table);
            std::array::from_fn(|i| if s > 0.0 { s * poly.eval(grid(i)) * sw[i] } else { 0.0 })
        })
        .collect();
    // The basis is fitted to the texels' spectral *shapes* (each normalised to unit length),
    // weighted by solid angle only: fitted to energy, a sun holding most of the power would take
    // every component and leave the sky's colour to chance (measured: 0.70 ΔE2000 between the
    // spectral and rgb backgrounds of rooitou_park with energy weighting).
    let mut c = vec![0.0f64; GRID_N * GRID_N];
    for y in 0..rgb.height {
        let om = rgb.row_solid_angle(y) as f64;
        for x in &samples[(y * rgb.width) as usize..((y + 1) * rgb.width) as usize] {
            let n2: f64 = x.iter().map(|v| v * v).sum();
            if n2 <= 0.0 {
                continue;
            }
            let k = om / n2;
            for i in 0..GRID_N {
                let xi = x[i] * k;
                for j in 0..GRID_N {
                    c[i * GRID_N + j] += xi * x[j];
                }
            }
        }
    }
    let vecs = top_eigenvectors(&c, GRID_N, K);
    let phi = vecs.iter().map(|v| std::array::from_fn(|i| v[i] / sw[i])).collect();
    let project = |x: &[f64; GRID_N]| -> [f64; K] {
        std::array::from_fn(|j| (0..GRID_N).map(|i| x[i] * vecs[j][i]).sum::<f64>())
    };
    let coeffs: Vec<[f64; K]> = samples.par_iter().map(&project).collect();
    let largest: [f64; K] = std::array::from_fn(|j| coeffs.iter().map(|a| a[j].abs()).fold(0.0, f64::max));
    let used = (1..K).rev().find(|&j| largest[j] > UNUSED_COMPONENT * largest[0]).map_or(1, |j| j + 1);
    let texels = coeffs
        .iter()
        .map(|a| Vec4::from_array(std::array::from_fn(|j| if j < used { a[j] as f32 } else { 0.0 })))
        .collect();
    // Relative error of each texel's shape, ‖x − Σ αⱼ vⱼ‖ / ‖x‖ in the weighted norm, over the
    // components kept, computed as the difference itself (n² − Σα² would hide a basis that is
    // not orthonormal).
    let residual = samples
        .par_iter()
        .zip(&coeffs)
        .map(|(x, a)| {
            let n2: f64 = x.iter().map(|v| v * v).sum();
            if n2 <= 0.0 {
                return 0.0;
            }
            let r2: f64 = (0..GRID_N)
                .map(|i| {
                    let fit: f64 = (0..used).map(|j| a[j] * vecs[j][i]).sum();
                    (x[i] - fit).powi(2)
                })
                .sum();
            (r2 / n2).sqrt()
        })
        .reduce(|| 0.0, f64::max);
    (SpectralBasis { phi, residual, used }, Map { width: rgb.width, height: rgb.height, texels })
}

fn rayleigh(c: &[f64], v: &[f64]) -> f64 {
    let n = v.len();
    (0..n).map(|i| v[i] * (0..n).map(|j| c[i * n + j] * v[j]).sum::<f64>()).sum()
}

/// The k leading eigenvectors of a symmetric positive semi-definite n×n matrix (orthonormal),
/// by subspace iteration with Gram–Schmidt; plenty for n ≈ 100, k = 4.
fn top_eigenvectors(c: &[f64], n: usize, k: usize) -> Vec<Vec<f64>> {
    let mut v: Vec<Vec<f64>> = (0..k)
        .map(|j| (0..n).map(|i| 1.0 + ((i * (j + 3) * 7919) % 17) as f64 * 0.01 * j as f64).collect())
        .collect();
    // Gram–Schmidt, each projection done twice ("twice is enough": once leaves rounding of the
    // removed part, which dominates what is left when little is). A vector that (nearly)
    // vanishes in it — a rank-deficient matrix, such as an environment of one spectral shape,
    // whose later iterates are the first's direction plus rounding — is replaced by the first
    // unit vector independent of the others: normalised, that rounding was a vector far from
    // orthogonal to the first (measured: Gram off-diagonals 0.36–0.69, a small white light on a
    // black sky drawn 1.3–1.9× too bright).
    let ortho = |v: &mut Vec<Vec<f64>>| {
        for j in 0..v.len() {
            let (done, rest) = v.split_at_mut(j);
            let cur = &mut rest[0];
            let norm_of = |x: &[f64]| x.iter().map(|x| x * x).sum::<f64>().sqrt();
            let project = |cur: &mut Vec<f64>| {
                let before = norm_of(cur);
                for _ in 0..2 {
                    for p in done.iter() {
                        let d: f64 = cur.iter().zip(p).map(|(a, b)| a * b).sum();
                        cur.iter_mut().zip(p).for_each(|(a, b)| *a -= d * b);
                    }
                }
                let after = norm_of(cur);
                if after > 1e-10 * before && after > 1e-150 { Some(after) } else { None }
            };
            let mut norm = project(cur);
            let mut e = 0;
            while norm.is_none() && e < n {
                *cur = (0..n).map(|i| if i == e { 1.0 } else { 0.0 }).collect();
                norm = project(cur);
                e += 1;
            }
            let norm = norm.unwrap_or(1.0);
            cur.iter_mut().for_each(|x| *x /= norm);
        }
    };
    ortho(&mut v);
    for _ in 0..300 {
        let mut next: Vec<Vec<f64>> =
            v.iter().map(|x| (0..n).map(|i| (0..n).map(|j| c[i * n + j] * x[j]).sum()).collect()).collect();
        ortho(&mut next);
        v = next;
    }
    // Sort by captured energy, largest first.
    v.sort_by(|a, b| rayleigh(c, b).total_cmp(&rayleigh(c, a)));
    v
}

/// GGX D for α, at cos θ_h.
fn ggx_d(alpha: f32, nh: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = nh * nh * (a2 - 1.0) + 1.0;
    a2 / (PI * t * t)
}

/// Prefiltered radiance levels and the irradiance map of a coefficient map.
pub fn prefilter(map: &Map) -> EnvMaps {
    let base = map.reduced_to(GPU_WIDTH);
    let mut radiance = vec![base.clone()];
    let mut pyramid = base.clone();
    for level in 1..LEVELS {
        pyramid = pyramid.half();
        let roughness = level as f32 / (LEVELS - 1) as f32;
        radiance.push(ggx_convolve(&pyramid, &pyramid, roughness));
    }
    let src = base.reduced_to(2 * IRRADIANCE_WIDTH).enlarged_to(2 * IRRADIANCE_WIDTH);
    let out = Map { width: IRRADIANCE_WIDTH, height: IRRADIANCE_WIDTH / 2, texels: vec![] };
    let irradiance = convolve(&src, out, |n, l| n.dot(l).max(0.0), None, false);
    EnvMaps { radiance, irradiance }
}

/// Radiance convolved with the GGX lobe of `roughness` around each texel's direction (n = v = r):
/// weights D(h)·(r·l), normalised (the split-sum's pre-integrated radiance).
fn ggx_convolve(src: &Map, shape: &Map, roughness: f32) -> Map {
    let alpha = (roughness * roughness).max(1e-3);
    // Beyond ~8α (in l, around r) D is below 1 % of its peak for the rough levels that matter;
    // the window only saves time.
    let window = (8.0 * alpha).min(PI);
    let out = Map { width: shape.width, height: shape.height, texels: vec![] };
    convolve(
        src,
        out,
        |r, l| {
            let rl = r.dot(l);
            if rl <= 0.0 {
                return 0.0;
            }
            let h = (r + l).normalize();
            ggx_d(alpha, r.dot(h)) * rl
        },
        Some(window),
        true,
    )
}

/// out(d) = Σ_l k(d, l)·src(l)·Ω_l (÷ Σ k·Ω when `normalise`), over source texels within
/// `window` radians of d (all when `None`).
fn convolve(
    src: &Map,
    mut out: Map,
    k: impl Fn(Vec3, Vec3) -> f32 + Sync,
    window: Option<f32>,
    normalise: bool,
) -> Map {
    let dirs: Vec<Vec3> = (0..src.height)
        .flat_map(|y| (0..src.width).map(move |x| (x, y)))
        .map(|(x, y)| src.direction(x, y))
        .collect();
    let omega: Vec<f32> = (0..src.height).map(|y| src.row_solid_angle(y)).collect();
    let (w, h) = (out.width, out.height);
    out.texels = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let d = out.direction(x, y);
            let theta = PI * (y as f32 + 0.5) / h as f32;
            let (rows, cos_min) = match window {
                Some(win) => {
                    let lo = (((theta - win) / PI * src.height as f32).floor().max(0.0)) as u32;
                    let hi = (((theta + win) / PI * src.height as f32).ceil() as u32).min(src.height);
                    (lo..hi, win.cos())
                }
                None => (0..src.height, -2.0),
            };
            let (mut sum, mut ws) = (Vec4::ZERO, 0.0f32);
            for sy in rows {
                let row = (sy * src.width) as usize;
                for sx in 0..src.width as usize {
                    let l = dirs[row + sx];
                    if l.dot(d) < cos_min {
                        continue;
                    }
                    let kw = k(d, l) * omega[sy as usize];
                    if kw > 0.0 {
                        sum += src.texels[row + sx] * kw;
                        ws += kw;
                    }
                }
            }
            if normalise { if ws > 0.0 { sum / ws } else { Vec4::ZERO } } else { sum }
        })
        .collect();
    out
}

/// The split-sum table: for (n·v, roughness) at texel centres of a `LUT_SIZE`² grid, (A, B) with
/// ∫ f·cos dl = F0·A + B for the glTF BRDF's specular lobe (GGX D, height-correlated Smith V,
/// Schlick F), by GGX importance sampling with a fixed Hammersley set.
pub fn brdf_lut() -> Vec<[f32; 2]> {
    let n = 512u32;
    (0..LUT_SIZE * LUT_SIZE)
        .map(|i| {
            let nv = ((i % LUT_SIZE) as f32 + 0.5) / LUT_SIZE as f32;
            let r = ((i / LUT_SIZE) as f32 + 0.5) / LUT_SIZE as f32;
            let alpha = (r * r).max(1e-3);
            let a2 = alpha * alpha;
            let v = Vec3::new((1.0 - nv * nv).sqrt(), 0.0, nv);
            let (mut a, mut b) = (0.0f32, 0.0f32);
            for s in 0..n {
                let u1 = (s as f32 + 0.5) / n as f32;
                let u2 = (s.reverse_bits() as f64 / 4294967296.0) as f32;
                // Classic GGX sampling of h: pdf(h) = D·(n·h).
                let cos_t = ((1.0 - u1) / (1.0 + (a2 - 1.0) * u1)).sqrt();
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let phi = 2.0 * PI * u2;
                let h = Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t);
                let vh = v.dot(h);
                let l = 2.0 * vh * h - v;
                let (nl, nh) = (l.z, h.z);
                if nl <= 0.0 || vh <= 0.0 {
                    continue;
                }
                let vis =
                    0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
                // f·cos / pdf(l) with pdf(l) = D·nh / (4·vh): D cancels.
                let g = vis * nl * 4.0 * vh / nh;
                let fc = (1.0 - vh).powi(5);
                a += (1.0 - fc) * g;
                b += fc * g;
            }
            [a / n as f32, b / n as f32]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_environment_stays_uniform_and_its_irradiance_is_pi() {
        let env = Environment::uniform(Vec3::ONE);
        let m = rgb_map(&env);
        let maps = prefilter(&m);
        for level in &maps.radiance {
            for t in &level.texels {
                assert!((t.x - 1.0).abs() < 1e-4, "{t}");
            }
        }
        for t in &maps.irradiance.texels {
            assert!((t.x - PI).abs() < 0.02 * PI, "{t}");
        }
    }

    #[test]
    fn irradiance_of_the_default_sky_matches_the_closed_form() {
        // Sky 1 above, ground g below: a surface facing up gets π; facing down gets π·g; a
        // vertical one gets π·(1 + g)/2.
        let maps = prefilter(&rgb_map(&Environment::default_sky()));
        let g = scene::environment::DEFAULT_GROUND;
        let ir = &maps.irradiance;
        let at = |y: u32| ir.texels[(y * ir.width) as usize].x;
        assert!((at(0) - PI).abs() < 0.03 * PI, "{}", at(0));
        assert!((at(ir.height - 1) - PI * g).abs() < 0.05 * PI * g, "{}", at(ir.height - 1));
        let mid = (at(ir.height / 2 - 1) + at(ir.height / 2)) / 2.0;
        assert!((mid - PI * (1.0 + g) / 2.0).abs() < 0.03 * PI, "{mid}");
    }

    #[test]
    fn split_sum_table_is_an_albedo() {
        let lut = brdf_lut();
        for ab in &lut {
            assert!(ab[0] >= 0.0 && ab[1] >= 0.0 && ab[0] + ab[1] <= 1.02, "{ab:?}");
        }
        // Smooth at normal incidence: the lobe is a mirror, A + B ≈ 1 and B ≈ 0.
        let smooth = lut[(LUT_SIZE - 1) as usize];
        assert!(smooth[0] > 0.9 && smooth[1] < 0.05, "{smooth:?}");
    }

    #[test]
    fn pca_is_exact_for_a_one_colour_environment_and_close_for_a_photo_like_one() {
        let table = color::upsample::table("srgb").unwrap();
        let (basis, coeffs) = spectral_basis(&rgb_map(&Environment::default_sky()), &table);
        assert!(basis.residual < 1e-6, "{}", basis.residual);
        // One spectral shape: one component used, the others zero in every texel, so the
        // shader weighs one basis per node (`ENV_BASES`).
        assert_eq!(basis.used, 1);
        assert!(coeffs.texels.iter().all(|t| t.y == 0.0 && t.z == 0.0 && t.w == 0.0));
        // Reconstruct a ground texel's smooth part: 0.25 grey → s·ρ = 2·0.125·ρ(½) = 0.25.
        let t = coeffs.texels.last().unwrap();
        let x: f64 = (0..K).map(|j| t[j] as f64 * basis.eval(j, 550.0)).sum();
        assert!((x - 0.25).abs() < 1e-3, "{x}");
        // Many colours: a hue wheel over the sphere, bright and dark.
        let (w, h) = (64u32, 32u32);
        let texels = (0..w * h)
            .map(|i| {
                let hue = (i % w) as f32 / w as f32 * 2.0 * PI;
                let c = |o: f32| 0.5 + 0.45 * (hue + o).cos();
                Vec3::new(c(0.0), c(2.1), c(4.2)) * (1.0 + (i / w) as f32)
            })
            .collect();
        let env = Environment::from_rgb("wheel", w, h, texels).unwrap();
        let (basis, _) = spectral_basis(&rgb_map(&env), &table);
        assert!(basis.residual < 0.1, "residual {}", basis.residual);
        assert_eq!(basis.used, K, "every component carries some of a hue wheel");
        // Two shapes (a white sky over a saturated red ground): two components.
        let two: Vec<Vec3> =
            (0..w * h).map(|i| if i < w * h / 2 { Vec3::ONE } else { Vec3::new(0.8, 0.05, 0.02) }).collect();
        let env = Environment::from_rgb("two", w, h, two).unwrap();
        let (basis, _) = spectral_basis(&rgb_map(&env), &table);
        assert_eq!(basis.used, 2, "residual {}", basis.residual);
    }

    /// Found by a sweep: a small white light on a black sky (one spectral shape, a rank-one
    /// PCA) was drawn 1.3–1.9× too bright and tinted in spectral mode, its basis built from
    /// normalised rounding. The basis must be orthonormal and the light's texels exact.
    #[test]
    fn pca_of_a_small_light_on_black_is_orthonormal_and_exact() {
        let table = color::upsample::table("srgb").unwrap();
        for (w, h, lit, value) in [(64u32, 32u32, 1usize, 1.0f32), (64, 32, 1, 1e5), (512, 256, 10, 100.0)] {
            let texels = (0..w * h)
                .map(|i| {
                    let (x, y) = ((i % w) as usize, (i / w) as usize);
                    if x < lit && y >= h as usize / 2 && y < h as usize / 2 + lit {
                        Vec3::splat(value)
                    } else {
                        Vec3::ZERO
                    }
                })
                .collect();
            let env = Environment::from_rgb("light", w, h, texels).unwrap();
            let (basis, coeffs) = spectral_basis(&rgb_map(&env), &table);
            assert_eq!(basis.used, 1, "{w}×{h}, {value}");
            assert!(basis.residual < 1e-6, "{w}×{h}, {value}: residual {}", basis.residual);
            // The lit texels reconstruct their illuminant spectrum: at 550 nm, the value (white
            // upsamples to s·ρ with ρ = ½ and s = 2·value).
            let t = coeffs.texels.iter().max_by(|a, b| a.x.abs().total_cmp(&b.x.abs())).unwrap();
            let x: f64 = (0..K).map(|j| t[j] as f64 * basis.eval(j, 550.0)).sum();
            let scale = x / f64::from(rgb_map(&env).texels.iter().map(|t| t.x).fold(0.0, f32::max));
            assert!((scale - 1.0).abs() < 1e-3, "{w}×{h}, {value}: {scale}");
        }
        // Orthonormal in the weighted inner product: checked on the raw vectors.
        let c = vec![1.0; 9];
        let v = top_eigenvectors(&c, 3, 3);
        for a in 0..3 {
            for b in 0..3 {
                let d: f64 = (0..3).map(|i| v[a][i] * v[b][i]).sum();
                assert!((d - f64::from(u8::from(a == b))).abs() < 1e-12, "{a} {b}: {d}");
            }
        }
    }
}
