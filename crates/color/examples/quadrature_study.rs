//! Which quadrature for N reflectance nodes: `cargo run --release -p color --example
//! quadrature_study [COLOURS]`.
//!
//! Random sRGB colours (seeded) upsampled through the sRGB Jakob–Hanika table, lit by a spiky
//! (F11), a peaked (LED-RGB1) and a smooth (D65) light, integrated over 380–730 nm with the
//! midpoint rule and with prefiltered weights of three interpolation bases, against the dense
//! 0.25 nm integral. Prints mean and max CIEDE2000 (Lab relative to the light's own white) per N.
//! A fourth row, "learned", tries weights fitted to the data instead: Catmull–Rom plus a ridge
//! regression of the exact XYZ residual on the node values of 4,096 other upsampled colours
//! (constants kept exact). It does not beat the cubic bases enough to be worth a prior.

use color::quadrature::{Basis, NodeQuadrature, Nodes, Quadrature, dense_integral, integrate_nodes};
use color::upsample::roundtrip::random_colours;
use color::{Observer, WavelengthRange, ciede2000, illuminant, xyz_to_lab};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n_colours: usize = std::env::args().nth(1).map(|s| s.parse()).transpose()?.unwrap_or(3000);
    let table = color::upsample::cache::table("srgb")?;
    let obs = Observer::cie1931();
    let range = WavelengthRange::VISIBLE;
    let colours = random_colours(n_colours, 7);
    let polys: Vec<_> = colours.iter().map(|&c| table.fetch(c)).collect();
    let train: Vec<_> = random_colours(4096, 11).iter().map(|&c| table.fetch(c)).collect();
    let rules: [(&str, Quadrature, Basis); 4] = [
        ("midpoint", Quadrature::Midpoint, Basis::Linear),
        ("linear", Quadrature::Prefiltered, Basis::Linear),
        ("catmull-rom", Quadrature::Prefiltered, Basis::CatmullRom),
        ("spline", Quadrature::Prefiltered, Basis::Spline),
    ];
    let ns = [4usize, 6, 8, 12, 16, 18, 24, 32, 64];
    println!("{n_colours} random sRGB colours, 380–730 nm, mean / max ΔE2000 against the dense integral");
    for light_name in ["F11", "LED-RGB1", "D65"] {
        let light = illuminant::by_name(light_name)?;
        let white = dense_integral(range, &obs, |l| light.eval(l));
        let truth: Vec<[f64; 3]> = polys
            .iter()
            .map(|p| xyz_to_lab(dense_integral(range, &obs, |l| p.eval(l) * light.eval(l)), white))
            .collect();
        println!("\n{light_name}");
        print!("{:<12}", "N");
        for n in ns {
            print!("{n:>14}");
        }
        println!();
        for (name, rule, basis) in
            rules.iter().copied().chain([("learned", Quadrature::Prefiltered, Basis::Linear)])
        {
            print!("{name:<12}");
            for n in ns {
                let learned = name == "learned";
                let basis = if learned { Basis::CatmullRom } else { basis };
                let q = NodeQuadrature::with_basis(rule, Nodes::new(range, n, 0.5)?, &obs, basis);
                let mut w = q.weights(|l| light.eval(l));
                if learned {
                    w = learn(&q, &w, &train, &obs, range, &|l| light.eval(l));
                }
                let qw = color::quadrature::sum_weights(&w);
                let (mut sum, mut max) = (0.0, 0.0f64);
                for (p, t) in polys.iter().zip(&truth) {
                    let vals: Vec<f64> = q.nodes.lambda.iter().map(|&l| p.eval(l)).collect();
                    // Each rule's own white, as the renderer normalises.
                    let de = ciede2000(xyz_to_lab(integrate_nodes(&w, &vals), qw), *t);
                    sum += de;
                    max = max.max(de);
                }
                print!("{:>14}", format!("{:.3}/{:.2}", sum / polys.len() as f64, max));
            }
            println!();
        }
    }
    Ok(())
}

/// Ridge regression of the exact XYZ residual of `w` on the node values of `train`, with the
/// constant spectrum weighted heavily so that a constant stays exact.
fn learn(
    q: &NodeQuadrature,
    w: &[[f64; 3]],
    train: &[color::upsample::SigmoidPolynomial],
    obs: &Observer,
    range: WavelengthRange,
    light: &dyn Fn(f64) -> f64,
) -> Vec<[f64; 3]> {
    let n = q.len();
    let mut ata = vec![vec![0.0; n]; n];
    let mut atb = vec![[0.0; 3]; n];
    let mut add = |p: &[f64], r: [f64; 3], wt: f64| {
        for i in 0..n {
            for j in 0..n {
                ata[i][j] += wt * p[i] * p[j];
            }
            for c in 0..3 {
                atb[i][c] += wt * p[i] * r[c];
            }
        }
    };
    for poly in train {
        let p: Vec<f64> = q.nodes.lambda.iter().map(|&l| poly.eval(l)).collect();
        let y = dense_integral(range, obs, |l| poly.eval(l) * light(l));
        let got = integrate_nodes(w, &p);
        add(&p, [y[0] - got[0], y[1] - got[1], y[2] - got[2]], 1.0);
    }
    let ones = vec![1.0; n];
    add(&ones, [0.0; 3], 1e4 * train.len() as f64);
    let tr: f64 = (0..n).map(|i| ata[i][i]).sum::<f64>() / n as f64;
    for (i, row) in ata.iter_mut().enumerate() {
        row[i] += 1e-9 * tr;
    }
    // Gauss–Jordan on [ata | atb].
    let mut a: Vec<Vec<f64>> =
        ata.iter().zip(&atb).map(|(r, b)| r.iter().copied().chain(b.iter().copied()).collect()).collect();
    for c in 0..n {
        let piv = (c..n).max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs())).unwrap();
        a.swap(c, piv);
        let d = a[c][c];
        let pivot = a[c].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != c {
                let f = row[c] / d;
                row.iter_mut().zip(&pivot).skip(c).for_each(|(v, p)| *v -= f * p);
            }
        }
    }
    (0..n).map(|i| std::array::from_fn(|c| w[i][c] + a[i][n + c] / a[i][i])).collect()
}
