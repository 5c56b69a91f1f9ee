//! Frame-time cost of the underwater hooks (not a test): renders the built-in `underwater` scene
//! dry, with the paper's model, the isotropic model + 16-step single scattering and the default
//! (light-field) model, in the scene's water (type chosen, camera at 10 m, sea floor included) at
//! N = 8, 16, 32 (and rgb) and prints the median wall-clock frame time and the shading pass's
//! GPU time (where the hooks run) when timestamps are available.
//!
//! `cargo run --release -p render --example underwater_frametime -- [WIDTHxHEIGHT] [FRAMES] [TYPE]`

use render::passes::underwater;
use render::{CustomShader, Mode, RenderSettings, Renderer};
use scene::water::WaterMedium;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let size = args.get(1).map(String::as_str).unwrap_or("640x360");
    let frames: usize = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(15);
    let ty = color::water::WaterType::parse(args.get(3).map(String::as_str).unwrap_or("II"))?;
    let (w, h) = size.split_once('x').ok_or("size must be WxH")?;
    let (w, h): (u32, u32) = (w.parse()?, h.parse()?);
    let scene = scene::builtin("underwater")?;
    // The scene's own water (sun, sky) at 10 m with the chosen type, and the sea floor under
    // its camera, as `spectra render underwater --water TYPE --depth 10` draws it.
    let settings = scene.water.clone().ok_or("the underwater scene has water settings")?;
    let mut medium = WaterMedium::from_settings(&scene::WaterSettings {
        water_type: ty.to_string(),
        depth: 10.0,
        ..settings
    })?;
    medium.floor = scene::water::floor::below_camera(&scene, medium.scale)?;
    let mut r = Renderer::new()?;
    println!("adapter: {}", r.gpu().describe());
    r.set_scene(&scene)?;
    r.resize(w, h)?;
    for (mode, n) in [(Mode::Rgb, 16), (Mode::Spectral, 8), (Mode::Spectral, 16), (Mode::Spectral, 32)] {
        let mut line = format!("{:>8} N={n:<3} {w}x{h}:", mode.name());
        let mut dry_wet = [0.0; 4];
        let models = [
            ("dry", None),
            ("paper", Some(underwater::Options::paper())),
            ("marched", Some(underwater::Options::isotropic())),
            ("light field", Some(underwater::Options::default())),
        ];
        for (k, (name, model)) in models.into_iter().enumerate() {
            r.set_custom_shader(match model {
                Some(o) => underwater::shader_with(&medium, &o)?,
                None => CustomShader::default(),
            })?;
            let s = RenderSettings { mode, wavelengths: n, timestamps: true, ..Default::default() };
            // One warm-up frame uploads the per-wavelength buffers.
            r.render(&scene.camera, &s)?;
            r.read_ldr()?;
            let (mut wall, mut shading) = (Vec::new(), Vec::new());
            for _ in 0..frames {
                let t0 = Instant::now();
                r.render(&scene.camera, &s)?;
                // Reading the image back waits for the frame to finish.
                r.read_ldr()?;
                wall.push(t0.elapsed().as_secs_f64() * 1e3);
                if let Some(t) = r.read_timings()? {
                    shading.push(t.ms[2]);
                }
            }
            dry_wet[k] = median(wall);
            let gpu = if shading.is_empty() {
                String::new()
            } else {
                format!(", shading GPU {:.2} ms", median(shading))
            };
            line += &format!(" {name} {:.2} ms{gpu};", dry_wet[k]);
        }
        println!(
            "{line} underwater cost: paper {:+.2} ms, marched {:+.2} ms, light field {:+.2} ms",
            dry_wet[1] - dry_wet[0],
            dry_wet[2] - dry_wet[0],
            dry_wet[3] - dry_wet[0]
        );
    }
    Ok(())
}
