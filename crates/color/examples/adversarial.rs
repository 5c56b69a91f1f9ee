//! Fit (or load) a table and check it adversarially, as docs/upsampling.md reports:
//! `cargo run --release -p color --example adversarial -- SPACE [FILE.coeff]`.
//! Without FILE the default table (64³ fit + refinement) is fitted, timed and written to
//! `/tmp/SPACE-64.coeff`.
use color::upsample::{adversarial, roundtrip};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let space = color::RgbColorSpace::by_name(a.get(1).map(|s| s.as_str()).unwrap_or("srgb"))?;
    let table = match a.get(2) {
        Some(p) => color::upsample::CoeffTable::read(std::path::Path::new(p))?,
        None => {
            let t0 = std::time::Instant::now();
            let t = color::upsample::fit_default(&space, &indicatif::ProgressBar::hidden())?;
            println!("fit + refine {}: {:.1} s", space.name, t0.elapsed().as_secs_f64());
            t.write(std::path::Path::new(&format!("/tmp/{}-64.coeff", space.name)))?;
            t
        }
    };
    let opt = adversarial::AdversarialOptions::default();
    let u = roundtrip::roundtrip_table(&table, &space, 100_000, 1)?;
    println!("uniform 1e5: {}", serde_json::to_string(&u)?);
    let adv = adversarial::check(&table, &space, adversarial::Domain::Own, &opt)?;
    println!("adversarial (own cube): {}", serde_json::to_string(&adv)?);
    if space.name != "srgb" {
        let s = adversarial::check(&table, &space, adversarial::Domain::Srgb, &opt)?;
        println!("adversarial (inside sRGB): {}", serde_json::to_string(&s)?);
        let g = adversarial::gamut_report(&table, &space, 20_000, 1)?;
        println!("gamut report (2e4 uniform): {}", serde_json::to_string(&g)?);
    }
    Ok(())
}
