//! A lever for issue 27 measured and set aside: `cargo run --release -p color --example
//! reflected_grid [N]`. A textured pixel could skip the coefficient fetch and the per-light node
//! loop if what its base colour reflects under each light, Σᵢ ρ(λᵢ)·Wᵢ at N nodes, were read
//! from a per-light table over linear rgb (as constant colours get it once per material,
//! render::material_spectra::reflected_xyz). This prints the ΔE2000 of such a table's trilinear
//! interpolation (G³ grid, linear or √ axes) against the direct evaluation, on 20,000 random
//! colours uniform in linear rgb ("lin") and in sRGB-encoded values ("enc", more dark colours),
//! beside the N-node quadrature's own error against the dense integral. The table's error must
//! stay far below the accuracy contract (0.005 mean ΔE2000 of any evaluated case) to be used.
use color::quadrature::{NodeQuadrature, Nodes, Quadrature, dense_integral, integrate_nodes, sum_weights};
use color::upsample::roundtrip::random_colours;
use color::{Observer, WavelengthRange, ciede2000, illuminant, xyz_to_lab};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let table = color::upsample::cache::table("srgb")?;
    let obs = Observer::cie1931();
    let range = WavelengthRange::VISIBLE;
    let lin = random_colours(20000, 7);
    let enc: Vec<[f64; 3]> = lin.iter().map(|c| c.map(color::colorspace::srgb_decode)).collect();
    let n: usize = std::env::args().nth(1).map(|s| s.parse()).transpose()?.unwrap_or(8);
    let q = NodeQuadrature::new(Quadrature::Prefiltered, Nodes::new(range, n, 0.5)?, &obs);
    for light_name in ["D65", "F11", "LED-RGB1", "A"] {
        let light = illuminant::by_name(light_name)?;
        let w = q.weights(|l| light.eval(l));
        let white = sum_weights(&w);
        let f = |rgb: [f64; 3]| {
            let p = table.fetch(rgb);
            let vals: Vec<f64> = q.nodes.lambda.iter().map(|&l| p.eval(l)).collect();
            integrate_nodes(&w, &vals)
        };
        let dwhite = dense_integral(range, &obs, |l| light.eval(l));
        for (axis, warp, unwarp) in [
            ("linear", (|v: f64| v) as fn(f64) -> f64, (|v: f64| v) as fn(f64) -> f64),
            ("sqrt", |v: f64| v.sqrt(), |u: f64| u * u),
        ] {
            for g in [8usize, 16, 24, 32, 48] {
                let grid: Vec<[f64; 3]> = (0..g * g * g)
                    .map(|k| {
                        let (i, j, l) = (k % g, (k / g) % g, k / (g * g));
                        f([i, j, l].map(|t| unwarp(t as f64 / (g - 1) as f64)))
                    })
                    .collect();
                let interp = |rgb: [f64; 3]| {
                    let u = rgb.map(|v| warp(v.clamp(0.0, 1.0)) * (g - 1) as f64);
                    let i0 = u.map(|v| (v.floor() as usize).min(g - 2));
                    let t = [0, 1, 2].map(|a| u[a] - i0[a] as f64);
                    let mut out = [0f64; 3];
                    for corner in 0..8 {
                        let d = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
                        let wgt: f64 = (0..3).map(|a| if d[a] == 1 { t[a] } else { 1.0 - t[a] }).product();
                        let v = grid[(i0[0] + d[0]) + g * (i0[1] + d[1]) + g * g * (i0[2] + d[2])];
                        for c in 0..3 {
                            out[c] += wgt * v[c];
                        }
                    }
                    out
                };
                for (set, cols) in [("lin", &lin), ("enc", &enc)] {
                    let (mut s, mut m) = (0.0, 0.0f64);
                    for &c in cols.iter() {
                        let de = ciede2000(xyz_to_lab(interp(c), white), xyz_to_lab(f(c), white));
                        s += de;
                        m = m.max(de);
                    }
                    println!(
                        "{light_name:<9} {axis:<6} G={g:<3} {set}: mean {:.5} max {:.4}",
                        s / cols.len() as f64,
                        m
                    );
                }
            }
        }
        // The quadrature's own error, for scale.
        for (set, cols) in [("lin", &lin), ("enc", &enc)] {
            let (mut s, mut m) = (0.0, 0.0f64);
            for &c in cols.iter() {
                let p = table.fetch(c);
                let t = xyz_to_lab(dense_integral(range, &obs, |l| p.eval(l) * light.eval(l)), dwhite);
                let de = ciede2000(xyz_to_lab(f(c), white), t);
                s += de;
                m = m.max(de);
            }
            println!(
                "{light_name:<9} quadrature N={n} {set}: mean {:.5} max {:.4}",
                s / cols.len() as f64,
                m
            );
        }
    }
    Ok(())
}
