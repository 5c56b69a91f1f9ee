//! Lighting real assets end to end, on the real binary: scenes lit only by an emissive surface or
//! only by an environment must agree between the real-time renderer and the path tracer (direct
//! lighting, block means against the tracer's noise), and a scene without lights is never black.

use std::path::{Path, PathBuf};
use std::process::Command;

fn spectra(args: &[&str]) -> std::process::Output {
    let out = Command::new(env!("CARGO_BIN_EXE_spectra")).args(args).output().expect("running spectra");
    assert!(
        out.status.success(),
        "spectra {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("spectra-lighting-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn p(d: &Path, f: &str) -> String {
    d.join(f).display().to_string()
}

/// Mean block ΔE2000 of `test` against `reference` (8×8 blocks).
fn block_de(reference: &str, test: &str) -> f64 {
    let out = spectra(&["diff", reference, test, "--block", "8", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("diff --json");
    v["delta_e2000"]["mean"].as_f64().unwrap_or_else(|| panic!("no delta_e2000.mean in {v}"))
}

/// The built-in Cornell box without the point light that stands in for its lamp: lit only by the
/// emissive ceiling quad, in real time as in the path tracer.
#[test]
fn an_emissive_ceiling_lights_the_box_in_real_time_as_in_truth() {
    let d = dir("lamp");
    let mut s = scene::builtin("cornell").unwrap();
    s.lights.clear();
    let file = d.join("lamp.gltf");
    scene::write_gltf(&s, &file).unwrap();
    let f = file.display().to_string();
    let (truth, rt) = (p(&d, "truth.exr"), p(&d, "rt.exr"));
    spectra(&["truth", &f, "--direct-only", "--spp", "256", "--size", "96x96", "--out", &truth]);
    let out = spectra(&["render", &f, "--size", "96x96", "--out", &rt]);
    let note = String::from_utf8_lossy(&out.stderr);
    assert!(note.contains("emissive polygon light"), "{note}");
    assert!(!note.contains("default environment"), "a lamp lights the box: {note}");
    let de = block_de(&truth, &rt);
    assert!(de <= 3.0, "block-mean ΔE2000 {de:.2} > 3");
    eprintln!("emissive ceiling, spectral vs truth (direct): block-mean ΔE2000 {de:.3}");
    let _ = std::fs::remove_dir_all(&d);
}
