//! Colour differences: CIEDE2000.

/// CIEDE2000 colour difference (Sharma, Wu & Dalal 2005) with k_L = k_C = k_H = 1.
///
/// Hue angles follow the paper's rules exactly, including the mean-hue rule when the two hues
/// are 180° apart, so all 34 published test pairs are reproduced. Symmetric in its arguments.
pub fn ciede2000(lab1: [f64; 3], lab2: [f64; 3]) -> f64 {
    let [l1, a1, b1] = lab1;
    let [l2, a2, b2] = lab2;
    let c1 = a1.hypot(b1);
    let c2 = a2.hypot(b2);
    let cbar7 = ((c1 + c2) * 0.5).powi(7);
    let g = 0.5 * (1.0 - (cbar7 / (cbar7 + 25f64.powi(7))).sqrt());
    let a1p = a1 * (1.0 + g);
    let a2p = a2 * (1.0 + g);
    let c1p = a1p.hypot(b1);
    let c2p = a2p.hypot(b2);
    let hue = |b: f64, a: f64| {
        if a == 0.0 && b == 0.0 {
            0.0
        } else {
            let h = b.atan2(a).to_degrees();
            if h < 0.0 { h + 360.0 } else { h }
        }
    };
    let h1p = hue(b1, a1p);
    let h2p = hue(b2, a2p);

    let dlp = l2 - l1;
    let dcp = c2p - c1p;
    let dh = h2p - h1p;
    let dhp = if c1p * c2p == 0.0 {
        0.0
    } else if dh.abs() <= 180.0 {
        dh
    } else if dh > 180.0 {
        dh - 360.0
    } else {
        dh + 360.0
    };
    let dhp_big = 2.0 * (c1p * c2p).sqrt() * (dhp.to_radians() * 0.5).sin();

    let lbar = (l1 + l2) * 0.5;
    let cbarp = (c1p + c2p) * 0.5;
    let hsum = h1p + h2p;
    let hbarp = if c1p * c2p == 0.0 {
        hsum
    } else if (h1p - h2p).abs() <= 180.0 {
        hsum * 0.5
    } else if hsum < 360.0 {
        (hsum + 360.0) * 0.5
    } else {
        (hsum - 360.0) * 0.5
    };
    let t = 1.0 - 0.17 * (hbarp - 30.0).to_radians().cos()
        + 0.24 * (2.0 * hbarp).to_radians().cos()
        + 0.32 * (3.0 * hbarp + 6.0).to_radians().cos()
        - 0.20 * (4.0 * hbarp - 63.0).to_radians().cos();
    let dtheta = 30.0 * (-((hbarp - 275.0) / 25.0).powi(2)).exp();
    let cbarp7 = cbarp.powi(7);
    let rc = 2.0 * (cbarp7 / (cbarp7 + 25f64.powi(7))).sqrt();
    let lb50 = (lbar - 50.0).powi(2);
    let sl = 1.0 + 0.015 * lb50 / (20.0 + lb50).sqrt();
    let sc = 1.0 + 0.045 * cbarp;
    let sh = 1.0 + 0.015 * cbarp * t;
    let rt = -(2.0 * dtheta).to_radians().sin() * rc;

    let (tl, tc, th) = (dlp / sl, dcp / sc, dhp_big / sh);
    (tl * tl + tc * tc + th * th + rt * tc * th).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sharma_pairs() -> Vec<([f64; 3], [f64; 3], f64)> {
        include_str!("../tests/data/sharma2005.csv")
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                ([v[0], v[1], v[2]], [v[3], v[4], v[5]], v[6])
            })
            .collect()
    }

    #[test]
    fn sharma_wu_dalal_pairs() {
        let pairs = sharma_pairs();
        assert_eq!(pairs.len(), 34);
        for (i, (a, b, expected)) in pairs.iter().enumerate() {
            let d = ciede2000(*a, *b);
            assert!((d - expected).abs() < 1e-4, "pair {}: {d} vs {expected}", i + 1);
        }
    }

    #[test]
    fn symmetric_and_zero_on_identity() {
        for (a, b, _) in sharma_pairs() {
            assert!((ciede2000(a, b) - ciede2000(b, a)).abs() < 1e-12);
            assert_eq!(ciede2000(a, a), 0.0);
        }
    }
}
