//! `--animation` and `--time` (glTF skins, morph targets and animations posed at load time) on
//! the real binary, with the Khronos Fox (crates/scene/tests/data/pose/Fox: a skinned mesh, 3
//! animations): the pose is part of a truth record's identity, so pieces of different moments
//! do not merge and pieces of one moment do; the real-time renderer and the path tracer draw the
//! same pose (their silhouettes of the running fox overlap as well as at rest, and differ from
//! the rest pose's); the options' errors are one line naming what is wrong. The real-time
//! renders use the GPU (lavapipe here): about 10 s with it on 2 cores.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const FOX: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../scene/tests/data/pose/Fox/Fox.gltf");

fn spectra(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spectra")).args(args).output().expect("running spectra")
}

fn ok(args: &[&str]) {
    let out = spectra(args);
    assert!(out.status.success(), "spectra {args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// Runs a command that must fail with one `error` line holding each of `parts`; returns it.
fn refused(args: &[&str], parts: &[&str]) -> String {
    let out = spectra(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "spectra {args:?}: {err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(lines.len(), 1, "one error line: {err}");
    for p in parts {
        assert!(lines[0].contains(p), "'{p}' missing: {err}");
    }
    lines[0].to_string()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectra-animation-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn with<'a>(base: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
    base.iter().chain(extra).copied().collect()
}

/// Truth pieces of two moments of one animation are different renders: `spectra merge` refuses
/// them naming `scene.time`, and writes nothing; pieces of one moment (the animation named once
/// by its name, once by its index) merge into the render of all their samples.
#[test]
fn moments_are_part_of_a_truth_records_identity() {
    let d = tmp("merge");
    let p = |n: &str| d.join(n);
    let base = ["truth", FOX, "--animation", "Run", "--size", "24x16", "--spp", "2"];
    ok(&with(&base, &["--time", "0.5", "--chunk", "0/2", "--out", s(&p("a.exr"))]));
    ok(&with(&base, &["--time", "0.6", "--chunk", "1/2", "--out", s(&p("b.exr"))]));
    let out = p("m.exr");
    let line = refused(
        &["merge", s(&p("a.exr")), s(&p("b.exr")), "--out", s(&out)],
        &["b.exr", "a different render", "a.exr", "scene.time", "0.5 s there and 0.6 s here"],
    );
    eprintln!("two moments: {line}");
    assert!(!out.exists(), "nothing written");
    // Another animation at the same moment: refused naming the animation.
    ok(&["truth", FOX, "--animation", "Walk", "--time", "0.5", "--size", "24x16", "--spp", "2"]
        .into_iter()
        .chain(["--chunk", "1/2", "--out", s(&p("walk.exr"))])
        .collect::<Vec<_>>());
    let line = refused(
        &["merge", s(&p("a.exr")), s(&p("walk.exr")), "--out", s(&out)],
        &["walk.exr", "scene.animation", "2 'Run' there and 1 'Walk' here"],
    );
    eprintln!("two animations: {line}");
    assert!(!out.exists(), "nothing written");
    // At rest (no choice) and posed: different renders.
    ok(&["truth", FOX, "--size", "24x16", "--spp", "2", "--chunk", "1/2", "--out", s(&p("rest.exr"))]);
    refused(&["merge", s(&p("a.exr")), s(&p("rest.exr")), "--out", s(&out)], &["rest.exr", "scene."]);
    assert!(!out.exists(), "nothing written");
    // The same moment, the second half of the samples, the animation named by its index.
    let b2 = ["truth", FOX, "--animation", "2", "--time", "0.5", "--size", "24x16", "--spp", "2"];
    ok(&with(&b2, &["--chunk", "1/2", "--out", s(&p("b2.exr"))]));
    ok(&["merge", s(&p("a.exr")), s(&p("b2.exr")), "--out", s(&out)]);
    let full = ["truth", FOX, "--animation", "Run", "--time", "0.5", "--size", "24x16", "--spp", "4"];
    ok(&with(&full, &["--out", s(&p("full.exr"))]));
    let frame = compare::read_exr_frame(&out).unwrap();
    assert_eq!(frame.get("spectra.samples"), Some("0..4"));
    assert_eq!(frame.get("spectra.setting.scene.animation"), Some("2 'Run'"));
    assert_eq!(frame.get("spectra.setting.scene.time"), Some("0.5 s"));
    let (m, f) = (compare::read_image(&out).unwrap().data, compare::read_image(p("full.exr")).unwrap().data);
    let worst = m
        .iter()
        .zip(&f)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs() / y.abs().max(1e-3)))
        .fold(0.0f32, f32::max);
    eprintln!("two chunks of one moment merged vs one render: worst relative difference {worst:e}");
    assert!(worst <= 1e-5, "merged chunks vs one render: {worst:e}");
    let _ = std::fs::remove_dir_all(&d);
}

/// The pixels that are not background: whose R + G + B differs from its row's median (the fox
/// fills under half of every row; the background, the default environment's sky and ground, is
/// the same along a row but for the horizon's slight tilt) by over 0.1 of that median, then
/// smoothed by a 3 × 3 majority (which fills the few pixels where the shaded fur is as bright
/// as the ground, and drops the path tracer's noise at the horizon).
fn silhouette(p: &Path) -> (Vec<bool>, usize) {
    let img = compare::read_image(p).unwrap();
    let (w, h) = img.size();
    let (w, h) = (w as usize, h as usize);
    let sums: Vec<f32> = img.data.iter().map(|v| v[0] + v[1] + v[2]).collect();
    let mut raw = Vec::with_capacity(sums.len());
    for row in sums.chunks(w) {
        let mut sorted = row.to_vec();
        sorted.sort_by(f32::total_cmp);
        let median = sorted[sorted.len() / 2];
        raw.extend(row.iter().map(|v| (v - median).abs() > 0.1 * median.max(0.05)));
    }
    let at = |x: usize, y: usize, dx: isize, dy: isize| {
        let (x, y) = (x as isize + dx, y as isize + dy);
        x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h && raw[y as usize * w + x as usize]
    };
    let mask: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let n =
                (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))).filter(|&(dx, dy)| at(x, y, dx, dy));
            n.count() >= 5
        })
        .collect();
    let n = mask.iter().filter(|&&m| m).count();
    (mask, n)
}

fn iou(a: &[bool], b: &[bool]) -> f64 {
    let both = a.iter().zip(b).filter(|(x, y)| **x && **y).count();
    let either = a.iter().zip(b).filter(|(x, y)| **x || **y).count();
    both as f64 / either.max(1) as f64
}

fn mean_delta_e(reference: &Path, test: &Path) -> f64 {
    let out = spectra(&["diff", s(reference), s(test), "--json"]);
    assert!(out.status.success(), "diff: {}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["delta_e2000"]["mean"].as_f64().unwrap()
}

/// `spectra render` and `spectra truth` draw the same pose: the running fox's silhouettes in
/// both overlap (IoU > 0.9) as the rest pose's do, and differ from the rest pose's (IoU < 0.9 in
/// both renderers, so that a renderer drawing the rest pose would fail); their ΔE2000 is about
/// the rest pose's.
#[test]
fn both_renderers_draw_the_same_pose() {
    let d = tmp("pose");
    let p = |n: &str| d.join(n);
    let common = ["--size", "128x96", "--env", "default"];
    let poses: [(&str, &[&str]); 2] = [("rest", &[]), ("run", &["--animation", "Run", "--time", "0.5"])];
    for (name, pose) in poses {
        let r = p(&format!("{name}-render.exr"));
        let t = p(&format!("{name}-truth.exr"));
        ok(&[&["render", FOX][..], pose, &common, &["--samples", "4", "--out", s(&r)]].concat());
        ok(&[&["truth", FOX][..], pose, &common, &["--spp", "16", "--out", s(&t)]].concat());
    }
    let m = |n: &str| silhouette(&p(n));
    let ((rr, nrr), (rt, nrt)) = (m("rest-render.exr"), m("rest-truth.exr"));
    let ((pr, npr), (pt, npt)) = (m("run-render.exr"), m("run-truth.exr"));
    let rest = iou(&rr, &rt);
    let posed = iou(&pr, &pt);
    let (moved_render, moved_truth) = (iou(&rr, &pr), iou(&rt, &pt));
    let de_rest = mean_delta_e(&p("rest-truth.exr"), &p("rest-render.exr"));
    let de_posed = mean_delta_e(&p("run-truth.exr"), &p("run-render.exr"));
    eprintln!(
        "silhouette pixels: rest render {nrr}, truth {nrt}; Run at 0.5 s render {npr}, truth {npt}\n\
         IoU render vs truth: rest {rest:.3}, Run at 0.5 s {posed:.3}\n\
         IoU rest vs Run at 0.5 s: render {moved_render:.3}, truth {moved_truth:.3}\n\
         mean ΔE2000 render vs truth: rest {de_rest:.2}, Run at 0.5 s {de_posed:.2}"
    );
    assert!(nrr > 100 && npr > 100, "the fox is drawn: {nrr}, {npr} pixels");
    assert!(rest > 0.9, "rest pose: render vs truth IoU {rest:.3}");
    assert!(posed > 0.9, "Run at 0.5 s: render vs truth IoU {posed:.3}");
    assert!(moved_render < 0.9 && moved_truth < 0.9, "posed vs rest: {moved_render:.3}, {moved_truth:.3}");
    assert!(de_posed < 1.5 * de_rest + 0.5, "mean ΔE2000 posed {de_posed:.2} vs rest {de_rest:.2}");
    let _ = std::fs::remove_dir_all(&d);
}

/// The options' mistakes: one error line each, nothing written.
#[test]
fn animation_options_are_checked() {
    let d = tmp("errors");
    let out = d.join("x.png");
    let o = s(&out);
    refused(
        &["render", "cornell", "--time", "1", "--out", o],
        &["--time 1", "animations belong to glTF files", "'cornell' is a built-in scene"],
    );
    refused(
        &["truth", "cornell", "--animation", "Run", "--out", o],
        &["--animation Run", "animations belong to glTF files", "'cornell'"],
    );
    refused(
        &["render", FOX, "--animation", "Jump", "--out", o],
        &[
            "--animation Jump",
            "no such animation",
            "0 'Survey' of 3.417 s, 1 'Walk' of 0.708 s and 2 'Run' of 1.158 s",
        ],
    );
    refused(
        &["render", FOX, "--animation", "3", "--out", o],
        &["--animation 3", "0 'Survey' of 3.417 s, 1 'Walk' of 0.708 s and 2 'Run' of 1.158 s"],
    );
    refused(
        &["truth", FOX, "--animation", "Run", "--time", "-1", "--out", o],
        &["--time -1", "seconds from 0"],
    );
    refused(&["truth", FOX, "--time", "nan", "--out", o], &["--time NaN"]);
    assert!(!out.exists(), "nothing written");
    let _ = std::fs::remove_dir_all(&d);
}

/// `render --times`: a numbered sequence, each frame the image a single `--time` render of its
/// moment makes (byte for byte), the running fox moving between frames; `--resume` draws only
/// the frames that are missing.
#[test]
fn times_render_a_sequence_of_the_single_moments() {
    let d = tmp("sequence");
    let base = ["render", FOX, "--animation", "Run", "--size", "32x24"];
    let pattern = d.join("run_%03d.png");
    ok(&with(&base, &["--times", "0:0.5:0.25", "--out", s(&pattern)]));
    let frame = |i: usize| std::fs::read(d.join(format!("run_{i:03}.png"))).unwrap();
    let mut names: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["run_000.png", "run_001.png", "run_002.png"]);
    for (i, t) in ["0", "0.25", "0.5"].iter().enumerate() {
        let single = d.join(format!("single_{i}.png"));
        ok(&with(&base, &["--time", t, "--out", s(&single)]));
        assert!(std::fs::read(&single).unwrap() == frame(i), "frame {i} is not the render at {t} s");
    }
    assert!(frame(0) != frame(2), "the fox does not move between 0 and 0.5 s");
    // An interrupted sequence's rerun: the frames there are kept, the missing one drawn.
    std::fs::remove_file(d.join("run_001.png")).unwrap();
    let before = std::fs::metadata(d.join("run_000.png")).unwrap().modified().unwrap();
    let out = spectra(&with(&base, &["--times", "0:0.5:0.25", "--resume", "--out", s(&pattern)]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("2 already there kept, 1 drawn"), "{err}");
    assert_eq!(std::fs::metadata(d.join("run_000.png")).unwrap().modified().unwrap(), before);
    assert!(std::fs::read(d.join("single_1.png")).unwrap() == frame(1));
    // To the animation's end: Walk's last key is at 0.708 s, so 0.5, 0.6 and 0.7.
    let walk = d.join("walk_%d.png");
    let out = spectra(&[
        "render",
        FOX,
        "--animation",
        "Walk",
        "--size",
        "16x12",
        "--times",
        "0.5:end:0.1",
        "--out",
        s(&walk),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("(3 frames, 0.5–0.7 s)"), "{err}");
    assert!(d.join("walk_2.png").is_file() && !d.join("walk_3.png").exists());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn times_are_checked() {
    let d = tmp("times");
    let out = d.join("f_%02d.png");
    refused(&["render", FOX, "--times", "0:1", "--out", s(&out)], &["--times 0:1", "START:END:STEP"]);
    refused(&["render", FOX, "--times", "0:1:0", "--out", s(&out)], &["the step 0 is not a positive"]);
    refused(
        &["render", FOX, "--times", "0:1:0.5", "--out", s(&d.join("f.png"))],
        &["--out", "frame-number pattern"],
    );
    refused(&["render", "cornell", "--times", "0:1:0.5", "--out", s(&out)], &["built-in scene"]);
    // The command line's own errors (clap's, status 2).
    for (args, want) in [
        (vec!["render", FOX, "--times", "0:1:0.5", "--time", "1", "--out", s(&out)], "cannot be used with"),
        (vec!["render", FOX, "--resume", "--out", s(&out)], "--times"),
    ] {
        let o = spectra(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            o.status.code() == Some(2) && err.starts_with("error:") && err.contains(want),
            "{args:?}: {err}"
        );
    }
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0, "nothing written");
    let _ = std::fs::remove_dir_all(&d);
}

/// `truth --times`: each frame is the path tracer's render of its moment (the same pixels as a
/// single `--time` render), the fox moving between them; `--resume` renders only the frames
/// that are missing.
#[test]
fn truth_times_render_each_moment() {
    let d = tmp("truth-sequence");
    let base = ["truth", FOX, "--animation", "Run", "--size", "24x16", "--spp", "2"];
    let pattern = d.join("t_%02d.exr");
    ok(&with(&base, &["--times", "0:0.5:0.25", "--out", s(&pattern)]));
    let frame = |i: usize| d.join(format!("t_{i:02}.exr"));
    let max_delta_e = |a: &Path, b: &Path| {
        let out = spectra(&["diff", s(a), s(b), "--json"]);
        assert!(out.status.success(), "diff: {}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["delta_e2000"]["max"].as_f64().unwrap()
    };
    let single = d.join("single.exr");
    ok(&with(&base, &["--time", "0.25", "--out", s(&single)]));
    assert_eq!(max_delta_e(&frame(1), &single), 0.0, "frame 1 is not the render at 0.25 s");
    assert!(mean_delta_e(&frame(0), &frame(2)) > 0.1, "the fox does not move between 0 and 0.5 s");
    std::fs::remove_file(frame(1)).unwrap();
    let out = spectra(&with(&base, &["--times", "0:0.5:0.25", "--resume", "--out", s(&pattern)]));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && err.contains("2 already there kept, 1 rendered"), "{err}");
    assert_eq!(max_delta_e(&frame(1), &single), 0.0);
    refused(&with(&base, &["--times", "0:1:0.5", "--out", s(&d.join("t.exr"))]), &["frame-number pattern"]);
    refused(
        &with(&base, &["--times", "0:1:0.5", "--export-mitsuba", s(&d.join("m"))]),
        &["--export-mitsuba exports one moment"],
    );
    let _ = std::fs::remove_dir_all(&d);
}
