//! Issue 18's study, rendered: how much of the underwater look survives when a Jerlov water is
//! known only by its RGB. The built-in `underwater` scene (as `spectra render underwater
//! --water TYPE --depth D` draws it: default light-field model, sea floor, N wavelengths)
//! with
//!
//! - (b) the measured spectra a(λ), b(λ), Kd(λ) — the existing pipeline;
//! - (a) their RGB projections (`color::upsample::medium::project`: the colour of each
//!   coefficient as a reflectance under D65) upsampled back as an RGB medium by
//!   `color::upsample::medium::medium` (σ_a, σ_s: the function the RGB medium uses everywhere)
//!   and `coefficient` (Kd), with box and with unbounded upsampling;
//! - (c) an RGB renderer with those projections: rgb mode on the box-upsampled water, whose
//!   coefficients at the RGB mode's three wavelengths are the projections themselves; and, for
//!   reference, rgb mode on the measured water (coefficients sampled at 611/549/464 nm, the
//!   underwater pass's own RGB baseline).
//!
//! Writes `b.exr`, `a-box.exr`, `a-unbounded.exr`, `c-rgb.exr`, `c-rgb-sampled.exr` (linear
//! sRGB, as `spectra render --out X.exr`) into OUTDIR; `tools/rgb_media_study.py` compares them
//! with `spectra truth underwater` (the measured spectra, path traced).
//!
//! `cargo run --release -p spectra --example rgb_water -- TYPE DEPTH WIDTHxHEIGHT OUTDIR [N]`

use anyhow::{Context, Result, anyhow};
use color::upsample::fit::LabModel;
use color::upsample::medium::{Attenuation, coefficient, medium, project};
use color::water::WaterProperties;
use color::{RgbColorSpace, Spectrum};
use render::passes::underwater;
use render::{Mode, RenderSettings, Renderer};
use scene::water::WaterMedium;
use std::path::{Path, PathBuf};

fn sum(a: &Spectrum, b: &Spectrum) -> Spectrum {
    Spectrum::Piecewise {
        lambda: (360..=830).map(f64::from).collect(),
        values: (360..=830).map(|l| a.eval(l as f64) + b.eval(l as f64)).collect(),
    }
}

fn write(
    r: &mut Renderer,
    scene: &scene::Scene,
    s: &RenderSettings,
    w: &WaterMedium,
    out: &Path,
) -> Result<()> {
    r.set_custom_shader(underwater::shader_with(w, &underwater::Options::default())?)?;
    r.render(&scene.camera, s)?;
    let (width, height) = r.size().context("the renderer has a size")?;
    let data = r.read_hdr()?.iter().map(|p| [p[0], p[1], p[2]]).collect();
    let img = compare::image::Image::new(width, height, data)?;
    compare::io::write_image(out, &img, Default::default())
        .with_context(|| format!("writing {}", out.display()))?;
    Ok(())
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [ty, depth, size, out, rest @ ..] = args.as_slice() else {
        return Err(anyhow!("usage: rgb_water TYPE DEPTH WIDTHxHEIGHT OUTDIR [N]"));
    };
    let depth: f32 = depth.parse().context("DEPTH")?;
    let n: usize = rest.first().map(|s| s.parse()).transpose().context("N")?.unwrap_or(16);
    let (w, h) = size.split_once('x').ok_or_else(|| anyhow!("size must be WIDTHxHEIGHT"))?;
    let (w, h): (u32, u32) = (w.parse()?, h.parse()?);
    let out = PathBuf::from(out);
    std::fs::create_dir_all(&out)?;

    let scene = scene::builtin("underwater")?;
    let settings = scene.water.clone().context("the underwater scene has water settings")?;
    let mut measured =
        WaterMedium::from_settings(&scene::WaterSettings { water_type: ty.clone(), depth, ..settings })?;
    measured.floor = scene::water::floor::below_camera(&scene, measured.scale).map_err(|e| anyhow!(e))?;

    let space = RgbColorSpace::srgb();
    let table = color::upsample::table("srgb")?;
    let model = LabModel::new(&space)?;
    let p = &measured.properties;
    let (a_rgb, b_rgb, kd_rgb) = (project(&model, &p.a), project(&model, &p.b), project(&model, &p.kd));
    println!("{ty}: RGB projections (1/m): a {a_rgb:.4?}, b {b_rgb:.4?}, Kd {kd_rgb:.4?}");
    let upsampled = |m: Attenuation| -> Result<WaterMedium> {
        let (sa, ss) = medium(&table, a_rgb, b_rgb, m)?;
        let kd = coefficient(&table, kd_rgb, m)?;
        let c = sum(&sa, &ss);
        Ok(WaterMedium {
            water_type: None,
            properties: WaterProperties { a: sa, b: ss, c, kd },
            ..measured.clone()
        })
    };
    let boxed = upsampled(Attenuation::Box)?;
    let unbounded = upsampled(Attenuation::Unbounded)?;

    let d = RenderSettings::default();
    let range = match scene.spectral.range {
        Some((lo, hi)) => color::WavelengthRange::new(lo as f64, hi as f64)?,
        None => d.range,
    };
    let spectral = RenderSettings {
        mode: Mode::Spectral,
        wavelengths: n,
        range,
        observer: scene.spectral.observer.clone().unwrap_or(d.observer.clone()),
        ..d
    };
    let rgb = RenderSettings { mode: Mode::Rgb, ..spectral.clone() };
    let mut r = Renderer::with_table(table.clone())?;
    r.set_scene(&scene)?;
    r.resize(w, h)?;
    write(&mut r, &scene, &spectral, &measured, &out.join("b.exr"))?;
    write(&mut r, &scene, &spectral, &boxed, &out.join("a-box.exr"))?;
    write(&mut r, &scene, &spectral, &unbounded, &out.join("a-unbounded.exr"))?;
    write(&mut r, &scene, &rgb, &boxed, &out.join("c-rgb.exr"))?;
    write(&mut r, &scene, &rgb, &measured, &out.join("c-rgb-sampled.exr"))?;
    Ok(())
}
