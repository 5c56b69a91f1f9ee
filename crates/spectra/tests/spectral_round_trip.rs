//! Issue 17's round trip: a truth spectral EXR, re-integrated by `spectra diff` (CIE 1931), equals
//! the RGB EXR written by the same run within 1e-4 per pixel (|Δ| linear sRGB, the channel mean).
//! The bands and `--out` come from the same samples but weigh them differently (the observer at
//! the band centre vs at each sample's wavelength), so this holds only with narrow bands and
//! many samples: 0.5 nm and 4096 spp here. The measured figures against band width and spp, and
//! why 5 nm bands cannot meet it at any spp, are in docs/spectral-exr.md.

use std::process::Command;

#[test]
fn half_nm_bands_reintegrate_to_the_rgb_output_within_1e_4() {
    let dir = tempfile::tempdir().unwrap();
    let (t, ts) = (dir.path().join("t.exr"), dir.path().join("ts.exr"));
    let bin = env!("CARGO_BIN_EXE_spectra");
    let out = Command::new(bin)
        .args(["truth", "metamerism", "--direct-only", "--spp", "4096", "--size", "24x18", "--out"])
        .arg(&t)
        .arg("--spectral-out")
        .arg(&ts)
        .args(["--spectral-bin", "0.5"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let out = Command::new(bin).arg("diff").arg(&t).arg(&ts).arg("--json").output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let (mean, max) = (v["mae_linear"]["mean"].as_f64().unwrap(), v["mae_linear"]["max"].as_f64().unwrap());
    eprintln!("round trip, 0.5 nm bands, 4096 spp: mean |Δ| {mean:.2e}, max {max:.2e}");
    assert!(v["test_spectral"].as_str().unwrap().contains("700 bands"), "{}", v["test_spectral"]);
    assert!(max < 1e-4, "max |Δ| {max:.2e}");
}
