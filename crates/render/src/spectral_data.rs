//! Everything per-wavelength the GPU needs, computed once on the CPU whenever the wavelengths,
//! range, observer, quadrature or mode change: the node wavelengths, each light's node weights,
//! the white's node weights, naive band masks and the XYZ → RGB matrix.
//!
//! The shader evaluates the reflectance ρ at N nodes and computes, per light l,
//! `XYZ = Σᵢ ρ(λᵢ)·W_{l,i}` where `W_{l,i}` (a vec3 per node) holds the light's emission, the
//! observer and the integration rule together ([`color::quadrature`]): point samples × Δλ for
//! the midpoint rule, or the light × observer integrated densely against the nodes' cardinal
//! functions for the prefiltered rule. The shader does not know which rule made the weights,
//! so both cost the same per node.
//!
//! These are small buffers (N ≤ 256 × 3 floats per light), so changing N or the range at run
//! time only re-uploads them. The same numbers serve the CPU cross-checks in the tests.

use crate::error::{RenderError, Result};
use crate::settings::{Mode, RenderSettings};
use color::quadrature::{Basis, NodeQuadrature, Nodes, Quadrature, sum_weights};
use color::upsample::CoeffTable;
use color::{Observer, RgbColorSpace, SampledWavelengths, SpectralIntegrator, Spectrum, WavelengthRange};
use glam::{DMat3, DVec3};
use scene::Emission;

/// The node count from which the prefiltered rule interpolates the node values with the
/// not-a-knot cubic spline instead of Catmull–Rom ([`node_quadrature`]).
pub const SPLINE_FROM: usize = 8;

/// The real-time renderer's node quadrature, which every weight of a frame comes from (and the
/// GPU tests' CPU references too). The prefiltered rule's interpolant of the node values is
/// Catmull–Rom below [`SPLINE_FROM`] nodes and the global not-a-knot spline from there on:
/// over random upsampled colours the spline's mean error is lower at every N ≥ 8 under a
/// spiky, a peaked and a smooth light (`quadrature_study`; docs/quadrature.md), while at
/// N = 4–6 it rings (max 36 ΔE2000 at N = 4). The choice lives here, not in
/// [`color::quadrature`], because only the real-time renderer integrates at nodes: the path
/// tracer samples wavelengths continuously, and its code hash (the truth cache's key) does not
/// depend on this.
pub fn node_quadrature(rule: Quadrature, nodes: Nodes, observer: &Observer) -> NodeQuadrature {
    let basis = if nodes.len() >= SPLINE_FROM { Basis::Spline } else { Basis::CatmullRom };
    NodeQuadrature::with_basis(rule, nodes, observer, basis)
}

/// Four node wavelengths and what the shader needs at them. `WavelengthGroup` in
/// `wgsl/spectral.wgsl` (checked by `layout_tests`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct WavelengthGroup {
    pub lambda: [f32; 4],
    /// The white illuminant's node weights for X, Y and Z (what an emissive surface of node
    /// reflectance ρ is multiplied by: emission uses the "illuminant" upsampling ρ·W(λ)).
    pub white_x: [f32; 4],
    pub white_y: [f32; 4],
    pub white_z: [f32; 4],
    pub band_r: [f32; 4],
    pub band_g: [f32; 4],
    pub band_b: [f32; 4],
    pub _pad: [f32; 4],
    /// The white's node weights split by the naive bands (red, green, blue): column c of
    /// band b's matrix holds channel c's weights of `W(λ)·1_b(λ)`, so that a box spectrum
    /// (an absorption upsampled per channel) times a smooth one integrates exactly, steps
    /// included, instead of being sampled at the nodes. `Σ_b band_white[b]` = the white's
    /// weights. (`band_white_r`, `_g`, `_b`.)
    pub band_white_r: GroupWeights,
    pub band_white_g: GroupWeights,
    pub band_white_b: GroupWeights,
}

/// One light's node weights for four nodes: column c holds channel c (X, Y, Z). Matches the
/// `mat3x4<f32>` elements of `light_weights` in `wgsl/spectral.wgsl`.
pub type GroupWeights = [[f32; 4]; 3];

/// The node wavelengths with the quadrature that goes with them and the matching colour
/// conversion.
#[derive(Clone, Debug)]
pub struct SpectralSetup {
    pub wavelengths: SampledWavelengths,
    pub quadrature: Quadrature,
    /// The point-sampled observer at the nodes, `x̄(λᵢ)·Δλ / k` (k = the white's Y): the
    /// midpoint rule's weights for a light of radiance 1. Kept for per-wavelength tests; the
    /// renderer uploads [`Self::light_weights`].
    pub integrator: SpectralIntegrator,
    /// RGB white's emission: the colour space's illuminant (D65 for sRGB) at the luminance of
    /// the scene white ([`color::RgbColorSpace::emission_white`]), unnormalised.
    pub white: Spectrum,
    /// The white illuminant at each node.
    pub white_samples: Vec<f64>,
    /// XYZ → linear RGB, including a diagonal correction (in XYZ) that maps the white
    /// illuminant, integrated by this quadrature over the render range, exactly onto the colour
    /// space's white. With it, a white surface under a white light is (1, 1, 1) for every N;
    /// without it, small N tints everything by the quadrature error of the white (midpoint) or
    /// by the part of the white outside the range (both). With jitter the correction uses the
    /// dense white instead, so it is the same for every frame (and only the average of frames
    /// is white). That is for a CIE observer; any other is balanced by this quadrature's
    /// response to the white and shown as `RenderSettings::camera_view` asks. Both are
    /// [`color::film::to_linear_srgb`]'s, which the path tracer calls with its own integral.
    pub xyz_to_rgb: DMat3,
    pub space: RgbColorSpace,
    quad: NodeQuadrature,
    /// The spectral capture's frame ([`Self::for_capture`]): its weights in place of `quad`'s,
    /// normalised as the frame's (by `k`; lights scaled by `lum_quad`), so that the scene's
    /// radiance is the frame's.
    capture: Option<CaptureWeights>,
    /// The white's Y as every normalisation sees it: this quadrature's, or with jitter the
    /// dense integral's over the render range.
    k: f64,
    /// Dense (1 nm over the observer range) integrator for converting spectral lights to RGB.
    dense: SpectralIntegrator,
    /// Luminance (CIE 1931 Y, whatever the frame's observer), as a spectral light's scale
    /// sees it: on the frame's nodes and rule, over `k_lum` (the white's), or with jitter the
    /// dense integral over the render range, normalised alike (`lum_norm`).
    lum_quad: NodeQuadrature,
    k_lum: f64,
    lum_norm: Option<SpectralIntegrator>,
}

impl SpectralSetup {
    pub fn new(settings: &RenderSettings) -> Result<Self> {
        let observer = Observer::by_name(&settings.observer)?;
        let space = RgbColorSpace::srgb();
        let scene_white = color::illuminant::by_name(&settings.white)?;
        let offset = settings.jitter.map_or(0.5, f64::from);
        let nodes = Nodes::new(settings.range, settings.wavelengths, offset)?;
        let quad = node_quadrature(settings.quadrature, nodes, &observer);
        let wavelengths = SampledWavelengths {
            lambda: quad.nodes.lambda.clone(),
            weight: vec![quad.nodes.spacing; quad.len()],
        };
        // With jitter, normalise with the dense integral over the render range, not these
        // nodes: a ratio of two N-node estimates is biased, so frame averages would not
        // converge (see `RenderSettings::jitter`).
        let dense_over_range = |observer: &Observer| -> Result<Option<SpectralIntegrator>> {
            if settings.jitter.is_none() {
                return Ok(None);
            }
            let n_dense = settings.range.width().round().max(1.0) as usize;
            let dense_wl = SampledWavelengths::midpoint(settings.range, n_dense)?;
            Ok(Some(SpectralIntegrator {
                lambda: dense_wl.lambda.clone(),
                weights: dense_wl
                    .lambda
                    .iter()
                    .zip(&dense_wl.weight)
                    .map(|(&l, &dl)| observer.eval(l).map(|c| c * dl))
                    .collect(),
            }))
        };
        let raw = dense_over_range(&observer)?;
        let integrate = |s: &Spectrum| match &raw {
            None => quad.total(|l| s.eval(l)),
            Some(raw) => raw.integrate(|l| s.eval(l)),
        };
        // Luminance is CIE 1931's Y whatever the frame's observer (the scene format's convention,
        // and the path tracer's, `truth::lights`): measured with the frame's nodes and rule (or
        // with jitter the dense integral), so that for a CIE 1931 frame it is that frame's Y.
        let cie = Observer::cie1931();
        let is_cie = observer == cie;
        let lum_quad = if is_cie {
            quad.clone()
        } else {
            node_quadrature(settings.quadrature, quad.nodes.clone(), &cie)
        };
        let lum_raw = dense_over_range(&cie)?;
        let luminance = |s: &Spectrum| match &lum_raw {
            None => lum_quad.total(|l| s.eval(l))[1],
            Some(r) => r.integrate(|l| s.eval(l))[1],
        };
        // RGB white as the scene white has it: the colour space's illuminant at the scene
        // white's luminance, so the normalisation below is the scene white's (as in truth).
        let white = space.emission_white(&scene_white, luminance);
        let white_y = luminance(&white);
        let k_lum = if white_y > 0.0 { white_y } else { 1.0 };
        let lum_norm = lum_raw.map(|raw| SpectralIntegrator {
            weights: raw.weights.iter().map(|w| w.map(|c| c / k_lum)).collect(),
            ..raw
        });
        let sampled_white = integrate(&white);
        let k = if sampled_white[1] > 0.0 { sampled_white[1] } else { 1.0 };
        let sampled_white = sampled_white.map(|c| c / k);
        let weights = wavelengths
            .lambda
            .iter()
            .zip(&wavelengths.weight)
            .map(|(&l, &dl)| observer.eval(l).map(|c| c * dl / k))
            .collect();
        let integrator = SpectralIntegrator { lambda: wavelengths.lambda.clone(), weights };
        let white_samples = white.sample(&wavelengths.lambda);
        // This quadrature's own value of the white is what the display balances to (a diagonal
        // in XYZ for a CIE observer, von Kries for any other), so the white is (1, 1, 1) at every
        // N and range, as in the path tracer, which balances to its own integral alike.
        let xyz_to_rgb = color::film::to_linear_srgb(&observer, sampled_white, &white, settings.camera_view)?;
        let dense_wl = SampledWavelengths::midpoint(WavelengthRange::FULL, 470)?;
        // A measured light's colour in the RGB mode: its chromaticity, a CIE 1931 quantity.
        let dense = SpectralIntegrator::emission(&cie, &white, &dense_wl);
        Ok(SpectralSetup {
            wavelengths,
            quadrature: settings.quadrature,
            integrator,
            white,
            white_samples,
            xyz_to_rgb,
            space,
            quad,
            capture: None,
            k,
            dense,
            lum_quad,
            k_lum,
            lum_norm,
        })
    }

    pub fn len(&self) -> usize {
        self.wavelengths.len()
    }

    pub fn is_empty(&self) -> bool {
        self.wavelengths.is_empty()
    }

    /// The setup of the spectral capture's frame (`Renderer::set_spectral_capture`): `new`'s,
    /// its node weights those of a flat observer (1 at every wavelength, in all three
    /// channels), so that the weighted form of a node carries the radiance alone and the
    /// capture is the same whatever the frame's observer; what the weights are normalised by
    /// stays the frame's. With the midpoint rule a light's weight at node k is its emission
    /// there times Δλ; with the prefiltered rule its integral over the node's bin (the N equal
    /// bins around the nodes), so that a node's value is the mean over the bin of what the
    /// lights send, times the surface's factors at the node (its reflectance, the hooks'
    /// transmittances) — the path tracer's band means (`truth --spectral-out`) where those
    /// factors are smooth across the bin.
    pub fn for_capture(settings: &RenderSettings) -> Result<Self> {
        let mut s = Self::new(settings)?;
        let nodes = &s.quad.nodes;
        s.capture = Some(match settings.quadrature {
            Quadrature::Midpoint => {
                CaptureWeights::Points { lambda: nodes.lambda.clone(), spacing: nodes.spacing }
            }
            Quadrature::Prefiltered => {
                let (grid, d) = nodes.dense_grid();
                let n = nodes.len();
                let bin = grid
                    .iter()
                    .map(|&l| (((l - nodes.range.min) / nodes.spacing).floor().max(0.0) as usize).min(n - 1))
                    .collect();
                CaptureWeights::Bins { grid, d, bin, n }
            }
        });
        Ok(s)
    }

    /// Number of vec4 groups (N rounded up to a multiple of four, over four).
    pub fn groups(&self) -> usize {
        self.len().div_ceil(4)
    }

    /// Linear RGB of XYZ with this setup's matrix.
    pub fn to_rgb(&self, xyz: [f64; 3]) -> [f64; 3] {
        (self.xyz_to_rgb * DVec3::from_array(xyz)).to_array()
    }

    /// Normalised node weights of an emission spectrum: `XYZ = Σᵢ ρᵢ·Wᵢ` in the units where
    /// the white illuminant has Y = 1.
    pub fn weights_of(&self, emission: impl Fn(f64) -> f64) -> Vec<[f64; 3]> {
        let k = self.k;
        let w = match &self.capture {
            None => self.quad.weights(emission),
            Some(c) => c.weights(emission),
        };
        w.into_iter().map(|w| w.map(|c| c / k)).collect()
    }

    /// [`Self::weights_of`] by the display's rule even in a capture's setup: what the frame's
    /// colours (not the capture's nodes) are integrated with.
    pub fn display_weights_of(&self, emission: impl Fn(f64) -> f64) -> Vec<[f64; 3]> {
        let k = self.k;
        self.quad.weights(emission).into_iter().map(|w| w.map(|c| c / k)).collect()
    }

    /// The white illuminant's normalised node weights (for emissive surfaces).
    pub fn white_weights(&self) -> Vec<[f64; 3]> {
        self.weights_of(|l| self.white.eval(l))
    }

    /// The GPU layout. Padding lanes repeat the last wavelength with zero weights, so they
    /// add nothing whatever the shader computes there.
    pub fn gpu_groups(&self) -> Vec<WavelengthGroup> {
        let n = self.len();
        let (blue_max, green_max) = naive_band_edges();
        let white = self.white_weights();
        let band_white: Vec<Vec<[f64; 3]>> = (0..3)
            .map(|b| {
                self.weights_of(|l| {
                    if naive_band(l, blue_max, green_max) == b { self.white.eval(l) } else { 0.0 }
                })
            })
            .collect();
        let mut groups = vec![WavelengthGroup::default(); self.groups()];
        let last = self.wavelengths.lambda[n - 1];
        for (i, grp_lane) in (0..self.groups() * 4).map(|i| (i, (i / 4, i % 4))) {
            let (g, lane) = grp_lane;
            let grp = &mut groups[g];
            let l = self.wavelengths.lambda.get(i).copied().unwrap_or(last);
            grp.lambda[lane] = l as f32;
            if let Some(w) = white.get(i) {
                grp.white_x[lane] = w[0] as f32;
                grp.white_y[lane] = w[1] as f32;
                grp.white_z[lane] = w[2] as f32;
                let band = naive_band(l, blue_max, green_max);
                grp.band_r[lane] = (band == 0) as u8 as f32;
                grp.band_g[lane] = (band == 1) as u8 as f32;
                grp.band_b[lane] = (band == 2) as u8 as f32;
                for (m, bw) in [&mut grp.band_white_r, &mut grp.band_white_g, &mut grp.band_white_b]
                    .into_iter()
                    .zip(&band_white)
                {
                    for c in 0..3 {
                        m[c][lane] = bw[i][c] as f32;
                    }
                }
            }
        }
        groups
    }

    /// A light's emission as a function of wavelength for the spectral modes, in the units the
    /// RGB path uses (so that a white RGB light gives the same Y in every mode).
    ///
    /// - A spectral light keeps its shape and is scaled so that its Y under this quadrature
    ///   (with jitter: its dense Y over the render range) equals the luminance of
    ///   `rgb × intensity` (the scene format's convention).
    /// - An RGB light uses the "illuminant" upsampling: `s·ρ(rgb/s)(λ)·W(λ)` with `s = 2·max(rgb)`
    ///   and W the colour space's white (sigmoid ρ in `Spectral` mode, box ρ in `Naive`).
    pub fn light_spectrum<'a>(
        &'a self,
        e: &'a Emission,
        mode: Mode,
        table: &CoeffTable,
    ) -> Result<Box<dyn Fn(f64) -> f64 + 'a>> {
        let rgb = [e.rgb.x as f64, e.rgb.y as f64, e.rgb.z as f64].map(|c| c * e.intensity as f64);
        if let Some(s) = &e.spectrum {
            let y = match &self.lum_norm {
                None => self.lum_quad.total(|l| s.eval(l))[1] / self.k_lum,
                Some(norm) => norm.integrate(|l| s.eval(l))[1],
            };
            let want = self.luminance(rgb);
            let r = self.quad.nodes.range;
            let k =
                scene::emission::range_scale(y, want, want, (r.min, r.max)).map_err(RenderError::Settings)?;
            return Ok(Box::new(move |l| s.eval(l) * k));
        }
        let white = &self.white;
        match mode {
            Mode::Naive => {
                let (blue_max, green_max) = naive_band_edges();
                Ok(Box::new(move |l| rgb[naive_band(l, blue_max, green_max)] * white.eval(l)))
            }
            _ => {
                let (scale, poly) = illuminant_coeffs(rgb, table);
                Ok(Box::new(move |l| scale * poly.eval(l) * white.eval(l)))
            }
        }
    }

    /// A light's emission at each node (see [`Self::light_spectrum`]).
    pub fn light_samples(&self, e: &Emission, mode: Mode, table: &CoeffTable) -> Result<Vec<f64>> {
        let f = self.light_spectrum(e, mode, table)?;
        Ok(self.wavelengths.lambda.iter().map(|&l| f(l)).collect())
    }

    /// A light's normalised node weights (see [`Self::weights_of`]).
    pub fn light_weights(&self, e: &Emission, mode: Mode, table: &CoeffTable) -> Result<Vec<[f64; 3]>> {
        Ok(self.weights_of(self.light_spectrum(e, mode, table)?))
    }

    /// The GPU layout of node weights: one [`GroupWeights`] per group, padding lanes zero.
    pub fn gpu_weights(&self, weights: &[[f64; 3]]) -> Vec<GroupWeights> {
        let mut out = vec![[[0f32; 4]; 3]; self.groups()];
        for (i, w) in weights.iter().enumerate() {
            for c in 0..3 {
                out[i / 4][c][i % 4] = w[c] as f32;
            }
        }
        out
    }

    /// XYZ of a light seen by a reflectance of one (Σᵢ Wᵢ): what its ρ-independent terms
    /// (specular reflection) integrate to.
    pub fn light_total(weights: &[[f64; 3]]) -> [f64; 3] {
        sum_weights(weights)
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
        self.space.luminance(rgb)
    }
}

/// The spectral capture's node weights ([`SpectralSetup::for_capture`]): the same in all three
/// channels (a flat observer), unnormalised.
#[derive(Clone, Debug)]
enum CaptureWeights {
    /// The emission at each node times the node spacing.
    Points { lambda: Vec<f64>, spacing: f64 },
    /// The emission integrated over each node's bin: `grid` the dense midpoint grid of step `d`
    /// over the range, `bin[i]` the bin of its sample i.
    Bins { grid: Vec<f64>, d: f64, bin: Vec<usize>, n: usize },
}

impl CaptureWeights {
    fn weights(&self, emission: impl Fn(f64) -> f64) -> Vec<[f64; 3]> {
        match self {
            CaptureWeights::Points { lambda, spacing } => {
                lambda.iter().map(|&l| [emission(l) * spacing; 3]).collect()
            }
            CaptureWeights::Bins { grid, d, bin, n } => {
                let mut w = vec![[0.0; 3]; *n];
                for (&l, &b) in grid.iter().zip(bin) {
                    let e = emission(l) * d;
                    w[b] = w[b].map(|c| c + e);
                }
                w
            }
        }
    }
}

/// pbrt-style "illuminant" upsampling of an emission colour: the coefficients of `rgb / s` and
/// the scale `s = 2·max(rgb)` ([`color::upsample::variants::unbounded_split`]), so that RGB
/// (1, 1, 1) becomes exactly the white illuminant (ρ ≡ ½, times s = 2).
pub fn illuminant_coeffs(rgb: [f64; 3], table: &CoeffTable) -> (f64, color::upsample::SigmoidPolynomial) {
    let u = color::upsample::variants::UnboundedSpectrum::clamped(table, rgb);
    (u.scale, u.poly)
}

/// Band edges (nm) of the naive box upsampling: below `blue_max` is blue, below `green_max`
/// green, the rest red.
pub fn naive_band_edges() -> (f64, f64) {
    (color::upsample::boxes::BOX_BLUE_GREEN_NM, color::upsample::boxes::BOX_GREEN_RED_NM)
}

/// 0 = red, 1 = green, 2 = blue: the channel whose band contains `lambda`.
pub fn naive_band(lambda: f64, blue_max: f64, green_max: f64) -> usize {
    if lambda < blue_max {
        2
    } else if lambda < green_max {
        1
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use color::quadrature::dense_integral;
    use glam::Vec3;

    fn table() -> std::sync::Arc<CoeffTable> {
        color::upsample::table("srgb").expect("the sRGB table")
    }

    #[test]
    fn a_light_outside_the_range_is_an_error_naming_the_range() {
        let setup = SpectralSetup::new(&RenderSettings::default()).unwrap();
        let ir = Spectrum::piecewise(vec![790.0, 800.0, 810.0], vec![0.0, 1.0, 0.0]).unwrap();
        let e = Emission { rgb: Vec3::ONE, intensity: 2.0, spectrum: Some(ir) };
        let err = setup.light_weights(&e, Mode::Spectral, &table()).unwrap_err().to_string();
        assert!(err.contains("380–730"), "{err}");
        // A dark light with the same spectrum is not an error: there is nothing to scale.
        let dark = Emission { intensity: 0.0, ..e };
        assert!(setup.light_weights(&dark, Mode::Spectral, &table()).is_ok());
    }

    /// Why the renderer's rule switches basis at `SPLINE_FROM`: over random upsampled colours
    /// (not the evaluation's scenes), under a line spectrum and a smooth light, its mean ΔE2000
    /// against the dense integral is at least 5 % below Catmull–Rom's from 8 nodes on (10 % at
    /// N = 8 under F11, 1.4–5× from N = 12); below 8 it is Catmull–Rom, whose spline rival
    /// rings there.
    #[test]
    fn the_renderers_basis_beats_catmull_rom_from_eight_nodes_and_is_it_below() {
        use color::quadrature::integrate_nodes;
        use color::{ciede2000, xyz_to_lab};
        let table = table();
        let obs = Observer::cie1931();
        let range = WavelengthRange::VISIBLE;
        let polys: Vec<_> =
            color::upsample::roundtrip::random_colours(400, 3).iter().map(|&c| table.fetch(c)).collect();
        for light in ["F11", "D65"] {
            let e = color::illuminant::by_name(light).unwrap();
            let white = dense_integral(range, &obs, |l| e.eval(l));
            let truth: Vec<[f64; 3]> = polys
                .iter()
                .map(|p| xyz_to_lab(dense_integral(range, &obs, |l| p.eval(l) * e.eval(l)), white))
                .collect();
            let mean_error = |q: &NodeQuadrature| {
                let w = q.weights(|l| e.eval(l));
                let white = sum_weights(&w);
                let sum: f64 = polys
                    .iter()
                    .zip(&truth)
                    .map(|(p, t)| {
                        let v: Vec<f64> = q.nodes.lambda.iter().map(|&l| p.eval(l)).collect();
                        ciede2000(xyz_to_lab(integrate_nodes(&w, &v), white), *t)
                    })
                    .sum();
                sum / polys.len() as f64
            };
            for n in [4, 6, 8, 12, 16, 24] {
                let nodes = || Nodes::new(range, n, 0.5).unwrap();
                let ours = mean_error(&node_quadrature(Quadrature::Prefiltered, nodes(), &obs));
                let cr = mean_error(&NodeQuadrature::with_basis(
                    Quadrature::Prefiltered,
                    nodes(),
                    &obs,
                    Basis::CatmullRom,
                ));
                eprintln!("{light} N = {n}: renderer {ours:.4}, Catmull–Rom {cr:.4}");
                if n < SPLINE_FROM {
                    assert_eq!(ours, cr, "{light} N = {n}");
                } else {
                    assert!(ours < 0.95 * cr, "{light} N = {n}: renderer {ours} vs Catmull–Rom {cr}");
                }
            }
        }
    }

    #[test]
    fn prefiltered_light_weights_carry_the_dense_integral_at_every_n() {
        let f11 = color::illuminant::by_name("F11").unwrap();
        let e = Emission { rgb: Vec3::ONE, intensity: 1.0, spectrum: Some(f11.clone()) };
        let obs = color::Observer::cie1931();
        let dense = dense_integral(WavelengthRange::VISIBLE, &obs, |l| f11.eval(l));
        for n in [1, 3, 4, 8, 16, 17, 64] {
            let s = RenderSettings { wavelengths: n, ..Default::default() };
            let setup = SpectralSetup::new(&s).unwrap();
            let total =
                SpectralSetup::light_total(&setup.light_weights(&e, Mode::Spectral, &table()).unwrap());
            // Y is the light's luminance (1); X/Y and Z/Y are the dense integral's.
            assert!((total[1] - 1.0).abs() < 1e-9, "N={n}: Y {}", total[1]);
            for c in [0, 2] {
                let want = dense[c] / dense[1];
                assert!((total[c] - want).abs() < 1e-6 * want, "N={n} channel {c}: {} vs {want}", total[c]);
            }
            let groups = setup.gpu_weights(&setup.light_weights(&e, Mode::Spectral, &table()).unwrap());
            assert_eq!(groups.len(), n.div_ceil(4));
        }
    }

    /// A measured light is scaled to its CIE 1931 luminance relative to the white's whatever
    /// the frame's observer, as the path tracer scales it (`truth::lights`): it was scaled by
    /// the observer's second channel, so that under a camera or CIE 1964 the two renderers lit
    /// the scene differently (metamerism with a Nikon D5100 against truth: mean ΔE2000 5.0,
    /// after 2.5; docs/observers.md).
    #[test]
    fn a_measured_light_has_its_cie_1931_luminance_under_every_observer() {
        let f11 = color::illuminant::by_name("F11").unwrap();
        let e = Emission { rgb: Vec3::new(0.8, 0.6, 0.3), intensity: 2.0, spectrum: Some(f11.clone()) };
        let cie = color::Observer::cie1931();
        let want = RgbColorSpace::srgb().luminance([1.6, 1.2, 0.6]);
        for quadrature in [Quadrature::Prefiltered, Quadrature::Midpoint] {
            let mut reference = None;
            for observer in ["cie1931", "cie1964", "nikon_d5100", "dog"] {
                let s = RenderSettings {
                    observer: observer.into(),
                    quadrature,
                    white: "A".into(),
                    ..Default::default()
                };
                let setup = SpectralSetup::new(&s).unwrap();
                let light = setup.light_spectrum(&e, Mode::Spectral, &table()).unwrap();
                let y = |f: &dyn Fn(f64) -> f64| dense_integral(s.range, &cie, f)[1];
                let ratio = y(&|l| light(l)) / y(&|l| setup.white.eval(l));
                eprintln!(
                    "{observer} {quadrature:?}: the light's Y / the white's {ratio:.6}, rgb's luminance {want:.6}"
                );
                // The prefiltered rule integrates densely: the luminance exactly. The midpoint
                // rule measures on the nodes (F11's lines: 40 % off at N = 16), as a CIE 1931
                // frame with these nodes does: the same for every observer.
                if quadrature == Quadrature::Prefiltered {
                    assert!((ratio / want - 1.0).abs() < 1e-6, "{observer}: {ratio} vs {want}");
                }
                let r = *reference.get_or_insert(ratio);
                assert!(
                    (ratio / r - 1.0).abs() < 1e-12,
                    "{observer} {quadrature:?}: {ratio} vs CIE 1931's {r}"
                );
            }
        }
    }
}
