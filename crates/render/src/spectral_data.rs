//! Everything per-wavelength the GPU needs, computed once on the CPU whenever the wavelengths,
//! range, observer or mode change: wavelengths, integration weights, the white illuminant,
//! naive band masks, each light's emission spectrum and the XYZ → RGB matrix.
//!
//! These are small buffers (N ≤ 256 floats each), so changing N or the range at run time only
//! re-uploads them. The same numbers serve the CPU cross-checks in the tests.

use crate::error::Result;
use crate::settings::{Mode, RenderSettings};
use color::upsample::CoeffTable;
use color::{Observer, RgbColorSpace, SampledWavelengths, SpectralIntegrator, Spectrum, WavelengthRange};
use glam::{DMat3, DVec3};
use scene::Emission;

/// Four wavelengths and what the shader needs at them. Matches `WavelengthGroup` in
/// `wgsl/spectral.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct WavelengthGroup {
    pub lambda: [f32; 4],
    pub wx: [f32; 4],
    pub wy: [f32; 4],
    pub wz: [f32; 4],
    pub white: [f32; 4],
    pub band_r: [f32; 4],
    pub band_g: [f32; 4],
    pub band_b: [f32; 4],
}

/// The sampled wavelengths with their weights and the matching colour conversion.
#[derive(Clone, Debug)]
pub struct SpectralSetup {
    pub wavelengths: SampledWavelengths,
    /// Emission integrator: XYZ = Σ L(λᵢ)·wᵢ, scaled so that the white illuminant has Y = 1
    /// (over these samples; with jitter, over the dense integral of the render range).
    pub integrator: SpectralIntegrator,
    /// The white illuminant (the colour space's, D65 for sRGB), unnormalised.
    pub white: Spectrum,
    /// The white illuminant at each wavelength.
    pub white_samples: Vec<f64>,
    /// XYZ → linear RGB, including a diagonal correction (in XYZ) that maps the white
    /// illuminant integrated with these N samples exactly onto the colour space's white. With
    /// it, a white surface under a white light is (1, 1, 1) for every N; without it, small N
    /// tints everything by the quadrature error of the white. With jitter the correction uses
    /// the dense white instead, so it is the same for every frame (and only the average of
    /// frames is white).
    pub xyz_to_rgb: DMat3,
    pub space: RgbColorSpace,
    /// Dense (1 nm over the observer range) integrator for converting spectral lights to RGB.
    dense: SpectralIntegrator,
    /// With jitter: the dense (1 nm midpoint over the render range) emission integrator that
    /// every normalisation uses instead of the frame's own samples.
    norm: Option<SpectralIntegrator>,
}

impl SpectralSetup {
    pub fn new(settings: &RenderSettings) -> Result<Self> {
        let observer = Observer::by_name(&settings.observer)?;
        let space = RgbColorSpace::srgb();
        let white = space.illuminant();
        let (wavelengths, integrator, sampled_white, norm) = match settings.jitter {
            None => {
                let wavelengths = SampledWavelengths::midpoint(settings.range, settings.wavelengths)?;
                let integrator = SpectralIntegrator::emission(&observer, &white, &wavelengths);
                let sampled_white = integrator.integrate_samples(&white.sample(&wavelengths.lambda));
                (wavelengths, integrator, sampled_white, None)
            }
            Some(u) => {
                // Normalise with the dense integral over the render range, not these samples:
                // a ratio of two N-sample estimates is biased, so frame averages would not
                // converge (see `RenderSettings::jitter`).
                let n_dense = settings.range.width().round().max(1.0) as usize;
                let dense_wl = SampledWavelengths::midpoint(settings.range, n_dense)?;
                let norm = SpectralIntegrator::emission(&observer, &white, &dense_wl);
                let k: f64 = dense_wl
                    .lambda
                    .iter()
                    .zip(&dense_wl.weight)
                    .map(|(&l, &dl)| observer.eval(l)[1] * white.eval(l) * dl)
                    .sum();
                let k = if k > 0.0 { k } else { 1.0 };
                let wavelengths =
                    SampledWavelengths::stratified(settings.range, &vec![u as f64; settings.wavelengths])?;
                let weights = wavelengths
                    .lambda
                    .iter()
                    .zip(&wavelengths.weight)
                    .map(|(&l, &dl)| observer.eval(l).map(|c| c * dl / k))
                    .collect();
                let integrator = SpectralIntegrator { lambda: wavelengths.lambda.clone(), weights };
                let dense_white = norm.integrate(|l| white.eval(l));
                (wavelengths, integrator, dense_white, Some(norm))
            }
        };
        let white_samples = white.sample(&wavelengths.lambda);
        let target_white = space.white_xyz();
        let correction = DVec3::from_array(std::array::from_fn(|c| {
            if sampled_white[c] > 1e-12 { target_white[c] / sampled_white[c] } else { 1.0 }
        }));
        let xyz_to_rgb = space.from_xyz * DMat3::from_diagonal(correction);
        let dense_wl = SampledWavelengths::midpoint(WavelengthRange::FULL, 470)?;
        let dense = SpectralIntegrator::emission(&observer, &white, &dense_wl);
        Ok(SpectralSetup { wavelengths, integrator, white, white_samples, xyz_to_rgb, space, dense, norm })
    }

    pub fn len(&self) -> usize {
        self.wavelengths.len()
    }

    pub fn is_empty(&self) -> bool {
        self.wavelengths.is_empty()
    }

    /// Number of vec4 groups (N rounded up to a multiple of four, over four).
    pub fn groups(&self) -> usize {
        self.len().div_ceil(4)
    }

    /// Linear RGB of XYZ with this setup's matrix.
    pub fn to_rgb(&self, xyz: [f64; 3]) -> [f64; 3] {
        (self.xyz_to_rgb * DVec3::from_array(xyz)).to_array()
    }

    /// The GPU layout. Padding lanes repeat the last wavelength with zero weights, so they
    /// add nothing whatever the shader computes there.
    pub fn gpu_groups(&self) -> Vec<WavelengthGroup> {
        let n = self.len();
        let (blue_max, green_max) = naive_band_edges();
        let mut groups = vec![WavelengthGroup::default(); self.groups()];
        for i in 0..self.groups() * 4 {
            let (g, lane) = (i / 4, i % 4);
            let grp = &mut groups[g];
            let src = i.min(n - 1);
            let l = self.wavelengths.lambda[src];
            grp.lambda[lane] = l as f32;
            if i < n {
                let w = self.integrator.weights[i];
                grp.wx[lane] = w[0] as f32;
                grp.wy[lane] = w[1] as f32;
                grp.wz[lane] = w[2] as f32;
                grp.white[lane] = self.white_samples[i] as f32;
                let band = naive_band(l, blue_max, green_max);
                grp.band_r[lane] = (band == 0) as u8 as f32;
                grp.band_g[lane] = (band == 1) as u8 as f32;
                grp.band_b[lane] = (band == 2) as u8 as f32;
            }
        }
        groups
    }

    /// A light's emission at each wavelength for the spectral modes, in the units the RGB path
    /// uses (so that a white RGB light gives the same Y in every mode).
    ///
    /// - A spectral light keeps its shape and is scaled so that its Y over these samples (with
    ///   jitter: its dense Y over the render range) equals the luminance of `rgb × intensity`
    ///   (the scene format's convention).
    /// - An RGB light uses the "illuminant" upsampling: `s·ρ(rgb/s)(λ)·W(λ)` with `s = 2·max(rgb)`
    ///   and W the colour space's white (sigmoid ρ in `Spectral` mode, box ρ in `Naive`).
    pub fn light_samples(&self, e: &Emission, mode: Mode, table: &CoeffTable) -> Vec<f64> {
        let rgb = [e.rgb.x as f64, e.rgb.y as f64, e.rgb.z as f64].map(|c| c * e.intensity as f64);
        let lambda = &self.wavelengths.lambda;
        if let Some(s) = &e.spectrum {
            let samples = s.sample(lambda);
            let y = match &self.norm {
                None => self.integrator.integrate_samples(&samples)[1],
                Some(norm) => norm.integrate(|l| s.eval(l))[1],
            };
            let k = if y > 0.0 { self.luminance(rgb) / y } else { 0.0 };
            return samples.iter().map(|v| v * k).collect();
        }
        match mode {
            Mode::Naive => {
                let (blue_max, green_max) = naive_band_edges();
                lambda
                    .iter()
                    .zip(&self.white_samples)
                    .map(|(&l, w)| rgb[naive_band(l, blue_max, green_max)] * w)
                    .collect()
            }
            _ => {
                let (scale, poly) = illuminant_coeffs(rgb, table);
                lambda.iter().zip(&self.white_samples).map(|(&l, w)| scale * poly.eval(l) * w).collect()
            }
        }
    }

    /// A light's linear-sRGB emission for the RGB mode: its RGB, or for a spectral light the
    /// colour of its spectrum (integrated at 1 nm) at the luminance of `rgb × intensity`.
    pub fn light_rgb(&self, e: &Emission) -> [f64; 3] {
        let rgb = [e.rgb.x as f64, e.rgb.y as f64, e.rgb.z as f64].map(|c| c * e.intensity as f64);
        match &e.spectrum {
            None => rgb,
            Some(s) => {
                let xyz = self.dense.integrate(|l| s.eval(l));
                let k = if xyz[1] > 0.0 { self.luminance(rgb) / xyz[1] } else { 0.0 };
                self.space.xyz_to_rgb(xyz.map(|c| c * k))
            }
        }
    }

    /// Y of a linear RGB colour in the output colour space.
    pub fn luminance(&self, rgb: [f64; 3]) -> f64 {
        self.space.rgb_to_xyz(rgb)[1]
    }
}

/// pbrt-style "illuminant" upsampling of an emission colour: the coefficients of `rgb / s` and
/// the scale `s = 2·max(rgb)`, so that the sigmoid works in its comfortable middle range and
/// RGB (1, 1, 1) becomes exactly the white illuminant (ρ ≡ ½, times s = 2).
pub fn illuminant_coeffs(rgb: [f64; 3], table: &CoeffTable) -> (f64, color::upsample::SigmoidPolynomial) {
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m <= 0.0 {
        return (0.0, table.fetch([0.0; 3]));
    }
    let s = 2.0 * m;
    (s, table.fetch(rgb.map(|c| c.max(0.0) / s)))
}

/// Band edges (nm) of the naive box upsampling: below `blue_max` is blue, below `green_max`
/// green, the rest red.
pub fn naive_band_edges() -> (f64, f64) {
    (color::upsample::boxes::BOX_BLUE_GREEN_NM, color::upsample::boxes::BOX_GREEN_RED_NM)
}

/// 0 = red, 1 = green, 2 = blue: the channel whose band contains `lambda`.
fn naive_band(lambda: f64, blue_max: f64, green_max: f64) -> usize {
    if lambda < blue_max {
        2
    } else if lambda < green_max {
        1
    } else {
        0
    }
}
