//! `spectra`: real-time spectral rendering of RGB scenes, with the instruments to prove it.
//!
//! Each subcommand lives in its own file under `cmd/`.

mod cmd;
mod eval;
mod view;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "spectra",
    version,
    about = "Real-time spectral rendering of RGB assets, measured against ground truth"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The paper's claim on one scene: ground truth, rgb, naive and spectral renders, and their errors.
    Demo(cmd::demo::Args),
    /// Render a scene with the real-time (wgpu) renderer, headless, to PNG or EXR.
    Render(cmd::render::RenderArgs),
    /// Measure a render against a reference: CIEDE2000 and MAE statistics, optional heat map.
    Diff(cmd::diff::Args),
    /// Fit a Jakob–Hanika RGB→spectrum coefficient table (rgb2spec `.coeff` format).
    Lut(cmd::lut::Args),
    /// Convert one RGB to a spectrum and report its round trip; or measure a method (--roundtrip N, --bench).
    Upsample(cmd::upsample::Args),
    /// Ground truth: render a scene with the CPU spectral path tracer (or export it for Mitsuba).
    Truth(cmd::truth::Args),
    /// Open an interactive window: live mode/N/range/observer/exposure, orbit and fly camera.
    View(cmd::view::Args),
    /// Frame time of RGB vs spectral rendering at N = 1…64 (median, p10/p90, cost per wavelength).
    Bench(cmd::bench::Args),
    /// The paper's evaluation: truth vs ours/naive/RGB on a suite, frame time vs N, HTML report.
    Eval(cmd::eval::Args),
}

fn main() {
    let cli = Cli::parse();
    let result: anyhow::Result<()> = match cli.command {
        Command::Demo(a) => cmd::demo::run(a),
        Command::Render(a) => cmd::render::run(a),
        Command::Diff(a) => cmd::diff::run(a),
        Command::Lut(a) => cmd::lut::run(a),
        Command::Upsample(a) => cmd::upsample::run(a),
        Command::Truth(a) => cmd::truth::run(a),
        Command::View(a) => cmd::view::run(a),
        Command::Bench(a) => cmd::bench::run(a),
        Command::Eval(a) => cmd::eval::run(a),
    };
    if let Err(e) = result {
        // `{:#}` prints the whole context chain on one line: "reading x.coeff: file is truncated".
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
