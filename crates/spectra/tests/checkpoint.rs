//! Checkpoints and `--resume` of `spectra truth` (issue 31) on the real binary: killed with
//! SIGKILL three times and resumed, a render ends bit-identical to the uninterrupted one;
//! Ctrl-C keeps its samples; a checkpoint of another render, a damaged one, or one left over
//! without `--resume` is refused naming the file. CPU only.

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant, SystemTime};

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_spectra"));
    c.stdout(Stdio::null()).stderr(Stdio::piped());
    c
}

fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("running spectra")
}

/// The render every case uses: a few seconds here, with a checkpoint every 0.3 s.
fn args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["truth", "cornell", "--size", "64x48", "--out", out];
    for (k, d) in [("--spp", "600"), ("--seed", "5")] {
        if !extra.contains(&k) {
            v.extend([k, d]);
        }
    }
    v.extend(extra);
    v
}

fn mtime(p: &Path) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

/// Starts the render and kills it (SIGKILL) once its checkpoint has been written (again, if
/// one was there); returns whether it was killed mid-render (not already finished).
fn kill_after_a_checkpoint(out: &str, ckpt: &Path, resume: bool) -> bool {
    let before = mtime(ckpt);
    let mut extra = vec!["--checkpoint-every", "0.3"];
    if resume {
        extra.push("--resume");
    }
    let mut child = bin().args(args(out, &extra)).spawn().unwrap();
    let t = Instant::now();
    while t.elapsed() < Duration::from_secs(60) {
        if child.try_wait().unwrap().is_some() {
            return false;
        }
        if mtime(ckpt).is_some() && mtime(ckpt) != before {
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    true
}

fn pixels(p: &Path) -> Vec<[f32; 3]> {
    compare::read_image(p).unwrap().data
}

#[test]
fn killed_three_times_and_resumed_equals_the_uninterrupted_render() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full.exr");
    let out = dir.path().join("r.exr");
    let (f, o) = (full.to_str().unwrap(), out.to_str().unwrap());
    let t = Instant::now();
    assert!(run(&args(f, &["--checkpoint-every", "0"])).status.success());
    let alone = t.elapsed();
    let ckpt = dir.path().join("r.exr.checkpoint");
    let mut kills = 0;
    for i in 0..3 {
        if kill_after_a_checkpoint(o, &ckpt, i > 0) {
            kills += 1;
            assert!(ckpt.exists() && !out.exists(), "kill {i}: the checkpoint, and no output yet");
        }
    }
    assert!(kills >= 2, "the render was killed mid-way at least twice (took {alone:?} alone)");
    let r = run(&args(o, &["--checkpoint-every", "0.3", "--resume"]));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(r.status.success(), "{err}");
    assert!(err.contains("resumed from"), "{err}");
    assert_eq!(pixels(&out), pixels(&full), "resumed render = uninterrupted render, bit for bit");
    assert!(!ckpt.exists(), "a finished render removes its checkpoint");
}

#[test]
fn checkpoints_that_do_not_fit_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.exr");
    let o = out.to_str().unwrap();
    let ckpt = dir.path().join("r.exr.checkpoint");
    assert!(kill_after_a_checkpoint(o, &ckpt, false), "killed mid-way");
    let refused = |extra: &[&str], parts: &[&str]| {
        let r = run(&args(o, extra));
        let err = String::from_utf8_lossy(&r.stderr).to_string();
        assert_eq!(r.status.code(), Some(1), "{err}");
        let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
        assert_eq!(lines.len(), 1, "{err}");
        for p in parts {
            assert!(lines[0].contains(p), "'{p}' missing: {err}");
        }
        assert!(!out.exists());
    };
    refused(&[], &["r.exr.checkpoint", "--resume"]);
    refused(
        &["--resume", "--seed", "6"],
        &["r.exr.checkpoint", "different render", "seed is 5 there and 6 here"],
    );
    refused(&["--resume", "--spp", "601"], &["r.exr.checkpoint", "601"]);
    // Spectral bands the interrupted run did not have (or the other way round, where the
    // checkpoint is the larger file): named as such, not as a hash.
    let sp = dir.path().join("s.exr");
    refused(
        &["--resume", "--spectral-out", sp.to_str().unwrap()],
        &["r.exr.checkpoint", "spectral bands (--spectral-out) is none there"],
    );
    let bytes = std::fs::read(&ckpt).unwrap();
    std::fs::write(&ckpt, &bytes[..bytes.len() - 9]).unwrap();
    refused(&["--resume"], &["r.exr.checkpoint", "truncated"]);
    std::fs::remove_file(&ckpt).unwrap();
    refused(&["--resume"], &["no checkpoint", "r.exr.checkpoint"]);
    refused(&["--checkpoint-every", "-1"], &["--checkpoint-every"]);
    refused(&["--checkpoint-every", "1e-30"], &["--checkpoint-every", "0.1"]);
}

/// Ctrl-C after a checkpoint interval keeps the samples so far; `--resume` finishes the render.
/// So does SIGTERM, what a cluster's scheduler sends on pre-emption (it ended the process as
/// `kill -9` would, losing the samples since the last checkpoint).
#[test]
fn ctrl_c_keeps_the_samples() {
    for signal in [libc::SIGINT, libc::SIGTERM] {
        keeps_the_samples_on(signal);
    }
}

fn keeps_the_samples_on(signal: libc::c_int) {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full.exr");
    let out = dir.path().join("r.exr");
    let (f, o) = (full.to_str().unwrap(), out.to_str().unwrap());
    assert!(run(&args(f, &["--checkpoint-every", "0"])).status.success());
    let ckpt = dir.path().join("r.exr.checkpoint");
    let child = bin().args(args(o, &["--checkpoint-every", "0.3"])).spawn().unwrap();
    let t = Instant::now();
    while !ckpt.exists() && t.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(10));
    }
    std::thread::sleep(Duration::from_millis(100));
    // SAFETY: kill(2) on our own child's pid.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
    let r = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&r.stderr);
    if r.status.success() {
        eprintln!("the render finished before signal {signal}; nothing to check");
        return;
    }
    assert_eq!(r.status.code(), Some(130), "signal {signal}: {err}");
    assert!(err.contains("samples kept in") && err.contains("--resume"), "{err}");
    assert!(ckpt.exists() && !out.exists());
    let r = run(&args(o, &["--checkpoint-every", "0.3", "--resume"]));
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert_eq!(pixels(&out), pixels(&full));
}

/// Two renders to one --out shared its checkpoint (each overwrote the other's, the first to
/// finish deleted it); the second is refused while the first runs, naming the lock, and the
/// lock file goes with the first render. Found by a sweep.
#[test]
fn a_second_render_to_the_same_out_is_refused_while_the_first_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.exr");
    let o = out.to_str().unwrap();
    let lock = dir.path().join(".r.exr.lock");
    let child = bin().args(args(o, &["--spp", "1000000", "--checkpoint-every", "0.3"])).spawn().unwrap();
    let t = Instant::now();
    while !lock.exists() && t.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(10));
    }
    let second = run(&args(o, &["--spp", "4"]));
    let err = String::from_utf8_lossy(&second.stderr);
    // SAFETY: kill(2) on our own child's pid.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let first = child.wait_with_output().unwrap();
    assert_eq!(second.status.code(), Some(1), "{err}");
    assert!(
        err.contains("another `spectra truth` is rendering to it") && err.contains(".r.exr.lock"),
        "{err}"
    );
    assert_eq!(first.status.code(), Some(130), "{}", String::from_utf8_lossy(&first.stderr));
    assert!(!lock.exists(), "the lock file stays behind");
    // The first one's samples are kept (for --resume); set aside here.
    let _ = std::fs::remove_file(dir.path().join("r.exr.checkpoint"));
    // Without checkpoints nothing is shared: no lock.
    assert!(run(&args(o, &["--spp", "4", "--checkpoint-every", "0"])).status.success());
    assert!(!lock.exists());
}

/// Found by a sweep: a checkpoint that could not be written (here its path taken by a
/// directory; a full disk or a quota alike) ended the render and lost every sample. It is a
/// safety net: the render warns and finishes.
#[test]
fn a_checkpoint_that_cannot_be_written_does_not_stop_the_render() {
    use std::io::BufRead;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.exr");
    let o = out.to_str().unwrap();
    let cache = dir.path().join("cache");
    let mut child = bin()
        .args(args(o, &["--checkpoint-every", "0.2", "--truth-cache", cache.to_str().unwrap()]))
        .spawn()
        .unwrap();
    // The cache's note comes after the checks of a leftover checkpoint, before the first pass.
    let mut err = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut text = String::new();
    while !text.contains("rendering") {
        let mut line = String::new();
        if err.read_line(&mut line).unwrap() == 0 {
            panic!("spectra ended before rendering: {text}");
        }
        text.push_str(&line);
    }
    std::fs::create_dir(dir.path().join("r.exr.checkpoint")).unwrap();
    let mut rest = String::new();
    std::io::Read::read_to_string(&mut err, &mut rest).unwrap();
    let status = child.wait().unwrap();
    assert!(status.success(), "{text}{rest}");
    assert!(rest.contains("warning: writing the checkpoint") && rest.contains("rendering on"), "{rest}");
    assert!(out.exists());
}
