//! `metamerism`: procedurally textured objects under a spiky F11 fluorescent and an LED-RGB1
//! light, where RGB rendering is most wrong.
//!
//! - Floor: a checkerboard of ColorChecker neutral 8 / neutral 6.5 (palette).
//! - Back wall: vertical stripes of six chromatic ColorChecker patches (palette).
//! - A pair of boxes that are *metamers under D65*: the left one has the ColorChecker
//!   "neutral 6.5" reflectance, the right one that spectrum plus a metameric black (a spectral
//!   wiggle invisible to the CIE 1931 observer under D65). Same base colour, so an RGB renderer
//!   draws them identical; under F11 and LED-RGB1 they differ, and only spectral rendering shows it.
//! - A checkered cube of orange / purplish blue / yellow green patches (palette).
//!
//! Lights: an F11 spot from the left and an LED-RGB1 spot from the right, both aimed at the
//! middle of the floor.

use color::{Observer, SpectralIntegrator, Spectrum, WavelengthRange};
use glam::{DMat3, DVec3, Vec3};

use super::{empty, measured_material, patch, patch_index, reflectance_rgb, shapes, spot_at};
use crate::context::Ctx;
use crate::error::SceneError;
use crate::{Camera, Material, PaletteEntry, Scene, SpectralReflectance, Texture, TextureRef, srgb};

/// The wavelengths of the metameric pair's samples: the ColorChecker grid, 380–780 nm at 5 nm.
fn grid() -> Vec<f64> {
    (0..81).map(|i| 380.0 + 5.0 * i as f64).collect()
}

/// XYZ under D65 of each piecewise-linear "hat" basis function on the grid: the 3 × 81 matrix
/// that maps samples to XYZ exactly as [`super::reflectance_rgb`] integrates them.
fn d65_weights(lambda: &[f64]) -> Vec<DVec3> {
    let d65 = color::illuminant::by_name("D65").expect("D65 is tabulated");
    let integ = SpectralIntegrator::reference(&Observer::cie1931(), &d65, WavelengthRange::FULL)
        .expect("valid range");
    (0..lambda.len())
        .map(|i| {
            let mut v = vec![0.0; lambda.len()];
            v[i] = 1.0;
            let hat = Spectrum::piecewise(lambda.to_vec(), v).expect("grid increases");
            DVec3::from_array(integ.integrate(|l| hat.eval(l)))
        })
        .collect()
}

/// `base + a·b`, where b is `wiggle` with its projection onto the D65-weighted colour matching
/// functions removed (a metameric black), and `a` is as large as keeps every sample within
/// [`lo`, `hi`]. Returns the spectrum on [`grid`].
pub fn metamer(base: &Spectrum, wiggle: impl Fn(f64) -> f64, lo: f64, hi: f64) -> Spectrum {
    let lambda = grid();
    let w = d65_weights(&lambda);
    let f: Vec<f64> = lambda.iter().map(|&l| wiggle(l)).collect();
    // b = f − Wᵀ (W Wᵀ)⁻¹ W f, so that W b = 0.
    let wwt = w.iter().fold(DMat3::ZERO, |m, wi| m + DMat3::from_cols(*wi * wi.x, *wi * wi.y, *wi * wi.z));
    let wf = w.iter().zip(&f).fold(DVec3::ZERO, |s, (wi, fi)| s + *wi * *fi);
    let c = wwt.inverse() * wf;
    let b: Vec<f64> = w.iter().zip(&f).map(|(wi, fi)| fi - wi.dot(c)).collect();
    let s0: Vec<f64> = lambda.iter().map(|&l| base.eval(l)).collect();
    // Largest a with lo ≤ s0 + a·b ≤ hi everywhere.
    let a = s0
        .iter()
        .zip(&b)
        .filter(|(_, bi)| bi.abs() > 1e-12)
        .map(|(s, bi)| if *bi > 0.0 { (hi - s) / bi } else { (lo - s) / bi })
        .fold(f64::INFINITY, f64::min);
    let values = s0.iter().zip(&b).map(|(s, bi)| s + a * bi).collect();
    Spectrum::piecewise(lambda, values).expect("grid increases")
}

/// Texels per side of one uniform block of a procedural texture: large enough that filtering
/// blends palette colours only along block edges, so most texels match a palette entry.
pub const BLOCK: u32 = 16;

/// Period (nm) of the sinusoid turned into the metameric black. Of the periods and phases
/// tried (60–200 nm), 80 nm at phase 0 separates the twins most under both lights at once.
pub const WIGGLE_PERIOD: f64 = 80.0;

/// An RGBA8 texture from a function of texel position giving a palette colour index.
fn pattern(name: &str, w: u32, h: u32, colours: &[[u8; 3]], at: impl Fn(u32, u32) -> usize) -> Texture {
    let mut rgba = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            rgba.extend_from_slice(&colours[at(x, y)]);
            rgba.push(255);
        }
    }
    Texture { sampler: Default::default(), name: name.into(), width: w, height: h, rgba8: rgba, srgb: true }
}

/// A palette-textured material over the named ColorChecker patches.
fn palette_material(
    s: &mut Scene,
    name: &str,
    patches: &[&str],
    w: u32,
    h: u32,
    at: impl Fn(u32, u32) -> usize,
) -> usize {
    let spectra: Vec<Spectrum> = patches.iter().map(|p| patch(patch_index(p))).collect();
    let texels: Vec<[u8; 3]> = spectra.iter().map(|sp| srgb::linear_to_srgb8(reflectance_rgb(sp))).collect();
    let tex = s.textures.len();
    s.textures.push(pattern(name, w, h, &texels, at));
    let palette =
        texels.iter().zip(spectra).map(|(&rgb8, spectrum)| PaletteEntry { rgb8, spectrum }).collect();
    s.materials.push(Material {
        name: name.into(),
        base_color_texture: Some(TextureRef { transform: None, index: tex, tex_coord: 0 }),
        spectral: Some(SpectralReflectance::Palette(palette)),
        ..Material::default()
    });
    s.materials.len() - 1
}

pub(crate) fn build(ctx: &Ctx) -> Result<Scene, SceneError> {
    let camera =
        Camera::look_at(Vec3::new(0.0, 0.55, 1.45), Vec3::new(0.0, 0.18, 0.0), Vec3::Y, 45f32.to_radians());
    let mut s = empty(ctx, camera);

    let floor = palette_material(
        &mut s,
        "floor checks (neutral 8 / neutral 6.5)",
        &["neutral 8 (.23 D)", "neutral 6.5 (.44 D)"],
        8 * BLOCK,
        8 * BLOCK,
        |x, y| ((x / BLOCK + y / BLOCK) % 2) as usize,
    );
    let stripes = ["red", "orange", "yellow", "green", "blue", "magenta"];
    let wall = palette_material(
        &mut s,
        "wall stripes (six ColorChecker patches)",
        &stripes,
        6 * BLOCK,
        BLOCK,
        |x, _| (x / BLOCK) as usize,
    );
    let cube = palette_material(
        &mut s,
        "cube checks",
        &["orange", "purplish blue", "yellow green"],
        3 * BLOCK,
        3 * BLOCK,
        |x, y| ((x / BLOCK + y / BLOCK) % 3) as usize,
    );

    let grey = patch(patch_index("neutral 6.5 (.44 D)"));
    let twin =
        metamer(&grey, |l| (2.0 * std::f64::consts::PI * (l - 380.0) / WIGGLE_PERIOD).sin(), 0.02, 0.9);
    let mut a = measured_material("metamer A (ColorChecker neutral 6.5)", &grey);
    let mut b = measured_material("metamer B (neutral 6.5 + metameric black)", &twin);
    // Identical RGB on purpose: they *are* the same colour under D65.
    b.base_color = a.base_color;
    a.roughness = 0.8;
    b.roughness = 0.8;
    s.materials.push(a);
    s.materials.push(b);
    let (ma, mb) = (s.materials.len() - 2, s.materials.len() - 1);

    let (fw, wh) = (1.4f32, 0.8f32);
    s.meshes.push(shapes::quad(Vec3::new(-fw * 0.5, 0.0, fw * 0.5), Vec3::X * fw, -Vec3::Z * fw, floor));
    s.meshes.push(shapes::quad(Vec3::new(-fw * 0.5, 0.0, -fw * 0.5), Vec3::X * fw, Vec3::Y * wh, wall));
    s.meshes.push(shapes::cuboid(Vec3::new(-0.3, 0.0, 0.05), Vec3::new(0.2, 0.25, 0.2), 0.3, ma));
    s.meshes.push(shapes::cuboid(Vec3::new(0.05, 0.0, 0.1), Vec3::new(0.2, 0.25, 0.2), -0.2, mb));
    s.meshes.push(shapes::cuboid(Vec3::new(0.38, 0.0, -0.2), Vec3::splat(0.18), 0.6, cube));

    // Two spots 1.1 m up and to the sides, aimed at the floor's centre: ≈ π lux there each.
    let target = Vec3::new(0.0, 0.0, 0.0);
    for (name, illum, x) in [("F11 spot", "F11", -0.7f32), ("LED-RGB1 spot", "LED-RGB1", 0.7)] {
        let position = Vec3::new(x, 1.1, 0.6);
        let to = target - position;
        let intensity = std::f32::consts::PI * to.length_squared() / (to.normalize().dot(-Vec3::Y));
        let cones = (35f32.to_radians(), 60f32.to_radians());
        s.lights.push(spot_at(ctx, name, illum, position, target, intensity, cones)?);
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn xyz(s: &Spectrum, illum: &str) -> [f64; 3] {
        let e = color::illuminant::by_name(illum).unwrap();
        SpectralIntegrator::reference(&Observer::cie1931(), &e, WavelengthRange::FULL)
            .unwrap()
            .integrate(|l| s.eval(l))
    }

    #[test]
    fn procedural_textures_hold_palette_values() {
        let s = build(&Ctx::builtin("metamerism")).unwrap();
        for m in &s.materials {
            let Some(SpectralReflectance::Palette(p)) = &m.spectral else { continue };
            let t = &s.textures[m.base_color_texture.unwrap().index];
            // Every texel is one of the palette's colours, and every colour is used.
            let texels: Vec<[u8; 3]> = t.rgba8.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect();
            assert!(texels.iter().all(|x| p.iter().any(|e| e.rgb8 == *x)), "{}", m.name);
            assert!(p.iter().all(|e| texels.contains(&e.rgb8)), "{}", m.name);
        }
    }

    /// CIEDE2000 between the twins under `illum`, each adapted to that illuminant's white.
    fn delta_e(a: &Spectrum, b: &Spectrum, illum: &str) -> f64 {
        let e = color::illuminant::by_name(illum).unwrap();
        let integ = SpectralIntegrator::reference(&Observer::cie1931(), &e, WavelengthRange::FULL).unwrap();
        let w = integ.white();
        let lab = |s: &Spectrum| color::lab::xyz_to_lab(integ.integrate(|l| s.eval(l)), w);
        color::delta_e::ciede2000(lab(a), lab(b))
    }

    #[test]
    fn twins_match_under_d65_and_not_under_f11_or_led() {
        let grey = patch(patch_index("neutral 6.5 (.44 D)"));
        let twin =
            metamer(&grey, |l| (2.0 * std::f64::consts::PI * (l - 380.0) / WIGGLE_PERIOD).sin(), 0.02, 0.9);
        let (a, b) = (xyz(&grey, "D65"), xyz(&twin, "D65"));
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 1e-9, "D65: {a:?} vs {b:?}");
        }
        assert!(delta_e(&grey, &twin, "D65") < 1e-6);
        // The spectra really differ, and so do their colours under the scene's lights: a ΔE00
        // of 10 is a difference nobody misses.
        assert!(
            (0..81)
                .any(|i| (grey.eval(380.0 + 5.0 * i as f64) - twin.eval(380.0 + 5.0 * i as f64)).abs() > 0.1)
        );
        for ill in ["F11", "LED-RGB1"] {
            let d = delta_e(&grey, &twin, ill);
            println!("metamer twins under {ill}: ΔE00 = {d:.2}");
            assert!(d > 10.0, "{ill}: ΔE00 only {d}");
        }
        assert!(
            twin.max_value(380.0, 780.0) <= 0.9 + 1e-12
                && -twin.scaled(-1.0).max_value(380.0, 780.0) >= 0.02 - 1e-12
        );
    }
}
