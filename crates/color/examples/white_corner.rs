//! Near white: direct fetch vs the negated complement fetch, and the blend band, measured on a
//! table: `cargo run --release -p color --example white_corner -- SPACE FILE.coeff`.
use color::upsample::{
    CoeffTable, SigmoidPolynomial, fit::LabModel, fit::nm_to_normalised, roundtrip::random_colours,
};

fn de(m: &LabModel, rgb: [f64; 3], c: [f64; 3]) -> f64 {
    color::ciede2000(m.target_lab(rgb), m.lab_of_xyz(m.xyz(nm_to_normalised(c))))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let space = color::RgbColorSpace::by_name(&a[1])?;
    let t = CoeffTable::read(std::path::Path::new(&a[2]))?;
    let m = LabModel::new(&space)?;
    let direct = |rgb: [f64; 3]| t.fetch(rgb).c;
    let comp = |rgb: [f64; 3]| t.fetch(rgb.map(|v| 1.0 - v)).c.map(|v| -v);
    for thr in [0.3, 0.5, 0.7, 0.8, 0.9, 0.95, 0.97] {
        // Region min ≥ thr: errors of both fetches; on the boundary: spectral jump.
        let pts: Vec<[f64; 3]> =
            random_colours(20000, 7).into_iter().map(|u| u.map(|v| thr + (1.0 - thr) * v)).collect();
        let (mut dmax, mut cmax, mut csum) = (0.0f64, 0.0f64, 0.0);
        let mut cworst = [0.0; 3];
        for &p in &pts {
            dmax = dmax.max(de(&m, p, direct(p)));
            let e = de(&m, p, comp(p));
            csum += e;
            if e > cmax {
                cmax = e;
                cworst = p;
            }
        }
        let mut jump = 0.0f64;
        for (n, mut p) in random_colours(2000, 9).into_iter().enumerate() {
            p = p.map(|v| thr + (1.0 - thr) * v);
            p[n % 3] = thr;
            let (s1, s2) = (SigmoidPolynomial { c: direct(p) }, SigmoidPolynomial { c: comp(p) });
            for lam in (380..=730).step_by(5) {
                jump = jump.max((s1.eval(lam as f64) - s2.eval(lam as f64)).abs());
            }
        }
        println!(
            "thr {thr}: direct max {dmax:.3}  complement max {cmax:.4} mean {:.5} at {cworst:.4?}  boundary spectral jump {jump:.4}",
            csum / pts.len() as f64
        );
    }
    // Blended band: α = smoothstep((min − t0)/(t1 − t0)), coefficients blended.
    for (t0, t1) in [(0.3, 0.5), (0.2, 0.4), (0.5, 0.7), (0.6, 0.8), (0.5, 0.8), (0.7, 0.9), (0.4, 0.7)] {
        let blend = |rgb: [f64; 3]| {
            let mn = rgb.iter().cloned().fold(1.0, f64::min);
            let u = ((mn - t0) / (t1 - t0)).clamp(0.0, 1.0);
            let al = u * u * (3.0 - 2.0 * u);
            let (d, c) = (direct(rgb), comp(rgb));
            [0, 1, 2].map(|k| (1.0 - al) * d[k] + al * c[k])
        };
        let (mut bmax, mut bsum, mut worst) = (0.0f64, 0.0, [0.0; 3]);
        let pts: Vec<[f64; 3]> =
            random_colours(40000, 11).into_iter().map(|u| u.map(|v| t0 - 0.05 + (1.05 - t0) * v)).collect();
        for &p in &pts {
            let p = p.map(|v: f64| v.min(1.0));
            let e = de(&m, p, blend(p));
            bsum += e;
            if e > bmax {
                bmax = e;
                worst = p;
            }
        }
        println!("band {t0}..{t1}: max {bmax:.4} mean {:.5} at {worst:.4?}", bsum / pts.len() as f64);
    }
    Ok(())
}
