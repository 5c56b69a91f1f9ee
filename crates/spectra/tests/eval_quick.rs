//! `spectra eval --quick` end to end: the default quick suite (spiky-emission scene, ColorChecker
//! under D65/F11/LED, underwater in Jerlov I) at a reduced size, on the real binary and lavapipe.
//! The report files must exist and the measured orderings must hold by more than the truth's own
//! noise, at the headline N and, for ours with prefiltered quadrature, across the N sweep.
//! Which orderings, and why not others, is in docs/evaluation.md.

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

/// Mean ΔE2000 of the sweep point (mode, quadrature, N) of `case`.
fn swept(v: &Value, case: &str, mode: &str, quadrature: &str, n: u64) -> f64 {
    let c = v["cases"].as_array().unwrap().iter().find(|c| c["id"] == case).unwrap();
    let p =
        c["sweep"].as_array().unwrap().iter().find(|p| {
            p["mode"] == mode && p["quadrature"] == quadrature && p["wavelengths"].as_u64() == Some(n)
        });
    let p = p.unwrap_or_else(|| panic!("{case}: no sweep point {mode}, {quadrature}, N = {n}"));
    p["delta_e2000_mean"].as_f64().unwrap()
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
    // spiky scene's ours-vs-rgb margin with the midpoint rule, 0.135, falls below its truth
    // noise, 0.161: edge pixels, the noisiest, are a larger share of a smaller image. The
    // default prefiltered rule keeps 0.358 there; docs/evaluation.md.)
    let out = Command::new(env!("CARGO_BIN_EXE_spectra"))
        .args(["eval", "--quick", "--out"])
        .arg(&dir)
        .output()
        .expect("running spectra eval");
    assert!(out.status.success(), "eval failed: {}", String::from_utf8_lossy(&out.stderr));
    for f in [
        "index.html",
        "results.json",
        "results.csv",
        "delta_e.svg",
        "frame_time.svg",
        "jitter.svg",
        "error_vs_frame_time.svg",
    ] {
        assert!(dir.join(f).is_file(), "missing {f}");
    }
    let v: Value = serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    let ids: Vec<&str> = v["cases"].as_array().unwrap().iter().map(|c| c["id"].as_str().unwrap()).collect();
    assert_eq!(
        ids,
        [
            "metamerism",
            "colorchecker-d65",
            "colorchecker-f11",
            "colorchecker-led",
            "iridescence-d65",
            "iridescence-f11",
            "glass",
            "underwater-i"
        ]
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
    // Thin films: the exact film per node against the extension's RGB approximation.
    for case in ["iridescence-d65", "iridescence-f11"] {
        beats(&v, case, "ours", "rgb");
    }
    // Direct-lighting truth must be clean enough for per-pixel errors to mean something.
    for case in ["metamerism", "colorchecker-f11"] {
        let (ours, noise) = (mean(&v, case, "ours"), mean(&v, case, "noise"));
        assert!(noise < 0.5 * ours, "{case}: truth noise {noise} vs ours {ours}");
    }

    // The N sweep: every case, ours and naive, both quadratures, at the quick budget's N.
    for id in &ids {
        assert!(dir.join(format!("sweep_{id}.svg")).is_file(), "missing sweep_{id}.svg");
        let c = v["cases"].as_array().unwrap().iter().find(|c| c["id"] == *id).unwrap();
        let mut got: Vec<(String, String, u64)> = c["sweep"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| {
                let s = |k: &str| p[k].as_str().unwrap().to_string();
                (s("mode"), s("quadrature"), p["wavelengths"].as_u64().unwrap())
            })
            .collect();
        got.sort();
        let mut want = Vec::new();
        for m in ["naive", "ours"] {
            for q in ["midpoint", "prefiltered"] {
                for n in [4, 8, 16] {
                    want.push((m.to_string(), q.to_string(), n));
                }
            }
        }
        assert_eq!(got, want, "{id}: sweep points");
        // The headline is the default (prefiltered) rule at the case's N = 16: the same render.
        let head = mean(&v, id, "ours");
        let sw = swept(&v, id, "ours", "prefiltered", 16);
        assert!((head - sw).abs() < 1e-9, "{id}: headline ours {head} vs sweep ours-prefiltered N=16 {sw}");
    }
    // Prefiltered quadrature keeps ours ahead of rgb at small N on the line-spectrum scenes,
    // where the midpoint rule's aliasing made the error jump with N.
    for case in ["metamerism", "colorchecker-f11"] {
        let (rgb, noise) = (mean(&v, case, "rgb"), mean(&v, case, "noise"));
        for n in [8, 16] {
            let ours = swept(&v, case, "ours", "prefiltered", n);
            assert!(
                ours + noise < rgb,
                "{case}: ours-prefiltered N={n} {ours:.3} vs rgb {rgb:.3} must differ by more than the truth noise {noise:.3}"
            );
        }
    }
    // The error-vs-frame-time curve pairs the timed and swept N of the first case.
    let curve: Vec<u64> = v["tradeoff"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["mode"] == "ours" && p["quadrature"] == "prefiltered")
        .map(|p| p["wavelengths"].as_u64().unwrap())
        .collect();
    assert_eq!(curve, [4, 8, 16]);
    let _ = std::fs::remove_dir_all(&dir);
}
