//! The flat water surface seen from below: Fresnel transmission of a uniform sky through
//! Snell's window, Fresnel reflection and total internal reflection (TIR) outside it.
//!
//! The surface is the top face of the water medium's box (`Medium::surface_ior`). A path that
//! reaches it from below going up, at cosθ = ω_y to the vertical, sees
//!
//! - inside Snell's window (n·sinθ < 1): the sky radiance refracted into the water,
//!   `L_air·T(θ)·n²` — T the exact unpolarised Fresnel transmittance, n² because radiance/n² is
//!   conserved across an interface (the window squeezes the sky's hemisphere into a cone of
//!   half-angle asin(1/n) ≈ 48°); plus the Fresnel-reflected light from below, R = 1 − T;
//! - outside the window: only reflected light (TIR, R = 1).
//!
//! The estimator adds the sky term and then follows the mirror direction with probability R
//! (throughput unchanged, R/R = 1), so it is unbiased for the whole Fresnel surface, and under
//! TIR it always reflects.
//!
//! The sky is uniform with radiance L_air(λ) above the surface, chosen so that the irradiance it
//! gives just below the surface is the scene's sky irradiance E_sky(λ) (`scene::sky`: `sky` ×
//! the sun's downwelling irradiance, the stand-in lights' emission):
//!
//! ```text
//! E_sky = ∫_window L_air·T·n² cosθ_w dω_w = L_air ∫_{2π} T cosθ_a dω_a = π·T̄·L_air
//! ```
//!
//! (n²·cosθ_w·dω_w = cosθ_a·dω_a, étendue), so L_air = E_sky / (π·T̄) with
//! T̄ = 2∫₀¹ T(μ) μ dμ the cosine-weighted hemispherical mean transmittance, [`mean_transmittance`].
//!
//! What is not modelled: waves (the surface is flat), light from objects above the water (the
//! surface shows the sky only; the real-time model refuses such scenes), polarisation along a
//! path (each event uses unpolarised Fresnel), and the sun's own Fresnel loss — the scene's sun
//! is already the light *below* the surface, as in the real-time model.

use crate::medium::Region;
use crate::spectral::DenseSpectrum;
use glam::Vec3;

// The Fresnel functions live with the CPU water model, which the real-time pass tests against.
pub use scene::water::fresnel::{fresnel_reflectance, mean_transmittance, transmittance_up};

/// The surface as the integrator uses it.
#[derive(Clone, Debug)]
pub struct Surface {
    /// Height (y, scene units) of the surface.
    pub height: f32,
    /// Sideways extent (x, z) of the water below it.
    pub min: Vec3,
    pub max: Vec3,
    /// Refractive index of the water relative to the air above.
    pub ior: f32,
    /// Uniform sky radiance above the surface, L_air(λ), in tracer units; `None` = a black sky.
    pub sky: Option<DenseSpectrum>,
}

impl Surface {
    /// The top face of `region` (a box) as a water surface of index `ior` under a sky whose
    /// irradiance just below the surface is `sky_irradiance` (tracer units).
    pub fn new(region: Region, ior: f32, sky_irradiance: Option<DenseSpectrum>) -> Option<Surface> {
        let Region::Box { min, max } = region else { return None };
        let k = 1.0 / (std::f64::consts::PI * mean_transmittance(ior as f64));
        Some(Surface { height: max.y, min, max, ior, sky: sky_irradiance.map(|e| e.scaled(k as f32)) })
    }

    /// Distance along the ray `o + t·d` to the surface, for a ray at or below it going up and
    /// meeting it over the water; `None` otherwise (the surface is seen from below only).
    #[inline]
    pub fn crossing(&self, o: Vec3, d: Vec3) -> Option<f32> {
        if d.y <= 0.0 || o.y > self.height {
            return None;
        }
        let t = (self.height - o.y) / d.y;
        let p = o + d * t;
        (p.x >= self.min.x && p.x <= self.max.x && p.z >= self.min.z && p.z <= self.max.z).then_some(t)
    }

    /// Unpolarised Fresnel reflectance for a ray going up at cosine `cos_w` (1 under TIR).
    #[inline]
    pub fn reflectance(&self, cos_w: f32) -> f32 {
        fresnel_reflectance(cos_w as f64, self.ior as f64, 1.0) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Walsh's closed form of the hemispherical (diffuse) reflectance of a flat dielectric lit
    /// from the rarer side (Walsh 1926; e.g. Judd 1942, J. Res. NBS 29, 329, eq. 11), written
    /// out independently of the quadrature in `mean_transmittance`.
    fn walsh_diffuse_reflectance(n: f64) -> f64 {
        let (n2, n4) = (n * n, n.powi(4));
        0.5 + (n - 1.0) * (3.0 * n + 1.0) / (6.0 * (n + 1.0).powi(2))
            + n2 * (n2 - 1.0).powi(2) / (n2 + 1.0).powi(3) * ((n - 1.0) / (n + 1.0)).ln()
            - 2.0 * n.powi(3) * (n2 + 2.0 * n - 1.0) / ((n2 + 1.0) * (n4 - 1.0))
            + 8.0 * n4 * (n4 + 1.0) / ((n2 + 1.0) * (n4 - 1.0).powi(2)) * n.ln()
    }

    #[test]
    fn mean_transmittance_matches_walshs_closed_form() {
        for n in [1.2, 1.333, 1.34, 1.5, 2.0] {
            let (q, w) = (mean_transmittance(n), 1.0 - walsh_diffuse_reflectance(n));
            assert!((q - w).abs() < 1e-8, "n={n}: quadrature {q} vs closed form {w}");
        }
        // Glass (n = 1.5) reflects the familiar 9.2 % of diffuse light; water (1.34) 6.75 %.
        assert!((1.0 - mean_transmittance(1.5) - 0.0918).abs() < 1e-4);
        assert!((1.0 - mean_transmittance(1.34) - 0.0675).abs() < 1e-4);
    }

    #[test]
    fn fresnel_limits_and_reciprocity() {
        let n = 1.34;
        // Normal incidence: R = ((n − 1)/(n + 1))² from either side.
        let r0 = ((n - 1.0) / (n + 1.0)) * ((n - 1.0) / (n + 1.0));
        assert!((fresnel_reflectance(1.0, 1.0, n) - r0).abs() < 1e-15);
        assert!((transmittance_up(1.0, n) - (1.0 - r0)).abs() < 1e-15);
        // Critical angle asin(1/n): beyond it TIR, just inside it T → 0 continuously.
        let cos_c = (1.0 - 1.0 / (n * n)).sqrt();
        assert_eq!(transmittance_up(cos_c - 1e-6, n), 0.0);
        assert!(transmittance_up(cos_c + 1e-9, n) < 1e-3);
        // Brewster's angle from air: tanθ = n, where the p-polarised part vanishes, so
        // R = Rs/2 with Rs = ((cosθ − n cosθt)/(cosθ + n cosθt))² and θ + θt = 90°.
        let tb = n.atan();
        let rs = ((tb.cos() - n * tb.sin()) / (tb.cos() + n * tb.sin())).powi(2);
        assert!((fresnel_reflectance(tb.cos(), 1.0, n) - 0.5 * rs).abs() < 1e-12);
        // Reciprocity: the same pair of directions transmits the same from both sides.
        for cos_a in [0.05, 0.3, 0.7, 0.99] {
            let sin_w = (1.0f64 - cos_a * cos_a).sqrt() / n;
            let cos_w = (1.0 - sin_w * sin_w).sqrt();
            let (down, up) = (1.0 - fresnel_reflectance(cos_a, 1.0, n), transmittance_up(cos_w, n));
            assert!((down - up).abs() < 1e-12, "{cos_a}: {down} vs {up}");
        }
    }

    #[test]
    fn crossing_from_below_only_and_over_the_water_only() {
        let region = Region::Box { min: Vec3::splat(-10.0), max: Vec3::new(10.0, 2.0, 10.0) };
        let s = Surface::new(region, 1.34, None).unwrap();
        assert_eq!(s.crossing(Vec3::ZERO, Vec3::Y), Some(2.0));
        let d = Vec3::new(1.0, 1.0, 0.0).normalize();
        assert!((s.crossing(Vec3::ZERO, d).unwrap() - 2.0 * 2f32.sqrt()).abs() < 1e-5);
        assert_eq!(s.crossing(Vec3::ZERO, -Vec3::Y), None);
        assert_eq!(s.crossing(Vec3::new(0.0, 3.0, 0.0), Vec3::Y), None);
        assert_eq!(s.crossing(Vec3::new(9.0, 1.0, 0.0), Vec3::new(1.0, 0.1, 0.0).normalize()), None);
        assert!(Surface::new(Region::Everywhere, 1.34, None).is_none());
    }
}

#[cfg(test)]
#[path = "water_surface_tests.rs"]
mod transport_tests;
