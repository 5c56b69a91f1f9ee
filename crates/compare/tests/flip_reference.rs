//! LDR- and HDR-FLIP against NVIDIA's reference implementation (the `flip-evaluator` 1.7
//! package) on the same inputs: tools/check_flip.py wrote the inputs and the reference's means,
//! exposures and error maps. The reference tool prints means with six decimals and its own
//! tests compare means at that precision, so that is the bound here for the mean; the maps are
//! held to the same 1e-6 per pixel.

use color::colorspace::srgb_decode;
use compare::Image;
use compare::flip::{DEFAULT_PIXELS_PER_DEGREE, HdrOptions, hdr_flip, ldr_flip};

fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn expected(name: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(data(name)).unwrap()).unwrap()
}

fn size(exp: &serde_json::Value) -> (u32, u32) {
    (exp["width"].as_u64().unwrap() as u32, exp["height"].as_u64().unwrap() as u32)
}

fn load_rgb8(name: &str, w: u32, h: u32) -> Image {
    let codes = std::fs::read(data(name)).unwrap();
    let lin: Vec<f32> = codes.iter().map(|&c| srgb_decode(f64::from(c) / 255.0) as f32).collect();
    Image::from_interleaved(w, h, &lin, 3).unwrap()
}

fn load_f32(name: &str, w: u32, h: u32) -> Image {
    let bytes = std::fs::read(data(name)).unwrap();
    let v: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_le_bytes(b.try_into().unwrap())).collect();
    Image::from_interleaved(w, h, &v, 3).unwrap()
}

fn check_map(what: &str, got: &compare::flip::FlipMap, exp: &serde_json::Value) {
    let want_mean = exp["mean"].as_f64().unwrap();
    eprintln!(
        "{what} mean {:.6} (reference {want_mean:.6}), |Δ| {:.1e}",
        got.mean(),
        (got.mean() - want_mean).abs()
    );
    assert!((got.mean() - want_mean).abs() <= 1e-6, "{what}: {} vs {want_mean}", got.mean());
    let want: Vec<f64> = exp["map"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert_eq!(got.values.len(), want.len());
    let worst = got.values.iter().zip(&want).map(|(a, b)| (f64::from(*a) - b).abs()).fold(0.0, f64::max);
    eprintln!("{what} worst per-pixel difference {worst:.1e}");
    assert!(worst <= 1e-6, "{what}: {worst}");
}

#[test]
fn ldr_flip_matches_the_reference_implementation() {
    let exp = expected("flip_expected.json");
    let (w, h) = size(&exp);
    let map = ldr_flip(
        &load_rgb8("flip_reference.rgb8", w, h),
        &load_rgb8("flip_test.rgb8", w, h),
        DEFAULT_PIXELS_PER_DEGREE,
    )
    .unwrap();
    check_map("LDR-FLIP", &map, &exp);
}

#[test]
fn hdr_flip_matches_the_reference_implementation() {
    let exp = expected("flip_hdr_expected.json");
    let (w, h) = size(&exp);
    let map = hdr_flip(
        &load_f32("flip_hdr_reference.f32", w, h),
        &load_f32("flip_hdr_test.f32", w, h),
        DEFAULT_PIXELS_PER_DEGREE,
        &HdrOptions::default(),
    )
    .unwrap();
    let e = map.exposures.unwrap();
    eprintln!("exposures {} to {}, {} ({})", e.start, e.stop, e.count, e.tone_mapper);
    assert_eq!(e.tone_mapper, exp["tonemapper"].as_str().unwrap());
    assert_eq!(i64::from(e.count), exp["num_exposures"].as_i64().unwrap());
    // The exposures come from the same f32 code: equal to the reference's (printed as f64).
    assert_eq!(f64::from(e.start), exp["start_exposure"].as_f64().unwrap());
    assert_eq!(f64::from(e.stop), exp["stop_exposure"].as_f64().unwrap());
    check_map("HDR-FLIP", &map, &exp);
}

/// 16-bit codes reach FLIP as they are: two 32×24 images of integer-formula 16-bit sRGB codes
/// (a = ((2053x + 977y), (311x + 4099y), (37x² + 13y)) mod 65536, b = a + ((7x + 13y + 5c) mod
/// 6001) − 3000 clamped), given to flip-evaluator 1.7's `evaluate(a / 65535, b / 65535, 'LDR')`:
/// mean 0.25465670228004456 (at 8 bits, rounded, 0.2546183168888092 — the difference the depth
/// makes, which the bound below tells apart). The reference tool's own PNG loader reads 16-bit
/// files at 8 bits (truncated), so its command line differs from both on such files.
#[test]
fn ldr_flip_of_16_bit_codes_matches_the_reference_implementation() {
    use compare::flip::ldr_flip_at_depths;
    let (w, h) = (32u32, 24u32);
    let code = |x: i64, y: i64, c: i64| -> i64 {
        match c {
            0 => (x * 2053 + y * 977) % 65536,
            1 => (x * 311 + y * 4099) % 65536,
            _ => (x * x * 37 + y * 13) % 65536,
        }
    };
    let image = |shift: bool| {
        let v: Vec<f32> = (0..h as i64)
            .flat_map(|y| (0..w as i64).flat_map(move |x| (0..3).map(move |c| (x, y, c))))
            .map(|(x, y, c)| {
                let a = code(x, y, c);
                let v = if shift { (a + (x * 7 + y * 13 + c * 5) % 6001 - 3000).clamp(0, 65535) } else { a };
                srgb_decode(v as f64 / 65535.0) as f32
            })
            .collect();
        Image::from_interleaved(w, h, &v, 3).unwrap()
    };
    let map = ldr_flip_at_depths(&image(false), &image(true), DEFAULT_PIXELS_PER_DEGREE, (16, 16)).unwrap();
    let want = 0.25465670228004456;
    eprintln!("16-bit LDR-FLIP mean {:.8} (reference {want:.8})", map.mean());
    assert!((map.mean() - want).abs() <= 1e-6, "{} vs {want}", map.mean());
}
