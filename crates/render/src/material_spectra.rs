//! The Jakob–Hanika coefficients of the colours that are constant over a material
//! ([`ConstantColour`]), fetched once on the CPU when the scene's spectral data is built, so that
//! the spectral shading pass fetches per pixel only where a texture or vertex colours vary the
//! colour. The G-buffer writes each pixel's material slot (beside the normal, `gbuffer_slot` in
//! wgsl/common.wgsl); `material_spectra[slot − 1]` in shading.wgsl is the record below.

use crate::scene_gpu::{ConstantColour, MAX_LIGHTS};
use crate::spectral_data::{GroupWeights, WavelengthGroup};
use color::upsample::{CoeffTable, SigmoidPolynomial};

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
    /// With [`MEASURED_EMISSION`]: the measured spectrum's XYZ per unit luminance of the
    /// pixel's emissive colour and w the index of its node weights in `light_weights` (the
    /// spectral modes), or its linear RGB per unit luminance (the RGB mode).
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
    /// `KHR_materials_specular`'s F0 colour where it is constant ([`ConstantColour::specular`]):
    /// its coefficients, w = 1; zero where a texture varies it or the material has none.
    pub specular: [f32; 4],
    /// `KHR_materials_sheen`'s colour where it is constant ([`ConstantColour::sheen`]): its
    /// coefficients, w = 1; zero where a texture varies it or the material has none.
    pub sheen: [f32; 4],
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
            let poly = SigmoidPolynomial::new(c0, c1, c2);
            for g in groups {
                for lane in 0..4 {
                    let e = scale * poly.eval(f64::from(g.lambda[lane]));
                    for (c, w) in xyz.iter_mut().zip([g.white_x, g.white_y, g.white_z]) {
                        *c += e * f64::from(w[lane]);
                    }
                }
            }
        }
        let emission_xyz = [xyz[0] as f32, xyz[1] as f32, xyz[2] as f32, 0.0];
        let [refraction, absorption] = refraction;
        let known = |rgb: Option<[f32; 3]>| {
            rgb.map_or([0.0; 4], |rgb| {
                let [c0, c1, c2] = coeffs(rgb);
                [c0, c1, c2, 1.0]
            })
        };
        let (specular, sheen) = (known(c.specular), known(c.sheen));
        MaterialSpectrum { base, emission, emission_xyz, film, refraction, absorption, specular, sheen }
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

/// `MaterialSpectrum::emission` of a material that glows with a measured spectrum
/// (`emission_xyz` says how): w = −2, which the shader tells from a varying emission's −1; x
/// the luminance of a constant emission (−1 where it varies: the G-buffer's is used).
pub const MEASURED_EMISSION: [f32; 4] = [-1.0, 0.0, 0.0, -2.0];

/// Entries of [`reflected_xyz`] per material for `n_lights` lights: a column per light, three
/// to an entry, then one for the environment.
pub fn reflected_stride(n_lights: usize) -> usize {
    n_lights.min(MAX_LIGHTS).div_ceil(3) + 1
}

/// What a material of constant base colour reflects, integrated on the CPU once per frame
/// setting instead of per pixel and light: the XYZ Σᵢ ρ(λᵢ)·Wᵢ of its reflectance (the sigmoid
/// of `record.base`, at the frame's nodes) under each shaded light's node weights `lights[l]`,
/// and under each of the environment's basis spectra `basis[j]` (empty without one). The
/// shading pass's node loop computes exactly this sum for such a material, the same at every
/// pixel of it; summed here in f64, it costs a pixel one load per light, as the RGB mode's
/// light colour does.
///
/// Layout, `reflected_stride(lights.len())` [`GroupWeights`] per material record, appended to
/// the light weights (`light_weights[n_lights · n_groups + record · stride + k]` in
/// shading.wgsl): entry k < stride − 1 holds lights 3k, 3k + 1, 3k + 2 as its columns' XYZ
/// (w = 0); the last one holds the environment's basis j in lane j of column c = X, Y, Z. A
/// material whose base colour varies (`record.base[3] == 0`) has zeros: the shader fetches
/// and loops for it.
///
/// Where some record has a constant specular F0 colour (`record.specular[3] == 1`), the same
/// follows for that colour's reflectance, a second block of `records.len() · stride` entries
/// in the same layout (at `n_lights · n_groups + (records.len() + record) · stride + k`): a
/// tinted F0's part of the specular lobe is Σᵢ F0(λᵢ)·Wᵢ times a factor that does not depend on
/// λ. Where some record has a constant sheen colour (`record.sheen[3] == 1`), a third block
/// for it (after the second, which is then there even if zero): the sheen lobe is its colour
/// times a factor too. Scenes without either get neither block.
pub fn reflected_xyz(
    records: &[MaterialSpectrum],
    lights: &[Vec<[f64; 3]>],
    basis: &[Vec<[f64; 3]>],
    groups: &[WavelengthGroup],
) -> Vec<GroupWeights> {
    let lights = &lights[..lights.len().min(MAX_LIGHTS)];
    let stride = reflected_stride(lights.len());
    let block = |coeffs: &dyn Fn(&MaterialSpectrum) -> [f32; 4]| {
        let mut out = vec![[[0f32; 4]; 3]; records.len() * stride];
        for (m, rec) in records.iter().enumerate() {
            let [c0, c1, c2, known] = coeffs(rec).map(f64::from);
            if known == 0.0 {
                continue;
            }
            let poly = SigmoidPolynomial::new(c0, c1, c2);
            // At the f32 nodes the shader reads.
            let rho = |i: usize| poly.eval(f64::from(groups[i / 4].lambda[i % 4]));
            let integrate = |w: &[[f64; 3]]| {
                let mut xyz = [0f64; 3];
                for (i, wi) in w.iter().enumerate() {
                    let r = rho(i);
                    for c in 0..3 {
                        xyz[c] += r * wi[c];
                    }
                }
                xyz
            };
            let row = &mut out[m * stride..(m + 1) * stride];
            for (l, w) in lights.iter().enumerate() {
                let xyz = integrate(w);
                for c in 0..3 {
                    row[l / 3][l % 3][c] = xyz[c] as f32;
                }
            }
            for (j, w) in basis.iter().enumerate().take(4) {
                let xyz = integrate(w);
                for c in 0..3 {
                    row[stride - 1][c][j] = xyz[c] as f32;
                }
            }
        }
        out
    };
    let mut out = block(&|r| r.base);
    let sheen = records.iter().any(|r| r.sheen[3] != 0.0);
    if sheen || records.iter().any(|r| r.specular[3] != 0.0) {
        out.extend(block(&|r| r.specular));
    }
    if sheen {
        out.extend(block(&|r| r.sheen));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn groups(lambda: &[f32]) -> Vec<WavelengthGroup> {
        lambda
            .chunks(4)
            .map(|c| {
                let mut g = WavelengthGroup::default();
                g.lambda[..c.len()].copy_from_slice(c);
                g
            })
            .collect()
    }

    /// The entries hold Σᵢ ρ(λᵢ)·Wᵢ where the shader reads them: light l in column l % 3 of
    /// entry l / 3, basis j in lane j of the last; a varying colour's row is zero; lights past
    /// the shaded 32 have no column.
    #[test]
    fn reflected_xyz_sums_the_nodes_into_the_shaders_layout() {
        let lambda = [400.0, 450.0, 500.0, 550.0, 600.0, 650.0];
        let g = groups(&lambda);
        let grey = MaterialSpectrum { base: [0.0, 0.0, 0.0, 1.0], ..Default::default() };
        let ramp = MaterialSpectrum { base: [0.0, 0.01, -5.5, 1.0], ..Default::default() };
        let varying = MaterialSpectrum { base: [0.0, 0.01, -5.5, 0.0], ..Default::default() };
        let weights = |k: f64| -> Vec<[f64; 3]> {
            (0..lambda.len()).map(|i| [k + i as f64, 2.0 * k, 0.5 * i as f64]).collect()
        };
        let lights: Vec<_> = (0..40).map(|l| weights(l as f64)).collect();
        let basis: Vec<_> = (0..4).map(|j| weights(10.0 * j as f64 + 1.0)).collect();
        let out = reflected_xyz(&[grey, ramp, varying], &lights, &basis, &g);
        let stride = reflected_stride(40);
        assert_eq!(stride, 11 + 1);
        assert_eq!(out.len(), 3 * stride);
        let sig = |x: f64| 0.5 + 0.5 * x / (1.0 + x * x).sqrt();
        let expect = |rho: &dyn Fn(f64) -> f64, w: &[[f64; 3]]| -> [f64; 3] {
            let mut s = [0.0; 3];
            for (l, wi) in lambda.iter().zip(w) {
                for c in 0..3 {
                    s[c] += rho(f64::from(*l)) * wi[c];
                }
            }
            s
        };
        let close = |a: f32, b: f64| ((f64::from(a) - b) / b.abs().max(1e-6)).abs() < 1e-6;
        for (m, rho) in [(0usize, &(|_: f64| 0.5) as &dyn Fn(f64) -> f64), (1, &|l: f64| sig(0.01 * l - 5.5))]
        {
            let row = &out[m * stride..(m + 1) * stride];
            for l in [0usize, 2, 3, 31] {
                let e = expect(rho, &lights[l]);
                for c in 0..3 {
                    assert!(close(row[l / 3][l % 3][c], e[c]), "material {m}, light {l}, channel {c}");
                }
                assert_eq!(row[l / 3][l % 3][3], 0.0);
            }
            for j in 0..4 {
                let e = expect(rho, &basis[j]);
                for c in 0..3 {
                    assert!(close(row[stride - 1][c][j], e[c]), "material {m}, basis {j}, channel {c}");
                }
            }
        }
        assert!(out[2 * stride..].iter().all(|e| *e == [[0.0; 4]; 3]));
    }

    /// A constant specular F0 colour's sums follow every material's base colours' in the same
    /// layout, at its own record's row; none of it where no record has one.
    #[test]
    fn reflected_xyz_appends_the_specular_colours_block() {
        let lambda = [420.0, 480.0, 560.0, 610.0, 680.0];
        let g = groups(&lambda);
        let weights = |k: f64| -> Vec<[f64; 3]> {
            (0..lambda.len()).map(|i| [k + i as f64, 1.0 + k, 0.25 * i as f64]).collect()
        };
        let lights: Vec<_> = (0..4).map(|l| weights(l as f64)).collect();
        let basis: Vec<_> = (0..2).map(|j| weights(3.0 * j as f64 + 0.5)).collect();
        let plain = MaterialSpectrum { base: [0.0, 0.0, 0.0, 1.0], ..Default::default() };
        let tinted = MaterialSpectrum {
            base: [0.0, 0.0, 0.0, 1.0],
            specular: [0.0, 0.02, -9.0, 1.0],
            ..Default::default()
        };
        let stride = reflected_stride(4);
        assert_eq!(reflected_xyz(&[plain, plain], &lights, &basis, &g).len(), 2 * stride);
        let out = reflected_xyz(&[plain, tinted], &lights, &basis, &g);
        assert_eq!(out.len(), 4 * stride);
        // The base colours' block is the one without specular colours.
        assert_eq!(out[..2 * stride], reflected_xyz(&[plain, plain], &lights, &basis, &g)[..]);
        let sig = |x: f64| 0.5 + 0.5 * x / (1.0 + x * x).sqrt();
        let f0 = |l: f64| sig(0.02 * l - 9.0);
        let close = |a: f32, b: f64| ((f64::from(a) - b) / b.abs().max(1e-6)).abs() < 1e-6;
        let spec_row = &out[3 * stride..4 * stride];
        for (l, w) in lights.iter().enumerate() {
            for c in 0..3 {
                let e: f64 = lambda.iter().zip(w).map(|(x, wi)| f0(f64::from(*x)) * wi[c]).sum();
                assert!(close(spec_row[l / 3][l % 3][c], e), "light {l}, channel {c}");
            }
        }
        for (j, w) in basis.iter().enumerate() {
            for c in 0..3 {
                let e: f64 = lambda.iter().zip(w).map(|(x, wi)| f0(f64::from(*x)) * wi[c]).sum();
                assert!(close(spec_row[stride - 1][c][j], e), "basis {j}, channel {c}");
            }
        }
        // The material without one has none.
        assert!(out[2 * stride..3 * stride].iter().all(|e| *e == [[0.0; 4]; 3]));
        // A constant sheen colour's block comes third, after a specular block (zero here).
        let sheened = MaterialSpectrum {
            base: [0.0, 0.0, 0.0, 1.0],
            sheen: [0.0, 0.02, -9.0, 1.0],
            ..Default::default()
        };
        let out = reflected_xyz(&[plain, sheened], &lights, &basis, &g);
        assert_eq!(out.len(), 6 * stride);
        assert!(out[2 * stride..4 * stride].iter().all(|e| *e == [[0.0; 4]; 3]));
        assert_eq!(out[5 * stride..6 * stride], spec_row[..]);
    }
}
