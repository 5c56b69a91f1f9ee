//! Requests that used to panic or allocate without bound (issue 14), run through the binary:
//! each must end with one `error:` line naming the flag, exit status 1, and no panic.

use std::process::{Command, Stdio};

fn spectra(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_spectra")).args(args).output().expect("spawn spectra")
}

fn refused(args: &[&str], needles: &[&str]) {
    let t = std::time::Instant::now();
    let out = spectra(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{n}' not in {err}");
    }
    // Refused up front, not after minutes of work or gigabytes of allocation.
    assert!(t.elapsed().as_secs() < 20, "{args:?} took {:?}", t.elapsed());
}

fn two_images(dir: &std::path::Path) -> (String, String) {
    let a = dir.join("a.png");
    let b = dir.join("b.png");
    image::RgbaImage::from_pixel(8, 8, image::Rgba([40, 80, 120, 255])).save(&a).unwrap();
    image::RgbaImage::from_pixel(8, 8, image::Rgba([42, 80, 118, 255])).save(&b).unwrap();
    (a.display().to_string(), b.display().to_string())
}

#[test]
fn absurd_counts_and_sizes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = two_images(dir.path());
    refused(&["diff", &a, &b, "--white-y", "1e-310"], &["--white-y", "1e-310", "white luminance"]);
    let heat = dir.path().join("h.png").display().to_string();
    // Values written as one would type them ("-1", not "-1e0").
    refused(&["diff", &a, &b, "--white-y", "-1"], &["--white-y -1:", "between 1e-20 and 1e20"]);
    for (m, shown) in [("1e300", "1e300"), ("1e-300", "1e-300"), ("0e0", "got 0"), ("-1", "got -1")] {
        refused(
            &["diff", &a, &b, "--heatmap", &heat, "--max-de", m],
            &["--max-de", "from 0.0001 to 10000", shown],
        );
    }
    assert!(!dir.path().join("h.png").exists());
    refused(&["upsample", "--roundtrip", "18446744073709551615"], &["--roundtrip", "at most"]);
    let out = dir.path().join("t.coeff").display().to_string();
    refused(
        &["lut", "--res", "8", "--check", "18446744073709551615", "--out", &out],
        &["--check", "at most"],
    );
    let exr = dir.path().join("t.exr").display().to_string();
    refused(&["truth", "cornell", "--size", "4294967295x1", "--out", &exr], &["4294967295", "too large"]);
    // Too deep for the light-field table in every command (truth drew black at 10⁶ m); too many
    // march steps named as the flag, not as a shader that does not compile.
    for cmd in [&["truth", "cornell", "--spp", "1"][..], &["render", "cornell"][..]] {
        let args = [cmd, &["--size", "8x8", "--water", "IB", "--depth", "1e6", "--out", &exr][..]].concat();
        refused(&args, &["--depth 1000000", "too deep", "at most 980"]);
    }
    refused(
        &["render", "fog", "--size", "8x8", "--scatter-steps", "1000", "--out", &exr],
        &["--scatter-steps 1000", "0–32"],
    );
    // The media's bounds hold on any scene, each naming its flag (on a dry scene they were
    // accepted silently, under water the message named no flag; found by a sweep).
    for (scene, flag, value, shown) in [
        ("cornell", "--scatter-steps", "33", "0–32"),
        ("underwater", "--scatter-steps", "33", "0–32"),
        ("cornell", "--phase-g", "1", "between −1 and 1"),
        ("cornell", "--forward-cone", "46", "0–45"),
        ("cornell", "--light-field-photons", "0", "photons"),
    ] {
        refused(
            &["render", scene, "--size", "8x8", flag, value, "--out", &exr],
            &[&format!("{flag} {value}"), shown],
        );
    }
    let missing = dir.path().join("no/such/dir/t.exr").display().to_string();
    refused(&["truth", "cornell", "--spp", "100000", "--out", &missing], &["--out", "does not exist"]);
    // Issue 29: numbers that aborted, ran for minutes or overflowed into garbage.
    refused(
        &[
            "truth",
            "cornell",
            "--size",
            "8x8",
            "--spp",
            "1",
            "--out",
            &exr,
            "--spectral-out",
            &p_(dir.path(), "s.exr"),
            "--spectral-bin",
            "1e-9",
        ],
        &["--spectral-bin", "at most 2048"],
    );
    for ppd in ["1e9", "1e30", "1e-30", "0.5"] {
        refused(&["diff", &a, &b, "--metric", "flip", "--flip-ppd", ppd], &["--flip-ppd", "between"]);
    }
    for (s0, s1) in [("-1e5", "1e5"), ("-1e30", "1e30"), ("-40", "40")] {
        refused(
            &[
                "diff",
                &a,
                &b,
                "--metric",
                "flip",
                "--flip",
                "hdr",
                "--flip-start-exposure",
                s0,
                "--flip-stop-exposure",
                s1,
            ],
            &["exposure"],
        );
    }
    for (flag, v) in [("--frames", "4294967295"), ("--warmup", "4294967295"), ("--frames", "0")] {
        refused(&["bench", "cornell", "--size", "8x8", flag, v], &[flag, v]);
    }
    let r = ["render", "cornell", "--size", "8x8", "--out", &exr];
    for (flag, v, needle) in [
        ("--exposure", "1e30", "±64"),
        ("--exposure", "-200", "±64"),
        ("--env-rotation", "1e30", "rotation"),
        ("--env-intensity", "-1", "between 0 and"),
        ("--env-sun-share", "1.5", "(got 1.5)"),
        ("--env-sun-share", "0", "(0, 1]"),
        ("--env-sun-share", "-0.2", "(got -0.2)"),
    ] {
        refused(&[&r[..], &["--env", "default", flag, v]].concat(), &[needle]);
    }
    refused(&["upsample", "0.5", "0.2", "0.1", "--samples", "100000000000"], &["--samples", "at most"]);
    // A well-formed table too coarse to upsample anything (res 2: round trip ΔE 40–66) rendered
    // black; the cache refused such tables, `--table` did not.
    let coarse = p_(dir.path(), "coarse.coeff");
    let out = spectra(&["lut", "--res", "2", "--check", "0", "--out", &coarse]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    refused(
        &["render", "cornell", "--size", "8x8", "--table", &coarse, "--out", &exr],
        &["--table", "coarse.coeff", "ΔE2000"],
    );
    refused(
        &["truth", "cornell", "--size", "8x8", "--spp", "1", "--table", &coarse, "--out", &exr],
        &["--table", "round trip"],
    );
    std::fs::remove_file(&coarse).unwrap();
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

fn p_(d: &std::path::Path, f: &str) -> String {
    d.join(f).display().to_string()
}

/// `spectra diff … --json | head -c 100`: the reader goes away; the writer ends quietly
/// (killed by SIGPIPE like any Unix filter), without a panic message.
#[test]
fn a_closed_stdout_ends_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = two_images(dir.path());
    let mut child = Command::new(env!("CARGO_BIN_EXE_spectra"))
        .args(["diff", &a, &b, "--json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked") && !err.contains("Broken pipe"), "{err}");
    use std::os::unix::process::ExitStatusExt;
    assert!(out.status.success() || out.status.signal() == Some(libc::SIGPIPE), "{:?}: {err}", out.status);
}

/// Standard output that cannot be written (a full disk; `/dev/full` here): one error line and
/// exit status 1, as for any other failure, where `println!` panicked (status 101).
#[test]
fn an_unwritable_stdout_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = two_images(dir.path());
    for args in [
        vec!["diff", a.as_str(), b.as_str()],
        vec!["diff", a.as_str(), b.as_str(), "--json"],
        vec!["observers"],
    ] {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").expect("/dev/full");
        let out = Command::new(env!("CARGO_BIN_EXE_spectra")).args(&args).stdout(full).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(
            err.trim_end().lines().collect::<Vec<_>>(),
            ["error: cannot write to standard output: No space left on device (os error 28)"],
            "{args:?}"
        );
    }
}

/// Outputs that would destroy an input, another output of the same command, or something that
/// is not a regular file (issue 29) are refused before any work, naming both flags; the inputs
/// are left as they were.
#[test]
fn outputs_never_overwrite_inputs_each_other_or_devices() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = two_images(dir.path());
    let before = std::fs::read(&a).unwrap();
    let p = |n: &str| dir.path().join(n).display().to_string();
    refused(
        &["diff", &a, &b, "--per-pixel-out", &a],
        &["--per-pixel-out", "reference", "must not overwrite"],
    );
    refused(&["diff", &a, &b, "--heatmap", &b], &["--heatmap", "test image"]);
    refused(&["diff", &a, &b, "--heatmap", &p("h.png"), "--per-pixel-out", &p("h.png")], &["same file"]);
    refused(
        &["diff", &a, &b, "--metric", "flip", "--heatmap", &p("m.png"), "--flip-map", &p("m.png")],
        &["--flip-map", "--heatmap", "same file"],
    );
    let x = p("x.exr");
    refused(
        &["render", "cornell", "--size", "8x8", "--out", &x, "--spectral-out", &x],
        &["--spectral-out", "same file"],
    );
    refused(
        &["truth", "cornell", "--size", "8x8", "--spp", "1", "--out", &x, "--spectral-out", &x],
        &["--spectral-out", "same file"],
    );
    // A device or a FIFO behind an image name (the write renames a new file over the path, which
    // would replace the device node).
    let null = p("null.exr");
    std::os::unix::fs::symlink("/dev/null", &null).unwrap();
    refused(&["render", "cornell", "--size", "8x8", "--out", &null], &["character device"]);
    refused(&["truth", "cornell", "--size", "8x8", "--spp", "1", "--out", &null], &["character device"]);
    let fifo = p("fifo.png");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    refused(&["diff", &a, &b, "--heatmap", &fifo], &["--heatmap", "FIFO"]);
    // The files a scene references: its textures are PNGs, which `--out` could name.
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../scene/tests/data");
    for f in ["textured.gltf", "base.png", "normal.png", "quad.bin", "reflectance.csv", "spectrum.csv"] {
        std::fs::copy(format!("{data}/{f}"), dir.path().join(f)).unwrap();
    }
    let g = p("textured.gltf");
    let texture = p("base.png");
    let texture_before = std::fs::read(&texture).unwrap();
    refused(
        &["render", &g, "--size", "8x8", "--out", &texture],
        &["--out", "file the scene references", "base.png"],
    );
    refused(&["truth", &g, "--size", "8x8", "--spp", "1", "--out", &texture], &["file the scene references"]);
    refused(&["bench", &g, "--size", "8x8", "--frames", "1", "--csv", &g], &["--csv", "scene file"]);
    // The suite's asset too, with what it references (its buffer was overwritten by the CSV).
    let buffer = p("quad.bin");
    let buffer_before = std::fs::read(&buffer).unwrap();
    let suite =
        ["bench", "--suite", "--suite-asset", &g, "--suite-sizes", "8x8", "--frames", "1", "--warmup", "0"];
    refused(&[&suite[..], &["--csv", &buffer]].concat(), &["--csv", "--suite-asset references", "quad.bin"]);
    refused(&[&suite[..], &["--markdown", &texture]].concat(), &["--markdown", "base.png"]);
    refused(&[&suite[..], &["--csv", &g]].concat(), &["--csv", "--suite-asset"]);
    assert_eq!(std::fs::read(&buffer).unwrap(), buffer_before);
    assert_eq!(std::fs::read(&texture).unwrap(), texture_before);
    let env = p("sky.exr");
    compare::io::write_image(
        &env,
        &compare::image::Image::new(4, 2, vec![[1.0; 3]; 8]).unwrap(),
        Default::default(),
    )
    .unwrap();
    refused(&["render", "cornell", "--env", &env, "--size", "8x8", "--out", &env], &["--env file"]);
    assert_eq!(std::fs::read(&a).unwrap(), before);
    // An observer file (any name: `--out` may end in .csv for diff's table or name an .exr).
    let obs = p("camera.csv");
    let rows: String = (380..=730).step_by(10).map(|l| format!("{l},0.5,0.6,0.4\n")).collect();
    std::fs::write(&obs, &rows).unwrap();
    refused(
        &["diff", &a, &b, "--observer", &obs, "--per-pixel-out", &obs],
        &["--per-pixel-out", "--observer file", "must not overwrite"],
    );
    // A path is a file whatever its extension: one named like an image.
    let obs_exr = p("camera.exr");
    std::fs::write(&obs_exr, &rows).unwrap();
    refused(
        &["render", "cornell", "--size", "8x8", "--observer", &obs_exr, "--out", &obs_exr],
        &["--observer file"],
    );
    refused(
        &["truth", "cornell", "--size", "8x8", "--spp", "1", "--observer", &obs_exr, "--out", &obs_exr],
        &["--observer file"],
    );
    assert_eq!(std::fs::read_to_string(&obs).unwrap(), rows);
    assert_eq!(std::fs::read_to_string(&obs_exr).unwrap(), rows);
    // The truth cache is a folder made on first use: the same path as --out is refused before
    // the render, not after it.
    let t = p("t.exr");
    refused(
        &["truth", "cornell", "--size", "8x8", "--spp", "1", "--truth-cache", &t, "--out", &t],
        &["--out", "--truth-cache folder"],
    );
    assert!(std::fs::symlink_metadata(&t).is_err(), "nothing made at {t}");
}

/// The demo writes a folder: a file in its place is refused by name, and a scene that cannot
/// be loaded leaves no empty folder behind.
#[test]
fn the_demo_refuses_a_file_for_its_folder_and_leaves_nothing_for_a_bad_scene() {
    let dir = tempfile::tempdir().unwrap();
    let file = p_(dir.path(), "taken");
    std::fs::write(&file, b"mine").unwrap();
    refused(&["demo", "--out", &file], &["--out", "taken", "folder"]);
    assert_eq!(std::fs::read(&file).unwrap(), b"mine");
    let folder = p_(dir.path(), "demo");
    refused(&["demo", "--scene", &p_(dir.path(), "missing.gltf"), "--out", &folder], &["missing.gltf"]);
    assert!(!std::path::Path::new(&folder).exists(), "an empty folder was left behind");
    // demo refuses a size the real-time renderer cannot make before its ground truth.
    let demo = p_(dir.path(), "demo");
    let out = spectra(&["demo", "--size", "16385x2", "--spp", "1", "--out", &demo]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--size 16385x2"));
    assert!(!std::path::Path::new(&demo).exists(), "demo made its folder (and rendered the truth)");
    // eval likewise, for a size it refuses only once it runs.
    let runs = p_(dir.path(), "eval");
    let out = spectra(&["eval", "--quick", "--size", "100000x100000", "--out", &runs]);
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!std::path::Path::new(&runs).exists(), "eval left an empty folder behind");
}

/// `eval --out` at a folder holding files of the names an evaluation writes: files it did not
/// write are refused by name and kept; an earlier evaluation's are replaced, but only once the
/// run's inputs are read (a bad --table leaves them as they were).
#[test]
fn eval_keeps_files_it_did_not_write_and_an_earlier_runs_until_its_inputs_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let site = dir.path().join("site");
    std::fs::create_dir(&site).unwrap();
    let mine = site.join("index.html");
    std::fs::write(&mine, "<html>my site</html>").unwrap();
    let out = site.display().to_string();
    refused(
        &["eval", "--quick", "--out", &out],
        &["index.html", "not an earlier `spectra eval`'s output", "--out"],
    );
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "<html>my site</html>");

    let runs = dir.path().join("runs");
    std::fs::create_dir(&runs).unwrap();
    let earlier = [
        ("results.json", r#"{"quick": true, "budget": {}, "cases": [], "frame_times": []}"#),
        ("index.html", "<!DOCTYPE html><html><head><title>spectra evaluation</title></head></html>"),
        (
            "results.csv",
            "case,transport,width,height,truth_spp,mode,wavelengths,quadrature,de_mean,de_median,de_p95,de_max,\
             mae_mean,de_mean_masked,mae_mean_masked,masked_fraction\n",
        ),
    ];
    for (name, text) in earlier {
        std::fs::write(runs.join(name), text).unwrap();
    }
    let missing = dir.path().join("missing.coeff").display().to_string();
    let out = runs.display().to_string();
    refused(&["eval", "--quick", "--table", &missing, "--out", &out], &["missing.coeff"]);
    // An input inside the folder the run writes (a table named like a chart was replaced by it).
    let inside = runs.join("mae.svg");
    std::fs::write(&inside, "not a chart").unwrap();
    refused(
        &["eval", "--quick", "--table", inside.to_str().unwrap(), "--out", &out],
        &["--table", "lies in --out"],
    );
    assert_eq!(std::fs::read_to_string(&inside).unwrap(), "not a chart");
    std::fs::remove_file(&inside).unwrap();
    // A size a renderer refuses and a case whose water settings are bad are refused before the
    // earlier results go (they were removed, and the cases before the bad one rendered).
    let quick = ["eval", "--quick", "--spp", "2", "--sweep", "4", "--out", &out];
    refused(&[&quick[..], &["--scenes", "metamerism", "--size", "40000x2"]].concat(), &["--size 40000x2"]);
    refused(&[&quick[..], &["--scenes", "metamerism", "--size", "16385x2"]].concat(), &["--size 16385x2"]);
    refused(&[&quick[..], &["--scenes", "metamerism,underwater-xx"]].concat(), &["'XX'", "Jerlov"]);
    for (name, text) in earlier {
        assert_eq!(std::fs::read_to_string(runs.join(name)).unwrap(), text, "{name}");
    }
    assert!(!runs.join("metamerism_truth.exr").exists(), "a case rendered before the refusal");
}
