//! A lever for issue 27 measured and set aside: `cargo run --release -p render --example
//! light_basis -- SCENE [N]`. Could a textured pixel sum its node reflectances once per *basis*
//! spectrum instead of once per light? Only if the lights' node weights (each light's emission ×
//! observer × quadrature, as the renderer builds them) are combinations of a few. This builds
//! them for the scene's punctual lights and emissive area lights (clustered with one light kept
//! for an environment's sun, as `spectra bench SCENE --env default` renders it) and prints, for
//! a basis grown by pivoted Gram–Schmidt (the light least captured so far joins next), the worst
//! light's relative residual ‖Wₗ − Σⱼ αₗⱼQⱼ‖ / ‖Wₗ‖ after each basis spectrum.

use render::spectral_data::SpectralSetup;
use render::{Mode, RenderSettings};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).ok_or("usage: light_basis SCENE [N]")?;
    let n: usize = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(8);
    let scene = scene::load_any(path)?;
    let table = color::upsample::table("srgb")?;
    let setup = SpectralSetup::new(&RenderSettings { wavelengths: n, ..Default::default() })?;
    let budget = render::scene_gpu::MAX_LIGHTS.saturating_sub(scene.lights.len() + 1);
    let area = scene::emitters::area_lights(&scene, budget);
    let emissions = scene.lights.iter().map(|l| &l.emission).chain(area.lights.iter().map(|e| &e.emission));
    let mut lights = Vec::new();
    for e in emissions {
        lights.push(setup.light_weights(e, Mode::Spectral, &table)?);
    }
    let dot = |a: &[[f64; 3]], b: &[[f64; 3]]| -> f64 {
        a.iter().zip(b).map(|(x, y)| x[0] * y[0] + x[1] * y[1] + x[2] * y[2]).sum()
    };
    let norms: Vec<f64> = lights.iter().map(|w| dot(w, w).sqrt()).collect();
    let mut rest = lights.clone();
    println!("{path}: {} lights, N = {n} ({} weights each)", lights.len(), 3 * n);
    for k in 0..lights.len().min(3 * n) {
        let (worst, rel) = rest
            .iter()
            .zip(&norms)
            .map(|(r, &m)| if m > 0.0 { dot(r, r).sqrt() / m } else { 0.0 })
            .enumerate()
            .fold((0, 0.0f64), |a, (i, v)| if v > a.1 { (i, v) } else { a });
        println!("{k:>3} basis spectra: worst relative residual {rel:.3e}");
        if rel < 1e-9 {
            break;
        }
        let len = dot(&rest[worst], &rest[worst]).sqrt();
        let q: Vec<[f64; 3]> = rest[worst].iter().map(|w| w.map(|c| c / len)).collect();
        for r in &mut rest {
            let a = dot(r, &q);
            r.iter_mut().zip(&q).for_each(|(x, y)| *x = [0, 1, 2].map(|c| x[c] - a * y[c]));
        }
    }
    Ok(())
}
