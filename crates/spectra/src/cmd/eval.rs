//! `spectra eval`: reproduce the paper's evaluation (plus jittered accumulation) into a
//! directory with an HTML report. See `crate::eval` and docs/evaluation.md.

use crate::eval::{self, Config, suite};
use anyhow::{Result, bail};
use clap::Args as ClapArgs;
use std::path::PathBuf;

#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Small sizes and sample counts (a few minutes on a 2-core CPU; what CI runs).
    #[arg(long)]
    pub quick: bool,
    /// Cases to run, comma-separated. Default: metamerism, colorchecker-d65, colorchecker-f11,
    /// colorchecker-led and the underwater scene in Jerlov I (--quick) or I, IB, II, 3C (full);
    /// any Jerlov type as underwater-TYPE (underwater-iii, underwater-ii.5).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Vec<String>,
    /// Override the ground-truth samples per pixel (every case, underwater included).
    #[arg(long)]
    pub spp: Option<u32>,
    /// Override the image size WIDTHxHEIGHT of the error measurements (every case).
    #[arg(long)]
    pub size: Option<String>,
    /// Jakob–Hanika coefficient table (.coeff); default: the cached sRGB table.
    #[arg(long)]
    pub table: Option<PathBuf>,
    /// Output directory (created); gets index.html, results.json, results.csv, images, charts.
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(a: Args) -> Result<()> {
    let mut budget = if a.quick { suite::Budget::quick() } else { suite::Budget::full() };
    if a.spp == Some(0) {
        bail!("--spp must be at least 1");
    }
    let size = a.size.as_deref().map(crate::cmd::render::parse_size).transpose()?;
    budget.override_with(size, a.spp);
    let ids = if a.scenes.is_empty() {
        suite::default_ids(&budget)
    } else {
        for id in &a.scenes {
            suite::case(id)?;
        }
        a.scenes.clone()
    };
    let notes = suite::notes(&ids);
    let out = a.out.clone();
    let r = eval::run(Config { out: a.out, quick: a.quick, budget, ids, notes, table: a.table })?;
    println!("{}", eval::report::markdown_table(&r));
    println!("report: {}  ({:.0} s)", out.join("index.html").display(), r.seconds);
    Ok(())
}
