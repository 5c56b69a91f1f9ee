//! Cameras (issue 33) on the real binary and the library: one display convention for both
//! renderers (`color::film`), so real time and the path tracer agree for a camera as they do for
//! CIE 1931; `--camera-to-display`; the rawtoaces JSON files of the database read back as
//! themselves; every camera of the database renders the Cornell box in both renderers; bad
//! JSON is one error naming the file and the field, and nothing is written.

use std::path::{Path, PathBuf};
use std::process::Command;

fn run(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_spectra")).args(args).output().expect("running spectra")
}

fn ok(args: &[&str]) -> std::process::Output {
    let out = run(args);
    assert!(out.status.success(), "spectra {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectra-cameras-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn p(d: &Path, f: &str) -> String {
    d.join(f).display().to_string()
}

/// `spectra diff --json`'s mean ΔE2000 and mean linear MAE of `b` against `a`.
fn difference(a: &str, b: &str) -> (f64, f64) {
    let out = ok(&["diff", a, b, "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("diff --json");
    (v["delta_e2000"]["mean"].as_f64().unwrap(), v["mae_linear"]["mean"].as_f64().unwrap())
}

/// Real time against the truth on the ColorChecker, for CIE 1931 and for cameras, balanced and
/// through their fit to XYZ. Before one convention served both renderers, a camera's real-time
/// image was its channels through the sRGB matrix with a white correction, the truth's without
/// one: mean ΔE2000 7.0 for the Nikon D5100 against 0.38 for CIE 1931.
#[test]
fn real_time_and_truth_agree_for_cameras_as_for_cie() {
    let d = dir("agree");
    let pair = |observer: &str, extra: &[&str]| {
        let rt = p(&d, &format!("rt-{observer}-{}.exr", extra.len()));
        let tr = p(&d, &format!("tr-{observer}-{}.exr", extra.len()));
        let common = ["colorchecker", "--size", "72x48", "--observer", observer];
        let r: Vec<&str> = ["render"]
            .iter()
            .chain(&common)
            .chain(&["--wavelengths", "16", "--out", &rt])
            .chain(extra)
            .copied()
            .collect();
        let t: Vec<&str> = ["truth"]
            .iter()
            .chain(&common)
            .chain(&["--spp", "64", "--out", &tr])
            .chain(extra)
            .copied()
            .collect();
        ok(&r);
        ok(&t);
        (difference(&tr, &rt).0, rt)
    };
    let (cie, cie_img) = pair("cie1931", &[]);
    // CIE observers ignore the flag: the same image.
    let (_, cie_flag) = pair("cie1931", &["--camera-to-display"]);
    assert_eq!(difference(&cie_img, &cie_flag).1, 0.0);
    for cam in ["nikon_d5100", "canon_eos_r5", "sony_ilce_7m3"] {
        let (balanced, b_img) = pair(cam, &[]);
        let (display, d_img) = pair(cam, &["--camera-to-display"]);
        assert!(balanced < 2.0 * cie + 0.2, "{cam}: real time vs truth ΔE {balanced}, CIE 1931 {cie}");
        assert!(display < 2.5 * cie + 0.3, "{cam} (display): ΔE {display}, CIE 1931 {cie}");
        // The two views are different pictures of the same render.
        assert!(difference(&b_img, &d_img).1 > 1e-3, "{cam}: --camera-to-display changed nothing");
    }
    // Kept where an assertion failed, for the images.
    let _ = std::fs::remove_dir_all(&d);
}

/// A database camera's rawtoaces JSON, read from a file, is that camera: the identical image in
/// both renderers. The JSON schema's bad cases are refused naming the file and the field.
#[test]
fn a_rawtoaces_json_file_is_the_camera_and_bad_ones_are_refused() {
    let d = dir("json");
    let cam = color::Observer::camera("canon_eos_r5").expect("in the database");
    let file = p(&d, "r5.json");
    std::fs::write(&file, cam.json).unwrap();
    for (cmd, extra) in [("render", &["--wavelengths", "8"][..]), ("truth", &["--spp", "4"][..])] {
        let by_name = p(&d, &format!("{cmd}-name.exr"));
        let by_file = p(&d, &format!("{cmd}-file.exr"));
        for (obs, out) in [("canon_eos_r5", &by_name), (file.as_str(), &by_file)] {
            let args: Vec<&str> = [cmd, "metamerism", "--size", "40x30", "--observer", obs, "--out", out]
                .into_iter()
                .chain(extra.iter().copied())
                .collect();
            ok(&args);
        }
        let (de, mae) = difference(&by_name, &by_file);
        assert!(de == 0.0 && mae == 0.0, "{cmd}: the JSON file's image differs: ΔE {de}, MAE {mae}");
    }

    let no_blue = cam.json.replace(r#""B""#, r#""X""#);
    let bad = p(&d, "bad.json");
    std::fs::write(&bad, no_blue).unwrap();
    let out_file = p(&d, "never.exr");
    for (cmd, extra) in [("render", &[][..]), ("truth", &["--spp", "1"][..]), ("eval", &[][..])] {
        let args: Vec<&str> = match cmd {
            "eval" => {
                vec!["eval", "--quick", "--scenes", "metamerism", "--observer", &bad, "--out", &out_file]
            }
            _ => [cmd, "metamerism", "--size", "16x16", "--observer", &bad, "--out", &out_file]
                .into_iter()
                .chain(extra.iter().copied())
                .collect(),
        };
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{cmd} accepted a JSON without a B channel");
        assert!(
            err.contains("bad.json") && err.contains("spectral_data.index.main") && err.contains("'B'"),
            "{cmd}: {err}"
        );
        assert!(!Path::new(&out_file).exists(), "{cmd} wrote an output");
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// Every camera of the database renders the Cornell box in real time and in the path tracer:
/// finite, lit, and the same picture in both (their means within 15 %).
#[test]
fn every_camera_renders_the_cornell_box_in_both_renderers() {
    let scene = scene::builtin("cornell").unwrap();
    let table = color::upsample::table("srgb").unwrap();
    let mut r =
        render::Renderer::with_table(table.clone()).expect("a GPU adapter (lavapipe: mesa-vulkan-drivers)");
    r.set_scene(&scene).unwrap();
    let (w, h) = (24, 18);
    r.resize(w, h).unwrap();
    let names: Vec<&str> = color::Observer::names()
        .into_iter()
        .filter(|n| color::Observer::by_name(n).unwrap().kind() == color::observer::ObserverKind::CameraRgb)
        .collect();
    assert!(names.len() >= 50, "{} cameras", names.len());
    // Means of values clipped at 1: the lit walls, not the light's own few pixels (which the
    // two renderers draw differently at this size, for every observer).
    let mean = |px: &[[f32; 3]]| {
        let n = px.len() as f64;
        [0, 1, 2].map(|c| px.iter().map(|p| f64::from(p[c].min(1.0))).sum::<f64>() / n)
    };
    // Real time over truth, mean of the three channels: the two renderers differ at this size
    // (shadow maps, the light's near field) for every observer; a camera must add nothing.
    let mut ratio = |name: &str| {
        let settings = render::RenderSettings { wavelengths: 8, observer: name.into(), ..Default::default() };
        r.render(&scene.camera, &settings).unwrap_or_else(|e| panic!("{name}: {e}"));
        let rt: Vec<[f32; 3]> = r.read_hdr().unwrap().iter().map(|p| [p[0], p[1], p[2]]).collect();
        let mut st = truth::Settings::new(w, h, 4).unwrap();
        st.observer = color::Observer::by_name(name).unwrap();
        st.direct_only = true;
        let img = truth::render(&scene, table.as_ref(), &st, &Default::default(), &|_| {}).unwrap();
        let tr = img.to_display(&st, color::film::CameraView::Balanced).unwrap();
        for (what, px) in [("real time", &rt), ("truth", &tr)] {
            assert!(px.iter().flatten().all(|v| v.is_finite()), "{name} {what}: not finite");
            let m = mean(px);
            assert!(m.iter().all(|&v| v > 0.01), "{name} {what}: mean {m:?}");
        }
        let (a, b) = (mean(&rt), mean(&tr));
        (a.iter().sum::<f64>() / b.iter().sum::<f64>(), a, b)
    };
    let (cie, ..) = ratio("cie1931");
    for name in names {
        let (k, a, b) = ratio(name);
        assert!(
            (k / cie - 1.0).abs() < 0.1,
            "{name}: real time / truth {k} (CIE 1931: {cie}); {a:?} vs {b:?}"
        );
    }
}

#[test]
fn observers_lists_the_database_with_its_licence() {
    let out = ok(&["observers", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v.as_array().unwrap();
    let cams: Vec<_> = rows.iter().filter(|r| r["kind"] == "camera RGB").collect();
    assert!(cams.len() >= 50, "{} cameras", cams.len());
    let apache = cams.iter().filter(|r| r["source"].as_str().unwrap().contains("Apache-2.0")).count();
    assert_eq!(
        apache,
        cams.len() - 4,
        "all but the four older built-ins (three cameras, the ACES RICD) name the database licence"
    );
    assert!(rows.iter().any(|r| r["name"] == "canon_eos_r5" && r["from_nm"] == 380.0 && r["to_nm"] == 780.0));
}
