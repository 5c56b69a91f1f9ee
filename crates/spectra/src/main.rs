//! `spectra`: real-time spectral rendering of RGB scenes, with the instruments to prove it.
//!
//! The command line over the library (`lib.rs`): each subcommand lives in its own file under
//! `cmd/`.

#[cfg(test)]
mod limits_doc_tests;

use spectra::{cmd, progress};

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
    /// Combine sample chunks and crop tiles of one `truth` render into one image.
    Merge(cmd::merge::Args),
    /// List the built-in observers and cameras (the names --observer takes) with their sources.
    Observers(cmd::observers::Args),
    /// Open an interactive window: live mode/N/range/observer/exposure, orbit and fly camera.
    #[cfg(feature = "viewer")]
    View(cmd::view::Args),
    /// Frame time of RGB vs spectral rendering at N = 1…64 (median, p10/p90, cost per wavelength).
    Bench(cmd::bench::Args),
    /// The paper's evaluation: truth vs ours/naive/RGB on a suite, frame time vs N, HTML report.
    Eval(cmd::eval::Args),
}

/// Exit status after Ctrl-C, as shells report a process ended by SIGINT (128 + 2).
const EXIT_INTERRUPTED: i32 = 130;

/// How long the cooperative stop may take before the process is ended anyway.
const FORCED_EXIT_AFTER: std::time::Duration = std::time::Duration::from_millis(900);

/// Ctrl-C sets the process's cancellation token ([`color::cancel`]), which every long loop
/// polls: the command stops within a fraction of a second, removes its temporary files and
/// writes nothing. A few driver calls cannot be interrupted (lavapipe compiling a pipeline
/// with LLVM, a `vkQueueSubmit` that waits for the previous frame); if the command has not
/// ended [`FORCED_EXIT_AFTER`] the Ctrl-C, the process exits anyway. That is safe for the
/// outputs, which only ever appear by an atomic rename: at worst a temporary file is left,
/// named with the pid so that the next write of the same file removes it. A second Ctrl-C
/// exits at once.
fn install_interrupt_handler() {
    let r = ctrlc::set_handler(|| {
        if color::cancel::is_cancelled() {
            eprintln!("\ninterrupted twice: exiting at once");
            exit_now();
        }
        color::cancel::cancel();
        std::thread::spawn(|| {
            std::thread::sleep(FORCED_EXIT_AFTER);
            // Writing a checkpoint of the samples done so far is worth the wait (a large one
            // takes seconds); nothing else is.
            while color::cancel::held() {
                std::thread::sleep(std::time::Duration::from_millis(20));
            }
            eprintln!("interrupted: stopped (forced: the command did not stop in time); no output written");
            exit_now();
        });
    });
    if let Err(e) = r {
        eprintln!("warning: Ctrl-C handler not installed ({e}); Ctrl-C will end the process without cleanup");
    }
}

/// A headless command on a server without `XDG_RUNTIME_DIR`: the Vulkan driver probes the
/// Wayland window system when the instance is created, and libwayland prints "error:
/// XDG_RUNTIME_DIR is invalid or not set in the environment." twice although nothing is wrong.
/// A private (0700, mkdtemp) runtime directory for this process alone silences it; it is
/// empty, so no window system is found, and removed on exit. Must run before any thread is
/// started (it sets an environment variable).
/// The private runtime directory, for the forced exit (which skips destructors) to remove.
static RUNTIME_DIR: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();

/// Ends the process now with [`EXIT_INTERRUPTED`], after removing the private runtime directory.
fn exit_now() -> ! {
    if let Some(d) = RUNTIME_DIR.get() {
        let _ = std::fs::remove_dir(d);
    }
    // SAFETY: _exit(2) has no preconditions; it skips atexit handlers, which could wait for the
    // GPU driver's threads.
    unsafe { libc::_exit(EXIT_INTERRUPTED) }
}

fn quiet_runtime_dir(headless: bool) -> Option<tempfile::TempDir> {
    if !headless || std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir()) {
        return None;
    }
    let mut builder = tempfile::Builder::new();
    builder.prefix("spectra-runtime-");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o700));
    }
    let dir = builder.tempdir().ok()?;
    let _ = RUNTIME_DIR.set(dir.path().to_path_buf());
    // SAFETY: called first thing in `main`, before any other thread exists.
    unsafe { std::env::set_var("XDG_RUNTIME_DIR", dir.path()) };
    Some(dir)
}

/// `println!` and `eprintln!` panic when their stream cannot be written (standard output on a
/// full disk or `/dev/full`; a closed pipe already ends the process, see `main`): the payload
/// names the stream and the cause. Such a panic is an error like any other, one line and exit
/// status 1, not a panic report and 101.
fn print_failure(payload: &(dyn std::any::Any + Send)) -> Option<String> {
    let text = payload
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| payload.downcast_ref::<&str>().copied())?;
    print_failure_text(text)
}

fn print_failure_text(text: &str) -> Option<String> {
    let rest = text.strip_prefix("failed printing to ")?;
    let (stream, cause) = rest.split_once(": ").unwrap_or((rest, "unknown cause"));
    let stream = match stream {
        "stdout" => "standard output",
        "stderr" => "standard error",
        other => other,
    };
    Some(format!("cannot write to {stream}: {cause}"))
}

/// Keeps the default panic report for real panics and leaves a stream's write failure to
/// [`print_failure`].
fn install_print_failure_hook() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if print_failure(info.payload()).is_none() {
            default(info);
        }
    }));
}

fn main() {
    let cli = Cli::parse();
    #[cfg(feature = "viewer")]
    let headless = !matches!(cli.command, Command::View(_));
    #[cfg(not(feature = "viewer"))]
    let headless = true;
    let runtime_dir = quiet_runtime_dir(headless);
    // Rust ignores SIGPIPE, so printing to a closed pipe (`spectra diff … --json | head -c
    // 100`) would panic; the default action ends the process quietly, as for any Unix filter.
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to the default has no preconditions.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    install_interrupt_handler();
    progress::install();
    let unwritten = match cli.command {
        // The suite keeps the cases it finished; the summary is what is missing.
        Command::Eval(_) => "results.json and index.html not written",
        _ => "no output written",
    };
    install_print_failure_hook();
    let run = std::panic::AssertUnwindSafe(|| match cli.command {
        Command::Demo(a) => cmd::demo::run(a),
        Command::Render(a) => cmd::render::run(a),
        Command::Diff(a) => cmd::diff::run(a),
        Command::Lut(a) => cmd::lut::run(a),
        Command::Upsample(a) => cmd::upsample::run(a),
        Command::Truth(a) => cmd::truth::run(a),
        Command::Merge(a) => cmd::merge::run(a),
        Command::Observers(a) => cmd::observers::run(a),
        #[cfg(feature = "viewer")]
        Command::View(a) => cmd::view::run(a),
        Command::Bench(a) => cmd::bench::run(a),
        Command::Eval(a) => cmd::eval::run(a),
    });
    let result: anyhow::Result<()> = match std::panic::catch_unwind(run) {
        Ok(r) => r,
        Err(payload) => match print_failure(payload.as_ref()) {
            Some(what) => Err(anyhow::anyhow!("{what}")),
            None => std::panic::resume_unwind(payload),
        },
    };
    let code = match result {
        Ok(()) => 0,
        // Whatever error the interruption surfaced as ("fit interrupted", a GPU wait cut
        // short), the user pressed Ctrl-C: say so once.
        Err(e) if color::cancel::is_cancelled() => {
            match e.downcast_ref::<cmd::KeptOnInterrupt>() {
                Some(kept) => eprintln!("interrupted: stopped; {kept}"),
                None => eprintln!("interrupted: stopped; {unwritten}"),
            }
            EXIT_INTERRUPTED
        }
        Err(e) => {
            // `{:#}` prints the whole context chain on one line: "reading x.coeff: file is truncated".
            // Not `eprintln!`: standard error may be the stream that failed.
            use std::io::Write;
            let _ = writeln!(std::io::stderr(), "error: {e:#}");
            1
        }
    };
    drop(runtime_dir);
    if code != 0 {
        // A command that stopped early (Ctrl-C, an error mid-frame) may leave work in the GPU
        // driver's threads: `exit` would run the driver's static destructors under them, and
        // lavapipe then crashes (SIGSEGV after "interrupted: stopped", one run in 30 with the
        // machine loaded). Outputs appear only by rename, so nothing is lost by skipping them.
        use std::io::Write;
        let _ = std::io::stdout().flush();
        // SAFETY: _exit(2) has no preconditions.
        unsafe { libc::_exit(code) }
    }
    std::process::exit(code);
}
