//! `spectra upsample`: turn one RGB reflectance into a spectrum and show how well it round-trips;
//! `--roundtrip N` measures a method over N random colours (and a table adversarially); `--bench` measures evaluation speed.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use color::RgbColorSpace;
use color::upsample::{
    self, CoeffTable, Method, Reflectance, Upsampler, adversarial, fit::LabModel, method, roundtrip,
};
use serde_json::json;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Linear RGB components in [0, 1] (omit with --roundtrip or --bench).
    #[arg(num_args = 0..=3, allow_negative_numbers = true)]
    pub rgb: Vec<f64>,
    /// Colour space of the RGB: srgb, p3, rec2020, acescg, aces2065-1.
    #[arg(long, default_value = "srgb")]
    pub space: String,
    /// Upsampling method: jakob, smits, box (parsed by `color::upsample::Method`, aliases and any
    /// case included).
    #[arg(long, default_value = "jakob")]
    pub method: Method,
    /// Use this `.coeff` table for the jakob method instead of the cached default.
    #[arg(long)]
    pub table: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    /// Measure the round trip over this many random colours instead of converting one.
    #[arg(long, value_name = "N")]
    pub roundtrip: Option<usize>,
    /// Seed of the random colours for --roundtrip.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Measure evaluation throughput (scalar f64, f32 arrays, f32x4, f32x8).
    #[arg(long)]
    pub bench: bool,
    /// Wavelength range of the printed spectrum, MIN:MAX in nm (within 360–830).
    #[arg(long, default_value = "360:830")]
    pub range: String,
    /// Print the spectrum at this many equally spaced wavelengths (bin midpoints) instead of
    /// every 5 nm.
    #[arg(long)]
    pub samples: Option<usize>,
}

/// Writes to stdout; a closed pipe (`| head`) ends the output quietly instead of panicking.
fn emit(text: &str) -> Result<()> {
    use std::io::Write;
    match std::io::stdout().lock().write_all(text.as_bytes()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => r.context("writing to stdout"),
    }
}

fn upsampler(a: &Args, space: &RgbColorSpace) -> Result<Box<dyn Upsampler>> {
    let m = a.method;
    match (&a.table, m) {
        (Some(p), Method::Jakob) => {
            let t = CoeffTable::read(p)?;
            // This command measures tables, so a bad one is measured, not refused (render and
            // truth refuse it) — but said so first, before any spectrum it prints.
            if let Err(e) = color::upsample::cache::check_usable(&t, space) {
                eprintln!("warning: --table {}: {e}", p.display());
            }
            Ok(Box::new(method::Jakob(Arc::new(t))))
        }
        (Some(_), _) => bail!("--table only applies to --method jakob"),
        _ => Ok(upsample::upsampler(m, space).with_context(|| format!("getting the {} table", space.name))?),
    }
}

fn print_adversarial(what: &str, r: &adversarial::Adversarial) {
    println!(
        "  {what} ({} colours): ΔE2000 max {:.4}  p99 {:.4}  mean {:.4}",
        r.colours, r.stats.max, r.stats.p99, r.stats.mean
    );
    for w in r.worst.iter().take(5) {
        println!("    RGB {:.4} {:.4} {:.4}: {:.4}", w.rgb[0], w.rgb[1], w.rgb[2], w.delta_e);
    }
}

pub fn run(a: Args) -> Result<()> {
    let space = RgbColorSpace::by_name(&a.space)?;
    if a.bench {
        return bench(&a, &space);
    }
    if let Some(n) = a.roundtrip {
        roundtrip::check_count(n).map_err(|e| anyhow::anyhow!("--roundtrip {n}: {e}"))?;
        if !a.rgb.is_empty() {
            bail!("--roundtrip measures random colours; do not also give R G B");
        }
        let up = upsampler(&a, &space)?;
        let t0 = Instant::now();
        let r = roundtrip::roundtrip_upsampler(up.as_ref(), &space, n, a.seed)?;
        let secs = t0.elapsed().as_secs_f64();
        // A table is also searched adversarially: uniform colours almost never land on black,
        // the grey axis or the last percent below white, where tables go wrong.
        let adv = if up.method() == Method::Jakob {
            let table = match &a.table {
                Some(p) => Arc::new(CoeffTable::read(p)?),
                None => upsample::table_for(&space)?,
            };
            let opt = adversarial::AdversarialOptions { seed: a.seed, ..Default::default() };
            let own = adversarial::check(&table, &space, adversarial::Domain::Own, &opt)?;
            let wide = if space.name != "srgb" {
                Some((
                    adversarial::check(&table, &space, adversarial::Domain::Srgb, &opt)?,
                    adversarial::gamut_report(&table, &space, n, a.seed)?,
                ))
            } else {
                None
            };
            Some((own, wide))
        } else {
            None
        };
        if a.json {
            println!(
                "{}",
                json!({"space": space.name, "method": up.method().name(), "table": a.table, "roundtrip": r,
                       "adversarial": adv.as_ref().map(|x| &x.0),
                       "adversarial_inside_srgb": adv.as_ref().and_then(|x| x.1.as_ref().map(|w| &w.0)),
                       "gamut": adv.as_ref().and_then(|x| x.1.as_ref().map(|w| &w.1))})
            );
        } else {
            println!(
                "{} {} round trip, {} random colours (CIE 1931 2°, 1 nm, 360–830 nm, {}): ΔE2000 max {:.4}  p99 {:.4}  p95 {:.4}  mean {:.4}  (worst at RGB {:.4} {:.4} {:.4}; {secs:.2} s)",
                space.name,
                up.method(),
                r.colours,
                space.illuminant_name,
                r.stats.max,
                r.stats.p99,
                r.stats.p95,
                r.stats.mean,
                r.worst_rgb[0],
                r.worst_rgb[1],
                r.worst_rgb[2]
            );
            if let Some((own, wide)) = &adv {
                print_adversarial("adversarial search, whole cube", own);
                if let Some((srgb, g)) = wide {
                    print_adversarial("adversarial search, inside sRGB", srgb);
                    let line = |what: &str, s: &Option<color::metrics::Stats>, n: usize| match s {
                        Some(s) => println!(
                            "  uniform, {what} ({n} colours): max {:.4}  p99 {:.4}  mean {:.4}",
                            s.max, s.p99, s.mean
                        ),
                        None => println!("  uniform, {what}: no colours"),
                    };
                    line("inside sRGB", &g.inside_srgb, g.n_inside_srgb);
                    line("outside sRGB, inside the object-colour solid", &g.inside_solid, g.n_inside_solid);
                    line(
                        "outside the object-colour solid (no reflectance exists)",
                        &g.outside_solid,
                        g.n_outside_solid,
                    );
                }
            }
        }
        return Ok(());
    }
    let [r, g, b] = <[f64; 3]>::try_from(a.rgb.as_slice())
        .map_err(|_| anyhow::anyhow!("expected three numbers R G B, got {}", a.rgb.len()))?;
    let rgb = [r, g, b];
    let up = upsampler(&a, &space)?;
    let s = up.reflectance(rgb)?;
    let model = LabModel::new(&space)?;
    let (back, de) = roundtrip::round_trip_rgb(&model, rgb, |l| s.eval(l));
    let range = color::WavelengthRange::parse(&a.range).context("--range")?;
    let lambda: Vec<f64> = match a.samples {
        Some(n) => color::SampledWavelengths::midpoint(range, n).context("--samples")?.lambda,
        None => {
            let steps = (range.width() / 5.0).floor() as usize;
            (0..=steps).map(|i| range.min + 5.0 * i as f64).collect()
        }
    };
    let values: Vec<f64> = lambda.iter().map(|&l| s.eval(l)).collect();
    if a.json {
        let j = json!({
            "space": space.name, "method": up.method().name(), "rgb": rgb, "spectrum": s,
            "lambda_nm": lambda, "reflectance": values, "roundtrip_rgb": back, "delta_e2000": de,
        });
        return emit(&format!("{j}\n"));
    }
    use std::fmt::Write;
    let mut o = String::new();
    writeln!(o, "{} RGB ({r}, {g}, {b}) → {} spectrum", space.name, up.method())?;
    match s {
        Reflectance::Jakob(p) => {
            writeln!(o, "coefficients (λ in nm): c0 = {:e}  c1 = {:e}  c2 = {:e}", p.c[0], p.c[1], p.c[2])?
        }
        Reflectance::Smits(sm) => writeln!(o, "bins (380–720 nm): {:?}", sm.bins)?,
        Reflectance::Box(_) => writeln!(
            o,
            "bands: blue < {} nm ≤ green < {} nm ≤ red",
            upsample::boxes::BOX_BLUE_GREEN_NM,
            upsample::boxes::BOX_GREEN_RED_NM
        )?,
    }
    writeln!(o, "  λ nm     reflectance")?;
    for (l, v) in lambda.iter().zip(&values) {
        writeln!(o, "  {l:7.2}  {v:.6}")?;
    }
    writeln!(
        o,
        "round trip (CIE 1931 2°, 1 nm, {}): RGB ({:.6}, {:.6}, {:.6}), ΔE2000 {de:.5}",
        space.illuminant_name, back[0], back[1], back[2]
    )?;
    emit(&o)
}

/// Spectral samples per second for one coefficient set, per evaluation path.
fn bench(a: &Args, space: &RgbColorSpace) -> Result<()> {
    let up = upsampler(a, space)?;
    let Reflectance::Jakob(p) = up.reflectance([0.6, 0.3, 0.1])? else {
        bail!("--bench measures the sigmoid polynomial; use --method jakob");
    };
    let results = upsample::throughput::measure(&p, 4096, 4000);
    if a.json {
        let m: serde_json::Map<String, serde_json::Value> =
            results.iter().map(|(n, r)| (n.to_string(), json!(r))).collect();
        println!("{}", json!({"samples_per_second": m, "single_thread": true}));
    } else {
        println!("sigmoid-polynomial evaluation, one thread, 4096 wavelengths × 4000 repetitions:");
        for (n, r) in &results {
            println!("  {n:34} {:8.1} M samples/s", r / 1e6);
        }
    }
    Ok(())
}
