//! The Jakob–Hanika coefficients of the colours that are constant over a material
//! ([`ConstantColour`]), fetched once on the CPU when the scene's spectral data is built, so that
//! the spectral shading pass fetches per pixel only where a texture or vertex colours vary the
//! colour. The spectral G-buffer writes each pixel's material slot; `material_spectra[slot − 1]`
//! in shading.wgsl is the record below.

use crate::scene_gpu::ConstantColour;
use crate::spectral_data::WavelengthGroup;
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
    /// A constant emission's XYZ at the frame's nodes (Σ over the nodes of
    /// scale·sigmoid(λ)·white weights, what the shader's node loop would add up); w unused.
    pub emission_xyz: [f32; 4],
    /// The material's thin film (`KHR_materials_iridescence`): x its index (1 without a film),
    /// y and z its thickness minimum and maximum in nm, which every mode reads (the G-buffer
    /// holds only the weight and where the thickness lies between them per pixel); w the
    /// dielectric's F0 (`KHR_materials_ior`, `scene::dielectric_f0`).
    pub film: [f32; 4],
    /// A see-through material (`scene_gpu::refraction_record`): x its index at the d line, y
    /// its dispersion (20 / Abbe number; 0: none), z its volume's thickness in scene units (0:
    /// thin-walled); w unused. Read only by the transmissive layer's shading.
    pub refraction: [f32; 4],
    /// Its interior's absorption per scene unit, linear RGB (box-upsampled per node); w unused.
    pub absorption: [f32; 4],
}

impl MaterialSpectrum {
    /// The record of one material: the fetch the shading pass would make per pixel (the CPU
    /// `CoeffTable::fetch` matches the WGSL one, `coeff_table`'s tests), of the exact colours.
    pub fn new(
        c: &ConstantColour,
        film: [f32; 4],
        refraction: [[f32; 4]; 2],
        table: &CoeffTable,
        groups: &[WavelengthGroup],
    ) -> Self {
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
        let mut xyz = [0.0f64; 3];
        if emission[3] > 0.0 {
            let [c0, c1, c2, scale] = emission.map(f64::from);
            for g in groups {
                for lane in 0..4 {
                    let l = f64::from(g.lambda[lane]);
                    let x = ((c0 * l + c1) * l + c2).clamp(-1e18, 1e18);
                    let e = scale * (0.5 + 0.5 * x / (1.0 + x * x).sqrt());
                    for (c, w) in xyz.iter_mut().zip([g.white_x, g.white_y, g.white_z]) {
                        *c += e * f64::from(w[lane]);
                    }
                }
            }
        }
        let emission_xyz = [xyz[0] as f32, xyz[1] as f32, xyz[2] as f32, 0.0];
        let [refraction, absorption] = refraction;
        MaterialSpectrum { base, emission, emission_xyz, film, refraction, absorption }
    }

    /// The records of a scene's materials at the frame's node groups (one zero record for a scene without any: a storage
    /// binding cannot be empty).
    pub fn of_scene(
        colours: &[ConstantColour],
        films: &[[f32; 4]],
        refraction: &[[[f32; 4]; 2]],
        table: &CoeffTable,
        groups: &[WavelengthGroup],
    ) -> Vec<MaterialSpectrum> {
        let mut v: Vec<_> = colours
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let film = films.get(i).copied().unwrap_or([1.0, 0.0, 0.0, 0.04]);
                let refr = refraction.get(i).copied().unwrap_or([[1.5, 0.0, 0.0, 0.0], [0.0; 4]]);
                Self::new(c, film, refr, table, groups)
            })
            .collect();
        if v.is_empty() {
            v.push(MaterialSpectrum::default());
        }
        v
    }
}
