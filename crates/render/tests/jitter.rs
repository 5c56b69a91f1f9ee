//! Wavelength jitter (`RenderSettings::jitter`) on lavapipe at small sizes: under a spiky light
//! (F11), the average of K frames with N jittered wavelengths at stratified offsets converges to
//! a dense render, far better than one frame does. This only holds because jittered frames
//! normalise with dense integrals; with per-frame normalisation (each frame a ratio of two
//! N-sample estimates) the average stays biased.

mod common;

use color::Quadrature;
use common::*;
use render::{Mode, RenderSettings, Renderer};

const W: u32 = 96;
const H: u32 = 64;
const MARGIN: f32 = 0.1;

fn render_hdr(r: &mut Renderer, s: &RenderSettings) -> Vec<[f64; 3]> {
    let cam = r.scene_camera().unwrap();
    r.render(&cam, s).unwrap();
    r.read_hdr().unwrap().iter().map(rgb_of).collect()
}

/// The midpoint rule: point sampling is the only rule whose shifted grids average to the exact
/// integral (see `prefiltered_jitter_averages_to_a_blurred_integral`).
fn settings(n: usize, jitter: Option<f32>) -> RenderSettings {
    RenderSettings {
        mode: Mode::Spectral,
        wavelengths: n,
        shadows: false,
        jitter,
        quadrature: Quadrature::Midpoint,
        ..Default::default()
    }
}

/// K offsets, one uniformly placed in each of K equal strata of [0, 1): `centred` puts each at
/// its stratum's centre, otherwise at a pseudo-random position (SplitMix64, fixed seed).
fn stratified_offsets(k: usize, centred: bool, seed: u64) -> Vec<f32> {
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..k).map(|i| ((i as f64 + if centred { 0.5 } else { next() }) / k as f64) as f32).collect()
}

struct Fixture {
    r: Renderer,
    expected: Vec<Option<[f64; 3]>>,
}

impl Fixture {
    /// The colour chart under F11 and its reference: 256 midpoint wavelengths (per-N
    /// normalised), on the patches only.
    fn new() -> Self {
        let chart = Chart::colorchecker();
        let f11 = color::illuminant::by_name("F11").unwrap();
        let mut r = renderer();
        r.set_scene(&chart.scene(white_light(1.5, Some(f11)), 1.0, 0.0)).unwrap();
        r.resize(W, H).unwrap();
        let reference = render_hdr(&mut r, &settings(256, None));
        let expected = (0..H)
            .flat_map(|y| (0..W).map(move |x| (x, y)))
            .zip(&reference)
            .map(|((x, y), p)| chart.patch_at(pixel_to_chart(x, y, W, H).0, MARGIN).map(|_| *p))
            .collect();
        Fixture { r, expected }
    }

    fn mean_de(&self, img: &[[f64; 3]]) -> f64 {
        let de = img
            .iter()
            .zip(&self.expected)
            .filter_map(|(a, e)| e.map(|e| color::ciede2000(lab(*a), lab(e))))
            .collect();
        stats(de).0
    }

    /// The average of N-wavelength frames at the given jitter offsets.
    fn average(&mut self, n: usize, offsets: &[f32]) -> Vec<[f64; 3]> {
        let mut sum = vec![[0.0f64; 3]; (W * H) as usize];
        for &u in offsets {
            let img = render_hdr(&mut self.r, &settings(n, Some(u)));
            sum.iter_mut().zip(&img).for_each(|(a, b)| (0..3).for_each(|c| a[c] += b[c]));
        }
        sum.iter().map(|p| p.map(|c| c / offsets.len() as f64)).collect()
    }
}

#[test]
fn centred_jitter_frames_average_to_the_dense_render_under_f11() {
    // K frames of N wavelengths at offsets (k + ½)/K sample exactly the N·K midpoint grid, so
    // without bias their average must match the dense render as closely as N·K midpoint
    // wavelengths do. Per-frame normalisation instead averages K differently scaled frames.
    let mut f = Fixture::new();
    let (n, k) = (4, 16);
    let img = render_hdr(&mut f.r, &settings(n, Some(0.5)));
    let single = f.mean_de(&img);
    let img = render_hdr(&mut f.r, &settings(n * k, None));
    let grid = f.mean_de(&img);
    let avg = f.average(n, &stratified_offsets(k, true, 0));
    let de_avg = f.mean_de(&avg);
    println!(
        "F11: one {n}-wavelength frame ΔE {single:.3}; {k} centred frames ΔE {de_avg:.3}; {} midpoint ΔE {grid:.3}",
        n * k
    );
    assert!(single > 5.0, "one {n}-wavelength frame is already close under F11 (ΔE {single})");
    assert!(de_avg < grid + 0.2, "{k} centred frames ΔE {de_avg}, the {}-wavelength grid ΔE {grid}", n * k);
    assert_delta_e("jitter-centred-f11", W, H, &avg, &f.expected, 0.5, 2.0);
}

#[test]
fn random_stratified_jitter_converges_under_f11() {
    // Random positions within the strata: an unbiased estimate whose error shrinks as K grows.
    let mut f = Fixture::new();
    let n = 4;
    let img = render_hdr(&mut f.r, &settings(n, Some(0.37)));
    let single = f.mean_de(&img);
    let de: Vec<f64> = [4, 16, 64]
        .iter()
        .map(|&k| {
            let avg = f.average(n, &stratified_offsets(k, false, 7));
            f.mean_de(&avg)
        })
        .collect();
    println!("F11, N = {n}: one frame ΔE {single:.3}; K = 4, 16, 64 stratified frames ΔE {de:.3?}");
    // (K = 4 is reported only: four random frames may well be worse than one lucky frame.)
    assert!(de[1] < 0.5 * single && de[2] < 0.5 * de[1], "no convergence: {single} then {de:?}");
    assert!(de[2] < 1.0, "64 stratified frames still ΔE {} from the dense render", de[2]);
}

#[test]
fn prefiltered_jitter_averages_to_a_blurred_integral() {
    // Prefiltered frames on shifted grids: each frame is far closer than a midpoint frame, and
    // averaging over shifts helps, but the average converges to the reflectance blurred by the
    // cardinal functions (only point sampling is unbiased over shifts), so it keeps a floor of
    // the size of the interpolation error instead of converging. This measures the floor.
    let mut f = Fixture::new();
    for n in [4, 8] {
        let pre = |u: Option<f32>| RenderSettings { quadrature: Quadrature::Prefiltered, ..settings(n, u) };
        let img = render_hdr(&mut f.r, &pre(Some(0.37)));
        let single = f.mean_de(&img);
        let img = render_hdr(&mut f.r, &settings(n, Some(0.37)));
        let single_mid = f.mean_de(&img);
        let mut sum = vec![[0.0f64; 3]; (W * H) as usize];
        let offsets = stratified_offsets(16, false, 7);
        for &u in &offsets {
            let img = render_hdr(&mut f.r, &pre(Some(u)));
            sum.iter_mut()
                .zip(&img)
                .for_each(|(a, b)| (0..3).for_each(|c| a[c] += b[c] / offsets.len() as f64));
        }
        let avg = f.mean_de(&sum);
        println!(
            "F11 N={n}: one prefiltered frame ΔE {single:.3} (midpoint {single_mid:.3}); 16 frames {avg:.3}"
        );
        assert!(single < 0.6 * single_mid, "N={n}: prefiltered frame {single} vs midpoint {single_mid}");
        // The floor: the average stays within the interpolation error of one frame (measured:
        // N=4 3.11 → 1.42, N=8 0.23 → 0.29), far below any midpoint frame.
        assert!(
            avg < single.max(0.5) && avg < 0.2 * single_mid,
            "N={n}: 16 shifted frames ΔE {avg} vs one {single}"
        );
    }
}

#[test]
fn jitter_keeps_the_normalisation_fixed_across_frames() {
    // With jitter the XYZ → RGB matrix and the emission weights' scale come from dense
    // integrals over the range: the same for every offset.
    let a = render::SpectralSetup::new(&settings(4, Some(0.1))).unwrap();
    let b = render::SpectralSetup::new(&settings(4, Some(0.9))).unwrap();
    assert_eq!(a.xyz_to_rgb, b.xyz_to_rgb);
    assert!((a.wavelengths.lambda[0] - (380.0 + 0.1 * 87.5)).abs() < 1e-3, "{:?}", a.wavelengths.lambda);
    // Weight / CMF is Δλ / k with the same k for every offset.
    let obs = color::Observer::cie1931();
    let scale = |s: &render::SpectralSetup| s.integrator.weights[1][1] / obs.eval(s.wavelengths.lambda[1])[1];
    assert!((scale(&a) / scale(&b) - 1.0).abs() < 1e-12);
    assert!(RenderSettings { jitter: Some(1.0), ..settings(4, None) }.validate().is_err());
}
