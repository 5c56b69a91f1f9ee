//! Temporal accumulation (`Renderer::set_accumulation`) on lavapipe at small sizes: the
//! renderer's own running mean of jittered frames equals the CPU average of the same frames read
//! back one by one, a reset restarts the mean, and post displays the mean.

mod common;

use common::*;
use render::{Mode, RenderSettings, Renderer};

const W: u32 = 48;
const H: u32 = 32;

fn settings(u: f32) -> RenderSettings {
    RenderSettings {
        mode: Mode::Spectral,
        wavelengths: 4,
        shadows: false,
        jitter: Some(u),
        ..Default::default()
    }
}

/// Golden-ratio additive recurrence: well spread offsets for any number of frames.
fn offset(k: usize) -> f32 {
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    ((0.5 + k as f64 * phi).fract() as f32).min(1.0 - f32::EPSILON)
}

/// The colour chart under F11: four jittered wavelengths differ a lot from frame to frame.
fn chart_renderer() -> Renderer {
    let chart = Chart::colorchecker();
    let f11 = color::illuminant::by_name("F11").unwrap();
    let mut r = renderer();
    r.set_scene(&chart.scene(white_light(1.5, Some(f11)), 1.0, 0.0)).unwrap();
    r.resize(W, H).unwrap();
    r
}

/// Renders the frames at `offsets` with accumulation on; returns the CPU mean (f64) of their
/// individually read-back HDR images.
fn accumulate(r: &mut Renderer, offsets: &[f32]) -> Vec<[f64; 4]> {
    let cam = r.scene_camera().unwrap();
    let mut sum = vec![[0.0f64; 4]; (W * H) as usize];
    for &u in offsets {
        r.render(&cam, &settings(u)).unwrap();
        let frame = r.read_hdr().unwrap();
        sum.iter_mut().zip(&frame).for_each(|(s, p)| (0..4).for_each(|c| s[c] += p[c] as f64));
    }
    sum.iter().map(|p| p.map(|c| c / offsets.len() as f64)).collect()
}

/// Largest difference between the GPU mean and the CPU mean, relative to max(1, |value|).
fn max_rel_err(gpu: &[[f32; 4]], cpu: &[[f64; 4]]) -> f64 {
    gpu.iter()
        .zip(cpu)
        .flat_map(|(g, c)| (0..3).map(move |i| (g[i] as f64 - c[i]).abs() / c[i].abs().max(1.0)))
        .fold(0.0, f64::max)
}

#[test]
fn running_mean_equals_the_cpu_average_of_the_frames_and_resets() {
    let mut r = chart_renderer();
    let cam = r.scene_camera().unwrap();
    assert_eq!(r.accumulated_frames(), 0);
    assert!(r.read_accumulated().is_err(), "nothing accumulated while accumulation is off");

    // One frame without accumulation: the display the mean's first frame must reproduce.
    r.render(&cam, &settings(offset(0))).unwrap();
    let single_ldr = r.read_ldr().unwrap();
    let single_hdr = r.read_hdr().unwrap();
    // A renderer that does not accumulate holds no accumulation targets (issue 27 item 4).
    assert!(!r.accumulation_targets_made());

    r.set_accumulation(true);
    let k = 8;
    let offsets: Vec<f32> = (0..k).map(offset).collect();
    let cpu = accumulate(&mut r, &offsets[..1]);
    assert_eq!(r.accumulated_frames(), 1);
    assert!(r.accumulation_targets_made());
    assert_eq!(r.read_accumulated().unwrap(), single_hdr, "the first frame's mean is the frame");
    assert_eq!(r.read_ldr().unwrap(), single_ldr, "post shows the one-frame mean like the frame");
    assert!(max_rel_err(&r.read_accumulated().unwrap(), &cpu) == 0.0);

    let cpu = accumulate(&mut r, &offsets);
    // (Frame 0 is in the GPU mean twice now; restart to compare like with like.)
    r.reset_accumulation();
    assert_eq!(r.accumulated_frames(), 0);
    let cpu_again = accumulate(&mut r, &offsets);
    assert_eq!(cpu, cpu_again, "the same offsets render the same frames");
    assert_eq!(r.accumulated_frames(), k as u32);
    let gpu = r.read_accumulated().unwrap();
    // The frames must differ enough that a wrong weight shows: under F11 four jittered
    // wavelengths change the colours by far more than the tolerance below.
    let spread = max_rel_err(&single_hdr, &cpu);
    let err = max_rel_err(&gpu, &cpu);
    println!(
        "{k} frames: GPU running mean vs CPU mean max rel. error {err:.2e}; first frame vs mean {spread:.3}"
    );
    assert!(spread > 0.05, "jittered frames barely differ ({spread}): the test could not see a wrong weight");
    // f32 running mean of f16 inputs: a few f32 ulps per frame.
    assert!(err < 1e-5, "GPU running mean differs from the CPU average by {err:.3e} (relative)");
    assert_ne!(r.read_ldr().unwrap(), single_ldr, "post shows the mean, not one frame");

    // A reset restarts the mean; switching accumulation off and on does too.
    r.reset_accumulation();
    let cpu = accumulate(&mut r, &offsets[3..5]);
    assert_eq!(r.accumulated_frames(), 2);
    let err = max_rel_err(&r.read_accumulated().unwrap(), &cpu);
    assert!(err < 1e-5, "after a reset the mean differs from the new frames' average by {err:.3e}");
    r.set_accumulation(false);
    assert_eq!(r.accumulated_frames(), 0);
    r.set_accumulation(true);
    let cpu = accumulate(&mut r, &offsets[5..6]);
    assert_eq!(r.accumulated_frames(), 1);
    assert_eq!(max_rel_err(&r.read_accumulated().unwrap(), &cpu), 0.0);
}

#[test]
fn accumulation_off_renders_the_frame_itself() {
    // Turning accumulation on and off again leaves the display exactly as before.
    let mut r = chart_renderer();
    let cam = r.scene_camera().unwrap();
    r.render(&cam, &settings(0.25)).unwrap();
    let before = r.read_ldr().unwrap();
    r.set_accumulation(true);
    for k in 0..3 {
        r.render(&cam, &settings(offset(k))).unwrap();
    }
    r.set_accumulation(false);
    r.render(&cam, &settings(0.25)).unwrap();
    assert_eq!(r.read_ldr().unwrap(), before);
}
