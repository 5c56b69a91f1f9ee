//! Quick frame-time measurement (not a test): renders a scene at a given size in rgb and
//! spectral modes and prints the median wall-clock and per-pass GPU times.
//!
//! `cargo run --release -p render --example frametime -- [WIDTHxHEIGHT] [FRAMES] [SCENE]`

use render::{Mode, RenderSettings, Renderer};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let size = args.get(1).map(String::as_str).unwrap_or("1280x720");
    let frames: usize = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(9);
    let scene = scene::load_any(args.get(3).map(String::as_str).unwrap_or("cornell"))?;
    let (w, h) = size.split_once('x').ok_or("size must be WxH")?;
    let (w, h): (u32, u32) = (w.parse()?, h.parse()?);
    let mut r = Renderer::new()?;
    println!("adapter: {}", r.gpu().describe());
    r.set_scene(&scene)?;
    r.resize(w, h)?;
    let runs = [
        (Mode::Rgb, 16, true),
        (Mode::Rgb, 16, false),
        (Mode::Spectral, 1, true),
        (Mode::Spectral, 4, true),
        (Mode::Spectral, 16, true),
        (Mode::Spectral, 16, false),
        (Mode::Spectral, 64, true),
    ];
    for (mode, n, shadows) in runs {
        let s = RenderSettings { mode, wavelengths: n, shadows, timestamps: true, ..Default::default() };
        let mut wall = Vec::new();
        let mut gpu = Vec::new();
        for _ in 0..frames {
            let t0 = Instant::now();
            r.render(&scene.camera, &s)?;
            // Waits for the frame (timestamps are read after completion).
            let t = r.read_timings()?;
            wall.push(t0.elapsed().as_secs_f64() * 1e3);
            if let Some(t) = t {
                gpu.push(t);
            }
        }
        wall.sort_by(f64::total_cmp);
        let med = |v: Vec<f64>| {
            let mut v = v;
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let passes: Vec<String> = render::timing::PASSES
            .iter()
            .enumerate()
            .map(|(i, p)| format!("{p} {:.1}", med(gpu.iter().map(|t| t.ms[i]).collect())))
            .collect();
        println!(
            "{:>8} N={:<3} shadows {:<5} {w}x{h}: median wall {:.1} ms; GPU ms: {}",
            mode.name(),
            n,
            shadows,
            wall[wall.len() / 2],
            passes.join(", ")
        );
    }
    Ok(())
}
