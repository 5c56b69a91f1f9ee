//! `spectra bench --suite` end to end on the real binary and whatever adapter there is
//! (lavapipe here): a tiny run writes its CSV and Markdown with every built-in scene's rows
//! and the per-pass columns, reports the missing asset as skipped, and a run where no row can
//! be measured fails and writes nothing. No timing is asserted.

use std::process::{Command, Output};

fn bench(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spectra"))
        .arg("bench")
        .args(args)
        .output()
        .expect("running spectra bench")
}

#[test]
fn tiny_suite_writes_csv_and_markdown() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, md) = (dir.path().join("s.csv"), dir.path().join("s.md"));
    let missing = dir.path().join("Missing.gltf");
    let out = bench(&[
        "--suite",
        "--suite-asset",
        missing.to_str().unwrap(),
        "--suite-sizes",
        "32x24",
        "--frames",
        "1",
        "--warmup",
        "0",
        "--wavelengths",
        "1,4",
        "--csv",
        csv.to_str().unwrap(),
        "--markdown",
        md.to_str().unwrap(),
    ]);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{stderr}\n(no GPU? {})", render::NO_ADAPTER_HELP);
    assert!(stdout.starts_with("adapter: "), "{stdout}");
    assert!(stdout.contains("skipped: scene Missing+env"), "{stdout}");
    assert!(stderr.contains("skipping scene Missing+env"), "{stderr}");

    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    assert_eq!(&header[..4], ["scene", "size", "mode", "wavelengths"]);
    assert_eq!(header.last(), Some(&"adapter"));
    for p in render::timing::PASSES {
        assert!(header.contains(&format!("{p}_gpu_median_ms").as_str()), "{}", lines[0]);
    }
    // 3 scenes (the asset skipped) × 1 size × (rgb + 2 N).
    assert_eq!(lines.len(), 1 + 9, "{text}");
    for (i, scene) in ["cornell", "cornell+env", "underwater"].iter().enumerate() {
        for (j, mode) in ["rgb,", "spectral/prefiltered,1,", "spectral/prefiltered,4,"].iter().enumerate() {
            let want = format!("{scene},32x24,{mode}");
            assert!(lines[1 + 3 * i + j].starts_with(&want), "{want}: {}", lines[1 + 3 * i + j]);
        }
    }
    let md = std::fs::read_to_string(&md).unwrap();
    assert!(
        md.contains("| scene | size | mode | N |") && md.contains("| underwater | 32x24 | rgb |"),
        "{md}"
    );
    assert!(md.contains("Skipped:") && md.contains("Missing+env"), "{md}");
}

#[test]
fn suite_without_any_row_fails_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("s.csv");
    let out = bench(&[
        "--suite",
        "--suite-sizes",
        "70000x70000",
        "--frames",
        "1",
        "--wavelengths",
        "1",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("no row of the suite could be measured"), "{stderr}");
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none(), "something was written");
}

#[test]
fn bench_runs_the_shading_and_its_reference_in_either_stage() {
    for stage in ["compute", "fragment"] {
        let out = bench(&[
            "cornell",
            "--env",
            "default",
            "--size",
            "32x24",
            "--frames",
            "1",
            "--warmup",
            "0",
            "--wavelengths",
            "4",
            "--reference",
            "--shading-stage",
            stage,
        ]);
        let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        assert!(out.status.success(), "{stage}: {stderr}\n(no GPU? {})", render::NO_ADAPTER_HELP);
        assert!(stdout.contains(&format!("; shading pass: {stage}")), "{stage}: {stdout}");
        for row in ["rgb ", "reference ", "spectral/prefiltered "] {
            assert!(stdout.lines().any(|l| l.starts_with(row)), "{stage}: no {row}row in {stdout}");
        }
    }
    let out = bench(&["cornell", "--shading-stage", "vertex"]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("expected compute or fragment, got \"vertex\""), "{stderr}");
    // Every command's default comes from SPECTRA_SHADING_STAGE where it is set.
    let tiny = ["cornell", "--size", "16x16", "--frames", "1", "--warmup", "0", "--wavelengths", "1"];
    let with_env = |value: &str| {
        Command::new(env!("CARGO_BIN_EXE_spectra"))
            .env("SPECTRA_SHADING_STAGE", value)
            .arg("bench")
            .args(tiny)
            .output()
            .expect("running spectra bench")
    };
    let out = with_env("compute");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("; shading pass: compute"));
    let out = with_env("vertex");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("SPECTRA_SHADING_STAGE must be compute or fragment, got \"vertex\""), "{stderr}");
}
