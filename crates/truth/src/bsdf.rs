//! The glTF 2.0 metallic-roughness BRDF (specification, appendix B), one lane per wavelength:
//!
//! f = (1 − F)·c_diff/π + F·D·V, with c_diff = base·(1 − metallic),
//! F = f0 + (1 − f0)(1 − |v·h|)⁵, f0 = lerp(0.04, base, metallic), α = roughness²,
//! D the Trowbridge–Reitz (GGX) distribution and V the height-correlated Smith visibility
//! V = 0.5 / (n·l·√(n·v²(1−α²)+α²) + n·v·√(n·l²(1−α²)+α²)) the appendix's implementation uses.
//!
//! Directions are in the local shading frame (normal = +z). Sampling mixes a cosine lobe with
//! GGX visible-normal sampling (Heitz 2018); the mixture weight is the same for all four
//! wavelengths, so one pdf serves the whole path.

use crate::sampling::cosine_hemisphere;
use glam::{Vec3, Vec4};
use std::f32::consts::{FRAC_1_PI, PI};

/// Smallest α: below it the lobe is a mirror that neither NEE nor f32 can represent.
const MIN_ALPHA: f32 = 1e-3;

#[derive(Clone, Copy, Debug)]
pub struct Brdf {
    pub base: Vec4,
    pub metallic: f32,
    pub alpha: f32,
    /// Pure Lambert (base/π), ignoring metallic and roughness: only for comparisons with
    /// renderers that have no glTF BRDF (Mitsuba's `diffuse`).
    pub lambert: bool,
}

/// A sampled direction with its BRDF value and pdf (solid angle).
pub struct BrdfSample {
    pub wi: Vec3,
    pub f: Vec4,
    pub pdf: f32,
}

impl Brdf {
    pub fn new(base: Vec4, metallic: f32, roughness: f32) -> Self {
        let r = roughness.clamp(0.0, 1.0);
        Brdf { base, metallic: metallic.clamp(0.0, 1.0), alpha: (r * r).max(MIN_ALPHA), lambert: false }
    }

    pub fn lambertian(base: Vec4) -> Self {
        Brdf { base, metallic: 0.0, alpha: 1.0, lambert: true }
    }

    fn f0(&self) -> Vec4 {
        Vec4::splat(0.04 * (1.0 - self.metallic)) + self.base * self.metallic
    }

    fn d(&self, n_h: f32) -> f32 {
        let a2 = self.alpha * self.alpha;
        let t = n_h * n_h * (a2 - 1.0) + 1.0;
        a2 / (PI * t * t)
    }

    fn vis(&self, n_l: f32, n_v: f32) -> f32 {
        let a2 = self.alpha * self.alpha;
        let gv = n_l * (n_v * n_v * (1.0 - a2) + a2).sqrt();
        let gl = n_v * (n_l * n_l * (1.0 - a2) + a2).sqrt();
        let s = gv + gl;
        if s > 0.0 { 0.5 / s } else { 0.0 }
    }

    /// Smith G1 for the visible-normal pdf.
    fn g1(&self, n_v: f32) -> f32 {
        let a2 = self.alpha * self.alpha;
        2.0 * n_v / (n_v + (a2 + (1.0 - a2) * n_v * n_v).sqrt())
    }

    /// Probability of sampling the specular lobe: its share of the Fresnel-weighted albedo
    /// estimate at normal incidence, averaged over the four wavelengths.
    fn p_spec(&self, n_v: f32) -> f32 {
        if self.lambert {
            return 0.0;
        }
        let f0 = self.f0();
        let fr = f0 + (Vec4::ONE - f0) * (1.0 - n_v).max(0.0).powi(5);
        let spec = fr.element_sum();
        let diff = ((Vec4::ONE - fr) * self.base * (1.0 - self.metallic)).element_sum();
        if spec + diff <= 0.0 { 1.0 } else { (spec / (spec + diff)).clamp(0.05, 1.0) }
    }

    /// f(wo, wi), zero unless both are above the surface.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec4 {
        let (n_v, n_l) = (wo.z, wi.z);
        if n_v <= 0.0 || n_l <= 0.0 {
            return Vec4::ZERO;
        }
        if self.lambert {
            return self.base * FRAC_1_PI;
        }
        let h = (wo + wi).normalize();
        let v_h = wo.dot(h).abs();
        let f0 = self.f0();
        let fr = f0 + (Vec4::ONE - f0) * (1.0 - v_h).powi(5);
        let diffuse = (Vec4::ONE - fr) * self.base * ((1.0 - self.metallic) * FRAC_1_PI);
        diffuse + fr * (self.d(h.z) * self.vis(n_l, n_v))
    }

    /// The pdf [`Self::sample`] draws `wi` with.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (n_v, n_l) = (wo.z, wi.z);
        if n_v <= 0.0 || n_l <= 0.0 {
            return 0.0;
        }
        let ps = self.p_spec(n_v);
        let h = (wo + wi).normalize();
        let v_h = wo.dot(h).max(0.0);
        // Visible-normal pdf of h, then the reflection Jacobian 1/(4·v·h).
        let pdf_spec = if v_h > 0.0 { self.g1(n_v) * self.d(h.z) / (4.0 * n_v) } else { 0.0 };
        ps * pdf_spec + (1.0 - ps) * n_l * FRAC_1_PI
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BrdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let wi = if u_lobe < self.p_spec(wo.z) {
            let h = self.sample_visible_normal(wo, u);
            let wi = 2.0 * wo.dot(h) * h - wo;
            if wi.z <= 0.0 {
                return None;
            }
            wi
        } else {
            cosine_hemisphere(u)
        };
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BrdfSample { wi, f: self.eval(wo, wi), pdf })
    }

    /// Heitz 2018, "Sampling the GGX distribution of visible normals".
    fn sample_visible_normal(&self, wo: Vec3, u: [f32; 2]) -> Vec3 {
        let a = self.alpha;
        let vh = Vec3::new(a * wo.x, a * wo.y, wo.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
        let t2 = vh.cross(t1);
        let r = u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        Vec3::new(a * nh.x, a * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Sampler;

    fn dir(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    #[test]
    fn lambert_limit() {
        // metallic 0, f0 = 0.04: at normal incidence the diffuse part is 0.96·base/π.
        let b = Brdf::new(Vec4::splat(0.5), 0.0, 1.0);
        let f = b.eval(Vec3::Z, Vec3::Z);
        let diffuse = 0.96 * 0.5 / PI;
        assert!(f.x > diffuse && f.x < diffuse + 0.1);
    }

    #[test]
    fn lambertian_has_albedo_base() {
        let b = Brdf::lambertian(Vec4::splat(0.6));
        assert!((b.eval(dir(0.2, 0.0), dir(1.0, 1.0)) - Vec4::splat(0.6 / PI)).abs().max_element() < 1e-7);
        assert!((b.pdf(dir(0.2, 0.0), dir(1.0, 1.0)) - 1.0f32.cos() / PI).abs() < 1e-6);
    }

    #[test]
    fn reciprocal() {
        let b = Brdf::new(Vec4::new(0.9, 0.5, 0.2, 0.7), 0.4, 0.35);
        let (a, c) = (dir(0.3, 0.2), dir(1.1, 2.5));
        assert!((b.eval(a, c) - b.eval(c, a)).abs().max_element() < 1e-5);
    }

    /// The pdf integrates (by quadrature) to the fraction of samples the sampler returns
    /// (GGX reflections that go below the horizon are lost, so it can be below one), and the
    /// sampler's estimate of ∫ f cos equals the quadrature's.
    #[test]
    fn pdf_normalised_and_sampling_consistent() {
        for (m, r) in [(0.0, 0.5), (1.0, 0.3), (0.5, 0.8), (1.0, 0.1)] {
            let b = Brdf::new(Vec4::new(0.8, 0.6, 0.3, 0.9), m, r);
            let wo = dir(0.6, 0.0);
            let (nt, np) = (800, 400);
            let (mut ip, mut ialb) = (0.0f64, Vec4::ZERO);
            for i in 0..nt {
                // Quadrature in cos θ for a smooth integrand near the pole.
                let c0 = (i as f32 + 0.5) / nt as f32;
                for j in 0..np {
                    let phi = 2.0 * PI * (j as f32 + 0.5) / np as f32;
                    let wi = dir(c0.acos(), phi);
                    let dw = (1.0 / nt as f32) * (2.0 * PI / np as f32);
                    ip += (b.pdf(wo, wi) * dw) as f64;
                    ialb += b.eval(wo, wi) * wi.z * dw;
                }
            }
            let mut s = Sampler::new(1, 2);
            let n = 200_000;
            let mut est = Vec4::ZERO;
            let mut returned = 0;
            for _ in 0..n {
                if let Some(x) = b.sample(wo, s.uniform(), s.next2()) {
                    est += x.f * x.wi.z / x.pdf;
                    returned += 1;
                }
            }
            est /= n as f32;
            let frac = returned as f64 / n as f64;
            assert!(ip <= 1.0 + 1e-3 && (ip - frac).abs() < 0.01, "m={m} r={r}: ∫pdf = {ip}, sampled {frac}");
            assert!((est - ialb).abs().max_element() < 0.01, "m={m} r={r}: {est} vs {ialb}");
            // Energy conservation (single scattering never exceeds 1).
            assert!(ialb.max_element() <= 1.0);
        }
    }
}
