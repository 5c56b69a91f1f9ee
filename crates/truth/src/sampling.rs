//! Warping uniform numbers into directions and points, and the MIS heuristic.

use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// An orthonormal frame around a unit normal (Duff et al. 2017, branchless).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

impl Frame {
    pub fn from_normal(n: Vec3) -> Self {
        let s = 1.0f32.copysign(n.z);
        let a = -1.0 / (s + n.z);
        let b = n.x * n.y * a;
        Frame {
            t: Vec3::new(1.0 + s * n.x * n.x * a, s * b, -s * n.x),
            b: Vec3::new(b, s + n.y * n.y * a, -n.y),
            n,
        }
    }

    /// A frame whose first axis follows `t` projected onto the plane of `n` (for tangent space).
    pub fn from_normal_tangent(n: Vec3, t: Vec3, handedness: f32) -> Self {
        let t = (t - n * n.dot(t)).normalize_or_zero();
        if t == Vec3::ZERO {
            return Self::from_normal(n);
        }
        Frame { t, b: n.cross(t) * handedness, n }
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

/// Cosine-weighted hemisphere around +z (Malley: concentric disk, lifted). pdf = cosθ/π.
pub fn cosine_hemisphere(u: [f32; 2]) -> Vec3 {
    let d = concentric_disk(u);
    Vec3::new(d.x, d.y, (1.0 - d.length_squared()).max(0.0).sqrt())
}

fn concentric_disk(u: [f32; 2]) -> Vec2 {
    let o = Vec2::new(2.0 * u[0] - 1.0, 2.0 * u[1] - 1.0);
    if o == Vec2::ZERO {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, PI / 4.0 * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y))
    };
    Vec2::new(r * theta.cos(), r * theta.sin())
}

/// Uniform barycentrics on a triangle (Heitz 2019 low-distortion map, area-preserving).
pub fn triangle_barycentrics(u: [f32; 2]) -> (f32, f32, f32) {
    let (mut b0, mut b1);
    if u[0] < u[1] {
        b0 = u[0] / 2.0;
        b1 = u[1] - b0;
    } else {
        b1 = u[1] / 2.0;
        b0 = u[0] - b1;
    }
    b0 = b0.clamp(0.0, 1.0);
    b1 = b1.clamp(0.0, 1.0 - b0);
    (b0, b1, 1.0 - b0 - b1)
}

/// Veach's power heuristic (β = 2) for one sample from each of two strategies.
#[inline]
pub fn power_heuristic(pdf_a: f32, pdf_b: f32) -> f32 {
    let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
    if a + b == 0.0 {
        0.0
    } else if (a + b).is_infinite() {
        // A pdf beyond ≈ 1.8·10¹⁹ (a near-delta lobe) squares past f32's range, and ∞/∞ is NaN:
        // the same weight in f64; an infinite pdf takes it all, two share it.
        let (a, b) = (f64::from(pdf_a).powi(2), f64::from(pdf_b).powi(2));
        match (a.is_infinite(), b.is_infinite()) {
            (true, true) => 0.5,
            (true, false) => 1.0,
            (false, true) => 0.0,
            (false, false) => (a / (a + b)) as f32,
        }
    } else {
        a / (a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pdfs whose squares overflow f32 still weigh as the ratio says (they gave NaN).
    #[test]
    fn power_heuristic_survives_huge_pdfs() {
        assert_eq!(power_heuristic(4e19, 1.0), 1.0);
        assert!(power_heuristic(1.0, 4e19) < 1e-30);
        assert_eq!(power_heuristic(4e19, 4e19), 0.5);
        assert!((power_heuristic(4e19, 2e19) - 0.8).abs() < 1e-6);
        assert_eq!(power_heuristic(f32::INFINITY, 3.0), 1.0);
        assert_eq!(power_heuristic(f32::INFINITY, f32::INFINITY), 0.5);
        // Ordinary pdfs as before.
        assert_eq!(power_heuristic(2.0, 1.0), 0.8);
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
    }

    #[test]
    fn frame_is_orthonormal() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::new(0.3, -0.5, 0.8).normalize(), Vec3::X] {
            let f = Frame::from_normal(n);
            assert!((f.t.dot(f.b)).abs() < 1e-6 && (f.t.dot(n)).abs() < 1e-6 && (f.b.dot(n)).abs() < 1e-6);
            let v = Vec3::new(0.2, 0.4, -0.7);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-6);
        }
    }

    #[test]
    fn cosine_hemisphere_has_mean_cos_two_thirds() {
        // E[cosθ] under pdf cosθ/π is 2/3.
        let n = 200;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let d = cosine_hemisphere([(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32]);
                assert!((d.length() - 1.0).abs() < 1e-4 && d.z >= 0.0);
                sum += d.z as f64;
            }
        }
        assert!((sum / (n * n) as f64 - 2.0 / 3.0).abs() < 1e-3);
    }

    #[test]
    fn triangle_samples_are_uniform() {
        // Mean barycentric is (1/3, 1/3, 1/3) for a uniform density.
        let n = 100;
        let mut m = [0.0f64; 3];
        for i in 0..n {
            for j in 0..n {
                let (a, b, c) =
                    triangle_barycentrics([(i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32]);
                assert!(a >= 0.0 && b >= 0.0 && c >= -1e-6);
                m[0] += a as f64;
                m[1] += b as f64;
                m[2] += c as f64;
            }
        }
        for v in m {
            assert!((v / (n * n) as f64 - 1.0 / 3.0).abs() < 1e-3);
        }
    }
}
