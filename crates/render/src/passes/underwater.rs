//! Real-time underwater light transport (Monzón, Gutierrez, Akkaynak & Muñoz 2024, plus
//! ray-marched single scattering) as a [`CustomShader`]:
//! `Renderer::set_custom_shader(underwater::shader(&medium))`.
//!
//! The hooks run in pass 2, per wavelength group, on the radiance the surface reflects from
//! the scene's lights (ρ·E·BRDF·cos), and return
//!
//! `L(λ) = L_surface·e^{−Kd·z_s}·e^{−c·d} + L_ms + L_ss`
//!
//! with d the camera–surface distance in metres (scene units × `scale`), z_s the surface depth,
//! z0 the camera depth and cosθ = −ω_y for the view direction ω. Background pixels get only the
//! in-scattering, up to the water surface when looking up and to infinity otherwise.
//!
//! - `L_ms = b/(4π)·[E0·e^{−Kd·z0}·I(c + Kd·cosθ) − Σ_j E_j·μ_j·e^{−c·z0/μ_j}·I(c·(1 − ω_y/μ_j))]`,
//!   `I(k) = (1 − e^{−k·d})/k`: the paper's isotropic in-scattering of the Kd-attenuated
//!   downwelling field E0 = Σ_j E_j·μ_j (directional lights j, μ_j the cosine of their direction
//!   to the downward vertical), minus the unscattered beams inside it, clamped at 0. With
//!   [`Options::steps`] = 0 the subtraction is off and `L_ss` = 0: exactly the paper's model.
//! - `L_ss`: single scattering of every directional, point and spot light (at most
//!   [`SS_LIGHTS`]: the brightest as seen from the camera, `uw_marched_lights`), Henyey–Greenstein phase [`Options::phase_g`], shadowed through the lights'
//!   shadow maps. Directional beams reach depth z as E_j·e^{−c·z/μ_j} (the unscattered beam);
//!   the ray is cut in M equal segments, visibility taken at each midpoint, the exponential
//!   integrated exactly within each segment (so an unshadowed ray is exact); a ray to infinity
//!   is marched over the first six optical depths of the clearest wavelength and integrated
//!   analytically (unshadowed) beyond. Point and spot lights use M equiangular steps (Kulla &
//!   Fajardo 2012), attenuated by c from the light and to the camera.
//!
//! `scene::water` (`in_scatter`, `single`) is the CPU reference of every term;
//! `tests/underwater.rs` checks the GPU against it (the hooks' pixel terms, single scattering,
//! the light-field table).
//!
//! Spectral and naive modes sample b, c and Kd at the frame's wavelengths (the renderer
//! resamples [`CustomShader::spectra`] whenever N or the range change). The RGB baseline uses
//! the coefficients at three wavelengths, [`RGB_WAVELENGTHS`], one per channel — what an
//! RGB renderer without spectral data does — and runs the same code.
//!
//! Assumptions (shared with the paper): the scene's directional lights are the light field
//! under the surface (already refracted); surfaces are lit by all lights attenuated by Kd over
//! their depth (a diver's torch is not attenuated by c on its way to the surface); the
//! diffuse part of the in-scattering is isotropic; nothing above the surface (sky, Snell's
//! window) is drawn.

use super::custom::CustomShader;
use scene::water::light_field::{self, LightFieldTable};
use scene::water::{WaterError, WaterMedium};

/// The WGSL hooks (after [`super::custom::MEDIUM_COMMON`], which they use).
pub const HOOKS: &str = include_str!("underwater.wgsl");

/// Wavelengths (nm) at which the RGB mode takes c, Kd and b for its R, G, B channels: the
/// dominant wavelengths of the sRGB primaries under D65.
pub const RGB_WAVELENGTHS: [f64; 3] = [611.0, 549.0, 464.0];

/// Lights that get single scattering (the brightest seen from the camera); `UW_SS_LIGHTS` in the
/// WGSL, checked by `layout_tests`.
pub const SS_LIGHTS: usize = 4;
/// Most march steps; `UW_MAX_STEPS` in the WGSL, checked by `layout_tests`.
pub const MAX_STEPS: u32 = 32;
/// Largest half-angle of the light-field model's forward cone (degrees).
pub const MAX_FORWARD_CONE_DEG: f32 = 45.0;
/// Most photons per node and source for the light-field table's solver.
pub const MAX_PHOTONS: usize = 10_000_000;

/// Choices of the real-time model beyond the water itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// March steps M for single scattering (≤ [`MAX_STEPS`]); 0 = the paper's model alone.
    pub steps: u32,
    /// Henyey–Greenstein asymmetry of the single scattering (default: Petzold's mean cosine,
    /// the ground truth's phase function).
    pub phase_g: f32,
    /// Scatter the diffuse field's scalar irradiance E_o = (Kd/a)·E_d (Gershun's law) instead
    /// of the paper's plane irradiance E_d. Off by default: against the path-traced water it
    /// overshoots in turbid water (docs/underwater.md).
    pub scalar_irradiance: bool,
    /// Remove the unscattered beams from the isotropic term (they are counted by single
    /// scattering with the real phase function) instead of adding single scattering on top of
    /// the paper's term.
    pub split_beams: bool,
    /// Draw the surface seen from below: the sky through Snell's window, Fresnel reflection and
    /// total internal reflection of what lies below. With the light-field model (default on)
    /// the reflection is the table's (`LightFieldTable::surface`: the water's light and the
    /// lit sea floor, not other objects); with the isotropic model (default off) it is the
    /// water's isotropic in-scattering alone, which is further from the path-traced water than
    /// not drawing it (docs/underwater.md).
    pub surface: bool,
    /// The in-scattering source from the water's own light field
    /// (`scene::water::light_field`, same a, b and phase function as the path-traced truth)
    /// instead of the paper's isotropic b·E0·e^{−Kd·z}/(4π), and the surface term attenuated
    /// by that field's downwelling irradiance instead of the tabulated Kd. Needs `steps > 0`:
    /// the table leaves the unscattered sun beam to the march.
    pub light_field: bool,
    /// With `light_field`, attenuate surfaces by the tabulated Kd anyway (the documented
    /// option; the default derives the attenuation from a, b and the phase function).
    pub tabulated_kd: bool,
    /// With `light_field`, light G-buffer surfaces with the column's diffuse irradiance for
    /// their normal (`LightFieldTable::irradiance`: the sky's and all scattered light, from
    /// every side) and the sun's unscattered beam, instead of the scene's lights attenuated by
    /// the downwelling E_d with the sky stand-in straight down (which leaves vertical and
    /// downward faces without the water's sideways and upwelling light).
    pub irradiance: bool,
    /// With `light_field`: half-angle (degrees) of the forward cone whose scattering the table
    /// leaves out of its source term and view rays treat as not scattering (attenuation
    /// c − f·b): objects seen through turbid water keep their image instead of washing out
    /// into the open water's light (`light_field::LightFieldKey::forward_cone`). 0 = off.
    pub forward_cone_deg: f32,
    /// Photons per wavelength node and source of the light-field solver.
    pub photons: usize,
    /// With `light_field`, close the column with the medium's sea floor
    /// ([`WaterMedium::floor`], found under the camera) so the light it reflects back into the
    /// water is in the table; off (or no floor found) = a bottomless column.
    pub sea_floor: bool,
}

/// Default forward cone of the light-field model (degrees). Light a view ray gathers from
/// within θc of its own direction comes, on average, from within θc/2 of where the ray looks
/// (the scattering point lies anywhere between camera and object), so it carries the image of
/// any object larger than ~θc on screen; with the truth's phase function (HG 0.924) a 15° cone
/// holds 74 % of the scattering. Why 15° rather than the 10° of session 8: against the truth,
/// 8×8 block means over six water types at 1 and 5 m, 10° 1.25, 15° 1.00, 20° 1.01 ΔE2000 mean
/// (`docs/underwater.md`, "Forward cone, session 10"); 15° is the middle of that flat optimum.
pub const FORWARD_CONE_DEG: f32 = 15.0;

/// Default photons of the light-field solver (per wavelength node and source).
pub const LIGHT_FIELD_PHOTONS: usize = 8000;

impl Default for Options {
    fn default() -> Self {
        Options {
            steps: 16,
            phase_g: PETZOLD_G,
            scalar_irradiance: false,
            split_beams: false,
            surface: true,
            light_field: true,
            tabulated_kd: false,
            irradiance: true,
            forward_cone_deg: FORWARD_CONE_DEG,
            photons: LIGHT_FIELD_PHOTONS,
            sea_floor: true,
        }
    }
}

impl Options {
    /// The CPU reference's view of the diffuse term (`scene::water::single::diffuse`).
    pub fn diffuse_model(&self) -> scene::water::single::DiffuseModel {
        // (the surface seen from below uses the same model for the water it reflects)
        scene::water::single::DiffuseModel {
            scalar_irradiance: self.scalar_irradiance,
            split_beams: self.split_beams && self.steps > 0,
        }
    }

    /// The paper's model: analytic isotropic in-scattering only.
    pub fn paper() -> Self {
        Options { steps: 0, light_field: false, surface: false, ..Default::default() }
    }

    /// The previous default: the paper's isotropic term plus the marched single scattering.
    pub fn isotropic() -> Self {
        Options { light_field: false, surface: false, ..Default::default() }
    }

    /// Checks the values a user can set.
    pub fn validate(&self) -> Result<(), OptionsError> {
        if self.steps > MAX_STEPS {
            return Err(OptionsError::Steps(self.steps));
        }
        if !(self.phase_g.is_finite() && self.phase_g.abs() < 1.0) {
            return Err(OptionsError::PhaseG(self.phase_g));
        }
        if self.light_field && self.steps == 0 {
            return Err(OptionsError::LightFieldNoMarch);
        }
        if self.light_field && (self.split_beams || self.scalar_irradiance) {
            return Err(OptionsError::NeedsIsotropic);
        }
        if !(self.forward_cone_deg.is_finite()
            && (0.0..=MAX_FORWARD_CONE_DEG).contains(&self.forward_cone_deg))
        {
            return Err(OptionsError::ForwardCone(self.forward_cone_deg));
        }
        if self.light_field && !(1..=MAX_PHOTONS).contains(&self.photons) {
            return Err(OptionsError::Photons(self.photons));
        }
        Ok(())
    }
}

/// An [`Options`] value the model cannot run with.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OptionsError {
    #[error("underwater march steps must be 0..={MAX_STEPS}, got {0}")]
    Steps(u32),
    #[error("phase function g must be in (−1, 1), got {0}")]
    PhaseG(f32),
    #[error(
        "the light-field model needs march steps ≥ 1 (the table leaves the sun's unscattered beam to the \
         march); use the paper's model for no march"
    )]
    LightFieldNoMarch,
    #[error(
        "split beams and scalar irradiance change the paper's isotropic term; they need the isotropic model \
         (--isotropic)"
    )]
    NeedsIsotropic,
    #[error("forward cone must be 0…45°, got {0}")]
    ForwardCone(f32),
    #[error("light-field photons must be 1..=10000000, got {0}")]
    Photons(usize),
}

pub use scene::water::PETZOLD_G;

/// The hooks' parameters, byte for byte `UwParams` in `underwater.wgsl` (the reflection test
/// `layout_tests` checks the offsets); the renderer hands them over as the custom shader's
/// sixteen floats.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct WaterParams {
    /// Camera depth z0 (m).
    pub depth: f32,
    /// Metres per scene unit.
    pub scale: f32,
    /// March steps M (0 = the paper's model alone), as a float.
    pub steps: f32,
    /// Henyey–Greenstein g.
    pub phase_g: f32,
    /// c at [`RGB_WAVELENGTHS`].
    pub c_rgb: [f32; 3],
    /// The smallest c over 360–830 nm.
    pub c_min: f32,
    /// Kd at [`RGB_WAVELENGTHS`].
    pub kd_rgb: [f32; 3],
    /// 1 = scalar irradiance by Gershun's law ([`Options::scalar_irradiance`]).
    pub gershun: f32,
    /// b at [`RGB_WAVELENGTHS`].
    pub b_rgb: [f32; 3],
    /// 1 = take the beams out of L_ms ([`Options::split_beams`]).
    pub split_beams: f32,
}

impl WaterParams {
    /// The parameters of `medium` with `options`.
    pub fn new(medium: &WaterMedium, options: &Options) -> Self {
        let at = |f: fn(&scene::water::WaterCoefficients) -> f64| {
            RGB_WAVELENGTHS.map(|l| f(&medium.coefficients(l)) as f32)
        };
        WaterParams {
            depth: medium.depth as f32,
            scale: medium.scale as f32,
            steps: options.steps.min(MAX_STEPS) as f32,
            phase_g: options.phase_g,
            c_rgb: at(|k| k.c),
            c_min: (360..=830).map(|l| medium.coefficients(l as f64).c).fold(f64::INFINITY, f64::min) as f32,
            kd_rgb: at(|k| k.kd),
            gershun: if options.scalar_irradiance { 1.0 } else { 0.0 },
            b_rgb: at(|k| k.b),
            split_beams: if options.split_beams { 1.0 } else { 0.0 },
        }
    }

    /// As the custom shader's parameters.
    pub fn to_array(self) -> [f32; 16] {
        bytemuck::cast(self)
    }
}

/// The custom-shader parameters for `medium` ([`WaterParams`] with the default [`Options`]).
/// Use with `Renderer::set_custom_params` to move the camera's depth without recompiling.
pub fn params(medium: &WaterMedium) -> [f32; 16] {
    params_with(medium, &Options::default())
}

/// [`params`] with explicit [`Options`].
pub fn params_with(medium: &WaterMedium, options: &Options) -> [f32; 16] {
    WaterParams::new(medium, options).to_array()
}

/// The spectra the hooks read: b, c, Kd.
pub fn spectra(medium: &WaterMedium) -> Vec<color::Spectrum> {
    let p = &medium.properties;
    vec![p.b.clone(), p.c.clone(), p.kd.clone()]
}

/// Deepest node of the light-field table for a camera at `depth` m: 20 m below the camera,
/// rounded up to 20 m so that nearby depths share a cached table. Deeper points use the last
/// segment's decay (`light_field::log_interp`).
pub fn light_field_range(depth: f64) -> f64 {
    20.0 * ((depth + 20.0) / 20.0).ceil()
}

/// The solver's input for `medium` (its refracted sun, its sky, its sea floor) with `options`.
/// With a floor the table ends at the floor's depth.
pub fn light_field_key(medium: &WaterMedium, options: &Options) -> light_field::LightFieldKey {
    let floor = medium.floor.as_ref().filter(|_| options.sea_floor).map(|f| {
        let albedo = (0..light_field::N_LAMBDA)
            .map(|l| f.albedo.eval(light_field::lambda_node(l).min(830.0)).clamp(0.0, 1.0))
            .collect();
        (medium.depth + f.below_camera, light_field::Floor { albedo })
    });
    light_field::LightFieldKey {
        properties: medium.properties.clone(),
        name: medium.water_type.map_or_else(|| "custom".to_string(), |t| t.to_string()),
        sun_mu: medium.sun_dir_underwater().y as f64,
        sky: medium.sky,
        z_max: floor.as_ref().map_or_else(|| light_field_range(medium.depth), |f| f.0.max(1e-3)),
        g: options.phase_g as f64,
        photons: options.photons,
        floor: floor.map(|f| f.1),
        forward_cone: if options.light_field { (options.forward_cone_deg as f64).to_radians() } else { 0.0 },
    }
}

/// The two tables the real-time pass reads: the column closed by the medium's sea floor, and
/// the bottomless column over the same depth range (for the parts of the view beyond the
/// floor's extent). Without a floor both are the same table.
pub fn light_field_tables(
    medium: &WaterMedium,
    options: &Options,
) -> Result<[std::sync::Arc<LightFieldTable>; 2], WaterError> {
    let key = light_field_key(medium, options);
    let main = light_field_table_for(key.clone())?;
    if key.floor.is_none() {
        return Ok([main.clone(), main]);
    }
    let deep = light_field_table_for(light_field::LightFieldKey { floor: None, ..key })?;
    Ok([main, deep])
}

/// The light-field table for `medium` (closed by its floor, if it has one and `options` wants
/// it): see [`light_field_table_for`].
pub fn light_field_table(
    medium: &WaterMedium,
    options: &Options,
) -> Result<std::sync::Arc<LightFieldTable>, WaterError> {
    light_field_table_for(light_field_key(medium, options))
}

/// The light-field table for `key`: from this process's memory, else the disk cache
/// (`$SPECTRA_CACHE_DIR`, as the upsampling tables), else solved (with a progress bar on a
/// terminal; a few seconds per water type and range) and cached.
pub fn light_field_table_for(
    key: light_field::LightFieldKey,
) -> Result<std::sync::Arc<LightFieldTable>, WaterError> {
    use std::sync::{Arc, Mutex, OnceLock};
    type Solved = Vec<(String, Arc<LightFieldTable>)>;
    static MEMORY: OnceLock<Mutex<Solved>> = OnceLock::new();
    key.validate()?;
    let name = key.cache_name();
    let memory = MEMORY.get_or_init(Default::default);
    if let Some((_, t)) = memory.lock().unwrap_or_else(|e| e.into_inner()).iter().find(|(n, _)| *n == name) {
        return Ok(t.clone());
    }
    let dir = color::upsample::cache::cache_dir().ok();
    let bar = indicatif::ProgressBar::new(2 * light_field::N_LAMBDA as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("light field {msg} [{bar:30}] {pos}/{len} ({elapsed})")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar.set_message(format!("{} (solving once, then cached)", key.name));
    let progress = |done: usize, _total: usize| bar.set_position(done as u64);
    let t =
        LightFieldTable::cached(&key, dir.as_deref(), &progress, &std::sync::atomic::AtomicBool::new(false));
    bar.finish_and_clear();
    let t = Arc::new(t?);
    memory.lock().unwrap_or_else(|e| e.into_inner()).push((name, t.clone()));
    Ok(t)
}

/// The tables as custom spectra (indices from 4, see `underwater.wgsl`): for the floored table
/// and then the bottomless one, J per cell, E_d per depth node and the surface's reflection of
/// the water and of the floor per view node, as piecewise-linear spectra over the table's
/// wavelength nodes (resampled by the renderer at the frame's wavelengths); then the same at
/// [`RGB_WAVELENGTHS`] as three constants each for the RGB hook.
fn table_spectra(tables: [&LightFieldTable; 2]) -> Vec<color::Spectrum> {
    use light_field::*;
    let lambda: Vec<f64> = (0..N_LAMBDA).map(lambda_node).collect();
    let (cells, views) = (N_DEPTH * N_ELEV * N_AZ, N_ELEV * N_AZ);
    let row = |v: &[f32]| color::Spectrum::Piecewise {
        lambda: lambda.clone(),
        values: v.iter().map(|&x| x as f64).collect(),
    };
    let rows =
        |v: &[f32], n: usize| (0..n).map(|c| row(&v[c * N_LAMBDA..(c + 1) * N_LAMBDA])).collect::<Vec<_>>();
    let mut out = Vec::new();
    for t in tables {
        out.extend(rows(&t.j, cells));
        out.extend(rows(&t.e_d, N_DEPTH));
        out.extend(rows(&t.surface, views));
        out.extend(rows(&t.surface_floor, views));
        out.extend(rows(&t.irradiance, N_DEPTH * N_NORMAL_ELEV * N_NORMAL_AZ));
    }
    for t in tables {
        let mut push = |f: &dyn Fn(f64) -> f64| {
            for l in RGB_WAVELENGTHS {
                out.push(color::Spectrum::Constant(f(l)));
            }
        };
        for c in 0..cells {
            let (d, rest) = (c / views, c % views);
            push(&|l| t.j_node(d, rest / N_AZ, rest % N_AZ, l));
        }
        for d in 0..N_DEPTH {
            push(&|l| t.e_d_node(d, l));
        }
        for floor in [false, true] {
            for v in 0..views {
                push(&|l| t.surface_node(v / N_AZ, v % N_AZ, l, floor));
            }
        }
        let normals = N_NORMAL_ELEV * N_NORMAL_AZ;
        for c in 0..N_DEPTH * normals {
            let (d, rest) = (c / normals, c % normals);
            push(&|l| t.irradiance_node(d, rest / N_NORMAL_AZ, rest % N_NORMAL_AZ, l));
        }
    }
    out
}

/// The underwater custom shader for `medium` with the default [`Options`].
pub fn shader(medium: &WaterMedium) -> Result<CustomShader, WaterError> {
    shader_with(medium, &Options::default())
}

/// The underwater custom shader for `medium`. Whether it marches is decided here, at compile
/// time (`options.steps > 0`); the step count itself, like the depth, is a parameter. The
/// light-field model solves (or loads) its table here; bad options or a bad sun are errors.
pub fn shader_with(medium: &WaterMedium, options: &Options) -> Result<CustomShader, WaterError> {
    use scene::water::{WATER_IOR, fresnel::mean_transmittance};
    options.validate().map_err(|e| WaterError::BadQuery(e.to_string()))?;
    let tables = if options.light_field { Some(light_field_tables(medium, options)?) } else { None };
    let source = format!("{}\n{HOOKS}", super::custom::MEDIUM_COMMON);
    // Values of the hooks' pipeline-overridable constants (`override UW_…` in underwater.wgsl).
    let mut constants: Vec<(String, f64)> = Vec::new();
    let mut set = |name: &str, value: f64| constants.push((name.to_string(), value));
    let flag = |on: bool| f64::from(u8::from(on));
    set("UW_MARCH", flag(options.steps > 0));
    set("UW_SURFACE", flag(options.surface));
    set("UW_N", WATER_IOR);
    set("UW_SKY_NORM", f64::from((1.0 / (std::f64::consts::PI * mean_transmittance(WATER_IOR))) as f32));
    set("UW_TABLE", flag(options.light_field));
    {
        use scene::water::light_field::{ELEV_WARP, N_AZ, N_DEPTH, N_ELEV, N_NORMAL_AZ, N_NORMAL_ELEV};
        set("UW_ND", N_DEPTH as f64);
        set("UW_NNE", N_NORMAL_ELEV as f64);
        set("UW_NNA", N_NORMAL_AZ as f64);
        set("UW_NE", N_ELEV as f64);
        set("UW_NA", N_AZ as f64);
        set("UW_ELEV_INV_WARP", f64::from((1.0 / ELEV_WARP) as f32));
    }
    set("UW_TABLE_KD", flag(options.light_field && !options.tabulated_kd));
    {
        // The forward-scattered fraction along view rays (light-field model only).
        let f = if options.light_field {
            let cone = (options.forward_cone_deg as f64).to_radians();
            scene::water::single::forward_fraction(options.phase_g as f64, cone)
        } else {
            0.0
        };
        set("UW_FWD", f64::from(f as f32));
    }
    set("UW_IRRADIANCE", flag(options.light_field && options.irradiance && !options.tabulated_kd));
    let mut spectra = spectra(medium);
    if let Some([t, deep]) = &tables {
        set("UW_ZMAX", f64::from(t.z_max as f32));
        // Where the mirrored view may show the floor: its mesh's extent (scene units).
        let b = medium.floor.as_ref().and_then(|f| f.extent).unwrap_or([-1e30, -1e30, 1e30, 1e30]);
        for (name, v) in
            ["UW_FLOOR_MIN_X", "UW_FLOOR_MIN_Z", "UW_FLOOR_MAX_X", "UW_FLOOR_MAX_Z"].iter().zip(b)
        {
            set(name, f64::from(v));
        }
        spectra.push(color::Spectrum::Constant(0.0));
        spectra.extend(table_spectra([t, deep]));
    }
    Ok(CustomShader { source, params: params_with(medium, options), spectra, constants })
}

#[cfg(test)]
mod tests {
    use super::*;
    use color::water::WaterType;
    use glam::Vec3;

    #[test]
    fn params_hold_depth_scale_and_rgb_coefficients() {
        let m = WaterMedium::new(WaterType::parse("II").unwrap(), 7.5, Vec3::Y, 0.5).unwrap();
        let p = params(&m);
        assert_eq!((p[0], p[1], p[2], p[3]), (7.5, 0.5, 16.0, PETZOLD_G));
        assert!(p[7] > 0.0 && p[7] <= p[6], "smallest c {} vs c(blue) {}", p[7], p[6]);
        let blue = m.coefficients(464.0);
        assert_eq!((p[6], p[10], p[14]), (blue.c as f32, blue.kd as f32, blue.b as f32));
        // Ocean water attenuates red more than blue, and its downwelling Kd by far (pure-water
        // absorption at 611 nm is ≈ 0.27 /m, in the blue ≈ 0.01 /m).
        assert!(p[4] > p[6] && p[8] > 3.0 * p[10], "{p:?}");
        let s = shader_with(&m, &Options::paper()).unwrap();
        assert_eq!(s.params[2], 0.0);
        let march = |s: &CustomShader| s.constants.iter().find(|(n, _)| n == "UW_MARCH").map(|c| c.1);
        assert_eq!(march(&s), Some(0.0), "the paper's model compiles without the march");
        assert_eq!(march(&shader_with(&m, &Options::isotropic()).unwrap()), Some(1.0));
        assert_eq!(s.spectra.len(), 3);
        assert_eq!(s.spectra[2].eval(500.0), m.coefficients(500.0).kd);
    }
}
