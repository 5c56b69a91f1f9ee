//! The environment light: a [`scene::Environment`] (equirectangular image of linear-sRGB
//! radiance) as the path tracer samples and evaluates it.
//!
//! - **What it is**: exactly [`scene::Environment::radiance`] — a constant radiance per texel,
//!   over the texel's patch of sphere, in the one convention of `scene::environment`
//!   ([`scene::Environment::direction`] / [`scene::Environment::texel_index`], rotation included).
//!   Each texel's RGB × intensity becomes a spectrum as RGB emission does
//!   ([`crate::lights::EmissionUnits::rgb`]: s·ρ(rgb/s)·W̃(λ), s = 2·max(rgb), W̃ the colour
//!   space's illuminant in tracer units), so RGB (1, 1, 1) is the scene white with Y = 1. The
//!   sigmoid coefficients and scale are fitted once per texel here, so a lookup costs four
//!   sigmoids and the illuminant.
//! - **Sampling**: a texel ∝ luminance × its solid angle (a row from the marginal distribution,
//!   then a column from the row's conditional one, each an alias table (Walker 1977, Vose 1991):
//!   O(1) and two memory accesses, where binary searches of CDFs cost a third of the render time
//!   on a 512×256 map), then a direction uniform in solid angle within the texel (uniform in φ
//!   and in cos θ between the row's edges), so the solid-angle pdf is constant over the texel:
//!   pdf_ω = p_texel / Ω_texel. For a grey map, L/pdf is then the same for every direction.

use crate::lights::{EmissionUnits, luminance};
use crate::spectral::DenseSpectrum;
use crate::upsample::{self, RgbToSpectrum};
use glam::{Vec2, Vec3, Vec4};
use rayon::prelude::*;
use scene::Environment;
use std::f64::consts::PI;

/// An environment prepared for next-event estimation and lookups.
pub struct EnvMap<'s> {
    pub env: &'s Environment,
    /// Per texel: the sigmoid coefficients of rgb/s and the scale s = 2·max(rgb·intensity)
    /// (s = 0: black).
    texels: Vec<[f32; 4]>,
    /// The colour space's illuminant in tracer units (W̃ of [`EmissionUnits`]).
    illuminant: DenseSpectrum,
    /// Marginal distribution over rows (empty: nothing to sample).
    rows: Vec<AliasEntry>,
    /// Conditional distribution over the columns of each row, row-major like the texels.
    cols: Vec<AliasEntry>,
    /// Probability of choosing each texel.
    pmf: Vec<f32>,
    /// cos θ at the row edges (height + 1 values, from +1 at the top to −1 at the bottom).
    row_cos: Vec<f64>,
    /// Solid angle of one texel of each row.
    row_omega: Vec<f32>,
}

/// A direction towards the environment drawn by [`EnvMap::sample`].
#[derive(Clone, Copy, Debug)]
pub struct EnvSample {
    /// Unit direction, away from the scene.
    pub wi: Vec3,
    /// Solid-angle pdf of `wi`: p_texel / Ω_texel.
    pub pdf: f32,
    /// The texel it lies in.
    pub texel: usize,
}

/// An environment map the tracer cannot sample, naming its file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EnvMapError {
    #[error("environment {file}: {texels} texels for {width}×{height}")]
    Size { file: String, texels: usize, width: u32, height: u32 },
    #[error(
        "environment {file}: texel ({x}, {y}) = {value} × intensity {intensity} is not a finite, non-negative radiance"
    )]
    Texel { file: String, x: usize, y: usize, value: Vec3, intensity: f32 },
}

impl<'s> EnvMap<'s> {
    /// Fits every texel and builds the sampling distribution. Fails only when a texel's
    /// radiance × intensity overflows f32.
    pub fn new(
        env: &'s Environment,
        units: &EmissionUnits,
        up: &dyn RgbToSpectrum,
    ) -> Result<Self, EnvMapError> {
        let (w, h) = (env.width as usize, env.height as usize);
        if w == 0 || h == 0 || env.texels.len() != w * h {
            return Err(EnvMapError::Size {
                file: env.source.clone(),
                texels: env.texels.len(),
                width: env.width,
                height: env.height,
            });
        }
        let k = env.intensity;
        if let Some(i) = env.texels.iter().position(|t| !(*t * k).is_finite() || t.min_element() < 0.0) {
            return Err(EnvMapError::Texel {
                file: env.source.clone(),
                x: i % w,
                y: i / w,
                value: env.texels[i],
                intensity: k,
            });
        }
        // Luminance is linear: its weights once, not a colour-space construction per texel.
        let y_weights = Vec3::new(luminance(Vec3::X), luminance(Vec3::Y), luminance(Vec3::Z));
        let texels: Vec<[f32; 4]> = env
            .texels
            .par_iter()
            .map(|t| match upsample::emission_coeffs(up, (*t * k).to_array()) {
                Some((s, c)) => [c[0], c[1], c[2], s],
                None => [0.0; 4],
            })
            .collect();

        let row_cos: Vec<f64> = (0..=h).map(|y| (PI * y as f64 / h as f64).cos()).collect();
        let row_omega: Vec<f32> =
            (0..h).map(|y| (2.0 * PI / w as f64 * (row_cos[y] - row_cos[y + 1])) as f32).collect();
        // Weights ∝ luminance × solid angle, in f64 so a small sun on a huge dim sky keeps its
        // share and the dim sky keeps a non-zero one.
        let weight: Vec<f64> = env
            .texels
            .iter()
            .enumerate()
            .map(|(i, t)| (y_weights.dot(*t * k).max(0.0) as f64) * row_omega[i / w] as f64)
            .collect();
        let row_sum: Vec<f64> = weight.chunks_exact(w).map(|r| r.iter().sum()).collect();
        let total: f64 = row_sum.iter().sum();
        let (rows, cols, pmf) = if total > 0.0 && total.is_finite() {
            let cols = weight.par_chunks_exact(w).flat_map_iter(alias_table).collect();
            (alias_table(&row_sum), cols, weight.iter().map(|&x| (x / total) as f32).collect())
        } else {
            (vec![], vec![], vec![0.0; w * h])
        };
        Ok(EnvMap {
            env,
            texels,
            illuminant: units.rgb_illuminant.clone(),
            rows,
            cols,
            pmf,
            row_cos,
            row_omega,
        })
    }

    /// Whether it has anything to sample (a black map has not).
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Radiance of texel `i` at four wavelengths, tracer units.
    #[inline]
    pub fn texel_radiance(&self, i: usize, l: Vec4) -> Vec4 {
        let [c0, c1, c2, s] = self.texels[i];
        if s == 0.0 {
            return Vec4::ZERO;
        }
        upsample::eval4([c0, c1, c2], l) * s * self.illuminant.eval4(l)
    }

    /// Radiance arriving from direction `d` (unit, away from the scene).
    #[inline]
    pub fn radiance(&self, d: Vec3, l: Vec4) -> Vec4 {
        self.texel_radiance(self.env.texel_index(d), l)
    }

    /// Solid-angle pdf with which [`Self::sample`] draws direction `d`.
    #[inline]
    pub fn pdf(&self, d: Vec3) -> f32 {
        let i = self.env.texel_index(d);
        self.pmf[i] / self.row_omega[i / self.env.width as usize]
    }

    /// Probability of choosing texel `i` (the pmf the distribution claims).
    pub fn texel_probability(&self, i: usize) -> f32 {
        self.pmf[i]
    }

    /// A direction ∝ luminance, from six uniform numbers: two for the row, two for the column
    /// (entry and alias choice each), cos θ and φ within the texel.
    pub fn sample(&self, u: [f32; 6]) -> Option<EnvSample> {
        if self.is_empty() {
            return None;
        }
        let w = self.env.width as usize;
        let y = alias_pick(&self.rows, u[0], u[1]);
        let x = alias_pick(&self.cols[y * w..(y + 1) * w], u[2], u[3]);
        let i = y * w + x;
        let p = self.pmf[i];
        if p <= 0.0 {
            return None;
        }
        // Uniform in solid angle within the texel: cos θ uniform between the row's edges.
        let (c0, c1) = (self.row_cos[y], self.row_cos[y + 1]);
        let cos = (c0 - u[4] as f64 * (c0 - c1)).clamp(-1.0, 1.0);
        let v = (cos.acos() / PI) as f32;
        let uu = (x as f32 + u[5]) / w as f32;
        let wi = self.env.direction(Vec2::new(uu, v));
        Some(EnvSample { wi, pdf: p / self.row_omega[y], texel: i })
    }
}

/// One entry of an alias table: keep this index with probability `keep`, else take `alias`.
#[derive(Clone, Copy, Debug)]
struct AliasEntry {
    keep: f32,
    alias: u32,
}

/// Vose's alias table of `weights` (non-negative, positive sum): entry k is chosen with
/// probability 1/n, then kept with probability `keep`, so index i comes out with probability
/// weights[i]/Σ. A zero weight keeps with probability 0 and is never returned.
fn alias_table(weights: &[f64]) -> Vec<AliasEntry> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let mut table: Vec<AliasEntry> = (0..n).map(|i| AliasEntry { keep: 1.0, alias: i as u32 }).collect();
    if total <= 0.0 {
        // A row without light is never chosen; keep it valid all the same.
        return table;
    }
    let mut scaled: Vec<f64> = weights.iter().map(|&x| x * n as f64 / total).collect();
    let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| scaled[i] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        table[s] = AliasEntry { keep: scaled[s] as f32, alias: l as u32 };
        scaled[l] -= 1.0 - scaled[s];
        if scaled[l] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What is left holds (up to round-off) exactly its own share: keep it, unless it has no
    // weight at all (only round-off can leave one), which goes to the largest weight.
    let biggest = (0..n).max_by(|&a, &b| weights[a].total_cmp(&weights[b])).unwrap_or(0) as u32;
    for i in small.into_iter().chain(large) {
        table[i] = if weights[i] > 0.0 {
            AliasEntry { keep: 1.0, alias: i as u32 }
        } else {
            AliasEntry { keep: 0.0, alias: biggest }
        };
    }
    table
}

/// The index an alias table gives for uniform numbers `u` (entry) and `v` (keep or alias).
#[inline]
fn alias_pick(table: &[AliasEntry], u: f32, v: f32) -> usize {
    let k = ((u * table.len() as f32) as usize).min(table.len() - 1);
    let e = table[k];
    if v < e.keep { k } else { e.alias as usize }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Sampler;
    use crate::upsample::GreyOnly;
    use color::WavelengthRange;

    fn units() -> EmissionUnits {
        EmissionUnits::new(&color::illuminant::by_name("D65").unwrap(), WavelengthRange::VISIBLE)
    }

    /// A small map with varied texels, some black, a black last row and a black first column.
    fn varied(w: u32, h: u32) -> Environment {
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if y == h - 1 || x == 0 || (x + 2 * y) % 5 == 0 {
                    Vec3::ZERO
                } else {
                    Vec3::splat(((i * 7919) % 13) as f32 * 0.3 + 0.1)
                }
            })
            .collect();
        let mut e = Environment::from_rgb("varied", w, h, texels).unwrap();
        e.rotation = 0.9;
        e
    }

    /// Chi-square test of the sampled directions against the claimed distribution: each texel
    /// split into 2×2 cells of equal solid angle (halves in φ and in cos θ), so both the texel
    /// choice (counts ∝ p_texel) and the uniformity in solid angle within a texel are checked.
    /// The direction is binned through `Environment::uv`, the shared convention, not through
    /// anything the sampler computed.
    #[test]
    fn sampled_directions_follow_the_claimed_pdf() {
        let env = varied(8, 4);
        let map = EnvMap::new(&env, &units(), &GreyOnly).unwrap();
        let (w, h) = (env.width as usize, env.height as usize);
        let n = 400_000usize;
        let mut counts = vec![0u64; w * h * 4];
        let mut rng = Sampler::new(3, 0);
        let mut elsewhere = 0;
        for _ in 0..n {
            let u: [f32; 6] = std::array::from_fn(|_| rng.uniform());
            let s = map.sample(u).expect("a sample");
            assert!((s.wi.length() - 1.0).abs() < 1e-5);
            let i = env.texel_index(s.wi);
            // Only f32 round-off on a texel edge may put a sample in its neighbour.
            if i != s.texel {
                elsewhere += 1;
            } else {
                assert!((s.pdf - map.pdf(s.wi)).abs() <= 1e-6 * s.pdf);
            }
            let uv = env.uv(s.wi);
            let (x, y) = (i % w, i / w);
            let fx = (uv.x * w as f32 - x as f32 >= 0.5) as usize;
            let cos_mid = 0.5 * (map.row_cos[y] + map.row_cos[y + 1]);
            let fy = (((PI * uv.y as f64).cos()) < cos_mid) as usize;
            counts[i * 4 + fy * 2 + fx] += 1;
        }
        let (mut chi2, mut dof, mut in_black) = (0.0f64, 0usize, 0);
        for i in 0..w * h {
            let p = map.texel_probability(i) as f64;
            if p == 0.0 {
                in_black += counts[i * 4..i * 4 + 4].iter().sum::<u64>();
                continue;
            }
            for c in &counts[i * 4..i * 4 + 4] {
                let e = n as f64 * p / 4.0;
                chi2 += (*c as f64 - e).powi(2) / e;
                dof += 1;
            }
        }
        assert!(elsewhere <= 5, "{elsewhere} samples outside the texel they claim");
        assert!(in_black <= elsewhere, "{in_black} samples in black texels");
        let dof = dof - 1;
        // Mean dof, sd √(2·dof); 6 sd is p < 1e-6 (Wilson–Hilferty puts it a little higher).
        let limit = dof as f64 + 6.0 * (2.0 * dof as f64).sqrt();
        println!("chi-square {chi2:.1} with {dof} degrees of freedom (limit {limit:.1})");
        assert!(chi2 < limit, "chi-square {chi2} ≥ {limit} with {dof} dof");
        let sum: f64 = (0..w * h).map(|i| map.texel_probability(i) as f64).sum();
        assert!((sum - 1.0).abs() < 1e-5);
    }

    /// The alias tables give each index exactly its share (summed over entries), zero weights
    /// never, for awkward weights (zeros, a huge one, tiny ones, equal ones).
    #[test]
    fn alias_tables_are_exact() {
        let cases: [&[f64]; 5] = [
            &[1.0],
            &[0.0, 3.0, 0.0, 1.0],
            &[1e-9, 5000.0, 0.2, 0.2, 0.0, 1e-3, 0.2],
            &[2.0; 7],
            &[0.0, 0.0, 1.0, 0.0],
        ];
        for w in cases {
            let t = alias_table(w);
            let total: f64 = w.iter().sum();
            let mut p = vec![0.0f64; w.len()];
            for (k, e) in t.iter().enumerate() {
                p[k] += e.keep as f64 / w.len() as f64;
                p[e.alias as usize] += (1.0 - e.keep as f64) / w.len() as f64;
            }
            for i in 0..w.len() {
                assert!(
                    (p[i] - w[i] / total).abs() < 1e-6,
                    "{w:?}: index {i} gets {} not {}",
                    p[i],
                    w[i] / total
                );
                if w[i] == 0.0 {
                    assert_eq!(p[i], 0.0, "{w:?}: zero weight {i} chosen");
                }
            }
            assert_eq!(alias_pick(&t, 1.0 - f32::EPSILON / 2.0, 0.0), alias_pick(&t, 0.99999, 0.0));
        }
    }

    /// ∫ pdf dω = 1 by quadrature over the sphere in the tracer's own directions, and the pdf is
    /// luminance-proportional: L/pdf is the same in every lit texel of a grey map.
    #[test]
    fn pdf_integrates_to_one_and_follows_luminance() {
        let env = varied(16, 8);
        let map = EnvMap::new(&env, &units(), &GreyOnly).unwrap();
        let (nt, np) = (400, 800);
        let mut total = 0.0f64;
        for i in 0..nt {
            let c = 1.0 - 2.0 * (i as f64 + 0.5) / nt as f64;
            let s = (1.0 - c * c).sqrt();
            for j in 0..np {
                let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
                let d = Vec3::new((s * phi.cos()) as f32, c as f32, (s * phi.sin()) as f32);
                total += map.pdf(d) as f64 * 4.0 * PI / (nt * np) as f64;
            }
        }
        assert!((total - 1.0).abs() < 5e-3, "∫pdf = {total}");
        let l = Vec4::splat(560.0);
        let mut ratio = None;
        for i in 0..env.texels.len() {
            if env.texels[i] == Vec3::ZERO {
                assert_eq!(map.texel_probability(i), 0.0);
                continue;
            }
            let y = i / env.width as usize;
            let r = map.texel_radiance(i, l).x / (map.texel_probability(i) / map.row_omega[y]);
            let r0 = *ratio.get_or_insert(r);
            assert!((r - r0).abs() < 1e-4 * r0, "texel {i}: L/pdf {r} vs {r0}");
        }
    }

    /// An arbitrary colour-dependent "table", so the test sees whether the precomputed texel
    /// fits are exactly the RGB-emission upsampling of `Environment::radiance`.
    struct Skewed;
    impl RgbToSpectrum for Skewed {
        fn coefficients(&self, rgb: [f32; 3]) -> [f32; 3] {
            [1e-5 * (rgb[0] - rgb[2]), 0.01 * (rgb[1] - 0.5), 2.0 * rgb[0] - rgb[1] - 0.3]
        }
    }

    #[test]
    fn radiance_is_the_rgb_emission_of_the_environments_texel() {
        let texels = (0..32).map(|i| Vec3::new(i as f32 * 0.1, 0.5, (31 - i) as f32 * 0.05)).collect();
        let env = Environment::from_rgb("colours", 8, 4, texels)
            .unwrap()
            .with_intensity(3.0)
            .unwrap()
            .with_rotation_degrees(40.0)
            .unwrap();
        let u = units();
        let map = EnvMap::new(&env, &u, &Skewed).unwrap();
        let l = Vec4::new(400.0, 480.0, 555.0, 690.0);
        let mut rng = Sampler::new(9, 9);
        for _ in 0..200 {
            let [a, b] = rng.next2();
            let d = Vec3::new(a - 0.5, b - 0.5, rng.uniform() - 0.5).normalize();
            let want = u.rgb(env.radiance(d), &Skewed, l);
            let got = map.radiance(d, l);
            assert!((got - want).abs().max_element() <= 1e-5 * want.abs().max_element().max(1e-3), "{d}");
        }
    }

    /// The smallest maps the scene accepts (1×1, 2×1, 3×1, 3×2) and the extreme random numbers
    /// neither panic nor sample outside the sphere.
    #[test]
    fn tiny_maps_and_extreme_numbers_do_not_panic() {
        let last = 1.0 - f32::EPSILON / 2.0;
        for (w, h) in [(1, 1), (2, 1), (3, 1), (3, 2)] {
            let env = Environment::from_rgb("tiny", w, h, vec![Vec3::ONE; (w * h) as usize]).unwrap();
            let map = EnvMap::new(&env, &units(), &GreyOnly).unwrap();
            for u in [[0.0; 6], [last; 6], [0.5, last, 0.0, last, 0.0, last]] {
                let s = map.sample(u).unwrap();
                assert!(s.wi.is_finite() && s.pdf.is_finite() && s.pdf > 0.0);
                assert!((s.pdf - 1.0 / (4.0 * std::f32::consts::PI)).abs() < 1e-5, "{w}×{h}: {}", s.pdf);
                assert!(map.radiance(s.wi, Vec4::splat(500.0)).x > 0.0);
            }
            for d in [Vec3::Y, -Vec3::Y, Vec3::X, Vec3::NEG_Z] {
                assert!(map.pdf(d) > 0.0);
            }
        }
        let black = Environment::from_rgb("black", 4, 2, vec![Vec3::ZERO; 8]).unwrap();
        let map = EnvMap::new(&black, &units(), &GreyOnly).unwrap();
        assert!(map.is_empty() && map.sample([0.5; 6]).is_none() && map.pdf(Vec3::Y) == 0.0);
        // Past what the loader accepts (scene::environment::MAX_RADIANCE), built directly: the
        // tracer's own guard still holds.
        assert!(Environment::from_rgb("huge", 4, 2, vec![Vec3::splat(1e38); 8]).is_err());
        let huge = Environment {
            source: "huge".into(),
            width: 4,
            height: 2,
            texels: vec![Vec3::splat(1e38); 8],
            intensity: 1e6,
            rotation: 0.0,
            sun_light: true,
            sun_min_share: scene::environment::SUN_MIN_SHARE,
        };
        assert!(EnvMap::new(&huge, &units(), &GreyOnly).err().unwrap().to_string().contains("huge"));
    }
}
