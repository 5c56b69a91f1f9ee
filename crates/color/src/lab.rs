//! CIE 1976 L*a*b* (CIELAB).

const EPSILON: f64 = 216.0 / 24389.0;
const KAPPA: f64 = 24389.0 / 27.0;

/// XYZ → L*a*b* relative to `white` (the XYZ of the reference white, usually Y = 1).
///
/// Uses the exact CIE constants ε = 216/24389 and κ = 24389/27 rather than the rounded
/// 0.008856 / 903.3, so the two branches meet continuously.
pub fn xyz_to_lab(xyz: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    let f = |t: f64| if t > EPSILON { t.cbrt() } else { (KAPPA * t + 16.0) / 116.0 };
    let fx = f(xyz[0] / white[0]);
    let fy = f(xyz[1] / white[1]);
    let fz = f(xyz[2] / white[2]);
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

/// L*a*b* → XYZ relative to `white`.
pub fn lab_to_xyz(lab: [f64; 3], white: [f64; 3]) -> [f64; 3] {
    let fy = (lab[0] + 16.0) / 116.0;
    let fx = fy + lab[1] / 500.0;
    let fz = fy - lab[2] / 200.0;
    let inv = |f: f64| {
        let f3 = f * f * f;
        if f3 > EPSILON { f3 } else { (116.0 * f - 16.0) / KAPPA }
    };
    let yr = if lab[0] > KAPPA * EPSILON { fy * fy * fy } else { lab[0] / KAPPA };
    [inv(fx) * white[0], yr * white[1], inv(fz) * white[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    const D65: [f64; 3] = [0.95047, 1.0, 1.08883];

    #[test]
    fn white_is_l100() {
        let l = xyz_to_lab(D65, D65);
        assert!((l[0] - 100.0).abs() < 1e-12 && l[1].abs() < 1e-12 && l[2].abs() < 1e-12);
    }

    // Reference: colour-science 0.4.7, colour.XYZ_to_Lab([0.20654008, 0.12197225, 0.05136952],
    // illuminant xy (0.3127, 0.3290)) = [41.52787529, 52.63858304, 26.92317922].
    #[test]
    fn matches_colour_science() {
        let w = crate::xyz::xy_to_xyz([0.3127, 0.3290]);
        let l = xyz_to_lab([0.20654008, 0.12197225, 0.05136952], w);
        let e = [41.52787529, 52.63858304, 26.92317922];
        for k in 0..3 {
            assert!((l[k] - e[k]).abs() < 1e-6, "{l:?}");
        }
    }

    #[test]
    fn round_trips_both_branches() {
        for xyz in [[0.5, 0.4, 0.3], [0.001, 0.002, 0.0005], [0.0, 0.0, 0.0], [1.2, 1.0, 0.9]] {
            let back = lab_to_xyz(xyz_to_lab(xyz, D65), D65);
            for k in 0..3 {
                assert!((back[k] - xyz[k]).abs() < 1e-12, "{xyz:?} -> {back:?}");
            }
        }
    }
}
