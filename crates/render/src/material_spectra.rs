//! The Jakob–Hanika coefficients of the colours that are constant over a material
//! ([`ConstantColour`]), fetched once on the CPU when the scene's spectral data is built, so that
//! the spectral shading pass fetches per pixel only where a texture or vertex colours vary the
//! colour. The spectral G-buffer writes each pixel's material slot; `material_spectra[slot − 1]`
//! in shading.wgsl is the record below.

use crate::scene_gpu::ConstantColour;
use color::upsample::CoeffTable;

/// Byte for byte `MaterialSpectrum` in shading.wgsl (src/layout_tests.rs checks it).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaterialSpectrum {
    /// The base colour's coefficients; w = 1 when they hold (the colour is constant), else 0.
    pub base: [f32; 4],
    /// The emission's coefficients of `emission / scale` and w = scale = 2·max(emission) (the
    /// shading pass's "illuminant" upsampling; 0 for a surface that emits nothing), or w = −1
    /// when the emission varies over the surface.
    pub emission: [f32; 4],
}

impl MaterialSpectrum {
    /// The record of one material: the fetch the shading pass would make per pixel (the CPU
    /// `CoeffTable::fetch` matches the WGSL one, `coeff_table`'s tests), of the exact colours.
    pub fn new(c: &ConstantColour, table: &CoeffTable) -> Self {
        let coeffs = |rgb: [f32; 3]| {
            let p = table.fetch(rgb.map(f64::from));
            p.c.map(|v| v as f32)
        };
        let base = c.base.map_or([0.0; 4], |rgb| {
            let [c0, c1, c2] = coeffs(rgb);
            [c0, c1, c2, 1.0]
        });
        let emission = c.emission.map_or([0.0, 0.0, 0.0, -1.0], |e| {
            // As the shader: in f32, the largest channel doubled, the colour divided by it.
            let max = e[0].max(e[1]).max(e[2]);
            if max > 0.0 {
                let scale = 2.0 * max;
                let [c0, c1, c2] = coeffs(e.map(|v| v / scale));
                [c0, c1, c2, scale]
            } else {
                [0.0; 4]
            }
        });
        MaterialSpectrum { base, emission }
    }

    /// The records of a scene's materials (one zero record for a scene without any: a storage
    /// binding cannot be empty).
    pub fn of_scene(colours: &[ConstantColour], table: &CoeffTable) -> Vec<MaterialSpectrum> {
        let mut v: Vec<_> = colours.iter().map(|c| Self::new(c, table)).collect();
        if v.is_empty() {
            v.push(MaterialSpectrum::default());
        }
        v
    }
}
