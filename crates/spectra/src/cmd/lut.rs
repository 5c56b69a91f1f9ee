//! `spectra lut`: fit a Jakob–Hanika coefficient table and write it in rgb2spec's `.coeff` format.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use color::RgbColorSpace;
use color::upsample::{self, FitOptions, cache, fit, refine, roundtrip};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Colour space: srgb, p3, rec2020, acescg, aces2065-1.
    #[arg(long, default_value = "srgb")]
    pub space: String,
    /// Grid points per axis (table memory is 36·res³ bytes).
    #[arg(long, default_value_t = cache::TABLE_RES)]
    pub res: usize,
    /// Output file (written atomically, rgb2spec's `.coeff` layout). The default table's chroma
    /// grid is denser next to 0 and is stored after the payload, which rgb2spec, Mitsuba and pbrt
    /// skip: they read it as a uniform grid and get the colours wrong. For them use --rgb2spec or
    /// --uniform-chroma.
    #[arg(long)]
    pub out: PathBuf,
    /// Reproduce rgb2spec: its double-smoothstep brightness grid and no refinement.
    #[arg(long)]
    pub rgb2spec: bool,
    /// spectra's fit and refinement on rgb2spec's uniform chroma grid, so that rgb2spec, Mitsuba
    /// and pbrt read the file correctly (sRGB adversarial max ΔE2000 0.160 with our fetch instead of 0.059).
    #[arg(long, conflicts_with = "rgb2spec")]
    pub uniform_chroma: bool,
    /// Skip the interpolation-aware refinement (faster; round-trip mean ΔE2000 ≈ 0.008 instead of ≈ 0.005).
    #[arg(long)]
    pub no_refine: bool,
    /// Colours in the round-trip check printed at the end (0 to skip).
    #[arg(long, default_value_t = 100_000)]
    pub check: usize,
}

pub fn run(a: Args) -> Result<()> {
    let space = RgbColorSpace::by_name(&a.space)?;
    if !(2..=upsample::table::MAX_RES).contains(&a.res) {
        bail!("--res {} is outside 2..={}", a.res, upsample::table::MAX_RES);
    }
    super::check_output("--out", &a.out)?;
    super::check_outputs(&[("--out", Some(&a.out))], &[])?;
    // Checked before the fit (minutes), not after it.
    if a.check > 0 {
        roundtrip::check_count(a.check).map_err(|e| anyhow::anyhow!("--check {}: {e}", a.check))?;
    }
    let mut opt = if a.rgb2spec { FitOptions::new(a.res) } else { FitOptions::spectra(a.res) };
    if a.uniform_chroma {
        opt.chroma = fit::uniform_chroma(a.res);
    }
    let t0 = Instant::now();
    let pb = crate::progress::fit_bar(&format!("fitting {} {}³", space.name, a.res));
    let mut table = upsample::fit_table_with(&space, &opt, &pb, upsample::interrupt_flag())
        .with_context(|| format!("fitting the {} table", space.name))?;
    let fit_s = t0.elapsed().as_secs_f64();
    let mut refine_s = 0.0;
    if !(a.rgb2spec || a.no_refine) {
        let t1 = Instant::now();
        let model = fit::LabModel::new(&space)?;
        let pb = crate::progress::fit_bar("refining for interpolation");
        refine::refine_table(
            &mut table,
            &model,
            &refine::RefineOptions::default(),
            &pb,
            upsample::interrupt_flag(),
        )?;
        refine_s = t1.elapsed().as_secs_f64();
    }
    table.write(&a.out).with_context(|| format!("writing {}", a.out.display()))?;
    eprintln!(
        "wrote {} ({} bytes): fit {fit_s:.2} s, refinement {refine_s:.2} s",
        a.out.display(),
        table.encoded_len(),
    );
    if a.check > 0 {
        let r = roundtrip::roundtrip_table(&table, &space, a.check, 1)?;
        eprintln!(
            "round trip through the table, {} random {} colours: ΔE2000 max {:.4}, p99 {:.4}, mean {:.4}",
            r.colours, space.name, r.stats.max, r.stats.p99, r.stats.mean
        );
    }
    Ok(())
}
