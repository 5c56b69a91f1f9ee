//! Developer chores: `cargo xtask setup | demo | test | ci`.
//!
//! The README's two commands are `cargo xtask demo` and `cargo xtask test`; CI runs
//! `cargo xtask ci`. Each installs what it needs on a fresh Debian machine, so nothing has to be
//! set up by hand: a Vulkan driver (Mesa's software rasteriser lavapipe when there is no GPU
//! driver) and, for the test oracles, the `colour-science`, `mitsuba` and `OpenEXR` Python packages.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

const VULKAN_PACKAGES: &[&str] = &["mesa-vulkan-drivers", "libvulkan1"];
const PYTHON_PACKAGES: &[&str] =
    &["colour-science==0.4.7", "scipy", "mitsuba", "OpenEXR==3.5.3", "flip-evaluator==1.7"];

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let task = args.first().map(String::as_str).unwrap_or("help");
    let rest = &args[args.len().min(1)..];
    let result = match task {
        "setup" => setup_vulkan().and_then(|_| setup_python()),
        "demo" => demo(rest),
        "test" => test(rest),
        "ci" => ci(),
        "fuzz" => fuzz(rest),
        _ => {
            eprintln!(
                "usage: cargo xtask <task>\n\n  setup   install the Vulkan driver and Python test oracles if missing\n  demo    render the demo scene to out/\n  test    run every test (Rust tests, the oracle checks in tools/, the Python package's tests)\n  ci      cargo fmt --check, clippy -D warnings, test, then a 10 s coverage-guided fuzz slice per target\n  fuzz    coverage-guided fuzzing (libFuzzer, nightly): [--seconds S per target, default 60 | --runs N executions per target] [--targets a,b]"
            );
            return if task == "help" { ExitCode::SUCCESS } else { ExitCode::FAILURE };
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask {task}: {e}");
            ExitCode::FAILURE
        }
    }
}

type Result<T = ()> = std::result::Result<T, String>;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().expect("xtask lives in the workspace").to_path_buf()
}

fn run(cmd: &mut Command) -> Result {
    eprintln!("$ {}", describe(cmd));
    let status =
        cmd.current_dir(root()).status().map_err(|e| format!("cannot start {}: {e}", describe(cmd)))?;
    if status.success() { Ok(()) } else { Err(format!("`{}` failed ({status})", describe(cmd))) }
}

fn describe(cmd: &Command) -> String {
    std::iter::once(cmd.get_program())
        .chain(cmd.get_args())
        .map(|s| s.to_string_lossy())
        .collect::<Vec<_>>()
        .join(" ")
}

fn cargo() -> Command {
    Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
}

/// A Vulkan ICD manifest means some driver (GPU or lavapipe) is installed.
fn has_vulkan_driver() -> bool {
    let icd_dirs = ["/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d"];
    let has_icd =
        icd_dirs.iter().any(|d| std::fs::read_dir(d).map(|mut r| r.next().is_some()).unwrap_or(false));
    let has_loader = [
        "/usr/lib/x86_64-linux-gnu/libvulkan.so.1",
        "/usr/lib/aarch64-linux-gnu/libvulkan.so.1",
        "/usr/lib/libvulkan.so.1",
        "/usr/lib64/libvulkan.so.1",
    ]
    .iter()
    .any(|p| Path::new(p).exists());
    has_icd && has_loader
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(false)
}

fn apt_install(packages: &[&str]) -> Result {
    if Command::new("apt-get").arg("--version").output().is_err() {
        return Err(format!(
            "no apt-get on this machine: install {} with your package manager",
            packages.join(" ")
        ));
    }
    let sudo = !is_root();
    let mk = |args: &[&str]| {
        let mut c = if sudo { Command::new("sudo") } else { Command::new("apt-get") };
        if sudo {
            c.arg("-n").arg("apt-get");
        }
        c.args(args).env("DEBIAN_FRONTEND", "noninteractive");
        c
    };
    run(&mut mk(&["update", "-qq"]))?;
    run(mk(&["install", "-y", "-qq"]).args(packages))
        .map_err(|e| format!("{e}\n  install them yourself: sudo apt-get install {}", packages.join(" ")))
}

/// Installs Mesa's Vulkan drivers when no Vulkan driver is present. A machine with a GPU
/// driver already has an ICD and is left alone.
fn setup_vulkan() -> Result {
    if has_vulkan_driver() {
        return Ok(());
    }
    eprintln!(
        "No Vulkan driver found: installing Mesa's ({}), which includes the software rasteriser lavapipe.",
        VULKAN_PACKAGES.join(" ")
    );
    apt_install(VULKAN_PACKAGES)
}

/// `compare`'s build compiles NVIDIA's FLIP reference implementation (C++, vendored in
/// crates/compare/flip): install a C++ compiler when there is none.
fn setup_cxx() -> Result {
    let cxx = std::env::var("CXX").unwrap_or_else(|_| "c++".into());
    if Command::new(&cxx).arg("--version").output().map(|o| o.status.success()).unwrap_or(false) {
        return Ok(());
    }
    eprintln!("No C++ compiler ({cxx}) found: installing g++ (FLIP's reference implementation is C++).");
    apt_install(&["g++"])
}

fn python() -> String {
    std::env::var("PYTHON").unwrap_or_else(|_| "python3".into())
}

/// The oracle scripts in tools/ compare against colour-science; install it if missing.
fn setup_python() -> Result {
    let ok = Command::new(python())
        .args(["-c", "import colour, scipy, mitsuba, OpenEXR"])
        .output()
        .map(|o| o.status.success())
        .map_err(|e| format!("cannot run {}: {e} (install python3)", python()))?;
    if ok {
        return Ok(());
    }
    let mut pip = Command::new(python());
    pip.args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"]).args(PYTHON_PACKAGES);
    if run(&mut pip).is_err() {
        apt_install(&["python3-pip"])?;
        run(&mut pip)?;
    }
    Ok(())
}

fn demo(extra: &[String]) -> Result {
    setup_vulkan()?;
    std::fs::create_dir_all(root().join("out")).map_err(|e| format!("cannot create out/: {e}"))?;
    run(cargo().args(["run", "--release", "--package", "spectra", "--", "demo", "--out", "out"]).args(extra))
}

/// Every test: the Rust suite, then each `tools/check_*.py` oracle script, then the Python
/// package's pytest suite.
fn test(extra: &[String]) -> Result {
    setup_vulkan()?;
    setup_cxx()?;
    setup_python()?;
    run(cargo().args(["test", "--workspace"]).args(extra))?;
    let mut checks: Vec<PathBuf> = std::fs::read_dir(root().join("tools"))
        .map_err(|e| format!("cannot list tools/: {e}"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("check_") && n.ends_with(".py"))
        })
        .collect();
    checks.sort();
    let (mut passed, mut failed) = (0, Vec::new());
    for check in &checks {
        match run(Command::new(python()).arg(check)) {
            Ok(()) => passed += 1,
            Err(e) => {
                eprintln!("{e}");
                failed.push(check.display().to_string());
            }
        }
    }
    println!("oracle checks: {passed} passed, {} failed", failed.len());
    let package = python_package();
    if !failed.is_empty() {
        return Err(format!("oracle checks failed: {}", failed.join(", ")));
    }
    package
}

/// The Python package's packages besides itself: what its tests need (OpenEXR, as an EXR reader
/// independent of spectra's; colour-science, the oracle of `upsample`, `diff`, observers and
/// illuminants; Ray, for `spectra.distributed`).
const PYTHON_PACKAGE_TEST_DEPS: &[&str] =
    &["pytest", "numpy", "OpenEXR==3.5.3", "colour-science==0.4.7", "ray==2.60.0"];

/// The Python package (python/): built and installed into a venv in target/ with
/// `pip install ./python` (debug profile, so it reuses the Rust suite's build), then its
/// pytest suite. Skipped, saying so, when there is no Python.
fn python_package() -> Result {
    if Command::new(python()).arg("--version").output().is_err() {
        eprintln!("python package tests skipped: no {} on this machine", python());
        return Ok(());
    }
    let t0 = std::time::Instant::now();
    let target =
        std::env::var("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|_| root().join("target"));
    let venv = target.join("py-venv");
    let bin = venv.join("bin");
    if !bin.join("python").exists() {
        let mk = || run(Command::new(python()).args(["-m", "venv"]).arg(&venv));
        if mk().is_err() {
            apt_install(&["python3-venv"])?;
            mk()?;
        }
    }
    let py = bin.join("python");
    run(Command::new(&py)
        .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "./python"])
        .args(PYTHON_PACKAGE_TEST_DEPS)
        .env("MATURIN_PEP517_ARGS", "--profile dev"))?;
    let r = run(Command::new(&py).args(["-m", "pytest", "-q", "-s", "python/tests"]));
    eprintln!("python package: built, installed and tested in {:.0} s", t0.elapsed().as_secs_f64());
    r
}

fn ci() -> Result {
    // A clean clone builds once: incremental caches only cost disk there (GBs per profile).
    // SAFETY: single-threaded at this point; children inherit the variable.
    unsafe { std::env::set_var("CARGO_INCREMENTAL", "0") };
    disk_report("before the build");
    setup_cxx()?;
    run(cargo().args(["fmt", "--all", "--", "--check"]))?;
    run(cargo().args(["clippy", "--workspace", "--all-targets", "--", "-D", "warnings"]))?;
    let result = test(&[]);
    disk_report("after the tests");
    result?;
    // The bounded coverage-guided slice (the long run is `cargo xtask fuzz --seconds 3600`).
    // It needs a nightly toolchain; where none can be installed, say so and keep the stable
    // harness's run (`cargo test -p fuzz`, above) as the only fuzzing.
    match ensure_fuzz_tools() {
        Ok(()) => fuzz(&["--seconds".into(), "10".into()]),
        Err(e) => {
            eprintln!("coverage-guided fuzz slice skipped: {e}");
            Ok(())
        }
    }
}

/// The coverage-guided targets (`crates/fuzz/coverage`) and the seed corpus each starts from
/// (`crates/fuzz/corpus/<name>`; the structure-aware glTF target builds its own documents).
const FUZZ_TARGETS: &[(&str, Option<&str>)] = &[
    ("gltf", Some("gltf")),
    ("gltf-structured", None),
    ("coeff", Some("coeff")),
    ("csv", Some("csv")),
    ("medium", Some("medium")),
    ("rgb-medium", Some("rgb-medium")),
    ("exr", Some("exr")),
    ("spectral-exr", Some("spectral-exr")),
    ("png", Some("png")),
    ("env", Some("env")),
];

fn nightly() -> Command {
    let mut c = Command::new("rustup");
    c.args(["run", "nightly"]);
    c
}

fn succeeds(cmd: &mut Command) -> bool {
    cmd.output().map(|o| o.status.success()).unwrap_or(false)
}

/// A nightly toolchain (libFuzzer's sanitizer coverage needs it) and cargo-fuzz, installed if
/// missing.
fn ensure_fuzz_tools() -> Result {
    if !succeeds(nightly().args(["rustc", "--version"])) {
        eprintln!("No nightly toolchain: installing one (minimal profile) for the coverage-guided fuzzer.");
        run(Command::new("rustup").args(["toolchain", "install", "nightly", "--profile", "minimal"]))?;
    }
    if !succeeds(nightly().args(["cargo", "fuzz", "--version"])) {
        eprintln!("No cargo-fuzz: installing it.");
        run(cargo().args(["install", "cargo-fuzz", "--locked"]))?;
    }
    Ok(())
}

/// Runs each coverage-guided target for `--seconds` from its seed corpus (copied: libFuzzer
/// writes what it finds into the first corpus directory) and prints executions, coverage and
/// features; a crash (libFuzzer's exit status) fails the task, its input under
/// `crates/fuzz/coverage/artifacts/<target>/`.
fn fuzz(args: &[String]) -> Result {
    let get = |k: &str| args.iter().position(|a| a == k).and_then(|i| args.get(i + 1));
    let seconds: u64 =
        get("--seconds").map_or(Ok(60), |s| s.parse().map_err(|_| format!("--seconds {s}")))?;
    let only: Option<Vec<&str>> = get("--targets").map(|t| t.split(',').collect());
    // `--runs N`: stop each target after N executions (the long run's 10⁷), whatever the time.
    let runs: Option<u64> =
        get("--runs").map(|s| s.parse().map_err(|_| format!("--runs {s}"))).transpose()?;
    ensure_fuzz_tools()?;
    let dir = root().join("crates/fuzz/coverage");
    let mut rows = Vec::new();
    for (target, seeds) in FUZZ_TARGETS {
        if only.as_ref().is_some_and(|o| !o.contains(target)) {
            continue;
        }
        let work = std::env::temp_dir().join(format!("spectra-fuzz-{target}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&work);
        std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
        let mut cmd = nightly();
        cmd.args(["cargo", "fuzz", "run", "--fuzz-dir"])
            .arg(&dir)
            .args(["-s", "none", "-O", target])
            .arg(&work);
        if let Some(s) = seeds {
            cmd.arg(root().join("crates/fuzz/corpus").join(s));
        }
        cmd.args(["--", "-rss_limit_mb=4096", "-print_final_stats=1"]);
        match runs {
            Some(n) => cmd.arg(format!("-runs={n}")),
            None => cmd.arg(format!("-max_total_time={seconds}")),
        };
        eprintln!("$ {}", describe(&cmd));
        let out = cmd.current_dir(root()).output().map_err(|e| format!("cannot start cargo fuzz: {e}"))?;
        let log = String::from_utf8_lossy(&out.stderr);
        let _ = std::fs::remove_dir_all(&work);
        let stat = |name: &str| {
            log.lines().find_map(|l| l.strip_prefix(&format!("stat::{name}:")).map(|v| v.trim().to_string()))
        };
        let done = log.lines().rev().find(|l| l.contains("cov:")).unwrap_or("").to_string();
        let field =
            |k: &str| done.split_whitespace().skip_while(|w| *w != k).nth(1).unwrap_or("?").to_string();
        if !out.status.success() {
            let tail: Vec<&str> = log.lines().rev().take(30).collect();
            let tail: Vec<&str> = tail.into_iter().rev().collect();
            return Err(format!("fuzz target {target} failed ({}):\n{}", out.status, tail.join("\n")));
        }
        rows.push(format!(
            "{target:16} {:>12} execs  cov {:>6}  ft {:>7}  corpus {:>5}  peak RSS {} MB",
            stat("number_of_executed_units").unwrap_or_else(|| "?".into()),
            field("cov:"),
            field("ft:"),
            field("corp:"),
            stat("peak_rss_mb").unwrap_or_else(|| "?".into()),
        ));
    }
    match runs {
        Some(n) => println!("coverage-guided fuzzing, {n} executions per target (crashes: 0):"),
        None => println!("coverage-guided fuzzing, {seconds} s per target (crashes: 0):"),
    }
    for r in rows {
        println!("  {r}");
    }
    Ok(())
}

/// Prints free disk space and the target directory's size: a CI machine once ran out of disk
/// mid-suite, and this makes the margin visible in every log.
fn disk_report(when: &str) {
    let target =
        std::env::var("CARGO_TARGET_DIR").map(PathBuf::from).unwrap_or_else(|_| root().join("target"));
    eprintln!("disk {when}:");
    let _ = Command::new("df").args(["-h", "."]).current_dir(root()).status();
    if target.exists() {
        let _ = Command::new("du").args(["-sh"]).arg(&target).status();
    }
}
