//! The attenuation round trip of RGB media (docs/rgb-media.md): for each upsampling method,
//! ΔE2000 between `exp(−σ_rgb·d)` and the colour of `exp(−σ(λ)·d)` over d = 0.1…10 mean free
//! paths, for hand-picked coloured media and random ones.
//!
//! `cargo run --release -p color --example rgb_media -- [SPACE] [RANDOM_MEDIA] [DEPTHS]`
//! (defaults: srgb 1000 21).

use color::upsample::fit::LabModel;
use color::upsample::medium::{Attenuation, study, study_depths, study_media};

fn stats(v: impl Iterator<Item = f64>) -> (f64, f64, f64) {
    let mut v: Vec<f64> = v.collect();
    v.sort_by(f64::total_cmp);
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let p95 = v[((v.len() as f64 * 0.95) as usize).min(v.len() - 1)];
    (mean, p95, *v.last().unwrap())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let space = color::RgbColorSpace::by_name(a.get(1).map(String::as_str).unwrap_or("srgb"))?;
    let random: usize = a.get(2).map(|s| s.parse()).transpose()?.unwrap_or(1000);
    let nd: usize = a.get(3).map(|s| s.parse()).transpose()?.unwrap_or(21);
    let table = color::upsample::table_for(&space)?;
    let model = LabModel::new(&space)?;
    let media = study_media(random);
    let depths = study_depths(nd);
    let named = media.iter().filter(|m| !m.name.starts_with("random")).count();
    let methods = [
        Attenuation::Unbounded,
        Attenuation::Transmittance { mfp_ref: 0.5 },
        Attenuation::Transmittance { mfp_ref: 1.0 },
        Attenuation::Transmittance { mfp_ref: 2.0 },
        Attenuation::Transmittance { mfp_ref: 4.0 },
        Attenuation::Box,
    ];
    println!(
        "{}: {} media ({} named, {} random, mean free path 1), {} depths 0.1–10 mfp; ΔE2000 of exp(−σ(λ)·d) vs exp(−σ_rgb·d)\n",
        space.name,
        media.len(),
        named,
        media.len() - named,
        depths.len()
    );
    println!("| method | named: mean | named: max | all: mean | all: p95 | all: max | worst medium, depth |");
    println!("|---|---|---|---|---|---|---|");
    let mut per_named = Vec::new();
    for m in methods {
        let e = study(&table, &model, &media, &depths, m)?;
        let (nm, _, nx) = stats(e[..named].iter().flatten().copied());
        let (am, ap, ax) = stats(e.iter().flatten().copied());
        let (wi, wj) = (0..e.len())
            .flat_map(|i| (0..depths.len()).map(move |j| (i, j)))
            .max_by(|x, y| e[x.0][x.1].total_cmp(&e[y.0][y.1]))
            .unwrap();
        println!(
            "| {} | {nm:.3} | {nx:.3} | {am:.3} | {ap:.3} | {ax:.3} | {} {:?}, {:.2} mfp |",
            m.label(),
            media[wi].name,
            media[wi].sigma_rgb.map(|v| (v * 1000.0).round() / 1000.0),
            depths[wj]
        );
        per_named.push(e);
    }
    // Box edges other than the renderer's (490 / 585 nm), 5 nm steps: how much is left on the
    // table by the naive mode's choice.
    let mut best = (f64::INFINITY, 0.0, 0.0, 0.0);
    for b in (450..=530).step_by(5) {
        for r in (550..=630).step_by(5) {
            let (b, r) = (b as f64, r as f64);
            let e = color::upsample::medium::study_with(&model, &media, &depths, |s| {
                // Steps 1e-6 nm wide, as color::upsample::medium's box spectrum.
                let lambda = vec![360.0, b - 1e-6, b, r - 1e-6, r, 830.0];
                let values = vec![s[2], s[2], s[1], s[1], s[0], s[0]];
                Ok(color::Spectrum::Piecewise { lambda, values })
            })?;
            let (am, _, ax) = stats(e.iter().flatten().copied());
            if am < best.0 {
                best = (am, ax, b, r);
            }
        }
    }
    println!(
        "\nBest box edges for the mean over all media (5 nm steps): {} / {} nm, mean {:.3}, max {:.3}",
        best.2, best.3, best.0, best.1
    );
    println!("\nPer named medium, max ΔE2000 over the depths:\n");
    print!("| medium | σ_rgb (mfp 1) |");
    for m in methods {
        print!(" {} |", m.label());
    }
    println!();
    println!("|---|---|{}", "---|".repeat(methods.len()));
    for i in 0..named {
        print!("| {} | {:?} |", media[i].name, media[i].sigma_rgb.map(|v| (v * 1000.0).round() / 1000.0));
        for e in &per_named {
            print!(" {:.3} |", e[i].iter().copied().fold(0.0, f64::max));
        }
        println!();
    }
    Ok(())
}
