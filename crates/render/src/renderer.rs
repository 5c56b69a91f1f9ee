//! The long-lived renderer: owns the device, pipelines, the uploaded scene and the targets;
//! [`Renderer::render`] draws one frame with the [`RenderSettings`] given for that frame.

use crate::coeff_table::GpuCoeffTable;
use crate::env_gpu::{EnvUniforms, GpuEnvironment};
use crate::error::{RenderError, Result};
use crate::gpu::Gpu;
use crate::material_spectra::MaterialSpectrum;
use crate::passes::accumulate::AccumulatePass;
use crate::passes::custom::{CustomPass, CustomShader, CustomUniforms};
use crate::passes::gbuffer::GBufferPass;
use crate::passes::gbuffer::{Fourth as GBufferFourth, Layer as GBufferLayer, Targets as GBufferTargets};
use crate::passes::post::PostPass;
use crate::passes::shading::{ShadingPass, ShadingStage, Variant};
use crate::passes::shadow::ShadowPass;
use crate::passes::{Draw, SharedGroups, SharedLayouts, SpectralInputs};
use crate::readback;
use crate::scene_gpu::{GpuLight, GpuScene};
use crate::settings::{Mode, RenderSettings};
use crate::spectral_data::SpectralSetup;
use crate::targets::Targets;
use crate::timing::{PassTimings, Timer};
use crate::uniforms::FrameUniforms;
use color::upsample::CoeffTable;
use glam::Mat4;
use std::sync::Arc;
use wgpu::util::DeviceExt;

/// The camera's projection for a target of width / height `aspect`: perspective from `yfov`, or
/// orthographic with half-height `ymag` and half-width `ymag × aspect` (like the perspective
/// camera, the target's aspect wins over the one the file was authored for, so nothing is
/// stretched; `xmag` is then unused).
///
/// Depth is reversed: 1 at the near plane, 0 at the far one ([`crate::passes::FAR_DEPTH`]). A
/// perspective depth falls as 1/distance, and a float holds small values finely where it holds
/// values near 1 coarsely; the usual order spent that precision at the near plane and left a
/// far surface's reconstructed position centimetres off (a camera with znear 10⁻⁴ and zfar 100
/// streaked its shadows), the reversed one keeps every distance to about 10⁻⁷ of itself.
pub fn projection(camera: &scene::Camera, aspect: f32) -> Mat4 {
    match camera.ortho {
        Some((_, ymag)) => {
            let y = ymag.abs();
            let x = y * aspect;
            Mat4::orthographic_rh(-x, x, -y, y, camera.zfar, camera.clip_near())
        }
        None => Mat4::perspective_rh(camera.yfov, aspect, camera.zfar, camera.clip_near()),
    }
}

/// The environment's sun as the renderer lights with it: its place in the scene's lights, and
/// what it was found as (direction at `rotation`, irradiance before the map's intensity).
#[derive(Clone, Debug)]
struct SunState {
    index: usize,
    direction: glam::Vec3,
    rotation: f32,
    irradiance: glam::Vec3,
    /// `scene::Sun::angular_radius`: its light's specular lobe is widened by it.
    angular_radius: f32,
}

impl SunState {
    /// The directional light for the map at `intensity` and `rotation` (radians about +Y, the
    /// map's convention: a turn by Δ takes (x, z) to (x cos Δ − z sin Δ, z cos Δ + x sin Δ)).
    fn light(&self, intensity: f32, rotation: f32) -> scene::Light {
        let (s, c) = (rotation - self.rotation).sin_cos();
        let d = self.direction;
        let towards = glam::Vec3::new(d.x * c - d.z * s, d.y, d.z * c + d.x * s);
        scene::Light {
            name: "the environment's sun".into(),
            kind: scene::LightKind::Directional { direction: -towards },
            emission: scene::Emission { rgb: self.irradiance * intensity, intensity: 1.0, spectrum: None },
            stands_in_for: None,
        }
    }
}

/// What the per-wavelength buffers were built for; a change triggers a re-upload.
#[derive(Clone, Debug, PartialEq)]
struct SpectralKey {
    observer: String,
    white: String,
    camera_view: color::film::CameraView,
    range: (u64, u64),
    n: usize,
    jitter: Option<u32>,
    mode: Mode,
    quadrature: color::Quadrature,
    scene_generation: u64,
    custom_generation: u64,
    /// The spectral capture's own frame (`SpectralSetup::for_capture`).
    capture: bool,
}

struct SpectralState {
    key: SpectralKey,
    setup: SpectralSetup,
    bind_group: wgpu::BindGroup,
    custom_bind_group: wgpu::BindGroup,
    n_lights: u32,
    /// XYZ of each environment basis spectrum (Σ of its node weights).
    env_totals: [[f32; 4]; 4],
}

/// Bind groups that reference the size-dependent targets.
struct TargetBindings {
    /// The shading's inputs with each of its outputs ([`ShadingPass::bind_both`]): index 0 where
    /// the custom pass is skipped (the shading writes `hdr`), 1 where it runs (`hdr_shaded`).
    shading: [wgpu::BindGroup; 2],
    occlusion: wgpu::BindGroup,
    custom: wgpu::BindGroup,
    post: wgpu::BindGroup,
    /// The accumulation pass's inputs, and post reading the accumulated mean instead of the
    /// current frame: made with the accumulation targets (`Targets::accum`).
    accumulated: Option<(wgpu::BindGroup, wgpu::BindGroup)>,
}

/// The spectral capture of one frame (see [`Renderer::set_spectral_capture`]).
struct Capture {
    buffer: wgpu::Buffer,
    bind_group: [wgpu::BindGroup; 2],
    width: u32,
    height: u32,
    /// The frame's wavelength settings, read back with it.
    settings: RenderSettings,
}

/// The node radiances of one frame ([`Renderer::read_spectral_capture`]).
#[derive(Clone, Debug)]
pub struct SpectralCapture {
    pub width: u32,
    pub height: u32,
    /// The node wavelengths in nm: the centres of N equal bins over the render range.
    pub lambda: Vec<f64>,
    /// The bins' edges, N + 1 (range.min + k·Δλ).
    pub edges: Vec<f64>,
    pub quadrature: color::Quadrature,
    /// `data[(y · width + x) · N + k]`: node k's radiance in the scene's relative units (a
    /// radiance equal to the scene white has Y = 1), before exposure, the same for every
    /// observer: L(λₖ) exactly with the midpoint rule, ∫L·φₖ dλ / ∫φₖ dλ with the prefiltered rule
    /// (see [`Renderer::set_spectral_capture`]).
    pub data: Vec<f32>,
}

/// Bytes the GPU needs to capture a `width`×`height` frame with `groups` groups of four nodes.
pub fn spectral_capture_bytes(width: u32, height: u32, groups: usize) -> u64 {
    width as u64 * height as u64 * groups as u64 * 16
}

/// Refuses a capture larger than the device's storage-buffer and buffer limits.
fn check_capture_size(limits: &wgpu::Limits, width: u32, height: u32, n: usize) -> Result<u64> {
    let bytes = spectral_capture_bytes(width, height, n.div_ceil(4));
    let limit = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    if bytes > limit {
        let mib = |b: u64| b as f64 / (1u64 << 20) as f64;
        return Err(RenderError::Settings(format!(
            "a spectral capture of {width}×{height} pixels with {n} wavelengths needs {:.0} MiB in one GPU \
             buffer, more than this device allows ({:.0} MiB); use a smaller image or fewer wavelengths",
            mib(bytes),
            mib(limit)
        )));
    }
    Ok(bytes)
}

/// A real-time spectral deferred renderer.
///
/// Typical use: [`Renderer::new`] once, [`Renderer::set_scene`], [`Renderer::resize`], then
/// [`Renderer::render`] every frame and either present [`Renderer::output_view`] (rgba8 sRGB)
/// or read it back with [`Renderer::read_ldr`] / [`Renderer::read_hdr`].
pub struct Renderer {
    gpu: Gpu,
    shared: SharedLayouts,
    gbuffer: GBufferPass,
    shadow: ShadowPass,
    shading: ShadingPass,
    /// Whether `shading` is the benchmark's reference shader ([`Self::set_reference_shading`]).
    reference_shading: bool,
    occlusion: crate::passes::occlusion::OcclusionPass,
    /// Made at the first frame with see-through materials.
    back_faces: Option<crate::passes::back_faces::BackFacesPass>,
    custom_pass: CustomPass,
    post: PostPass,
    accumulate: AccumulatePass,
    /// Whether frames go through the accumulation pass (off by default).
    accumulating: bool,
    /// Frames in the running mean since the last reset (0 = the next frame starts it).
    accumulated: u32,
    table: Arc<CoeffTable>,
    gpu_table: GpuCoeffTable,
    frame_buffer: wgpu::Buffer,
    frame_bind_group: wgpu::BindGroup,
    custom: CustomShader,
    custom_generation: u64,
    scene: Option<GpuScene>,
    scene_generation: u64,
    environment: GpuEnvironment,
    /// The polygon lights' specular table (src/ltc.rs), uploaded once.
    ltc: wgpu::TextureView,
    /// The environment's sun, lit with as a directional light ([`Self::set_environment`]).
    sun: Option<SunState>,
    env_buffer: wgpu::Buffer,
    spectral: Option<SpectralState>,
    targets: Option<(Targets, TargetBindings)>,
    timer: Option<Timer>,
    /// Whether frames write the spectral capture.
    capture_on: bool,
    /// Bound in place of the capture buffer when not capturing.
    capture_dummy: wgpu::Buffer,
    capture: Option<Capture>,
    /// The node radiances read back from the capture's own frame (see `render`).
    captured: Option<SpectralCapture>,
    /// While the capture's own frame renders: its spectral data (`SpectralSetup::for_capture`).
    capture_frame: bool,
}

impl Renderer {
    /// A headless renderer on the default adapter (honours `WGPU_BACKEND`) with the sRGB
    /// Jakob–Hanika table from `color::upsample::table` (fitted once per machine, then cached).
    /// Fails with an install hint when the machine has no adapter at all.
    pub fn new() -> Result<Self> {
        let gpu = Gpu::headless()?;
        Self::with_gpu(gpu, color::upsample::table("srgb")?)
    }

    /// [`Self::new`] with an explicit coefficient table.
    pub fn with_table(table: Arc<CoeffTable>) -> Result<Self> {
        Self::with_gpu(Gpu::headless()?, table)
    }

    /// A renderer on a device someone else opened (a window that presents the output).
    pub fn with_gpu(gpu: Gpu, table: Arc<CoeffTable>) -> Result<Self> {
        let device = &gpu.device;
        let shared = SharedLayouts::new(device);
        let custom = CustomShader::default();
        let gbuffer = GBufferPass::new(device, &shared)?;
        let shadow = ShadowPass::new(device, &gbuffer.material_layout)?;
        let shading =
            ShadingPass::new(device, &shared, &custom, ShadingStage::from_env(&gpu.adapter.get_info())?)?;
        let occlusion = crate::passes::occlusion::OcclusionPass::new(device, &shared, shading.stage())?;
        let custom_pass = CustomPass::new(device, &shared, &custom)?;
        let post = PostPass::new(device, &shared)?;
        let accumulate = AccumulatePass::new(device)?;
        let gpu_table = GpuCoeffTable::upload(device, &gpu.queue, &table);
        let frame_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame uniforms"),
            size: std::mem::size_of::<FrameUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let frame_bind_group = shared.frame_group(device, &frame_buffer);
        let timer =
            gpu.features.contains(wgpu::Features::TIMESTAMP_QUERY).then(|| Timer::new(device, &gpu.queue));
        let environment = GpuEnvironment::new(device, &gpu.queue, None);
        let ltc = crate::ltc::upload(device, &gpu.queue);
        let env_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("environment uniforms"),
            size: std::mem::size_of::<EnvUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let capture_dummy = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("spectral capture (unused)"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        Ok(Renderer {
            capture_on: false,
            capture_dummy,
            capture: None,
            captured: None,
            capture_frame: false,
            gpu,
            shared,
            gbuffer,
            shadow,
            shading,
            reference_shading: false,
            occlusion,
            back_faces: None,
            custom_pass,
            post,
            accumulate,
            accumulating: false,
            accumulated: 0,
            table,
            gpu_table,
            frame_buffer,
            frame_bind_group,
            custom,
            custom_generation: 0,
            scene: None,
            scene_generation: 0,
            environment,
            ltc,
            sun: None,
            env_buffer,
            spectral: None,
            targets: None,
            timer,
        })
    }

    pub fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    pub fn table(&self) -> &Arc<CoeffTable> {
        &self.table
    }

    /// Uploads `scene` (geometry, materials, textures, lights, environment), replacing the
    /// previous one.
    pub fn set_scene(&mut self, scene: &scene::Scene) -> Result<()> {
        self.set_scene_with_buffer_limit(scene, self.gpu.device.limits().max_buffer_size)
    }

    /// [`Self::set_scene`] with vertex and index buffers of at most `max_buffer_bytes` each
    /// (large meshes are split over several; tests use a small limit to exercise that).
    pub fn set_scene_with_buffer_limit(&mut self, scene: &scene::Scene, max_buffer_bytes: u64) -> Result<()> {
        // The old scene's buffers go first: two multi-gigabyte scenes need not coexist. Its
        // sun's light went with it.
        self.scene = None;
        self.sun = None;
        self.scene = Some(GpuScene::upload_with_buffer_limit(
            &self.gpu.device,
            &self.gpu.queue,
            &self.gbuffer.material_layout,
            scene,
            max_buffer_bytes,
        )?);
        self.set_environment(scene.environment.as_ref());
        Ok(())
    }

    /// How many vertex/index buffer pairs the scene's meshes occupy (more than one when they
    /// exceed the device's `max_buffer_size`).
    pub fn scene_buffer_count(&self) -> usize {
        self.scene.as_ref().map_or(0, |s| s.chunks.len())
    }

    /// What the last [`Self::set_scene`] had to change to fit the device (oversized textures
    /// downscaled, …), one line each, for the caller to show as warnings.
    pub fn scene_warnings(&self) -> &[String] {
        self.scene.as_ref().map_or(&[], |s| &s.warnings)
    }

    /// Replaces the environment light (prefilters it: tens of milliseconds for a 512-wide map,
    /// more the first time it is shown in spectral mode). `None`: no environment. A map with a
    /// sun (`scene::Environment::sun`, unless `sun_light` is off) is lit with as the sun — a
    /// directional light after the scene's own, with a shadow map — and the map without it
    /// (`without_sun`), so that its energy counts once; the environment is not shadowed here,
    /// and the sun is most of what a shadow would hide.
    pub fn set_environment(&mut self, env: Option<&scene::Environment>) {
        if let (Some(old), Some(gs)) = (self.sun.take(), self.scene.as_mut()) {
            gs.lights.remove(old.index);
        }
        let sun = env.filter(|e| e.sun_light).and_then(|e| e.sun().map(|s| (e, s)));
        let rest = match (sun, self.scene.as_mut()) {
            (Some((e, s)), Some(gs))
                if gs.lights.len() + gs.emitters.len() < crate::scene_gpu::MAX_LIGHTS =>
            {
                let state = SunState {
                    index: gs.lights.len(),
                    direction: s.direction,
                    rotation: e.rotation,
                    irradiance: s.irradiance,
                    angular_radius: s.angular_radius(),
                };
                gs.lights.push(state.light(e.intensity, e.rotation));
                self.sun = Some(state);
                Some(e.without_sun(&s))
            }
            (Some(_), Some(gs)) => {
                // Said, not silent: the sun stays in the map, lit unshadowed.
                let why = format!(
                    "the environment's sun is lit as part of the map, unshadowed: the scene's {} light(s) and {} \
                     emissive area light(s) fill the real-time renderer's {} light slots",
                    gs.lights.len(),
                    gs.emitters.len(),
                    crate::scene_gpu::MAX_LIGHTS
                );
                if !gs.warnings.contains(&why) {
                    gs.warnings.push(why);
                }
                None
            }
            _ => None,
        };
        self.environment = GpuEnvironment::new(&self.gpu.device, &self.gpu.queue, rest.as_ref().or(env));
        self.scene_generation += 1;
    }

    /// The environment's sun as the directional light it is lit with: (direction towards it,
    /// irradiance as linear RGB, intensity applied), or `None`.
    pub fn environment_sun(&self) -> Option<(glam::Vec3, glam::Vec3)> {
        let s = self.sun.as_ref()?;
        let l = &self.scene.as_ref()?.lights[s.index];
        match l.kind {
            scene::LightKind::Directional { direction } => Some((-direction, l.emission.rgb)),
            _ => None,
        }
    }

    /// Changes the environment's intensity and rotation (radians about +Y) without
    /// prefiltering again (its sun's light follows). Ignored when there is no environment.
    pub fn set_environment_transform(&mut self, intensity: f32, rotation: f32) {
        if let Some(e) = self.environment.source.as_mut() {
            e.intensity = intensity;
            e.rotation = rotation;
        }
        if let (Some(s), Some(gs)) = (self.sun.as_ref(), self.scene.as_mut()) {
            gs.lights[s.index] = s.light(intensity, rotation);
            // The lights and the sun's shadow map are rebuilt for the new direction.
            self.scene_generation += 1;
        }
    }

    /// The area lights emissive surfaces are lit with, the emitting polygons they stand for (more
    /// than the lights when clustered: `scene::emitters::area_lights`), and the fraction of the
    /// emitted power left out (more emitting materials than the `MAX_LIGHTS` budget).
    pub fn emitter_summary(&self) -> Option<(usize, usize, f64)> {
        self.scene.as_ref().map(|s| (s.emitters.len(), s.emitter_polygons.0, s.emitter_polygons.1))
    }

    /// The environment in use, if any.
    pub fn environment(&self) -> Option<&scene::Environment> {
        self.environment.source.as_ref()
    }

    /// Fraction of the environment's weighted spectral energy the spectral mode's basis does not
    /// capture (see [`crate::environment`]); `None` before a spectral frame or without one.
    pub fn environment_residual(&self) -> Option<f64> {
        self.environment.spectral.as_ref().map(|(b, _)| b.residual)
    }

    /// The camera the current scene was authored with.
    pub fn scene_camera(&self) -> Option<scene::Camera> {
        self.scene.as_ref().map(|s| s.camera)
    }

    /// Replaces the custom hooks; recompiles the shading and custom passes. On a compile
    /// error the previous shader stays in place.
    pub fn set_custom_shader(&mut self, custom: CustomShader) -> Result<()> {
        custom.validate()?;
        let device = &self.gpu.device;
        let shading = ShadingPass::new(device, &self.shared, &custom, self.shading.stage())?;
        let custom_pass = CustomPass::new(device, &self.shared, &custom)?;
        self.shading = shading;
        self.reference_shading = false;
        self.custom_pass = custom_pass;
        self.custom = custom;
        self.custom_generation += 1;
        Ok(())
    }

    /// Benchmarking: replaces pass 2 with the minimal single-light RGB shader
    /// (`passes/shading_reference.wgsl`: light 0, Lambert + GGX, no shadows, hooks or emission)
    /// so that its GPU time can be compared with the real pass's; `false` restores the real
    /// pass with the current custom hooks. Not for images: the reference ignores the mode.
    pub fn set_reference_shading(&mut self, on: bool) -> Result<()> {
        self.rebuild_shading(on, self.shading.stage())
    }

    /// Where the opaque layer's shading runs: a compute pass over the screen or a fullscreen
    /// triangle's fragments. The default is [`ShadingStage::from_env`] (the adapter's); the
    /// images are the same either way.
    pub fn set_shading_stage(&mut self, stage: ShadingStage) -> Result<()> {
        if stage == self.shading.stage() {
            return Ok(());
        }
        self.rebuild_shading(self.reference_shading, stage)
    }

    /// Where the opaque layer's shading runs ([`Self::set_shading_stage`]).
    pub fn shading_stage(&self) -> ShadingStage {
        self.shading.stage()
    }

    /// Remakes the shading pass (the reference shader when `reference`) and the occlusion pass
    /// in `stage`, and their inputs, which name the stage's output.
    fn rebuild_shading(&mut self, reference: bool, stage: ShadingStage) -> Result<()> {
        let device = &self.gpu.device;
        let shading = if reference {
            ShadingPass::reference(device, &self.shared, stage)?
        } else {
            ShadingPass::new(device, &self.shared, &self.custom, stage)?
        };
        if stage != self.shading.stage() {
            self.occlusion = crate::passes::occlusion::OcclusionPass::new(device, &self.shared, stage)?;
        }
        self.shading = shading;
        self.reference_shading = reference;
        if let Some((t, b)) = self.targets.as_mut() {
            b.shading = self.shading.bind_both(device, t, &self.shadow, &self.capture_dummy);
            b.occlusion = self.occlusion.bind_inputs(device, t);
            if let Some(c) = self.capture.as_mut() {
                c.bind_group = self.shading.bind_both(device, t, &self.shadow, &c.buffer);
            }
        }
        Ok(())
    }

    /// Changes the custom shader's parameters without recompiling (e.g. every frame from a UI).
    pub fn set_custom_params(&mut self, params: [f32; 16]) {
        if self.custom.params != params {
            self.custom.params = params;
            self.custom_generation += 1;
        }
    }

    /// Changes the custom shader's spectra without recompiling; they are resampled at the
    /// current wavelengths on the next frame.
    pub fn set_custom_spectra(&mut self, spectra: Vec<color::Spectrum>) -> Result<()> {
        let custom = CustomShader { spectra, ..self.custom.clone() };
        custom.validate()?;
        self.custom = custom;
        self.custom_generation += 1;
        Ok(())
    }

    /// The custom shader in use.
    pub fn custom_shader(&self) -> &CustomShader {
        &self.custom
    }

    /// Whether this device can render `width`×`height` (its largest texture): for callers that
    /// check every size before any work ([`Self::resize`] checks it too).
    pub fn check_size(&self, width: u32, height: u32) -> Result<()> {
        let max = self.gpu.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(RenderError::Settings(format!(
                "image size {width}×{height} must be between 1 and {max} a side (the device's largest texture)"
            )));
        }
        Ok(())
    }

    /// Sets the output size (pixels). Cheap when unchanged.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        self.check_size(width, height)?;
        if self.targets.as_ref().is_some_and(|(t, _)| t.width == width && t.height == height) {
            return Ok(());
        }
        let targets = Targets::new(&self.gpu.device, width, height);
        let bindings = self.target_bindings(&targets);
        self.targets = Some((targets, bindings));
        self.accumulated = 0;
        Ok(())
    }

    pub fn size(&self) -> Option<(u32, u32)> {
        self.targets.as_ref().map(|(t, _)| (t.width, t.height))
    }

    /// The display image of the last frame (`Rgba8UnormSrgb`, tone-mapped).
    pub fn output_view(&self) -> Option<&wgpu::TextureView> {
        self.targets.as_ref().map(|(t, _)| &t.ldr_view)
    }

    /// The linear HDR image of the last frame (`Rgba16Float`, after the custom pass, exposed:
    /// the shaders apply the exposure as they write it).
    pub fn hdr_view(&self) -> Option<&wgpu::TextureView> {
        self.targets.as_ref().map(|(t, _)| &t.hdr_view)
    }

    /// Turns temporal accumulation on or off. When on, each [`Self::render`] adds its linear
    /// HDR image (after the custom pass) to a running mean over the frames since the last
    /// [`Self::reset_accumulation`] (weight 1/k for the k-th, kept in f32), and post tone-maps
    /// that mean; [`Self::read_accumulated`] reads it. The renderer cannot tell a new view from a
    /// new noisy estimate of the same one: the caller resets whenever the camera, scene, size or
    /// settings change (a resize resets by itself). Pair with `RenderSettings::jitter` at a new
    /// offset every frame to converge to the dense spectral integral. Off (the default), frames
    /// render exactly as without this pass. Switching resets the mean.
    pub fn set_accumulation(&mut self, on: bool) {
        if self.accumulating != on {
            self.accumulating = on;
            self.accumulated = 0;
        }
    }

    /// Whether accumulation is on.
    pub fn accumulation(&self) -> bool {
        self.accumulating
    }

    /// Starts a new mean: the next frame rendered with accumulation on replaces it.
    pub fn reset_accumulation(&mut self) {
        self.accumulated = 0;
    }

    /// Frames in the current mean (0 when accumulation is off or was just reset).
    pub fn accumulated_frames(&self) -> u32 {
        if self.accumulating { self.accumulated } else { 0 }
    }

    /// The per-wavelength data of the last frame (wavelengths, weights, matrix).
    pub fn spectral_setup(&self) -> Option<&SpectralSetup> {
        self.spectral.as_ref().map(|s| &s.setup)
    }

    /// Makes the next frames also write the radiance at each of the N wavelength nodes of every
    /// pixel, read back by [`Self::read_spectral_capture`] (`spectra render --spectral-out`).
    ///
    /// The shading pass accumulates each node's radiance in weighted form, its X, Y and Z
    /// weights (light × observer × quadrature, `color::quadrature`); the capture stores their
    /// sum over X, Y and Z. So that the values are the scene's radiance whatever the frame's
    /// observer, the capture comes from a frame of its own rendered with the flat observer
    /// ([`color::Observer::flat`]: 1 at every wavelength), each node divided by that
    /// observer's weights of a radiance of one. With the midpoint rule every weight of node k
    /// is the radiance at λₖ times Δλ, so this is L(λₖ) exactly, and the N bins of width Δλ
    /// around the nodes integrate back with any observer's midpoint rule to that observer's
    /// frame. With the prefiltered rule it is ∫L·φₖ dλ / ∫φₖ dλ over the render range, φₖ the
    /// node's cardinal function: L weighted around λₖ as the node's interpolant sees it (L
    /// itself where L is smooth there; 1 for a flat spectrum). Dividing an observer's own weights instead (as before) gave
    /// the node's share of ∫L·s̄ over s̄(λₖ), which a camera nearly blind at a node turned into
    /// nonsense (−180 at 391 nm for a Nikon D5100).
    /// What the custom hooks add in the shading pass is included (they return weighted form);
    /// pass 3's `custom_pixel` is not (an RGB step, the identity for the built-in hooks). RGB
    /// mode and jittered nodes are refused. A render with the capture on costs two frames, and
    /// its image is drawn by the general node loop (as the capture's frame is).
    pub fn set_spectral_capture(&mut self, on: bool) {
        self.capture_on = on;
        if !on {
            self.capture = None;
        }
    }

    /// Refuses a spectral capture of a `width`×`height` frame with `wavelengths` nodes larger
    /// than this device's buffer limits; otherwise its size on the GPU in bytes.
    pub fn check_spectral_capture(&self, width: u32, height: u32, wavelengths: usize) -> Result<u64> {
        check_capture_size(&self.gpu.device.limits(), width, height, wavelengths)
    }

    /// The last frame's spectral capture (see [`Self::set_spectral_capture`]).
    pub fn read_spectral_capture(&self) -> Result<SpectralCapture> {
        self.captured.clone().ok_or_else(|| {
            RenderError::Settings("no spectral capture: call set_spectral_capture(true) and render".into())
        })
    }

    /// The capture buffer of the frame just rendered, as radiances (waits for it).
    fn read_capture_buffer(&self) -> Result<SpectralCapture> {
        let c = self.capture.as_ref().expect("a capture frame was rendered");
        let setup = SpectralSetup::for_capture(&c.settings)?;
        let n = setup.len();
        let groups = setup.groups();
        // The capture's weights of a radiance of one at each node (summed over its three equal
        // channels): the node spacing, normalised like the frame's weights.
        let divisor: Vec<f64> = setup.weights_of(|_| 1.0).iter().map(|w| w[0] + w[1] + w[2]).collect();
        let device = &self.gpu.device;
        readback::wait(device)?;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("spectral capture readback"),
            size: c.buffer.size(),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(&c.buffer, 0, &staging, 0, c.buffer.size());
        self.gpu.queue.submit([encoder.finish()]);
        let pixels = c.width as usize * c.height as usize;
        let data = readback::map_buffer(device, &staging, |bytes| {
            let values: &[f32] = bytemuck::cast_slice(bytes);
            let mut out = Vec::with_capacity(pixels * n);
            for px in values.chunks_exact(groups * 4).take(pixels) {
                out.extend(
                    px[..n]
                        .iter()
                        .zip(&divisor)
                        .map(|(&v, &d)| if d > 0.0 { (v as f64 / d) as f32 } else { 0.0 }),
                );
            }
            out
        })?;
        let range = c.settings.range;
        let step = range.width() / n as f64;
        let edges = (0..=n).map(|k| if k == n { range.max } else { range.min + k as f64 * step }).collect();
        Ok(SpectralCapture {
            width: c.width,
            height: c.height,
            lambda: setup.wavelengths.lambda.clone(),
            edges,
            quadrature: c.settings.quadrature,
            data,
        })
    }

    /// Renders one frame from `camera`. Requires [`Self::set_scene`] and [`Self::resize`].
    ///
    /// With the spectral capture on (`set_spectral_capture`), two: the capture's own frame,
    /// weighted by the flat observer ([`SpectralSetup::for_capture`]; not accumulated, not
    /// timed), whose node radiances are read back, then the frame asked for, through the same
    /// general node loop (so that its image is what the capture's loop draws).
    pub fn render(&mut self, camera: &scene::Camera, settings: &RenderSettings) -> Result<()> {
        self.captured = None;
        if !self.capture_on {
            self.capture = None;
            return self.render_frame(camera, settings, false);
        }
        let untimed = RenderSettings { timestamps: false, ..settings.clone() };
        let accumulating = std::mem::replace(&mut self.accumulating, false);
        // The capture's frame integrates with weights of its own (a radiance per node, the same
        // in X, Y and Z), so its RGB image is no colour: a see-through layer, which reads the
        // opaque layer's image as its background (transmission.wgsl), reads the one a frame
        // with the display's weights drew just before.
        if self.scene.as_ref().is_some_and(|s| s.has_transmission)
            && let Err(e) = self.render_frame(camera, &untimed, true)
        {
            self.accumulating = accumulating;
            return Err(e);
        }
        self.capture_frame = true;
        let radiance = self.render_frame(camera, &untimed, true).and_then(|()| self.read_capture_buffer());
        self.capture_frame = false;
        self.accumulating = accumulating;
        let radiance = radiance?;
        self.render_frame(camera, settings, true)?;
        self.captured = Some(radiance);
        Ok(())
    }

    /// One frame; `capture`: with the spectral capture's buffer and loop.
    fn render_frame(
        &mut self,
        camera: &scene::Camera,
        settings: &RenderSettings,
        capture: bool,
    ) -> Result<()> {
        if color::cancel::is_cancelled() {
            return Err(RenderError::Cancelled);
        }
        settings.validate()?;
        if self.scene.is_none() {
            return Err(RenderError::Settings("no scene: call set_scene first".into()));
        }
        let Some((targets, _)) = self.targets.as_ref() else {
            return Err(RenderError::Settings("no render size: call resize first".into()));
        };
        let (width, height) = (targets.width, targets.height);
        let (lo, hi) = scene::ORTHO_MAG_RANGE;
        if let Some((xmag, ymag)) = camera.ortho
            && !([xmag, ymag].iter().all(|m| (lo..=hi).contains(&m.abs())) && camera.zfar > camera.znear)
        {
            return Err(RenderError::Settings(format!(
                "orthographic camera with xmag {xmag}, ymag {ymag}, znear {}, zfar {}: the \
                 magnifications must be between {lo:e} and {hi:e} and zfar > znear",
                camera.znear, camera.zfar
            )));
        }
        self.capture = None;
        if capture {
            if settings.mode == Mode::Rgb {
                return Err(RenderError::Settings(
                    "a spectral capture needs the spectral or naive mode: RGB mode has no wavelengths".into(),
                ));
            }
            if settings.jitter.is_some() {
                return Err(RenderError::Settings(
                    "a spectral capture needs fixed nodes (jitter moves them off the bin centres)".into(),
                ));
            }
            let bytes = check_capture_size(&self.gpu.device.limits(), width, height, settings.wavelengths)?;
            let buffer = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("spectral capture"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_SRC
                    | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let (targets, _) = self.targets.as_ref().expect("checked above");
            let bind_group = self.shading.bind_both(&self.gpu.device, targets, &self.shadow, &buffer);
            self.capture = Some(Capture { buffer, bind_group, width, height, settings: settings.clone() });
        }
        if self.accumulating {
            self.ensure_accumulation_targets();
        }
        self.update_spectral(settings)?;
        let spectral = self.spectral.as_ref().expect("update_spectral sets it");
        let scene = self.scene.as_ref().expect("checked above");
        // The number this frame will have in the running mean (see `accumulate` below): the
        // salt of the stochastic transparency, so that its noise averages out over frames.
        let frame_index = if self.accumulating { self.accumulated.saturating_add(1) } else { 0 };
        let remade = self.shadow.update(
            &self.gpu.device,
            &self.gpu.queue,
            scene,
            self.scene_generation,
            settings.shadows,
            frame_index,
        );
        // An anisotropic scene's film target is another (`Targets::bind_film_anisotropy`).
        let film_changed = self
            .targets
            .as_mut()
            .is_some_and(|(t, _)| t.bind_film_anisotropy(&self.gpu.device, scene.has_anisotropy));
        // So is a diffuse-transmitting scene's specular target (`Targets::bind_specular_dt`).
        let specular_changed = self
            .targets
            .as_mut()
            .is_some_and(|(t, _)| t.bind_specular_dt(&self.gpu.device, scene.has_diffuse_transmission));
        let film_changed = film_changed || specular_changed;
        if remade || film_changed {
            // The shading inputs hold the old depth array, or the old film target.
            let device = &self.gpu.device;
            if let Some((t, b)) = self.targets.as_mut() {
                b.shading = self.shading.bind_both(device, t, &self.shadow, &self.capture_dummy);
                if let Some(c) = self.capture.as_mut() {
                    c.bind_group = self.shading.bind_both(device, t, &self.shadow, &c.buffer);
                }
            }
        }

        let aspect = width as f32 / height as f32;
        let view = camera.transform.inverse();
        let mut proj = projection(camera, aspect);
        if let Some([dx, dy]) = settings.pixel_offset {
            // The scene point that the pixel centre should see, (dx, dy) pixels away, moved onto
            // it: a shift in clip space by the offset in NDC times w (pixel y runs down).
            let shift = Mat4::from_translation(glam::Vec3::new(
                -2.0 * dx / width as f32,
                2.0 * dy / height as f32,
                0.0,
            ));
            proj = shift * proj;
        }
        let view_proj = proj * view;
        let m = spectral.setup.xyz_to_rgb;
        let uniforms = FrameUniforms {
            view_proj: view_proj.to_cols_array_2d(),
            // Inverted in f64: the shaders rebuild positions from depth with it.
            inv_view_proj: view_proj.as_dmat4().inverse().as_mat4().to_cols_array_2d(),
            camera_pos: camera.position().extend(1.0).to_array(),
            xyz_to_rgb: [m.x_axis, m.y_axis, m.z_axis].map(|c| [c.x as f32, c.y as f32, c.z as f32, 0.0]),
            viewport: [width as f32, height as f32, 1.0 / width as f32, 1.0 / height as f32],
            mode: settings.mode.gpu(),
            n_groups: spectral.setup.groups() as u32,
            n_lights: spectral.n_lights,
            exposure: settings.exposure_ev.exp2(),
            tonemap: settings.tonemap.gpu(),
            table_res: self.gpu_table.res,
            flags: if settings.lambert { 1 } else { 0 }
                | if camera.ortho.is_some() { 2 } else { 0 }
                | if self.capture.is_some() { 4 } else { 0 },
            frame_index,
            lod_bias: settings.texture_lod_bias,
            node_spacing: if settings.mode == Mode::Spectral {
                (settings.range.width() / settings.wavelengths.max(1) as f64) as f32
            } else {
                0.0
            },
            _pad: [0; 2],
        };
        self.gpu.queue.write_buffer(&self.frame_buffer, 0, bytemuck::bytes_of(&uniforms));
        // Screen-space occlusion of the environment searches half the scene's bounding radius.
        let occlusion_radius =
            if settings.env_occlusion { 0.5 * (scene.bounds.1 - scene.bounds.0).length() * 0.5 } else { 0.0 };
        let env_uniforms =
            self.environment.uniforms(spectral.env_totals, settings.mode == Mode::Spectral, occlusion_radius);
        // Ambient light to occlude (the environment's, a hook's irradiance): the occlusion pass
        // runs first and the shading reads its result.
        let occlusion = occlusion_radius > 0.0
            && (env_uniforms.flags[0] != 0 || self.custom.irradiance())
            && self.shading.reads_occlusion();
        self.gpu.queue.write_buffer(&self.env_buffer, 0, bytemuck::bytes_of(&env_uniforms));

        let variant = Variant {
            polygons: !scene.emitters.is_empty(),
            environment: env_uniforms.flags[0] != 0,
            emission: scene.has_emission,
            emission_spectra: scene.emission_spectra.iter().any(Option::is_some),
            naive: settings.mode == Mode::Naive,
            capture: self.capture.is_some(),
            fetch_base: scene.varying_colours.0,
            fetch_emission: scene.varying_colours.1,
            film: scene.has_film,
            coat: scene.has_coat,
            ior: scene.has_ior,
            specular: scene.has_specular,
            sheen: scene.has_sheen,
            anisotropy: scene.has_anisotropy,
            diffuse_transmission: scene.has_diffuse_transmission,
            transmission: false,
            thin_walls: scene.has_thin_walls,
            dispersion: scene.has_dispersion,
            // The naive mode's basis is the three bands (the fourth's weights are zero).
            env_bases: match settings.mode {
                Mode::Spectral => self.environment.spectral_bases() as u32,
                _ => 3,
            },
            occlusion_map: occlusion,
        };
        // See-through materials get a layer of their own, shaded over the opaque one
        // (`passes::gbuffer::Layer`), in every mode: the general node loop (a spectral hook,
        // the capture) shades it too, and the capture takes its pixels from it.
        let layered = scene.has_transmission;
        if layered {
            // Prepared first: `select` leaves the pipeline it makes last current.
            // The layer searches its occlusion on its own depth.
            let layer_variant = Variant {
                film: scene.has_transmission_film,
                coat: scene.has_transmission_coat,
                // The loader keeps no specular on see-through materials, and this renderer
                // draws no sheen there.
                specular: false,
                sheen: false,
                anisotropy: false,
                diffuse_transmission: false,
                transmission: true,
                occlusion_map: false,
                ..variant
            };
            self.shading.select(&self.gpu.device, layer_variant, settings.mode == Mode::Rgb)?;
            let (t, _) = self.targets.as_mut().expect("checked above");
            if t.layer.is_none() {
                t.layer = Some(crate::targets::LayerTargets::new(&self.gpu.device, t.width, t.height));
            }
            if self.back_faces.is_none() {
                self.back_faces =
                    Some(crate::passes::back_faces::BackFacesPass::new(&self.gpu.device, &self.shared)?);
            }
        }
        let layer_key = self.shading.current();
        self.shading.select(&self.gpu.device, variant, settings.mode == Mode::Rgb)?;
        // The film's target comes with a coat's or a specular's: the shading pass reads it beside
        // them; and with an anisotropy, which it carries.
        // A diffuse transmission is carried by the specular's target, which comes with the film's.
        let filmed = scene.has_film
            || scene.has_coat
            || scene.has_specular
            || scene.has_anisotropy
            || scene.has_diffuse_transmission;
        let gbuffer_targets = GBufferTargets {
            fourth: if filmed { GBufferFourth::Film } else { GBufferFourth::None },
            coat: scene.has_coat,
            specular: scene.has_specular,
            sheen: scene.has_sheen,
            anisotropy: scene.has_anisotropy,
            diffuse_transmission: scene.has_diffuse_transmission,
        };
        self.gbuffer.prepare(&self.gpu.device, gbuffer_targets)?;
        let layer_targets = GBufferTargets {
            fourth: GBufferFourth::Layer,
            coat: scene.has_transmission_coat,
            specular: false,
            sheen: false,
            anisotropy: false,
            diffuse_transmission: false,
        };
        if layered {
            self.gbuffer.prepare(&self.gpu.device, layer_targets)?;
        }
        let (targets, bindings) = self.targets.as_ref().expect("checked above");
        let timer = self.timer.as_ref().filter(|_| settings.timestamps);
        if let Some(t) = timer {
            t.start_frame();
        }
        let ts = |i: usize| timer.map(|t| t.writes(i));
        let mut encoder =
            self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        self.shadow.record(&mut encoder, scene, ts(0));
        let g = &targets.gbuffer_views;
        let (film, coat, spec, sheen) = (
            targets.film_view(),
            &targets.gbuffer_coat_view,
            targets.specular_view(),
            &targets.gbuffer_sheen_view,
        );
        // (The transmissive layer's targets are its own, below.)
        let colour: Vec<&wgpu::TextureView> = [&g[0], &g[1], &g[2]]
            .into_iter()
            .chain(filmed.then_some(film))
            .chain(gbuffer_targets.coat.then_some(coat))
            .chain((gbuffer_targets.specular || gbuffer_targets.diffuse_transmission).then_some(spec))
            .chain(gbuffer_targets.sheen.then_some(sheen))
            .collect();
        let first = if layered { GBufferLayer::Opaque } else { GBufferLayer::All };
        self.gbuffer.record(
            &mut encoder,
            gbuffer_targets,
            &colour,
            &targets.depth_view,
            &self.frame_bind_group,
            scene,
            first,
            ts(1),
        );
        if let Some(c) = &self.capture {
            // Background pixels without an environment write nothing.
            encoder.clear_buffer(&c.buffer, 0, None);
        }
        let shared = SharedGroups {
            frame: &self.frame_bind_group,
            spectral: &spectral.bind_group,
            custom: &spectral.custom_bind_group,
        };
        // An identity custom pass is skipped: shading writes what the custom pass would.
        let output = usize::from(!self.custom_pass.skipped());
        let inputs = self.capture.as_ref().map_or(&bindings.shading[output], |c| &c.bind_group[output]);
        if occlusion {
            let draw = Draw {
                target: &targets.occlusion_view,
                inputs: &bindings.occlusion,
                timestamps: ts(crate::timing::OCCLUSION),
            };
            self.occlusion.record(&mut encoder, &self.frame_bind_group, &spectral.bind_group, draw);
        } else if let Some(t) = timer {
            t.idle(&mut encoder, crate::timing::OCCLUSION);
        }
        let shaded = [&targets.hdr_view, &targets.hdr_shaded_view][output];
        match (layered, targets.layer.as_ref()) {
            (true, Some(layer)) => {
                // The opaque layer, kept aside as the background; the see-through one over it.
                // The shading's time spans both layers (the first's start, the second's end).
                let draw = Draw { target: shaded, inputs, timestamps: timer.map(|t| t.begins(2)) };
                self.shading.record(&mut encoder, &shared, draw);
                let shaded_texture =
                    if self.custom_pass.skipped() { &targets.hdr } else { &targets.hdr_shaded };
                // The capture's frame keeps the background the frame before it left (`render`):
                // its own opaque layer is drawn with the capture's weights, no colour.
                if !self.capture_frame {
                    encoder.copy_texture_to_texture(
                        shaded_texture.as_image_copy(),
                        layer.background.as_image_copy(),
                        wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                    );
                }
                encoder.copy_texture_to_texture(
                    targets.depth.as_image_copy(),
                    layer.depth.as_image_copy(),
                    wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                );
                let written = layer_targets.formats().len();
                let views: Vec<&wgpu::TextureView> = layer.gbuffer_views.iter().take(written).collect();
                self.gbuffer.record(
                    &mut encoder,
                    layer_targets,
                    &views,
                    &layer.depth_view,
                    &self.frame_bind_group,
                    scene,
                    GBufferLayer::Transmissive,
                    None,
                );
                self.back_faces.as_ref().expect("made with the layer").record(
                    &mut encoder,
                    &layer.back_faces_view,
                    &layer.back_depth_view,
                    &self.frame_bind_group,
                    scene,
                );
                let capture = self.capture.as_ref().map_or(&self.capture_dummy, |c| &c.buffer);
                let layer_inputs = self.shading.bind_layer_inputs(
                    &self.gpu.device,
                    layer,
                    &targets.depth_view,
                    &self.shadow,
                    capture,
                );
                let draw =
                    Draw { target: shaded, inputs: &layer_inputs, timestamps: timer.map(|t| t.ends(2)) };
                self.shading.record_layer(&mut encoder, &shared, draw, &layer.depth_view, scene, layer_key);
            }
            _ => {
                let draw = Draw { target: shaded, inputs, timestamps: ts(2) };
                self.shading.record(&mut encoder, &shared, draw);
            }
        }
        let draw = Draw { target: &targets.hdr_view, inputs: &bindings.custom, timestamps: ts(3) };
        self.custom_pass.record(&mut encoder, &shared, draw);
        let post_inputs = match (self.accumulating, targets.accum.as_ref(), bindings.accumulated.as_ref()) {
            (true, Some(a), Some((accumulate, post_accumulated))) => {
                self.accumulated = self.accumulated.saturating_add(1);
                self.accumulate.set_frame(&self.gpu.queue, self.accumulated);
                self.accumulate.record(&mut encoder, a, accumulate);
                post_accumulated
            }
            _ => &bindings.post,
        };
        let draw = Draw { target: &targets.ldr_view, inputs: post_inputs, timestamps: ts(4) };
        self.post.record(&mut encoder, &self.frame_bind_group, draw);
        if let Some(t) = timer {
            t.resolve(&mut encoder);
        }
        crate::shader::checked(&self.gpu.device, "rendering the frame", || {
            self.gpu.queue.submit([encoder.finish()]);
        })?;
        self.shadow.submitted();
        if let Some(t) = self.timer.as_mut() {
            t.pending = settings.timestamps;
        }
        Ok(())
    }

    /// GPU time per pass of the last frame rendered with `timestamps: true` (waits for it).
    /// `None` when the adapter has no timestamp queries or no such frame was rendered.
    pub fn read_timings(&mut self) -> Result<Option<PassTimings>> {
        match self.timer.as_mut() {
            Some(t) if t.pending => t.read(&self.gpu.device).map(Some),
            _ => Ok(None),
        }
    }

    /// Waits for the frames submitted so far; [`RenderError::Cancelled`] on Ctrl-C (see
    /// [`color::cancel`]), without waiting for the GPU to finish.
    pub fn wait(&self) -> Result<()> {
        readback::wait(&self.gpu.device)
    }

    /// The display image as tightly packed RGBA8 (sRGB-encoded) rows.
    pub fn read_ldr(&self) -> Result<Vec<u8>> {
        let (t, _) =
            self.targets.as_ref().ok_or_else(|| RenderError::Settings("nothing rendered yet".into()))?;
        readback::read_texture(&self.gpu.device, &self.gpu.queue, &t.ldr, 4)
    }

    /// The linear HDR image (after the custom pass; times 2^EV, which the shaders apply as they
    /// write it, before the half float) as RGBA f32 pixels.
    pub fn read_hdr(&self) -> Result<Vec<[f32; 4]>> {
        let (t, _) =
            self.targets.as_ref().ok_or_else(|| RenderError::Settings("nothing rendered yet".into()))?;
        let bytes = readback::read_texture(&self.gpu.device, &self.gpu.queue, &t.hdr, 8)?;
        Ok(bytes
            .chunks_exact(8)
            .map(|p| std::array::from_fn(|c| half::f16::from_le_bytes([p[2 * c], p[2 * c + 1]]).to_f32()))
            .collect())
    }

    /// Whether the accumulation's targets (two RGBA f32 and one RGBA f16 image at the frame's
    /// size) are held: made at the first accumulated frame, not before.
    pub fn accumulation_targets_made(&self) -> bool {
        self.targets.as_ref().is_some_and(|(t, _)| t.accum.is_some())
    }

    /// The accumulated mean (see [`Self::set_accumulation`]) as RGBA f32 pixels. An error when
    /// no frame has been accumulated since the last reset.
    pub fn read_accumulated(&self) -> Result<Vec<[f32; 4]>> {
        let (t, _) =
            self.targets.as_ref().ok_or_else(|| RenderError::Settings("nothing rendered yet".into()))?;
        if self.accumulated_frames() == 0 {
            return Err(RenderError::Settings(
                "no accumulated frame: turn accumulation on and render".into(),
            ));
        }
        let a = t.accum.as_ref().ok_or_else(|| {
            RenderError::Settings("no accumulated frame: turn accumulation on and render".into())
        })?;
        let bytes = readback::read_texture(&self.gpu.device, &self.gpu.queue, &a.accum, 16)?;
        Ok(bytes
            .chunks_exact(16)
            .map(|p| {
                std::array::from_fn(|c| {
                    f32::from_le_bytes([p[4 * c], p[4 * c + 1], p[4 * c + 2], p[4 * c + 3]])
                })
            })
            .collect())
    }

    fn target_bindings(&self, t: &Targets) -> TargetBindings {
        let device = &self.gpu.device;
        TargetBindings {
            shading: self.shading.bind_both(device, t, &self.shadow, &self.capture_dummy),
            occlusion: self.occlusion.bind_inputs(device, t),
            custom: self.custom_pass.bind_inputs(device, t),
            post: self.post.bind_inputs(device, &t.hdr_view, "post inputs"),
            accumulated: None,
        }
    }

    /// Makes the accumulation targets and their bind groups if they are not made yet.
    fn ensure_accumulation_targets(&mut self) {
        let device = &self.gpu.device;
        let Some((t, b)) = self.targets.as_mut() else { return };
        if t.accum.is_none() {
            t.accum = Some(crate::targets::AccumTargets::new(device, t.width, t.height));
        }
        if b.accumulated.is_none() {
            let a = t.accum.as_ref().expect("made above");
            b.accumulated = Some((
                self.accumulate.bind_inputs(device, t, a),
                self.post.bind_inputs(device, &a.accum_display_view, "post inputs (accumulated)"),
            ));
        }
    }

    /// Rebuilds the per-wavelength buffers when the wavelengths, observer, mode, scene or custom
    /// spectra changed since the last frame. These are a few KiB: nothing is recompiled.
    fn update_spectral(&mut self, settings: &RenderSettings) -> Result<()> {
        let key = SpectralKey {
            observer: settings.observer.to_ascii_lowercase(),
            white: settings.white.clone(),
            camera_view: settings.camera_view,
            range: (settings.range.min.to_bits(), settings.range.max.to_bits()),
            n: settings.wavelengths,
            jitter: settings.jitter.map(f32::to_bits),
            mode: settings.mode,
            quadrature: settings.quadrature,
            scene_generation: self.scene_generation,
            custom_generation: self.custom_generation,
            capture: self.capture_frame,
        };
        if self.spectral.as_ref().is_some_and(|s| s.key == key) {
            return Ok(());
        }
        let setup = if self.capture_frame {
            SpectralSetup::for_capture(settings)?
        } else {
            SpectralSetup::new(settings)?
        };
        if settings.mode == Mode::Spectral {
            self.environment.ensure_spectral(&self.gpu.device, &self.gpu.queue, &self.table);
        }
        let scene = self.scene.as_ref().expect("render checks the scene first");
        let device = &self.gpu.device;
        let groups = setup.gpu_groups();
        let ng = setup.groups();
        // Padding lanes repeat the last wavelength; their weights are zero.
        let padded_lambda: Vec<f64> = groups.iter().flat_map(|g| g.lambda.map(f64::from)).collect();

        let mut lights = Vec::new();
        // light_weights[light · n_groups + group]: the light's node weights (mat3x4 in WGSL).
        let mut light_weights: Vec<crate::spectral_data::GroupWeights> = Vec::new();
        // Each light's weights per node (spectral modes), for the materials' reflected XYZ.
        let mut light_node_weights: Vec<Vec<[f64; 3]>> = Vec::new();
        // Punctual lights, then the emissive polygons: each a GPU light and its emission.
        // Materials that glow with a measured spectrum: its node weights per unit luminance (the
        // spectral modes), or its colour per unit luminance (the RGB mode, as a light's). First,
        // so that a spectrum the range cannot show is named by its material, not by the
        // emissive polygons lit with it.
        let measured: Vec<Option<MeasuredEmission>> = scene
            .emission_spectra
            .iter()
            .map(|m| {
                let Some((name, spectrum)) = m else { return Ok(None) };
                let unit = scene::Emission {
                    rgb: glam::Vec3::ONE,
                    intensity: 1.0,
                    spectrum: Some(spectrum.clone()),
                };
                if settings.mode == Mode::Rgb {
                    return Ok(Some(MeasuredEmission::Rgb(setup.light_rgb(&unit))));
                }
                match setup.light_weights(&unit, settings.mode, &self.table) {
                    Ok(w) => Ok(Some(MeasuredEmission::Weights(w))),
                    Err(RenderError::Settings(why)) => {
                        Err(RenderError::Settings(format!("material '{name}': {why}")))
                    }
                    Err(other) => Err(other),
                }
            })
            .collect::<Result<_>>()?;
        let n_punctual = scene.lights.len();
        let sources =
            scene.lights.iter().map(|l| (GpuLight::new(l, setup.light_rgb(&l.emission)), &l.emission)).chain(
                scene
                    .emitters
                    .iter()
                    .map(|e| (GpuLight::polygon(e, setup.light_rgb(&e.emission)), &e.emission)),
            );
        for (i, (mut gpu, emission)) in sources.enumerate() {
            if settings.mode != Mode::Rgb {
                let w = setup.light_weights(emission, settings.mode, &self.table).map_err(|e| match e {
                    RenderError::Settings(why) if i < n_punctual => {
                        RenderError::Settings(format!("light '{}': {why}", scene.lights[i].name))
                    }
                    RenderError::Settings(why) => RenderError::Settings(format!(
                        "the emissive surface of mesh {}: {why}",
                        scene.emitters[i - n_punctual].mesh
                    )),
                    other => other,
                })?;
                let total = SpectralSetup::light_total(&w);
                gpu.xyz = [total[0] as f32, total[1] as f32, total[2] as f32, 0.0];
                light_weights.extend(setup.gpu_weights(&w));
                light_node_weights.push(w);
            } else {
                light_weights.extend(std::iter::repeat_n([[0f32; 4]; 3], ng));
            }
            lights.push(gpu);
        }
        if let Some(s) = &self.sun {
            lights[s.index].cone[1] = s.angular_radius;
        }
        let n_lights = lights.len() as u32;
        // Storage buffers may not be empty.
        if lights.is_empty() {
            lights.push(GpuLight::default());
        }
        let storage = |label: &str, bytes: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        // The environment's basis spectra: node weights [j · n_groups + g] and XYZ totals.
        let mut env_weights: Vec<crate::spectral_data::GroupWeights> = Vec::new();
        let mut env_totals = [[0f32; 4]; 4];
        let mut env_basis: Vec<Vec<[f64; 3]>> = Vec::new();
        if self.environment.source.is_some() && settings.mode != Mode::Rgb {
            let white = &setup.white;
            let (blue_max, green_max) = crate::spectral_data::naive_band_edges();
            // Basis spectrum j times the white: the spectral basis, or the naive mode's bands.
            let spectrum = |j: usize, l: f64| match (settings.mode, &self.environment.spectral) {
                (Mode::Spectral, Some((b, _))) => b.eval(j, l) * white.eval(l),
                _ => {
                    let band = crate::spectral_data::naive_band(l, blue_max, green_max);
                    if band == j { white.eval(l) } else { 0.0 }
                }
            };
            let basis: Vec<Vec<[f64; 3]>> =
                (0..crate::environment::K).map(|j| setup.weights_of(|l| spectrum(j, l))).collect();
            for (j, w) in basis.iter().enumerate() {
                // The totals are the environment's colour (the sky seen through glass is read as
                // one, `seen_through`): by the display's rule in a capture's frame too, whose own
                // weights (a radiance per node) make no colour; elsewhere the same weights.
                let t = SpectralSetup::light_total(&setup.display_weights_of(|l| spectrum(j, l)));
                env_totals[j] = [t[0] as f32, t[1] as f32, t[2] as f32, 0.0];
                env_weights.extend(setup.gpu_weights(w));
            }
            env_basis = basis;
        }
        let env_weight_buf = GpuEnvironment::storage(device, &env_weights);
        let env_tex = self.environment.textures(settings.mode == Mode::Spectral);
        let mut records = MaterialSpectrum::of_scene(
            &scene.constant_colours,
            &scene.material_films,
            &scene.material_refraction,
            &self.table,
            &groups,
        );
        // After the lights' weights, what each constant-colour material reflects under each
        // light and basis spectrum (the spectral mode's; the naive mode loops over boxes).
        if settings.mode == Mode::Spectral {
            light_weights.extend(crate::material_spectra::reflected_xyz(
                &records,
                &light_node_weights,
                &env_basis,
                &groups,
            ));
        }
        // The measured emissions' node weights after the rest, found by the record
        // (`MaterialSpectrum::emission`).
        for ((record, m), colour) in records.iter_mut().zip(&measured).zip(&scene.constant_colours) {
            let value = match m {
                None => continue,
                Some(MeasuredEmission::Rgb(rgb)) => [rgb[0] as f32, rgb[1] as f32, rgb[2] as f32, 0.0],
                Some(MeasuredEmission::Weights(w)) => {
                    let t = SpectralSetup::light_total(w);
                    let offset = light_weights.len();
                    light_weights.extend(setup.gpu_weights(w));
                    [t[0] as f32, t[1] as f32, t[2] as f32, offset as f32]
                }
            };
            // A constant emission's luminance from the material itself: the G-buffer's f16 loses
            // a dim one (4e-8 became 0, where `--exposure` was to bring it up).
            let k =
                colour.emission.map_or(-1.0, |e| scene::srgb::luminance(glam::Vec3::from_array(e)) as f32);
            record.emission = [k, 0.0, 0.0, crate::material_spectra::MEASURED_EMISSION[3]];
            record.emission_xyz = value;
        }
        if light_weights.is_empty() {
            light_weights.push([[0f32; 4]; 3]);
        }
        let wl_buf = storage("wavelengths", bytemuck::cast_slice(&groups));
        let light_buf = storage("lights", bytemuck::cast_slice(&lights));
        let light_spec_buf = storage("light weights", bytemuck::cast_slice(&light_weights));
        let material_spectra = storage("material spectra", bytemuck::cast_slice(&records));
        let bind_group = self.shared.spectral_group(
            device,
            &SpectralInputs {
                wavelengths: &wl_buf,
                lights: &light_buf,
                light_weights: &light_spec_buf,
                table: &self.gpu_table.view,
                table_scale: &self.gpu_table.scale,
                env_weights: &env_weight_buf,
                env_radiance: &env_tex.radiance,
                env_irradiance: &env_tex.irradiance,
                env_lut: &self.environment.lut,
                env_sampler: &self.environment.sampler,
                env_uniforms: &self.env_buffer,
                material_spectra: &material_spectra,
                ltc: &self.ltc,
            },
        );

        // custom_spectra[group * 4 + s] = spectrum s < 4 at the group's four wavelengths; the
        // spectra beyond the fourth (tables) follow at [s * n_groups + group].
        let n_custom = self.custom.spectra.len();
        let mut custom_spectra = vec![[0f32; 4]; ng * n_custom.max(4)];
        for (s, spectrum) in self.custom.spectra.iter().enumerate() {
            for g in 0..ng {
                let at = if s < 4 { g * 4 + s } else { s * ng + g };
                custom_spectra[at] = match spectrum {
                    color::Spectrum::Constant(v) => [*v as f32; 4],
                    _ => std::array::from_fn(|lane| spectrum.eval(padded_lambda[g * 4 + lane]) as f32),
                };
            }
        }
        let custom_uniforms = CustomUniforms {
            params: self.custom.params,
            n_spectra: self.custom.spectra.len() as u32,
            _pad: [0; 3],
        };
        let custom_uniform_buf = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("custom uniforms"),
            contents: bytemuck::bytes_of(&custom_uniforms),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let custom_spec_buf = storage("custom spectra", bytemuck::cast_slice(&custom_spectra));
        let custom_bind_group = self.shared.custom_group(device, &custom_uniform_buf, &custom_spec_buf);
        self.spectral =
            Some(SpectralState { key, setup, bind_group, custom_bind_group, n_lights, env_totals });
        Ok(())
    }
}

/// A material's measured emission spectrum prepared for a frame: its node weights per unit
/// luminance (the spectral modes) or its linear RGB per unit luminance (the RGB mode).
enum MeasuredEmission {
    Weights(Vec<[f64; 3]>),
    Rgb([f64; 3]),
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 16 bytes per group of four nodes and pixel, against wgpu's default storage-buffer limit
    /// (128 MiB): 1920×1080 fits at N = 16 (4 groups), not at N = 20 (5), and the error says
    /// how much was asked and what to change.
    #[test]
    fn capture_size_is_checked_against_the_device_limits() {
        let limits = wgpu::Limits::default();
        assert_eq!(check_capture_size(&limits, 1920, 1080, 16).unwrap(), 1920 * 1080 * 64);
        assert_eq!(check_capture_size(&limits, 1920, 1080, 13).unwrap(), 1920 * 1080 * 64);
        let e = check_capture_size(&limits, 1920, 1080, 20).unwrap_err().to_string();
        assert!(e.contains("1920×1080") && e.contains("20 wavelengths") && e.contains("158 MiB"), "{e}");
        assert!(e.contains("128 MiB") && e.contains("smaller image"), "{e}");
    }
}
