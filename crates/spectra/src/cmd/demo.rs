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
    // Every image is made in a private folder inside --out and the eleven are put in place
    // together at the end: an interrupt or a failure part way (Ctrl-C during the real-time
    // renders, a full disk) left a new truth beside the previous run's renders and heat maps,
    // as if they belonged together. The folder goes when the demo ends, however it ends; one
    // left by a killed demo is removed by the next (its name carries the dead pid).
    let work = color::outfile::temp_dir_next_to(&a.out.join("demo"))
        .with_context(|| format!("creating a working folder in {}", a.out.display()))?;
    let file = |name: &str| work.path().join(name);
    let spp = a.spp.to_string();

    eprintln!("1/3 ground truth: CPU spectral path tracer, direct lighting, {} spp", a.spp);
    let truth = file("truth.exr");
    {
        let (size, out) = (format!("--size={}", a.size), format!("--out={}", path_str(&truth)?));
        // No checkpoint: it would be kept in the working folder, which an interrupt removes.
        let argv =
            ["truth", "--direct-only", "--spp", &spp, "--checkpoint-every=0", &size, &out, "--", &a.scene];
        let mut args: super::truth::Args = parse(&argv)?;
        args.scene.files = a.files.clone();
        super::truth::run(args)?;
    }
    // The PNG is the EXR's values encoded as `spectra truth --out truth.png` encodes them (the
    // EXR holds them in f32): the same image without tracing it a second time.
    let reference = read_image(&truth)?;
    let png = compare::io::encode_image(file("truth.png"), &reference, Default::default())?;
    std::fs::write(file("truth.png"), png)
        .with_context(|| format!("writing {}", file("truth.png").display()))?;

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
    let mut rows = Vec::new();
    for mode in modes {
        let test = read_image(file(&format!("{mode}.exr")))?;
        let maps = DiffMaps::compute(&reference, &test, DiffOptions::default())?;
        let heat = file(&format!("{mode}-error.png"));
        Heatmap::of_delta_e(&maps, &HeatmapOptions { max: Some(10.0), ..Default::default() })?
            .save_png(&heat)?;
        rows.push((mode, maps.summary()));
    }
    if color::cancel::is_cancelled() {
        anyhow::bail!("interrupted");
    }
    let names = ["truth.exr", "truth.png"]
        .into_iter()
        .map(String::from)
        .chain(modes.iter().flat_map(|m| [format!("{m}.exr"), format!("{m}.png"), format!("{m}-error.png")]));
    let _hold = color::cancel::hold();
    let mut staged = Vec::new();
    for name in names {
        let bytes =
            std::fs::read(file(&name)).with_context(|| format!("reading {}", file(&name).display()))?;
        staged.push(super::stage_output(&a.out.join(&name), &bytes)?);
    }
    super::commit_outputs(staged)?;
    drop(work);
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
