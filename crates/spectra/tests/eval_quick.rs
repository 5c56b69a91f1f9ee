//! `spectra eval --quick` end to end on the spiky-emission scene, at a small size: the report
//! files exist and the measured ordering holds. Runs the real binary on lavapipe (≈1 min).

use std::process::Command;

#[test]
fn quick_eval_on_the_spiky_scene() {
    let dir = std::env::temp_dir().join(format!("spectra-eval-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_spectra"))
        .args(["eval", "--quick", "--scenes", "metamerism,colorchecker-f11", "--size", "96x72", "--out"])
        .arg(&dir)
        .output()
        .expect("running spectra eval");
    assert!(out.status.success(), "eval failed: {}", String::from_utf8_lossy(&out.stderr));
    for f in ["index.html", "results.json", "results.csv", "delta_e.svg", "frame_time.svg", "jitter.svg"] {
        assert!(dir.join(f).is_file(), "missing {f}");
    }
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    let mean = |case: &str, mode: &str| -> f64 {
        let c = v["cases"].as_array().unwrap().iter().find(|c| c["id"] == case).unwrap();
        if mode == "noise" {
            return c["noise_floor"]["delta_e2000"]["mean"].as_f64().unwrap();
        }
        let m = c["modes"].as_array().unwrap().iter().find(|m| m["mode"] == mode).unwrap();
        m["errors"]["delta_e2000"]["mean"].as_f64().unwrap()
    };
    for case in ["metamerism", "colorchecker-f11"] {
        let (ours, naive, rgb, noise) =
            (mean(case, "ours"), mean(case, "naive"), mean(case, "rgb"), mean(case, "noise"));
        // The method's claim: closer to truth than both baselines. (The issue also asked for
        // naive < rgb; measured, naive is the worst mode on these scenes: docs/evaluation.md.)
        assert!(ours < naive, "{case}: ours {ours} vs naive {naive}");
        assert!(ours < rgb, "{case}: ours {ours} vs rgb {rgb}");
        // Truth must be clean enough for the per-pixel errors to mean something.
        assert!(noise < 0.5 * ours, "{case}: truth noise {noise} vs ours {ours}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
