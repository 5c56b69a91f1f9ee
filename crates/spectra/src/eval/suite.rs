//! The evaluation suite: which scenes, under which lights, at which sizes.
//!
//! Every case is a scene whose lights the path tracer and the rasteriser treat identically
//! (punctual lights, no emissive stand-ins), so direct-only ground truth compares like for like
//! with the shadow-mapped real-time image.

use anyhow::{Context, Result, bail};
use glam::Vec3;
use scene::{Emission, Scene};

/// Sizes and sample counts of one run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Budget {
    pub width: u32,
    pub height: u32,
    /// Ground-truth samples per pixel (direct lighting only).
    pub truth_spp: u32,
    /// Frame-time measurement: frame size, measured frames per configuration, N values.
    pub bench_width: u32,
    pub bench_height: u32,
    pub bench_frames: usize,
    pub bench_counts: Vec<usize>,
    /// Jittered accumulation: wavelengths per frame and the frame counts to accumulate.
    pub jitter_per_frame: usize,
    pub jitter_frames: Vec<usize>,
}

impl Budget {
    pub fn quick() -> Budget {
        Budget {
            width: 128,
            height: 96,
            truth_spp: 1024,
            bench_width: 256,
            bench_height: 192,
            bench_frames: 9,
            bench_counts: vec![1, 2, 4, 8, 16, 32],
            jitter_per_frame: 6,
            jitter_frames: vec![1, 2, 4, 8],
        }
    }

    pub fn full() -> Budget {
        Budget {
            width: 320,
            height: 240,
            truth_spp: 4096,
            bench_width: 640,
            bench_height: 480,
            bench_frames: 31,
            bench_counts: vec![1, 2, 4, 8, 16, 32, 64],
            jitter_per_frame: 6,
            jitter_frames: vec![1, 2, 4, 8, 16],
        }
    }
}

/// One evaluated image: a named scene variant.
#[derive(Clone, Debug)]
pub struct Case {
    /// Short id used in file names and JSON (`colorchecker-f11`).
    pub id: String,
    /// What the case shows, for the report.
    pub title: String,
    pub scene: Scene,
}

/// Case ids `spectra eval --scenes` accepts.
pub const CASE_IDS: &[&str] = &["metamerism", "colorchecker-d65", "colorchecker-f11", "colorchecker-led"];

/// Why `underwater` (paper Figs. 1–2) is not in the suite yet.
pub const UNDERWATER_NOTE: &str = "underwater (paper Figs. 1–2) not evaluated: the scene exists, but the path tracer's water \
medium (truth::water) is not committed yet, and rendering the scene without water in both renderers would not be the \
paper's case";

/// The default suite and the notes about what it leaves out.
pub fn default_ids() -> (Vec<String>, Vec<String>) {
    (CASE_IDS.iter().map(|s| s.to_string()).collect(), vec![UNDERWATER_NOTE.to_string()])
}

/// Builds a case by id.
pub fn case(id: &str) -> Result<Case> {
    let cc = |illum: &str, title: &str| -> Result<Case> {
        let mut s = scene::builtin("colorchecker")?;
        if illum != "D65" {
            relight(&mut s, illum).with_context(|| format!("relighting the ColorChecker with {illum}"))?;
        }
        Ok(Case { id: id.to_string(), title: title.to_string(), scene: s })
    };
    match id {
        "metamerism" => Ok(Case {
            id: id.into(),
            title: "Spiky emission / metamerism (paper Fig. 3): F11 and LED-RGB1 spots, metameric pair"
                .into(),
            scene: scene::builtin("metamerism")?,
        }),
        "colorchecker-d65" => {
            cc("D65", "ColorChecker under D65 (control: RGB is exact here by construction)")
        }
        "colorchecker-f11" => cc("F11", "ColorChecker under CIE F11 (narrow-band fluorescent)"),
        "colorchecker-led" => cc("LED-RGB1", "ColorChecker under CIE LED-RGB1 (three-peak LED)"),
        "underwater" => bail!("{UNDERWATER_NOTE}"),
        other => bail!("unknown eval scene '{other}'; known: {}", CASE_IDS.join(", ")),
    }
}

/// Replaces the shape of every light with a CIE illuminant at the same luminance, and gives
/// RGB renderers that illuminant's own chromaticity (what an artist would pick for the lamp).
fn relight(s: &mut Scene, illum: &str) -> Result<()> {
    let shape = color::illuminant::by_name(illum)?;
    let xyz = scene::emission::spectrum_xyz(&shape);
    let rgb = scene::srgb::xyz_to_linear(xyz.map(|v| v / xyz[1])).max(glam::DVec3::ZERO).as_vec3();
    for l in &mut s.lights {
        // Keep the luminance the scene gave the light; only its spectrum changes.
        let y = l.emission.xyz()[1] as f32;
        l.emission = Emission::new(rgb, y / luminance(rgb), Some(&shape)).map_err(|e| anyhow::anyhow!(e))?;
    }
    Ok(())
}

fn luminance(rgb: Vec3) -> f32 {
    0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relit_chart_keeps_luminance_and_takes_the_new_shape() {
        let d65 = case("colorchecker-d65").unwrap();
        let f11 = case("colorchecker-f11").unwrap();
        let (a, b) = (&d65.scene.lights[0].emission, &f11.scene.lights[0].emission);
        assert!((a.xyz()[1] - b.xyz()[1]).abs() < 1e-3 * a.xyz()[1]);
        // F11 is greenish-yellow compared with D65: its x chromaticity is higher.
        let x = |e: &Emission| e.xyz()[0] / e.xyz().iter().sum::<f64>();
        assert!(x(b) > x(a) + 0.02, "{} vs {}", x(b), x(a));
        assert!(case("nope").unwrap_err().to_string().contains("colorchecker-f11"));
    }
}
