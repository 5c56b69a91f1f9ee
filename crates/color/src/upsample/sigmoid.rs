//! The Jakob–Hanika spectral model: a quadratic polynomial squashed by a sigmoid.
//!
//! `s(λ) = ½ + x / (2·√(1 + x²))` with `x = (c0·λ + c1)·λ + c2` and λ in nanometres. Three
//! coefficients describe a smooth reflectance that is bounded to (0, 1) by construction, so
//! every spectrum the tables produce is physically plausible. The scalar `f64` path is the
//! reference; the `f32` 4- and 8-wide paths are what a renderer uses per shading point (the
//! WGSL shader evaluates the same formula in `f32`).

use wide::{f32x4, f32x8};

/// Coefficients `c = [c0, c1, c2]` of the sigmoid polynomial, for λ in nanometres.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SigmoidPolynomial {
    pub c: [f64; 3],
}

/// `½ + x / (2·√(1 + x²))`, with the limits for infinite `x` (the formula itself would give
/// `∞/∞`).
#[inline]
pub fn sigmoid(x: f64) -> f64 {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + 0.5 * x / (1.0 + x * x).sqrt()
}

impl SigmoidPolynomial {
    pub const fn new(c0: f64, c1: f64, c2: f64) -> Self {
        SigmoidPolynomial { c: [c0, c1, c2] }
    }

    /// The polynomial `x(λ)` before the sigmoid.
    #[inline]
    pub fn poly(&self, lambda: f64) -> f64 {
        (self.c[0] * lambda + self.c[1]) * lambda + self.c[2]
    }

    /// Reflectance at `lambda` nanometres, in (0, 1).
    #[inline]
    pub fn eval(&self, lambda: f64) -> f64 {
        sigmoid(self.poly(lambda))
    }

    /// The coefficients rounded to `f32`, as a renderer stores them.
    #[inline]
    pub fn to_f32(&self) -> [f32; 3] {
        self.c.map(|v| v as f32)
    }

    /// One spectrum at four wavelengths, `f32` SIMD. `x` is clamped to ±1e18 first: there the
    /// sigmoid is exactly 0 or 1 in `f32`, and `1 + x²` still fits in an `f32` (no `∞·0 = NaN`).
    #[inline]
    pub fn eval_f32x4(&self, lambda: f32x4) -> f32x4 {
        let [c0, c1, c2] = self.to_f32();
        let x = lambda.mul_add(f32x4::splat(c0), f32x4::splat(c1)).mul_add(lambda, f32x4::splat(c2));
        let x = x.fast_max(f32x4::splat(-1e18)).fast_min(f32x4::splat(1e18));
        let y = f32x4::ONE / x.mul_add(x, f32x4::ONE).sqrt();
        (f32x4::HALF * x).mul_add(y, f32x4::HALF)
    }

    /// One spectrum at eight wavelengths, `f32` SIMD (AVX where the target has it).
    #[inline]
    pub fn eval_f32x8(&self, lambda: f32x8) -> f32x8 {
        let [c0, c1, c2] = self.to_f32();
        let x = lambda.mul_add(f32x8::splat(c0), f32x8::splat(c1)).mul_add(lambda, f32x8::splat(c2));
        let x = x.fast_max(f32x8::splat(-1e18)).fast_min(f32x8::splat(1e18));
        let y = f32x8::ONE / x.mul_add(x, f32x8::ONE).sqrt();
        (f32x8::HALF * x).mul_add(y, f32x8::HALF)
    }

    /// One spectrum at four wavelengths with plain arrays, written so that the compiler can
    /// auto-vectorise it; kept to measure against the explicit SIMD versions.
    #[inline]
    pub fn eval_array<const N: usize>(&self, lambda: [f32; N]) -> [f32; N] {
        let [c0, c1, c2] = self.to_f32();
        lambda.map(|l| {
            let x = ((c0 * l + c1) * l + c2).clamp(-1e18, 1e18);
            0.5 + 0.5 * x / (1.0 + x * x).sqrt()
        })
    }

    /// Evaluates at every wavelength of `lambda` into `out` (same length), eight at a time.
    pub fn eval_slice(&self, lambda: &[f32], out: &mut [f32]) {
        assert_eq!(lambda.len(), out.len(), "eval_slice: lambda and out differ in length");
        let mut lc = lambda.chunks_exact(8);
        let mut oc = out.chunks_exact_mut(8);
        for (l, o) in (&mut lc).zip(&mut oc) {
            let v = self.eval_f32x8(f32x8::from(<[f32; 8]>::try_from(l).unwrap()));
            o.copy_from_slice(&v.to_array());
        }
        for (l, o) in lc.remainder().iter().zip(oc.into_remainder()) {
            *o = self.eval(*l as f64) as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn analytic_values() {
        // x = 0 → ½; x = 1 → ½ + 1/(2√2); x = −√3 → ½ − √3/4.
        assert_eq!(SigmoidPolynomial::new(0.0, 0.0, 0.0).eval(500.0), 0.5);
        let s = SigmoidPolynomial::new(0.0, 0.0, 1.0).eval(123.0);
        assert!((s - (0.5 + 0.5 / 2f64.sqrt())).abs() < 1e-15);
        // c0·λ² + c1·λ + c2 at λ = 500 with c = (1e-5, −0.01, 1.5): 2.5 − 5 + 1.5 = −1.
        let p = SigmoidPolynomial::new(1e-5, -0.01, 1.5);
        assert!((p.poly(500.0) + 1.0).abs() < 1e-12);
        assert!((p.eval(500.0) - (0.5 - 0.5 / 2f64.sqrt())).abs() < 1e-12);
        assert_eq!(sigmoid(f64::INFINITY), 1.0);
        assert_eq!(sigmoid(f64::NEG_INFINITY), 0.0);
    }

    #[test]
    fn simd_paths_match_scalar() {
        let polys = [
            SigmoidPolynomial::new(1e-5, -0.01, 1.5),
            SigmoidPolynomial::new(-2e-4, 0.22, -60.0),
            SigmoidPolynomial::new(0.0, 0.0, 1e30),
            SigmoidPolynomial::new(0.0, 0.0, -1e30),
        ];
        let l8 = [380.0f32, 420.5, 455.0, 500.0, 555.5, 610.0, 700.0, 830.0];
        for p in polys {
            let v8 = p.eval_f32x8(f32x8::from(l8)).to_array();
            let v4a = p.eval_f32x4(f32x4::from([l8[0], l8[1], l8[2], l8[3]])).to_array();
            let va = p.eval_array(l8);
            let mut vs = [0f32; 8];
            p.eval_slice(&l8[..7], &mut vs[..7]);
            for k in 0..8 {
                let want = p.eval(l8[k] as f64);
                assert!((v8[k] as f64 - want).abs() < 2e-6, "{p:?} at {}: {} vs {want}", l8[k], v8[k]);
                assert!((va[k] as f64 - want).abs() < 2e-6);
                if k < 4 {
                    assert!((v4a[k] as f64 - want).abs() < 2e-6);
                }
                if k < 7 {
                    assert!((vs[k] as f64 - want).abs() < 2e-6);
                }
            }
        }
    }
}
