//! Fit (or load) a table and check it adversarially, as docs/upsampling.md reports:
//! `cargo run --release -p color --example adversarial -- SPACE [FILE.coeff] [--rgb2spec-fetch]`.
//! Without FILE the default table (64³ fit + refinement) is fitted, timed and written to
//! `/tmp/SPACE-64.coeff`. `--rgb2spec-fetch` reads the table as rgb2spec does (linear weights,
//! no complement; for rgb2spec_opt's tables) and prints only the adversarial search.
use color::upsample::{adversarial, roundtrip};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut a: Vec<String> = std::env::args().collect();
    let rgb2spec_fetch = a.iter().any(|s| s == "--rgb2spec-fetch");
    a.retain(|s| s != "--rgb2spec-fetch");
    let space = color::RgbColorSpace::by_name(a.get(1).map(|s| s.as_str()).unwrap_or("srgb"))?;
    let table = match a.get(2) {
        Some(p) => color::upsample::CoeffTable::read(std::path::Path::new(p))?,
        None => {
            let t0 = std::time::Instant::now();
            let t = color::upsample::fit_default(&space, &color::progress::Silent)?;
            println!("fit + refine {}: {:.1} s", space.name, t0.elapsed().as_secs_f64());
            t.write(std::path::Path::new(&format!("/tmp/{}-64.coeff", space.name)))?;
            t
        }
    };
    let opt = adversarial::AdversarialOptions { rgb2spec_fetch, ..Default::default() };
    if rgb2spec_fetch {
        let adv = adversarial::check(&table, &space, adversarial::Domain::Own, &opt)?;
        println!("adversarial (own cube, rgb2spec fetch): {}", serde_json::to_string(&adv)?);
        return Ok(());
    }
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
