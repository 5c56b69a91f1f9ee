//! `spectra demo`: the paper's claim on one scene, in one command.
//!
//! Renders a built-in scene lit by spiky-spectrum lights with the CPU path tracer (direct
//! lighting, the like-for-like reference for the real-time image) and with the real-time
//! renderer in its three modes, then measures each against the reference. Everything goes to
//! `--out`: `truth.{exr,png}`, `{rgb,naive,spectral}.{exr,png}` and `{mode}-error.png` heat maps.
//!
//! It drives the same code as `spectra truth`, `spectra render` and `spectra diff`, so what
//! the demo shows is what those commands do.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Parser;
use compare::{DiffMaps, DiffOptions, Heatmap, HeatmapOptions, read_image};

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Output directory (created if missing).
    #[arg(long, default_value = "out")]
    pub out: PathBuf,
    /// Built-in scene name or a .gltf/.glb file.
    #[arg(long, default_value = "metamerism")]
    pub scene: String,
    #[command(flatten)]
    pub files: super::setup::SceneFileArgs,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "480x360")]
    pub size: String,
    /// Ground-truth samples per pixel (each path carries four wavelengths). 256 keeps the
    /// tracer's noise well below the differences the demo shows.
    #[arg(long, default_value_t = 256)]
    pub spp: u32,
}

/// Parses a subcommand's arguments exactly as the command line would. Callers pass values as
/// `--option=value` and the scene after `--`, so a user's value that looks like an option (a
/// scene named `--xyz`) stays a value and gets that command's own error about it.
fn parse<A: clap::Args>(argv: &[&str]) -> Result<A> {
    #[derive(Parser)]
    struct Wrap<A: clap::Args> {
        #[command(flatten)]
        inner: A,
    }
    // clap's rendering starts "error: ", as main's does: keep one.
    Wrap::<A>::try_parse_from(argv).map(|w| w.inner).map_err(|e| {
        let text = e.render().to_string();
        anyhow::anyhow!("{}", text.trim_start_matches("error: ").lines().next().unwrap_or(""))
    })
}

fn path_str(p: &Path) -> Result<&str> {
    p.to_str().with_context(|| format!("{}: output paths must be valid UTF-8", p.display()))
}

pub fn run(a: Args) -> Result<()> {
    if a.out.exists() && !a.out.is_dir() {
        anyhow::bail!(
            "--out {}: a file is there; the demo writes a folder of images (give a folder)",
            a.out.display()
        );
    }
    // A scene that cannot be loaded, or a size either renderer refuses, is refused before the
    // folder is made and the ground truth rendered.
    a.files.load(&a.scene)?;
    let (w, h) = super::setup::parse_size(&a.size)?;
    let size_error = |e: String| anyhow::anyhow!("--size {}: {e}", a.size);
    truth::render::check_size(w, h).map_err(|e| size_error(e.to_string()))?;
    render::Renderer::new()?.check_size(w, h).map_err(|e| size_error(e.to_string()))?;
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let file = |name: &str| a.out.join(name);
    let spp = a.spp.to_string();

    eprintln!("1/3 ground truth: CPU spectral path tracer, direct lighting, {} spp", a.spp);
    let truth = file("truth.exr");
    for out in [&truth, &file("truth.png")] {
        let (size, out) = (format!("--size={}", a.size), format!("--out={}", path_str(out)?));
        let argv = ["truth", "--direct-only", "--spp", &spp, &size, &out, "--", &a.scene];
        let mut args: super::truth::Args = parse(&argv)?;
        args.scene.files = a.files.clone();
        super::truth::run(args)?;
    }

    eprintln!("2/3 real-time renderer: rgb, naive and spectral modes");
    let modes = ["rgb", "naive", "spectral"];
    for mode in modes {
        for ext in ["exr", "png"] {
            let out = file(&format!("{mode}.{ext}"));
            let (size, out) = (format!("--size={}", a.size), format!("--out={}", path_str(&out)?));
            let argv = ["render", "--mode", mode, &size, &out, "--", &a.scene];
            let mut args: super::render::RenderArgs = parse(&argv)?;
            args.scene.files = a.files.clone();
            super::render::run(args)?;
        }
    }

    eprintln!("3/3 error against the ground truth");
    let reference = read_image(&truth)?;
    let mut rows = Vec::new();
    for mode in modes {
        let test = read_image(file(&format!("{mode}.exr")))?;
        let maps = DiffMaps::compute(&reference, &test, DiffOptions::default())?;
        let heat = file(&format!("{mode}-error.png"));
        Heatmap::of_delta_e(&maps, &HeatmapOptions { max: Some(10.0), ..Default::default() })?
            .save_png(&heat)?;
        rows.push((mode, maps.summary()));
    }
    println!("\n{} against its path-traced ground truth ({} spp, direct lighting):\n", a.scene, a.spp);
    println!("{:<10} {:>12} {:>12} {:>14}", "mode", "mean ΔE2000", "p95 ΔE2000", "MAE (linear)");
    for (mode, s) in &rows {
        println!(
            "{:<10} {:>12.3} {:>12.3} {:>14.5}",
            mode, s.delta_e2000.mean, s.delta_e2000.p95, s.mae_linear.mean
        );
    }
    println!("\nimages and heat maps (ΔE00 scale 0–10) in {}/", a.out.display());
    Ok(())
}
