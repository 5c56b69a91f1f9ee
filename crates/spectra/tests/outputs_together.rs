//! A command with several outputs writes all of them or none: the real binary, with the write
//! of one output made to fail after the other could have been written. One after the other,
//! a failure on the second (a full disk) left the first replaced by the new one beside the
//! second's old version, and the command said it failed.
//!
//! Two failures that hold for any user, root included (root ignores a read-only directory):
//! - an output in a directory whose path is so long that the output's own path fits Linux's
//!   PATH_MAX but the temporary file beside it does not (creating it fails with ENAMETOOLONG,
//!   where the command's early check, which creates a shorter name there, passes);
//! - a file-size limit (RLIMIT_FSIZE) between the sizes of the outputs, so that writing the
//!   largest fails half way with EFBIG, as a full disk fails it with ENOSPC.
//!
//! The GPU commands (render, bench) need an adapter; without one they fail with the install hint,
//! and so do their tests (`apt-get install mesa-vulkan-drivers libvulkan1`).
#![cfg(target_os = "linux")]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn spectra(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_spectra"));
    c.args(args);
    c
}

fn run(mut c: Command) -> (Output, String) {
    let o = c.output().expect("spawn spectra");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    (o, err)
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Longest path Linux takes, in bytes (PATH_MAX, 4096, counts the terminating NUL).
const PATH_MAX: usize = 4095;

/// A new file `name` in a new directory under `base`, with old content: its path fits
/// [`PATH_MAX`] with room for the truth command's lock file (`.<name>.lock`), while the temporary
/// file an atomic write creates beside it (`.<name>.<pid>.<random>.tmp`) does not.
fn doomed(base: &Path, name: &str, old: &[u8]) -> PathBuf {
    let len = PATH_MAX - ".lock".len() - 1;
    let mut dir = base.to_path_buf();
    loop {
        let room = len - name.len() - 1 - dir.as_os_str().len() - 1;
        if room <= 200 {
            dir.push("d".repeat(room));
            break;
        }
        dir.push("d".repeat(150));
    }
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    assert_eq!(path.as_os_str().len(), len);
    std::fs::write(&path, old).unwrap();
    // The premise: the shortest temporary name (a one-digit pid) cannot be created there, and the
    // early check's probe name (21 bytes: a name shorter than 16 leaves it no room) can.
    let tmp = std::fs::write(dir.join(format!(".{name}.1.AbCdEf.tmp")), b"").unwrap_err();
    assert_eq!(tmp.raw_os_error(), Some(libc::ENAMETOOLONG), "{tmp}");
    std::fs::write(dir.join(".spectra-check.AbCdEf"), b"").unwrap();
    std::fs::remove_file(dir.join(".spectra-check.AbCdEf")).unwrap();
    path
}

/// The command failed with one error line, about writing `name`, and the outputs kept their old
/// contents.
fn failed_and_kept(o: &Output, err: &str, name: &str, kept: &[(&Path, &[u8])]) {
    assert_eq!(o.status.code(), Some(1), "{err}\n(no GPU? {})", render::NO_ADAPTER_HELP);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("writing") && err.contains(name), "{err}");
    for (path, old) in kept {
        let now = std::fs::read(path).unwrap();
        assert!(
            now == *old,
            "{} was replaced ({} bytes, was {:?}): {err}",
            path.display(),
            now.len(),
            String::from_utf8_lossy(old)
        );
    }
}

/// What `dir` holds besides the doomed directory's first component: no temporary file left.
fn left(dir: &Path) -> Vec<String> {
    entries(dir).into_iter().filter(|e| !e.starts_with("ddd")).collect()
}

#[test]
fn render_writes_its_image_and_spectral_file_together() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("s.exr");
    std::fs::write(&spec, b"old spectral").unwrap();
    let out = doomed(dir.path(), "the-real-time-frame.png", b"old frame");
    let args = ["render", "cornell", "--mode", "spectral", "--size", "16x12", "--wavelengths", "4"];
    let (o, err) = run(spectra(&[&args[..], &["--out", s(&out), "--spectral-out", s(&spec)]].concat()));
    failed_and_kept(&o, &err, "the-real-time-frame.png", &[(&spec, b"old spectral"), (&out, b"old frame")]);
    assert_eq!(left(dir.path()), vec!["s.exr"]);
    assert_eq!(entries(out.parent().unwrap()), vec!["the-real-time-frame.png"]);
    // Where both can be written, both are.
    let ok = dir.path().join("the-real-time-frame.png");
    let (o, err) = run(spectra(&[&args[..], &["--out", s(&ok), "--spectral-out", s(&spec)]].concat()));
    assert!(o.status.success(), "{err}\n(no GPU? {})", render::NO_ADAPTER_HELP);
    assert!(compare::read_spectral_exr(&spec).is_ok());
    assert_eq!(compare::read_image(&ok).unwrap().size(), (16, 12));
}

#[test]
fn truth_writes_its_image_and_spectral_file_together() {
    let dir = tempfile::tempdir().unwrap();
    let spec = dir.path().join("s.exr");
    std::fs::write(&spec, b"old spectral").unwrap();
    let out = doomed(dir.path(), "the-path-traced-truth.exr", b"old truth");
    let args = ["truth", "cornell", "--spp", "1", "--size", "16x12"];
    let (o, err) = run(spectra(&[&args[..], &["--out", s(&out), "--spectral-out", s(&spec)]].concat()));
    failed_and_kept(&o, &err, "the-path-traced-truth.exr", &[(&spec, b"old spectral"), (&out, b"old truth")]);
    assert_eq!(left(dir.path()), vec!["s.exr"]);
    // No lock file or checkpoint left either.
    assert_eq!(entries(out.parent().unwrap()), vec!["the-path-traced-truth.exr"]);
    let ok = dir.path().join("truth.exr");
    let (o, err) = run(spectra(&[&args[..], &["--out", s(&ok), "--spectral-out", s(&spec)]].concat()));
    assert!(o.status.success(), "{err}");
    assert!(compare::read_spectral_exr(&spec).is_ok());
    assert_eq!(compare::read_image(&ok).unwrap().size(), (16, 12));
}

/// `diff`'s heat map, FLIP map and per-pixel CSV, with the file size limited so that the two
/// PNGs fit and the CSV, written last, does not.
#[test]
fn diff_writes_its_maps_and_csv_together() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let grad = |k: u32| {
        image::RgbImage::from_fn(64, 48, |x, y| {
            image::Rgb([(x * 4) as u8, (y * 5 + k) as u8, ((x + y) * k) as u8])
        })
    };
    grad(1).save(p("a.png")).unwrap();
    grad(3).save(p("b.png")).unwrap();
    let diff = |heat: &Path, flip: &Path, csv: &Path| {
        spectra(&[
            "diff",
            s(&p("a.png")),
            s(&p("b.png")),
            "--heatmap",
            s(heat),
            "--metric",
            "flip",
            "--flip-map",
            s(flip),
            "--per-pixel-out",
            s(csv),
        ])
    };
    // Unlimited, for the sizes.
    let (new_heat, new_flip, new_csv) = (p("nh.png"), p("nf.png"), p("nc.csv"));
    let (o, err) = run(diff(&new_heat, &new_flip, &new_csv));
    assert!(o.status.success(), "{err}");
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    let limit = size(&new_heat).max(size(&new_flip)) + 1024;
    assert!(size(&new_csv) > 2 * limit, "the CSV ({} bytes) must pass the limit ({limit})", size(&new_csv));

    let (heat, flip, csv) = (p("h.png"), p("f.png"), p("c.csv"));
    for f in [&heat, &flip, &csv] {
        std::fs::write(f, b"old").unwrap();
    }
    let mut cmd = diff(&heat, &flip, &csv);
    // SAFETY: setrlimit(2) and signal(2) are async-signal-safe; they run in the child between
    // fork and exec and touch nothing of the parent's.
    unsafe {
        std::os::unix::process::CommandExt::pre_exec(&mut cmd, move || {
            // Ignored, SIGXFSZ does not kill the process: the write fails with EFBIG instead.
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            let lim = libc::rlimit { rlim_cur: limit, rlim_max: limit };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    let (o, err) = run(cmd);
    failed_and_kept(&o, &err, "c.csv", &[(&heat, b"old"), (&flip, b"old"), (&csv, b"old")]);
    assert!(err.contains("per-pixel values"), "{err}");
    assert_eq!(
        entries(dir.path()),
        vec!["a.png", "b.png", "c.csv", "f.png", "h.png", "nc.csv", "nf.png", "nh.png"]
    );
}

/// `bench --suite`'s CSV and Markdown tables (the CSV was put in place first).
#[test]
fn bench_suite_writes_its_tables_together() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("suite.csv");
    std::fs::write(&csv, b"old csv").unwrap();
    let md = doomed(dir.path(), "the-benchmark-suite.md", b"old markdown");
    let args = [
        "bench",
        "--suite",
        "--suite-sizes",
        "16x12",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--wavelengths",
        "1",
    ];
    let (o, err) = run(spectra(&[&args[..], &["--csv", s(&csv), "--markdown", s(&md)]].concat()));
    // The rows' progress goes to stderr before the error: only its last line is the error.
    let last = err.trim_end().lines().last().unwrap_or("").to_string();
    assert!(last.starts_with("error: writing") && last.contains("the-benchmark-suite.md"), "{err}");
    failed_and_kept(&o, &last, "the-benchmark-suite.md", &[(&csv, b"old csv"), (&md, b"old markdown")]);
    assert!(!err.contains("wrote"), "{err}");
    assert_eq!(left(dir.path()), vec!["suite.csv"]);
    assert_eq!(entries(md.parent().unwrap()), vec!["the-benchmark-suite.md"]);
}
