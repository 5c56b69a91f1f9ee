//! `spectra eval --quick` end to end: the default quick suite (spiky-emission scene, ColorChecker
//! under D65/F11/LED, underwater in Jerlov I) at a reduced size, on the real binary and lavapipe.
//! The report files must exist and the measured orderings must hold by more than the truth's own
//! noise. Which orderings, and why not others, is in docs/evaluation.md.

use serde_json::Value;
use std::process::Command;

/// Mean ΔE2000 of `mode` ("ours", "naive", "rgb") in `case`, or of the truth against itself
/// with another seed ("noise").
fn mean(v: &Value, case: &str, mode: &str) -> f64 {
    let c = v["cases"].as_array().unwrap().iter().find(|c| c["id"] == case);
    let c = c.unwrap_or_else(|| panic!("case {case} missing from results.json"));
    if mode == "noise" {
        return c["noise_floor"]["delta_e2000"]["mean"].as_f64().unwrap();
    }
    let m = c["modes"].as_array().unwrap().iter().find(|m| m["mode"] == mode).unwrap();
    m["errors"]["delta_e2000"]["mean"].as_f64().unwrap()
}

/// `a` beats `b` by more than the per-pixel truth noise of the case: a ranking that a different
/// truth seed could not overturn.
fn beats(v: &Value, case: &str, a: &str, b: &str) {
    let (x, y, noise) = (mean(v, case, a), mean(v, case, b), mean(v, case, "noise"));
    assert!(
        x + noise < y,
        "{case}: {a} {x:.3} vs {b} {y:.3} must differ by more than the truth noise {noise:.3}"
    );
}

#[test]
fn quick_suite_orders_the_modes() {
    let dir = std::env::temp_dir().join(format!("spectra-eval-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    // No --scenes, no --size: this is the quick suite exactly as users get it. (At 96×72 the
    // spiky scene's ours-vs-rgb margin, 0.135, falls below its truth noise, 0.161: edge pixels,
    // the noisiest, are a larger share of a smaller image.)
    let out = Command::new(env!("CARGO_BIN_EXE_spectra"))
        .args(["eval", "--quick", "--out"])
        .arg(&dir)
        .output()
        .expect("running spectra eval");
    assert!(out.status.success(), "eval failed: {}", String::from_utf8_lossy(&out.stderr));
    for f in ["index.html", "results.json", "results.csv", "delta_e.svg", "frame_time.svg", "jitter.svg"] {
        assert!(dir.join(f).is_file(), "missing {f}");
    }
    let v: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    let ids: Vec<&str> = v["cases"].as_array().unwrap().iter().map(|c| c["id"].as_str().unwrap()).collect();
    assert_eq!(
        ids,
        ["metamerism", "colorchecker-d65", "colorchecker-f11", "colorchecker-led", "underwater-i"]
    );

    // The method's claim, on the spiky-emission scene and under water: closer to truth than
    // both baselines.
    for case in ["metamerism", "underwater-i", "colorchecker-f11"] {
        beats(&v, case, "ours", "naive");
        beats(&v, case, "ours", "rgb");
    }
    // Naive (box) upsampling beats RGB under water, where attenuation is strongly
    // wavelength-dependent. On the spiky scene it does not (it is the worst mode there), so
    // that is not asserted: docs/evaluation.md records it as a finding.
    beats(&v, "underwater-i", "naive", "rgb");
    // Direct-lighting truth must be clean enough for per-pixel errors to mean something.
    for case in ["metamerism", "colorchecker-f11"] {
        let (ours, noise) = (mean(&v, case, "ours"), mean(&v, case, "noise"));
        assert!(noise < 0.5 * ours, "{case}: truth noise {noise} vs ours {ours}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
