//! `spectra diff` compares EXRs by where their pixels lie in the frame (data and display
//! windows): two 8×8 crops from different places of one frame were compared pixel for pixel,
//! (4, 2) with (0, 0), and a crop against its full frame was refused for its size.

use std::process::{Command, Output};

fn spectra(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spectra")).args(args).output().expect("running spectra")
}

fn pixel(x: u32, y: u32) -> [f32; 3] {
    [x as f32 * 0.05 + 0.01, y as f32 * 0.07 + 0.02, ((x * y) % 7) as f32 / 7.0 + 0.05]
}

/// `size` pixels of the 16×12 frame from `origin`, written as a crop of it.
fn crop(path: &std::path::Path, origin: (u32, u32), size: (u32, u32)) {
    let im = compare::Image::from_fn(size.0, size.1, |x, y| pixel(x + origin.0, y + origin.1)).unwrap();
    let frame = compare::ExrFrame { display: (16, 12), origin, attributes: vec![] };
    compare::write_exr_framed(path, &im, &frame).unwrap();
}

fn diff(a: &std::path::Path, b: &std::path::Path) -> serde_json::Value {
    let out = spectra(&["diff", a.to_str().unwrap(), b.to_str().unwrap(), "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn crops_are_compared_where_they_lie_in_the_frame() {
    let d = tempfile::tempdir().unwrap();
    let (full, a, b) = (d.path().join("full.exr"), d.path().join("a.exr"), d.path().join("b.exr"));
    crop(&full, (0, 0), (16, 12));
    crop(&a, (4, 2), (8, 8));
    crop(&b, (0, 0), (8, 8));
    let v = diff(&a, &b);
    assert_eq!((v["width"].as_u64(), v["height"].as_u64()), (Some(4), Some(6)), "{v}");
    assert_eq!(v["region"], serde_json::json!({"frame": [16, 12], "x": 4, "y": 2, "width": 4, "height": 6}));
    assert_eq!(v["delta_e2000"]["max"].as_f64(), Some(0.0), "{v}");
    let v = diff(&full, &a);
    assert_eq!(v["region"]["width"].as_u64(), Some(8), "{v}");
    assert_eq!(v["delta_e2000"]["max"].as_f64(), Some(0.0), "{v}");
    // The whole frames: no region.
    assert!(diff(&full, &full)["region"].is_null());
    // A frame of another size holding these pixels elsewhere: one error line, both placements.
    let other = d.path().join("other.exr");
    let im = compare::Image::from_fn(16, 12, pixel).unwrap();
    let frame = compare::ExrFrame { display: (22, 16), origin: (3, 2), attributes: vec![] };
    compare::write_exr_framed(&other, &im, &frame).unwrap();
    let out = spectra(&["diff", full.to_str().unwrap(), other.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error:") && err.contains("other.exr") && err.contains("(3, 2) of a 22×16"),
        "{err}"
    );
}
