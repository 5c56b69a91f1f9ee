//! `spectra eval`: reproduce the paper's evaluation (plus jittered accumulation) into a
//! directory with an HTML report. See `crate::eval` and docs/evaluation.md.

use crate::eval::{self, Config, suite};
use anyhow::{Context, Result, bail};
use clap::Args as ClapArgs;
use std::path::PathBuf;

#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Small sizes and sample counts (a few minutes on a 2-core CPU; what CI runs).
    #[arg(long)]
    pub quick: bool,
    /// Cases to run, comma-separated. Default: metamerism, colorchecker-d65, colorchecker-f11,
    /// colorchecker-led, iridescence-d65, iridescence-f11, glass and the underwater scene in
    /// Jerlov I (--quick) or I, IB, II, 3C (full); also clearcoat, specular, sheen,
    /// anisotropy and translucent, and any Jerlov type as
    /// underwater-TYPE (underwater-iii, underwater-ii.5).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Override the ground-truth samples per pixel (every case, underwater included).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Override the image size WIDTHxHEIGHT (or WIDTHXHEIGHT, WIDTH*HEIGHT) of the error
    /// measurements (every case).
    #[arg(long)]
    pub size: Option<String>,
    /// Wavelength counts N of the error sweep (ours and naive, midpoint and prefiltered
    /// quadrature, every case), comma-separated, each in 1..=256. Default: 4,8,16 (--quick) or
    /// 4,8,16,32,64. The error-vs-frame-time chart uses the N that are also timed
    /// (1,2,4,8,16,32 with --quick, up to 64 in the full run).
    #[arg(long, value_name = "N,N,...")]
    pub sweep: Option<String>,
    #[command(flatten)]
    pub table: crate::cmd::setup::TableArgs,
    /// Keep the ground truths in this directory (created) and start from the ones kept: a
    /// second run renders no truth, one with a higher --spp only the samples it lacks. Shared
    /// with `spectra truth --truth-cache` (docs/ground-truth.md).
    #[arg(long, value_name = "DIR")]
    pub truth_cache: Option<PathBuf>,
    /// Evaluate for this observer instead of CIE 1931: a camera (`spectra observers`) or a
    /// file, as --observer elsewhere. Both renderers integrate with it and a camera is shown
    /// through its least-squares matrix to CIE XYZ over the ColorChecker (--camera-to-display),
    /// so ΔE2000 compares colours a person sees and the rgb mode's sRGB is comparable.
    #[arg(long)]
    pub observer: Option<String>,
    /// Output directory (created); gets index.html, results.json, results.csv, images, charts.
    #[arg(long)]
    pub out: PathBuf,
}

/// The evaluation these flags ask for (suite, budget, cases), checked.
pub fn config(a: &Args) -> Result<Config> {
    let mut budget = if a.quick { suite::Budget::quick() } else { suite::Budget::full() };
    if a.spp == Some(0) {
        bail!("--spp must be at least 1");
    }
    let size = a.size.as_deref().map(crate::cmd::setup::parse_size).transpose()?;
    budget.override_with(size, a.spp);
    if let Some(s) = &a.sweep {
        budget.sweep_counts = parse_sweep(s)?;
    }
    let ids = if a.scenes.is_empty() {
        suite::default_ids(&budget)
    } else {
        let mut ids: Vec<String> = Vec::new();
        for id in &a.scenes {
            suite::case(id)?;
            if ids.contains(id) {
                eprintln!("warning: --scenes names {id} more than once; it is evaluated once");
            } else {
                ids.push(id.clone());
            }
        }
        ids
    };
    let notes = suite::notes(&ids);
    if let Some(o) = &a.observer {
        let obs = color::Observer::by_name(o).with_context(|| format!("--observer '{o}'"))?;
        let view = crate::eval::measure::view_of(&obs);
        let d65 = color::illuminant::by_name("D65")?;
        color::film::to_linear_srgb(&obs, obs.white_balance(&d65), &d65, view)
            .with_context(|| format!("--observer '{o}': the evaluation shows it through its fit to XYZ"))?;
    }
    Ok(Config {
        out: a.out.clone(),
        quick: a.quick,
        budget,
        ids,
        notes,
        table: a.table.table.clone(),
        truth_cache: a.truth_cache.clone(),
        observer: a.observer.clone(),
    })
}

pub fn run(a: Args) -> Result<()> {
    let out = a.out.clone();
    let r = eval::run(config(&a)?)?;
    println!("{}", eval::report::markdown_table(&r));
    println!("{}", eval::report::markdown_sweep(&r));
    println!("report: {}  ({:.0} s)", out.join("index.html").display(), r.seconds);
    Ok(())
}

/// `--sweep 4,8,16`: distinct counts in 1..=MAX_WAVELENGTHS, ascending (the charts draw lines
/// through them in order), or an error naming the bad value.
pub fn parse_sweep(s: &str) -> Result<Vec<usize>> {
    let mut out = crate::cmd::bench::parse_counts_for("--sweep", s)?;
    out.sort_unstable();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::parse_sweep;

    #[test]
    fn sweep_list_is_validated_sorted_and_deduplicated() {
        assert_eq!(parse_sweep("16, 4,8,4").unwrap(), vec![4, 8, 16]);
        assert_eq!(parse_sweep("256").unwrap(), vec![256]);
        let e = parse_sweep("4,257").unwrap_err().to_string();
        assert!(e.contains("257") && e.contains("1..=256"), "{e}");
        assert!(parse_sweep("0").unwrap_err().to_string().contains("outside"));
        assert!(parse_sweep("4,x").unwrap_err().to_string().contains("'x'"));
        assert!(parse_sweep(" , ").unwrap_err().to_string().contains("at least one"));
    }
}
