//! `KHR_materials_anisotropy`: highlights stretched along a direction on the surface (brushed
//! metal, hair, satin). This module is the extension's math in one place; both renderers call it
//! (the path tracer directly, the real-time renderer through its shader's port, tested against
//! the f64 functions here), so that the two draw the same lobe.
//!
//! At a point the extension gives a direction in the tangent frame and a strength:
//!
//! - `anisotropyTexture` (linear data): RG is a direction in [−1, 1]² of the (tangent,
//!   bitangent) plane, B a strength in [0, 1]; without a texture (1, 0) and 1;
//! - the direction is rotated by `anisotropyRotation` (radians, counter-clockwise from the
//!   tangent) and taken to the surface by the tangent frame, t = normalize(T·d.x + B·d.y),
//!   b = n × t; the strength is s = `anisotropyStrength` × B.
//!
//! The specular lobe (the dielectric's and the metal's; not a clear coat's or a sheen's) then is
//! GGX with two roughnesses, α_t along t and α_b across it:
//!
//! α_b = α = roughness²,  α_t = mix(α, 1, s²),
//!
//! D(h) = 1 / (π·α_t·α_b·((t·h/α_t)² + (b·h/α_b)² + (n·h)²)²),
//! V = 1 / (2·((n·l)·|(α_t·t·v, α_b·b·v, n·v)| + (n·v)·|(α_t·t·l, α_b·b·l, n·l)|)),
//!
//! the height-correlated Smith visibility G₂/(4·n·l·n·v) for anisotropic GGX (Heitz 2014), as
//! the extension writes them. At s = 0 both are the isotropic lobe exactly. Roughness floors (each
//! renderer's smallest α) apply to α before the mix, as they do without the extension.
//!
//! A zero direction (a texture texel at (0.5, 0.5)) has no orientation: it is read as the
//! rotated tangent, the direction without a texture, so that no renderer divides by zero.

use std::f64::consts::PI;

use crate::TextureRef;
use glam::{DVec3, Vec2, Vec3};

/// A material's anisotropy, as the extension gives it; the values at a point come from
/// [`Anisotropy::at`].
#[derive(Clone, Debug, PartialEq)]
pub struct Anisotropy {
    /// `anisotropyStrength` in [0, 1].
    pub strength: f32,
    /// `anisotropyRotation`, radians counter-clockwise from the tangent.
    pub rotation: f32,
    /// `anisotropyTexture` (linear): RG the direction in [−1, 1]² (encoded as [0, 1]), B a factor
    /// of the strength.
    pub texture: Option<TextureRef>,
}

/// Largest |`anisotropyRotation`| accepted: any angle is a direction, but past this f32 has no
/// fraction of a turn left (2²⁴ ulp ≈ 1 rad at 1.6·10⁷); a file with such a value is broken.
pub const MAX_ROTATION: f32 = 1.0e6;

impl Anisotropy {
    /// The direction in the tangent frame (unit length) and the strength at a point whose
    /// `anisotropyTexture` reads `rgb` (0–1 each, as stored).
    pub fn at(&self, rgb: Option<Vec3>) -> (Vec2, f32) {
        let (d, b) = match rgb {
            Some(c) => (Vec2::new(c.x, c.y) * 2.0 - Vec2::ONE, c.z),
            None => (Vec2::X, 1.0),
        };
        let (s, c) = self.rotation.sin_cos();
        let r = Vec2::new(c * d.x - s * d.y, s * d.x + c * d.y);
        let dir = r.try_normalize().unwrap_or(Vec2::new(c, s));
        (dir, (self.strength * b).clamp(0.0, 1.0))
    }

    /// Whether the extension changes nothing: strength 0 (whatever the texture holds, since it
    /// only multiplies the strength).
    pub fn is_off(&self) -> bool {
        self.strength == 0.0
    }
}

/// (α_t, α_b) of a lobe whose isotropic α is `alpha` (already floored) at strength `s`.
pub fn alphas(alpha: f64, s: f64) -> (f64, f64) {
    (alpha + (1.0 - alpha) * s * s, alpha)
}

/// [`alphas`] in f32, as the renderers compute it.
pub fn alphas_f32(alpha: f32, s: f32) -> (f32, f32) {
    (alpha + (1.0 - alpha) * s * s, alpha)
}

/// The anisotropic GGX distribution at half vector `h` given in the (t, b, n) frame.
pub fn ggx_d(at: f64, ab: f64, h: DVec3) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let k = (h.x / at).powi(2) + (h.y / ab).powi(2) + h.z * h.z;
    1.0 / (PI * at * ab * k * k)
}

/// Smith's Λ for anisotropic GGX at direction `w` in the (t, b, n) frame.
pub fn smith_lambda(at: f64, ab: f64, w: DVec3) -> f64 {
    let t2 = ((at * w.x).powi(2) + (ab * w.y).powi(2)) / (w.z * w.z);
    0.5 * ((1.0 + t2).sqrt() - 1.0)
}

/// The height-correlated visibility G₂/(4·n·l·n·v) in the (t, b, n) frame; 0 below the horizon.
pub fn visibility(at: f64, ab: f64, l: DVec3, v: DVec3) -> f64 {
    if l.z <= 0.0 || v.z <= 0.0 {
        return 0.0;
    }
    let gv = l.z * DVec3::new(at * v.x, ab * v.y, v.z).length();
    let gl = v.z * DVec3::new(at * l.x, ab * l.y, l.z).length();
    0.5 / (gv + gl)
}

/// D·V, the specular lobe without its Fresnel term, for light `l` and view `v` in the (t, b, n)
/// frame.
pub fn lobe(at: f64, ab: f64, l: DVec3, v: DVec3) -> f64 {
    let h = (l + v).normalize_or_zero();
    ggx_d(at, ab, h) * visibility(at, ab, l, v)
}

/// The lobe's directional albedo with Fresnel 1 (a white metal's), ∫ D·V·(n·l) dl over the
/// hemisphere at view `v` (unit, in the (t, b, n) frame), by the midpoint rule in (cos θ, φ)
/// with `n` × 2`n` nodes: the reference both renderers' energy tests measure against (n = 400
/// is within 10⁻³ of n = 1500 away from grazing views).
pub fn albedo(at: f64, ab: f64, v: DVec3, n: usize) -> f64 {
    let mut sum = 0.0;
    for i in 0..n {
        let mu = (i as f64 + 0.5) / n as f64;
        let st = (1.0 - mu * mu).sqrt();
        for j in 0..2 * n {
            let phi = (j as f64 + 0.5) / (2 * n) as f64 * 2.0 * PI;
            sum += lobe(at, ab, DVec3::new(st * phi.cos(), st * phi.sin(), mu), v) * mu;
        }
    }
    sum * PI / (n * n) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The albedo never exceeds 1, nears it for a smooth lobe seen head-on, is the same for the
    /// lobe turned a quarter turn with the view, and agrees across node counts.
    #[test]
    fn the_albedo_is_bounded_symmetric_and_converged() {
        let v = dir(0.7, 0.3);
        let turned = DVec3::new(-v.y, v.x, v.z);
        for (at, ab) in [(0.05, 0.05), (0.3, 0.1), (0.8, 0.2), (1.0, 1.0)] {
            let a = albedo(at, ab, v, 400);
            assert!(a > 0.3 && a <= 1.0, "{at} {ab}: {a}");
            assert!((a - albedo(ab, at, turned, 400)).abs() < 1e-9, "{at} {ab}");
            assert!((a - albedo(at, ab, v, 1500)).abs() < 1e-3, "{at} {ab}");
        }
        // Head-on, a smoother lobe loses less to masking: towards 1 as α → 0.
        let head_on = [0.6, 0.3, 0.1].map(|a| albedo(a, a, DVec3::Z, 1500));
        println!("head-on at α = 0.6, 0.3, 0.1: {head_on:?}");
        assert!(head_on[0] < head_on[1] && head_on[1] < head_on[2] && head_on[2] > 0.98, "{head_on:?}");
    }

    fn dir(theta: f64, phi: f64) -> DVec3 {
        DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    /// ∫ f(ω) dω over the upper hemisphere by the midpoint rule in (cos θ, φ).
    fn hemisphere(n: usize, f: impl Fn(DVec3) -> f64) -> f64 {
        let mut sum = 0.0;
        for i in 0..n {
            let mu = (i as f64 + 0.5) / n as f64;
            for j in 0..2 * n {
                let phi = (j as f64 + 0.5) / (2 * n) as f64 * 2.0 * PI;
                sum += f(dir(mu.acos(), phi));
            }
        }
        sum * (1.0 / n as f64) * (PI / n as f64)
    }

    #[test]
    fn the_distribution_is_normalised() {
        for (at, ab) in [(0.3, 0.3), (0.6, 0.2), (1.0, 0.35), (0.25, 0.8)] {
            let i = hemisphere(600, |h| ggx_d(at, ab, h) * h.z);
            assert!((i - 1.0).abs() < 2e-3, "α = ({at}, {ab}): ∫D·cos = {i}");
        }
    }

    #[test]
    fn the_masking_function_is_consistent() {
        // ∫ G1(v, h)·max(v·h, 0)·D(h) dh = v·n (Heitz 2014, eq. 18).
        for (at, ab) in [(0.4, 0.4), (0.9, 0.3)] {
            for v in [dir(0.3, 0.2), dir(1.1, 1.3), dir(1.4, 2.5)] {
                let g1 = 1.0 / (1.0 + smith_lambda(at, ab, v));
                let i = hemisphere(700, |h| g1 * v.dot(h).max(0.0) * ggx_d(at, ab, h));
                assert!((i - v.z).abs() < 3e-3 * v.z.max(0.1), "α = ({at}, {ab}), v = {v}: {i} vs {}", v.z);
            }
        }
    }

    #[test]
    fn isotropic_at_zero_strength() {
        let (at, ab) = alphas(0.09, 0.0);
        assert_eq!((at, ab), (0.09, 0.09));
        // The textbook isotropic forms.
        let a2: f64 = 0.09 * 0.09;
        for (l, v) in [(dir(0.4, 0.1), dir(0.7, 2.0)), (dir(1.2, -1.0), dir(0.2, 0.5))] {
            let h = (l + v).normalize();
            let d = a2 / (PI * (h.z * h.z * (a2 - 1.0) + 1.0).powi(2));
            let vis = 0.5
                / (l.z * (v.z * v.z * (1.0 - a2) + a2).sqrt() + v.z * (l.z * l.z * (1.0 - a2) + a2).sqrt());
            assert!((lobe(at, ab, l, v) / (d * vis) - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn the_lobe_stretches_along_the_direction() {
        // Light and view mirrored about n and tilted along t: with α_t > α_b the highlight is
        // wider along t, so an off-mirror pair tilted along t keeps more than one along b.
        let (at, ab) = alphas(0.04, 0.8);
        assert!(at > 0.6 && ab == 0.04);
        let v = dir(0.5, 0.0);
        let along = lobe(at, ab, dir(0.5 + 0.3, PI), v);
        let across = lobe(at, ab, DVec3::new(-v.x, 0.25, v.z).normalize(), v);
        assert!(along > 3.0 * across, "{along} vs {across}");
        // Reciprocity.
        let (l, w) = (dir(0.9, 0.4), dir(0.3, 2.2));
        assert!((lobe(at, ab, l, w) - lobe(at, ab, w, l)).abs() < 1e-12);
    }

    #[test]
    fn the_fallback_tangent_is_a_unit_perpendicular() {
        let mut normals = vec![Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y, Vec3::new(0.0, 0.0, -0.0).with_z(-1.0)];
        for i in 0..200 {
            let (a, b) = (i as f32 * 0.731, i as f32 * 0.377);
            normals.push(Vec3::new(a.sin() * b.cos(), a.sin() * b.sin(), a.cos()));
        }
        for n in normals {
            let t = crate::fallback_tangent(n);
            assert!(
                t.w == 1.0 && t.truncate().is_normalized() && t.truncate().dot(n).abs() < 1e-6,
                "{n}: {t}"
            );
        }
    }

    #[test]
    fn direction_and_strength_at_a_point() {
        let a = Anisotropy { strength: 0.5, rotation: std::f32::consts::FRAC_PI_2, texture: None };
        let (d, s) = a.at(None);
        assert!((d - Vec2::Y).length() < 1e-6 && s == 0.5);
        // Texture (1, 0.5, 0.5): direction +t, rotated a quarter turn to +b; strength halved.
        let (d, s) = a.at(Some(Vec3::new(1.0, 0.5, 0.5)));
        assert!((d - Vec2::Y).length() < 1e-6 && (s - 0.25).abs() < 1e-7);
        // A zero direction reads as the rotated tangent.
        let (d, _) = a.at(Some(Vec3::new(0.5, 0.5, 1.0)));
        assert!((d - Vec2::Y).length() < 1e-6);
        // Unnormalised texture directions are normalised.
        let b = Anisotropy { rotation: 0.0, ..a };
        let (d, _) = b.at(Some(Vec3::new(1.0, 1.0, 1.0)));
        assert!((d - Vec2::splat(std::f32::consts::FRAC_1_SQRT_2)).length() < 1e-6);
    }
}
