//! How much of a measured water's look survives when only its RGB is known (issue 18, study
//! (a)/(b)/(c), unscattered light only): a white wall under the space's white seen through d
//! metres of Jerlov water, by its beam attenuation c(λ) = a + b (no in-scattering, no forward
//! scattering gain). (b) the measured c(λ); (c) an RGB renderer with the RGB projection
//! c_rgb of c(λ) ([`project`]): exp(−c_rgb·d); (a) c_rgb upsampled back to a spectrum by each
//! method. ΔE2000 of (a) and (c) against (b).
//!
//! `cargo run --release -p color --example jerlov_rgb -- [TYPES…]` (default: IB 3C).

use color::upsample::fit::LabModel;
use color::upsample::medium::{Attenuation, coefficient, project};
use color::water::WaterProperties;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut types: Vec<String> = std::env::args().skip(1).collect();
    if types.is_empty() {
        types = vec!["IB".into(), "3C".into()];
    }
    let space = color::RgbColorSpace::srgb();
    let table = color::upsample::table_for(&space)?;
    let model = LabModel::new(&space)?;
    let methods = [Attenuation::DEFAULT, Attenuation::TRANSMITTANCE, Attenuation::Unbounded];
    print!("| water | c_rgb (1/m) | d (m) | (c) RGB |");
    for m in methods {
        print!(" (a) {} |", m.label());
    }
    println!();
    println!("|---|---|---|---|{}", "---|".repeat(methods.len()));
    for t in &types {
        let w = WaterProperties::jerlov(t)?;
        let c_rgb = project(&model, &w.c);
        let up: Vec<_> = methods.iter().map(|&m| coefficient(&table, c_rgb, m)).collect::<Result<_, _>>()?;
        for d in [1.0, 5.0, 10.0, 20.0] {
            let truth = model.lab_of_xyz(model.xyz_of(|l| (-w.c.eval(l) * d).exp()));
            let rgb = color::ciede2000(truth, model.target_lab(c_rgb.map(|s| (-s * d).exp())));
            print!("| {t} | {:?} | {d} | {rgb:.2} |", c_rgb.map(|v| (v * 1000.0).round() / 1000.0));
            for s in &up {
                let a = model.lab_of_xyz(model.xyz_of(|l| (-s.eval(l) * d).exp()));
                print!(" {:.2} |", color::ciede2000(truth, a));
            }
            println!();
        }
    }
    Ok(())
}
