//! Ctrl-C, for real: each long command is started as a child process, sent SIGINT while it
//! works, and must exit within about a second with status 130, an "interrupted" message and no
//! output file (nor a temporary one) left behind.
//!
//! The GPU commands need an adapter; without one they fail with the install hint, and so does
//! the test (`apt-get install mesa-vulkan-drivers libvulkan1`).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Longest time from SIGINT to exit. The target is 1 s (measured: 0.03 s for truth, 0.3 s for
/// a 4096² render on lavapipe); the margin is for a loaded two-core CI machine.
const LIMIT: Duration = Duration::from_millis(1500);

fn spectra(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_spectra"));
    c.args(args).stdout(Stdio::null()).stderr(Stdio::piped());
    c
}

fn entries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect()
}

/// Starts `cmd`, waits until it has worked for `after`, sends SIGINT and checks the exit.
/// `cooperative`: the command must stop by polling the token, not by the handler's forced
/// exit (which covers uninterruptible driver calls during GPU setup).
fn interrupt(cmd: Command, after: Duration, dir: Option<&Path>, cooperative: bool) -> String {
    interrupt_when(cmd, &|| false, after, dir, cooperative)
}

/// As [`interrupt`], but the SIGINT goes as soon as `ready()` holds (polled every 50 ms), or
/// at `after` at the latest: for a test that needs some work finished first, however loaded
/// the machine is.
fn interrupt_when(
    mut cmd: Command,
    ready: &dyn Fn() -> bool,
    after: Duration,
    dir: Option<&Path>,
    cooperative: bool,
) -> String {
    let mut child = cmd.spawn().expect("spawn spectra");
    let start = Instant::now();
    while start.elapsed() < after && !ready() {
        std::thread::sleep(Duration::from_millis(50));
    }
    if let Some(status) = child.try_wait().unwrap() {
        let out = child.wait_with_output().unwrap();
        panic!(
            "spectra ended before the SIGINT ({status}): {}\n(no GPU? {})",
            String::from_utf8_lossy(&out.stderr),
            render::NO_ADAPTER_HELP
        );
    }
    // SAFETY: kill(2) on our own child's pid.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let t = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if t.elapsed() > Duration::from_secs(20) {
            let _ = child.kill();
            panic!("still running 20 s after SIGINT");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let took = t.elapsed();
    let mut stderr = String::new();
    std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut stderr).unwrap();
    assert_eq!(status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("interrupted"), "{stderr}");
    assert!(took < LIMIT, "exit took {took:?} after SIGINT");
    if cooperative {
        assert!(!stderr.contains("forced"), "{stderr}");
    }
    if let Some(dir) = dir {
        assert!(entries(dir).is_empty(), "left behind: {:?}", entries(dir));
    }
    eprintln!("exited {took:?} after SIGINT");
    stderr
}

/// A `truth` of the Cornell box that runs until interrupted (10⁸ samples of 4×4 pixels).
fn long_truth(out: &str, extra: &[&str]) -> Command {
    spectra(&[&["truth", "cornell", "--spp", "100000000", "--size", "4x4", "--out", out][..], extra].concat())
}

#[test]
fn truth_stops_inside_a_pixel_at_a_huge_sample_count() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.exr");
    let o = out.to_str().unwrap();
    interrupt(long_truth(o, &["--checkpoint-every", "0"]), Duration::from_secs(3), Some(dir.path()), true);
    // With a truth cache that did not exist: no empty folder is left behind either.
    let cache = dir.path().join("gt");
    let extra = ["--truth-cache", cache.to_str().unwrap(), "--checkpoint-every", "0"];
    interrupt(long_truth(o, &extra), Duration::from_secs(3), Some(dir.path()), true);
}

/// With checkpoints (the default), Ctrl-C keeps the finished passes however soon it comes: a
/// render interrupted before its first interval threw away every sample.
#[test]
fn truth_keeps_its_finished_passes_on_ctrl_c_before_an_interval() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.exr");
    let cmd = long_truth(out.to_str().unwrap(), &[]);
    let stderr = interrupt(cmd, Duration::from_secs(3), None, true);
    assert!(stderr.contains("samples kept in") && stderr.contains("--resume"), "{stderr}");
    assert_eq!(entries(dir.path()), vec!["t.exr.checkpoint".to_string()]);
}

#[test]
fn render_stops_a_large_frame() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("big.png");
    let cmd = spectra(&[
        "render",
        "cornell",
        "--size",
        "4096x4096",
        "--env",
        "default",
        "--wavelengths",
        "64",
        "--out",
        out.to_str().unwrap(),
    ]);
    // The frame itself takes ~18 s on lavapipe (the plain Cornell frame at N = 16 takes 3 s since
    // issue 27's shading work, too short): at 6 s the process is surely waiting for it.
    interrupt(cmd, Duration::from_secs(6), Some(dir.path()), true);
}

#[test]
fn bench_stops() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.csv");
    let cmd = spectra(&[
        "bench",
        "cornell",
        "--size",
        "512x512",
        "--frames",
        "10000",
        "--csv",
        out.to_str().unwrap(),
    ]);
    interrupt(cmd, Duration::from_secs(4), Some(dir.path()), false);
}

#[test]
fn bench_suite_stops() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, md) = (dir.path().join("s.csv"), dir.path().join("s.md"));
    let cmd = spectra(&[
        "bench",
        "--suite",
        "--suite-sizes",
        "512x512",
        "--frames",
        "10000",
        "--csv",
        csv.to_str().unwrap(),
        "--markdown",
        md.to_str().unwrap(),
    ]);
    interrupt(cmd, Duration::from_secs(4), Some(dir.path()), false);
}

#[test]
fn lut_stops_the_fit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.coeff");
    let cmd = spectra(&["lut", "--res", "64", "--out", out.to_str().unwrap()]);
    interrupt(cmd, Duration::from_secs(2), Some(dir.path()), true);
}

#[test]
fn eval_stops_without_a_summary() {
    let parent = tempfile::tempdir().unwrap();
    let dir = parent.path().join("eval");
    let cmd = spectra(&["eval", "--quick", "--spp", "100000000", "--out", dir.to_str().unwrap()]);
    let stderr = interrupt(cmd, Duration::from_secs(5), None, false);
    assert!(stderr.contains("results.json"), "{stderr}");
    assert!(!dir.join("results.json").exists() && !dir.join("index.html").exists());
    if dir.exists() {
        let temps: Vec<String> = entries(&dir).into_iter().filter(|n| n.ends_with(".tmp")).collect();
        assert!(temps.is_empty(), "{temps:?}");
    }
}

/// `demo --out DIR` holding a previous run's image (`truth.png`): what is left after Ctrl-C at
/// `stage` (the line of standard error to wait for) and `after` it.
fn demo_interrupted(spp: &str, size: &str, stage: &str, after: Duration) -> (String, Vec<String>, String) {
    use std::io::BufRead;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("truth.png"), "previous run").unwrap();
    let mut cmd = spectra(&["demo", "--out", dir.path().to_str().unwrap(), "--spp", spp, "--size", size]);
    let mut child = cmd.spawn().expect("spawn spectra");
    let (tx, rx) = std::sync::mpsc::channel();
    let stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut all = String::new();
        for line in std::io::BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line.clone());
            all += &line;
            all.push('\n');
        }
        all
    });
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(line) if line.contains(stage) => break,
            Ok(_) => {}
            Err(_) if Instant::now() > deadline => panic!("no '{stage}' within 120 s"),
            Err(_) => assert!(child.try_wait().unwrap().is_none(), "demo ended before '{stage}'"),
        }
    }
    std::thread::sleep(after);
    // SAFETY: kill(2) on our own child's pid.
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let status = child.wait().unwrap();
    let stderr = reader.join().unwrap();
    assert_eq!(status.code(), Some(130), "{stderr}");
    let kept = std::fs::read_to_string(dir.path().join("truth.png")).unwrap_or_default();
    let mut left = entries(dir.path());
    left.sort();
    (stderr, left, kept)
}

/// Ctrl-C during the demo's ground truth, and during its real-time renders once the truth is
/// done, leaves --out as it was: the images are made in a private folder and put in place
/// together (the truth was written into --out before the renders, so an interrupt then left
/// a new truth beside the previous run's renders while saying nothing was written).
#[test]
fn demo_leaves_its_folder_as_it_was() {
    for (spp, size, stage) in [("100000000", "8x8", "1/3"), ("1", "1024x1024", "2/3")] {
        let (stderr, left, kept) = demo_interrupted(spp, size, stage, Duration::from_millis(1500));
        assert!(stderr.contains("no output written"), "{stderr}");
        assert_eq!(kept, "previous run", "truth.png replaced ({stage}); {stderr}");
        // The forced exit (a driver call that cannot be interrupted) skips the working folder's
        // removal; its name carries the pid, so the next demo removes it.
        let forced = stderr.contains("forced");
        let expected: &[&str] = &["truth.png"];
        let visible: Vec<&String> = left.iter().filter(|n| !(forced && n.starts_with(".demo."))).collect();
        assert_eq!(visible, expected, "left after Ctrl-C at {stage}: {left:?}; {stderr}");
    }
}

/// A sequence interrupted after some frames keeps them, each complete, says how many and how
/// to draw the rest, and leaves no temporary file.
#[test]
fn render_sequence_keeps_its_finished_frames() {
    let dir = tempfile::tempdir().unwrap();
    let fox = concat!(env!("CARGO_MANIFEST_DIR"), "/../scene/tests/data/pose/Fox/Fox.gltf");
    let pattern = dir.path().join("f_%04d.png");
    let cmd = spectra(&[
        "render",
        fox,
        "--animation",
        "Run",
        "--times",
        "0:1000:0.05",
        "--size",
        "64x48",
        "--out",
        pattern.to_str().unwrap(),
    ]);
    // The first frame compiles the pipelines (seconds on a loaded machine): the SIGINT goes once
    // two frames are written.
    let two = || entries(dir.path()).iter().filter(|n| n.ends_with(".png")).count() >= 2;
    let stderr = interrupt_when(cmd, &two, Duration::from_secs(120), None, true);
    let names = entries(dir.path());
    assert!(names.len() >= 2, "not two frames in 120 s: {stderr}");
    assert!(names.iter().all(|n| n.starts_with("f_") && n.ends_with(".png") && n.len() == 10), "{names:?}");
    assert!(stderr.contains(&format!("{} of 20001 frames written", names.len())), "{stderr}");
    assert!(stderr.contains("--resume"), "{stderr}");
    for n in names {
        image::open(dir.path().join(&n)).unwrap_or_else(|e| panic!("{n}: {e}"));
    }
}

/// A truth sequence interrupted inside its first frame keeps that frame's samples in its
/// checkpoint and says so, with how many frames were written.
#[test]
fn truth_sequence_keeps_the_current_frames_samples() {
    let dir = tempfile::tempdir().unwrap();
    let fox = concat!(env!("CARGO_MANIFEST_DIR"), "/../scene/tests/data/pose/Fox/Fox.gltf");
    let pattern = dir.path().join("t_%02d.exr");
    let cmd = spectra(&[
        "truth",
        fox,
        "--animation",
        "Run",
        "--times",
        "0,0.5",
        "--size",
        "8x6",
        "--spp",
        "100000000",
        "--out",
        pattern.to_str().unwrap(),
    ]);
    let stderr = interrupt(cmd, Duration::from_secs(4), None, true);
    assert!(stderr.contains("0 of 2 frames written; frame 0: "), "{stderr}");
    assert!(stderr.contains("t_00.exr.checkpoint") && stderr.contains("--resume"), "{stderr}");
    assert_eq!(entries(dir.path()), vec!["t_00.exr.checkpoint".to_string()]);
}
