//! Thin-film interference (glTF `KHR_materials_iridescence`, issue 30): the reflectance of a
//! dielectric film of thickness d and index η₂ on a base of complex index η₃ = n + ik, seen
//! from air (η₁ = 1, the extension's outside medium), at one wavelength — exactly, by Airy
//! summation of the multiply reflected amplitudes:
//!
//! r = (r₁₂ + r₂₃·e^{iδ}) / (1 + r₁₂·r₂₃·e^{iδ}),  δ = 4π·η₂·d·cos θ₂ / λ,
//!
//! per polarisation with both interfaces' Fresnel amplitudes (their phase shifts included:
//! a real base of lower index than the film reflects with the opposite sign, a conductor or
//! total internal reflection at the base with a complex one), R = (|r_s|² + |r_p|²)/2.
//! The extension's reference code evaluates the same sum in RGB with Schlick interfaces and
//! a Gaussian fit of the colour matching functions (Belcour & Barla 2017); a spectral renderer
//! can afford the exact value per wavelength.
//!
//! One home for every renderer: the path tracer calls [`reflectance`] per wavelength, the
//! real-time shader's WGSL port is tested against it, and `tools/check_film.py` checks it
//! against an independent transfer-matrix evaluation.

use num_complex::Complex64 as C;

/// Largest F0 [`ior_from_f0`] accepts (the extension's clamp: F0 = 1 has no index).
pub const MAX_F0: f64 = 0.9999;

/// The real index of a base whose normal-incidence reflectance from air is `f0`, the
/// extension's convention for a base given by its F0 (a dielectric's 0.04 → 1.5, a metal's
/// base colour → its index with k = 0): η = (1 + √F0) / (1 − √F0).
pub fn ior_from_f0(f0: f64) -> f64 {
    let s = f0.clamp(0.0, MAX_F0).sqrt();
    (1.0 + s) / (1.0 - s)
}

/// cos θ in a medium of index `n` of a ray that makes `sin2_1` = sin²θ₁ with the normal in air:
/// the root whose wave decays into the medium (Im(n·cos θ) ≥ 0), complex for an absorbing
/// medium and beyond the critical angle.
fn cos_in(n: C, sin2_1: f64) -> C {
    let c = (C::new(1.0, 0.0) - sin2_1 / (n * n)).sqrt();
    if (n * c).im < 0.0 { -c } else { c }
}

/// Fresnel amplitude reflection coefficients (s, p) from medium a into medium b.
fn amplitudes(na: C, ca: C, nb: C, cb: C) -> (C, C) {
    let rs = (na * ca - nb * cb) / (na * ca + nb * cb);
    let rp = (nb * ca - na * cb) / (nb * ca + na * cb);
    (rs, rp)
}

/// Reflectance of a film of `thickness_nm` and index `film_ior` (real, ≥ 1) on a base of index
/// `base` (n + ik), for light from air at `cos_i` (clamped to [0, 1]) and wavelength
/// `lambda_nm`; unpolarised. Thickness 0 is the bare base's Fresnel reflectance.
pub fn reflectance(lambda_nm: f64, cos_i: f64, thickness_nm: f64, film_ior: f64, base: C) -> f64 {
    let cos1 = cos_i.clamp(0.0, 1.0);
    let sin2 = 1.0 - cos1 * cos1;
    let n1 = C::new(1.0, 0.0);
    let n2 = C::new(film_ior, 0.0);
    let c1 = C::new(cos1, 0.0);
    let c2 = cos_in(n2, sin2);
    let c3 = cos_in(base, sin2);
    let (r12s, r12p) = amplitudes(n1, c1, n2, c2);
    let (r23s, r23p) = amplitudes(n2, c2, base, c3);
    let delta = 4.0 * std::f64::consts::PI * thickness_nm / lambda_nm * n2 * c2;
    let e = (C::i() * delta).exp();
    let airy = |r12: C, r23: C| {
        let r = (r12 + r23 * e) / (1.0 + r12 * r23 * e);
        r.norm_sqr()
    };
    (0.5 * (airy(r12s, r23s) + airy(r12p, r23p))).clamp(0.0, 1.0)
}

/// The film of a glTF material at one shading point: what [`reflectance`] needs besides the
/// wavelength and the angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Film {
    pub thickness_nm: f64,
    pub ior: f64,
}

impl Film {
    /// The reflectance over a dielectric base of index `base_ior` (real).
    pub fn over_dielectric(&self, lambda_nm: f64, cos_i: f64, base_ior: f64) -> f64 {
        reflectance(lambda_nm, cos_i, self.thickness_nm, self.ior, C::new(base_ior, 0.0))
    }

    /// The reflectance over a base given by its normal-incidence reflectance `f0` at this
    /// wavelength (a metal's base colour), by the extension's real-index convention.
    pub fn over_f0(&self, lambda_nm: f64, cos_i: f64, f0: f64) -> f64 {
        self.over_dielectric(lambda_nm, cos_i, ior_from_f0(f0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fresnel's equations for one interface, written out (no film).
    fn fresnel(cos_i: f64, n: f64) -> f64 {
        let sin_t = (1.0 - cos_i * cos_i).sqrt() / n;
        if sin_t >= 1.0 {
            return 1.0;
        }
        let ct = (1.0 - sin_t * sin_t).sqrt();
        let rs = (cos_i - n * ct) / (cos_i + n * ct);
        let rp = (n * cos_i - ct) / (n * cos_i + ct);
        0.5 * (rs * rs + rp * rp)
    }

    #[test]
    fn no_film_is_the_bare_interface() {
        for &c in &[1.0, 0.8, 0.3, 0.01] {
            for &n in &[1.33, 1.5, 2.4] {
                let r = reflectance(550.0, c, 0.0, 1.7, C::new(n, 0.0));
                assert!((r - fresnel(c, n)).abs() < 1e-12, "cos {c} n {n}: {r} vs {}", fresnel(c, n));
            }
        }
        assert!((ior_from_f0(0.04) - 1.5).abs() < 1e-12);
        // F0 of the index back at normal incidence.
        let n = ior_from_f0(0.6);
        assert!((reflectance(500.0, 1.0, 0.0, 1.3, C::new(n, 0.0)) - 0.6).abs() < 1e-12);
    }

    /// A film index-matched to the base, or to air, vanishes whatever its thickness.
    #[test]
    fn matched_films_vanish() {
        for &d in &[50.0, 333.0, 1200.0] {
            let r = reflectance(600.0, 0.7, d, 1.5, C::new(1.5, 0.0));
            assert!((r - fresnel(0.7, 1.5)).abs() < 1e-12);
            let r = reflectance(600.0, 0.7, d, 1.0, C::new(1.5, 0.0));
            assert!((r - fresnel(0.7, 1.5)).abs() < 1e-12);
        }
    }

    /// A quarter-wave film of index √n_base at normal incidence is a perfect anti-reflection
    /// coating; a half-wave film is absent (the classic closed forms).
    #[test]
    fn quarter_and_half_wave_films() {
        let (nb, lambda) = (2.25, 550.0);
        let nf = f64::sqrt(nb);
        let quarter = lambda / (4.0 * nf);
        assert!(reflectance(lambda, 1.0, quarter, nf, C::new(nb, 0.0)) < 1e-12);
        let half = lambda / (2.0 * nf);
        let r = reflectance(lambda, 1.0, half, nf, C::new(nb, 0.0));
        assert!((r - fresnel(1.0, nb)).abs() < 1e-12);
        // A quarter-wave film of higher index than the base raises the reflectance to
        // ((n_b − n_f²)/(n_b + n_f²))².
        let (nf, nb) = (2.0, 1.5);
        let r = reflectance(lambda, 1.0, lambda / (4.0 * nf), nf, C::new(nb, 0.0));
        let want = ((nb - nf * nf) / (nb + nf * nf)).powi(2);
        assert!((r - want).abs() < 1e-12, "{r} vs {want}");
    }

    /// Energy: between 0 and 1 everywhere, 1 at grazing incidence; a lossless stack's
    /// reflectance at grazing is total.
    #[test]
    fn bounded_and_total_at_grazing() {
        for i in 0..=40 {
            let c = i as f64 / 40.0;
            for &d in &[0.0, 120.0, 470.0, 1200.0] {
                for base in [C::new(1.2, 0.0), C::new(2.0, 0.0), C::new(0.2, 3.4), C::new(1.1, 6.8)] {
                    let r = reflectance(480.0, c, d, 1.6, base);
                    assert!((0.0..=1.0).contains(&r), "{r}");
                }
            }
        }
        assert!((reflectance(500.0, 0.0, 300.0, 1.4, C::new(1.5, 0.0)) - 1.0).abs() < 1e-12);
    }
}
