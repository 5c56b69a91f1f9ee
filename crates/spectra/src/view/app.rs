//! The window: winit event loop, wgpu surface, renderer, egui overlay, camera input.
//!
//! Every redraw renders one frame with the applied settings, waits for its GPU timestamps,
//! copies the display image to the swap chain, draws the egui panel over it and presents.
//! The renderer renders at the window's size, so the frame-time readout is for that size.

use super::blit::Blit;
use super::camera::{CameraController, scene_bounds};
use super::controls::{Controls, FrameTimes, HELP, next_screenshot_path};
use super::water::WaterControls;
use anyhow::{Context, Result, anyhow};
use color::upsample::CoeffTable;
use render::{Gpu, RenderSettings, Renderer};
use std::collections::HashSet;
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

/// Everything `spectra view` decided before opening the window.
pub struct ViewOptions {
    pub scene: scene::Scene,
    pub settings: RenderSettings,
    pub size: (u32, u32),
    pub table: Arc<CoeffTable>,
    /// The water the camera is in (`--water`/`--depth` or the scene's), drawn with the
    /// underwater hooks.
    pub water: Option<scene::water::WaterMedium>,
    /// The underwater model's choices (`--scatter-steps`, `--phase-g`).
    pub water_options: render::passes::underwater::Options,
    /// The RGB medium filling the scene (`--rgb-medium` or the scene's), as its hooks.
    pub medium: Option<render::CustomShader>,
}

/// Radians of orbit per pixel of drag.
const DRAG_RADIANS_PER_PIXEL: f32 = 0.005;
/// Fly speed in scene sizes per second.
const FLY_SPEED: f32 = 0.4;

/// Opens the window and runs until it is closed. Errors (no adapter, a GPU failure) end the
/// loop and are returned.
pub fn run(event_loop: EventLoop<()>, opts: ViewOptions) -> Result<()> {
    let mut app = App { opts, state: None, error: None };
    event_loop.run_app(&mut app).context("running the window event loop")?;
    match app.error {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

struct App {
    opts: ViewOptions,
    state: Option<Running>,
    error: Option<anyhow::Error>,
}

struct Running {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    view_format: wgpu::TextureFormat,
    renderer: Renderer,
    blit: Blit,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    controls: Controls,
    camera: CameraController,
    home: CameraController,
    keys: HashSet<KeyCode>,
    buttons: HashSet<MouseButton>,
    cursor: Option<(f64, f64)>,
    last_frame: Instant,
    times: FrameTimes,
    adapter: String,
    /// egui textures to free after the next submitted frame.
    pending_free: Vec<egui::TextureId>,
    /// The camera and settings of the last frame: accumulation restarts when either changes.
    last_view: Option<(scene::Camera, RenderSettings)>,
    /// The water panel, when the camera is under water.
    water: Option<WaterState>,
    /// The environment panel.
    env: super::environment::EnvControls,
}

/// The water the viewer started with and the panel's edits of it.
struct WaterState {
    base: scene::water::WaterMedium,
    wanted: WaterControls,
    applied: WaterControls,
    error: Option<String>,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.state.is_some() {
            return;
        }
        match Running::new(event_loop, &self.opts) {
            Ok(s) => self.state = Some(s),
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(s) = self.state.as_mut() else { return };
        if let Err(e) = s.window_event(event_loop, event) {
            self.error = Some(e);
            event_loop.exit();
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        // Continuous rendering: the frame time is the point of the readout.
        if let Some(s) = &self.state {
            s.window.request_redraw();
        }
    }
}

impl Running {
    fn new(event_loop: &ActiveEventLoop, opts: &ViewOptions) -> Result<Self> {
        let attrs = Window::default_attributes()
            .with_title(format!("spectra view — {}", opts.scene.source))
            .with_inner_size(PhysicalSize::new(opts.size.0, opts.size.1));
        let window = Arc::new(event_loop.create_window(attrs).context("creating the window")?);
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
            Box::new(event_loop.owned_display_handle()),
        ));
        // With no usable backend at all, surface creation is the first thing to fail.
        let surface = instance.create_surface(window.clone()).map_err(|e| {
            anyhow!("{} (no backend could create a surface for the window: {e})", render::NO_ADAPTER_HELP)
        })?;
        let backends = wgpu::Backends::from_env().unwrap_or_default();
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::from_env().unwrap_or_default(),
            force_fallback_adapter: false,
            compatible_surface: Some(&surface),
            ..Default::default()
        }))
        .map_err(|e| anyhow!("{} (backends tried: {backends:?}; wgpu said: {e})", render::NO_ADAPTER_HELP))?;
        let gpu = Gpu::from_adapter(instance, adapter)?;
        let adapter_name = gpu.describe();
        let mut renderer = Renderer::with_gpu(gpu, opts.table.clone())?;
        renderer.set_scene(&opts.scene)?;
        if let Some(w) = &opts.water {
            renderer.set_custom_shader(render::passes::underwater::shader_with(w, &opts.water_options)?)?;
        }
        if let Some(m) = &opts.medium {
            renderer.set_custom_shader(m.clone())?;
        }
        let water = opts.water.as_ref().map(|w| {
            let c = WaterControls::new(w, opts.water_options);
            WaterState { base: w.clone(), wanted: c.clone(), applied: c, error: None }
        });

        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&renderer.gpu().adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| anyhow!("the window surface is not supported by {adapter_name}"))?;
        // Draw through an sRGB view so the renderer's sRGB bytes reach the screen unchanged.
        let view_format = config.format.add_srgb_suffix();
        if view_format != config.format {
            config.view_formats = vec![view_format];
        }
        config.present_mode = wgpu::PresentMode::AutoVsync;
        renderer.resize(config.width, config.height)?;
        let device = &renderer.gpu().device;
        surface.configure(device, &config);
        let blit = Blit::new(device, view_format);
        let egui_renderer =
            egui_wgpu::Renderer::new(device, view_format, egui_wgpu::RendererOptions::default());
        let ctx = egui::Context::default();
        let egui_state = egui_winit::State::new(
            ctx,
            egui::ViewportId::ROOT,
            event_loop,
            Some(window.scale_factor() as f32),
            None,
            Some(device.limits().max_texture_dimension_2d as usize),
        );
        let (center, diag) = scene_bounds(&opts.scene);
        let camera = CameraController::from_camera(&opts.scene.camera, center, diag);
        eprintln!("spectra view: {} on {adapter_name}\n  {HELP}", opts.scene.source);
        Ok(Running {
            window,
            surface,
            config,
            view_format,
            renderer,
            blit,
            egui_state,
            egui_renderer,
            controls: Controls::new(RenderSettings { timestamps: true, ..opts.settings.clone() }),
            camera,
            home: camera,
            keys: HashSet::new(),
            buttons: HashSet::new(),
            cursor: None,
            last_frame: Instant::now(),
            times: FrameTimes::default(),
            adapter: adapter_name,
            pending_free: Vec::new(),
            last_view: None,
            water,
            env: super::environment::EnvControls::new(opts.scene.environment.clone()),
        })
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, event: WindowEvent) -> Result<()> {
        let response = self.egui_state.on_window_event(&self.window, &event);
        let ctx = self.egui_state.egui_ctx().clone();
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => self.resize(size)?,
            WindowEvent::RedrawRequested => self.frame()?,
            WindowEvent::KeyboardInput { event, .. } => {
                let PhysicalKey::Code(code) = event.physical_key else { return Ok(()) };
                if event.state == ElementState::Released {
                    self.keys.remove(&code);
                    return Ok(());
                }
                if response.consumed || ctx.egui_wants_keyboard_input() {
                    return Ok(());
                }
                self.keys.insert(code);
                if !event.repeat {
                    self.shortcut(code, event_loop);
                }
            }
            WindowEvent::MouseInput { state, button, .. } => match state {
                ElementState::Pressed if !response.consumed && !ctx.is_pointer_over_egui() => {
                    self.buttons.insert(button);
                }
                _ => {
                    self.buttons.remove(&button);
                }
            },
            WindowEvent::CursorMoved { position, .. } => {
                let p = (position.x, position.y);
                if let Some(prev) = self.cursor {
                    let (dx, dy) = ((p.0 - prev.0) as f32, (p.1 - prev.1) as f32);
                    let k = DRAG_RADIANS_PER_PIXEL;
                    // The scene turns with the pointer: dragging right swings the eye left around the target.
                    if self.buttons.contains(&MouseButton::Left) {
                        self.camera.orbit(-dx * k, dy * k);
                    } else if self.buttons.contains(&MouseButton::Right) {
                        self.camera.look(-dx * k, -dy * k);
                    }
                }
                self.cursor = Some(p);
            }
            WindowEvent::CursorLeft { .. } => self.cursor = None,
            WindowEvent::MouseWheel { delta, .. } if !response.consumed && !ctx.is_pointer_over_egui() => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.camera.zoom(steps);
            }
            WindowEvent::Focused(false) => {
                self.keys.clear();
                self.buttons.clear();
            }
            _ => {}
        }
        Ok(())
    }

    fn shortcut(&mut self, code: KeyCode, event_loop: &ActiveEventLoop) {
        let shift = self.keys.contains(&KeyCode::ShiftLeft) || self.keys.contains(&KeyCode::ShiftRight);
        let c = &mut self.controls;
        match code {
            KeyCode::Escape => event_loop.exit(),
            KeyCode::F12 | KeyCode::KeyP => c.screenshot_requested = true,
            KeyCode::KeyR => c.reset_camera_requested = true,
            KeyCode::KeyM => c.cycle_mode(),
            KeyCode::Digit1 => c.set_mode(render::Mode::Rgb),
            KeyCode::Digit2 => c.set_mode(render::Mode::Naive),
            KeyCode::Digit3 => c.set_mode(render::Mode::Spectral),
            // `{` and `}` are Shift+[ and Shift+] on US layouts.
            KeyCode::BracketLeft if shift => c.scale_wavelengths(false),
            KeyCode::BracketRight if shift => c.scale_wavelengths(true),
            KeyCode::BracketLeft => c.step_wavelengths(-1),
            KeyCode::BracketRight => c.step_wavelengths(1),
            KeyCode::KeyT => c.cycle_tonemap(),
            KeyCode::KeyI => c.cycle_quadrature(),
            KeyCode::KeyO => c.cycle_observer(),
            KeyCode::KeyJ => c.accumulate = !c.accumulate,
            KeyCode::Minus => c.step_exposure(-0.5),
            KeyCode::Equal => c.step_exposure(0.5),
            _ => {}
        }
    }

    fn resize(&mut self, size: PhysicalSize<u32>) -> Result<()> {
        if size.width == 0 || size.height == 0 {
            return Ok(()); // minimised
        }
        self.config.width = size.width;
        self.config.height = size.height;
        self.surface.configure(&self.renderer.gpu().device, &self.config);
        self.renderer.resize(size.width, size.height)?;
        Ok(())
    }

    /// Applies held fly keys for the time since the last frame.
    fn fly(&mut self, dt: f32) {
        let k = |c: KeyCode| if self.keys.contains(&c) { 1.0f32 } else { 0.0 };
        let fast = if k(KeyCode::ShiftLeft) + k(KeyCode::ShiftRight) > 0.0 { 4.0 } else { 1.0 };
        let step = FLY_SPEED * fast * dt;
        let (f, r, u) = (
            k(KeyCode::KeyW) - k(KeyCode::KeyS),
            k(KeyCode::KeyD) - k(KeyCode::KeyA),
            k(KeyCode::KeyE) - k(KeyCode::KeyQ),
        );
        if (f, r, u) != (0.0, 0.0, 0.0) {
            self.camera.fly(f * step, r * step, u * step);
        }
    }

    fn frame(&mut self) -> Result<()> {
        let start = Instant::now();
        let dt = (start - self.last_frame).as_secs_f32().min(0.25);
        self.last_frame = start;
        self.fly(dt);
        if std::mem::take(&mut self.controls.reset_camera_requested) {
            self.camera = self.home;
        }

        // UI first, so this frame renders with what the user just changed.
        let raw = self.egui_state.take_egui_input(&self.window);
        let ctx = self.egui_state.egui_ctx().clone();
        let size = (self.config.width, self.config.height);
        let (times, adapter) = (self.times, self.adapter.clone());
        let controls = &mut self.controls;
        let water = &mut self.water;
        let env = &mut self.env;
        let mut out = ctx.run_pass(raw, |ctx| {
            egui::Window::new("spectra").default_pos([8.0, 8.0]).default_width(300.0).vscroll(true).show(
                ctx,
                |ui| {
                    controls.ui(ui, &times, &adapter, size);
                    ui.collapsing("environment", |ui| env.ui(ui));
                    if let Some(w) = water {
                        ui.collapsing("water", |ui| {
                            w.wanted.ui(ui);
                            if let Some(e) = &w.error {
                                ui.colored_label(egui::Color32::from_rgb(255, 110, 90), e);
                            }
                        });
                    }
                },
            );
        });
        self.egui_state.handle_platform_output(&self.window, out.platform_output);
        // New glyphs/images go up now, whether or not this frame reaches the screen; frees
        // wait until a frame that no longer uses them has been submitted.
        {
            let gpu = self.renderer.gpu();
            for (id, deltas) in out.textures_delta.set.drain() {
                for delta in &deltas {
                    self.egui_renderer.update_texture(&gpu.device, &gpu.queue, id, delta);
                }
            }
        }
        self.pending_free.extend(out.textures_delta.free.drain());
        self.controls.commit();
        if self.env.apply(&mut self.renderer) {
            self.last_view = None;
        }
        if let Some(w) = &mut self.water
            && w.wanted != w.applied
        {
            // A refused edit stays in the panel with its reason; the last good water stays on screen.
            match w.wanted.apply(&w.applied, &w.base, &mut self.renderer) {
                Ok(()) => {
                    w.applied = w.wanted.clone();
                    w.error = None;
                    self.last_view = None;
                }
                Err(e) => w.error = Some(format!("{e:#}")),
            }
        }

        let camera = self.camera.camera();
        let settings = self.accumulation_settings(&camera);
        self.renderer.render(&camera, &settings)?;
        self.controls.accumulated_frames = self.renderer.accumulated_frames();
        self.times.gpu = self.renderer.read_timings()?;

        if std::mem::take(&mut self.controls.screenshot_requested) {
            self.controls.status = match self.screenshot() {
                Ok(p) => {
                    println!("{}", p.display());
                    format!("saved {}", p.display())
                }
                Err(e) => {
                    eprintln!("error: {e:#}");
                    format!("screenshot failed: {e:#}")
                }
            };
        }

        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(f) | wgpu::CurrentSurfaceTexture::Suboptimal(f) => f,
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => return Ok(()),
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&self.renderer.gpu().device, &self.config);
                return Ok(());
            }
            other => return Err(anyhow!("the window surface failed: {other:?}")),
        };
        let target = frame.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.view_format),
            ..Default::default()
        });
        let gpu = self.renderer.gpu();
        let (device, queue) = (&gpu.device, &gpu.queue);
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("view") });
        let source = self.renderer.output_view().context("the renderer has no output")?;
        self.blit.record(device, &mut encoder, source, &target);

        let ppp = out.pixels_per_point;
        let jobs = ctx.tessellate(out.shapes, ppp);
        let screen = egui_wgpu::ScreenDescriptor { size_in_pixels: [size.0, size.1], pixels_per_point: ppp };
        let extra = self.egui_renderer.update_buffers(device, queue, &mut encoder, &jobs, &screen);
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("egui"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &target,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                })
                .forget_lifetime();
            self.egui_renderer.render(&mut pass, &jobs, &screen);
        }
        queue.submit(extra.into_iter().chain([encoder.finish()]));
        queue.present(frame);
        for id in std::mem::take(&mut self.pending_free) {
            self.egui_renderer.free_texture(&id);
        }

        // Exponential smoothing keeps the readout legible at 60 updates a second.
        let ms = start.elapsed().as_secs_f64() * 1e3;
        self.times.cpu_ms = if self.times.cpu_ms == 0.0 { ms } else { 0.9 * self.times.cpu_ms + 0.1 * ms };
        Ok(())
    }

    /// This frame's settings: the applied ones, plus (when accumulating) the next wavelength
    /// jitter and place in the pixel of the running mean (textures one level finer), which restarts whenever the camera or the settings changed. (A
    /// window resize restarts it inside the renderer.)
    fn accumulation_settings(&mut self, camera: &scene::Camera) -> RenderSettings {
        let applied = &self.controls.applied;
        self.renderer.set_accumulation(self.controls.accumulate);
        let same = self.last_view.as_ref().is_some_and(|(c, s)| same_camera(c, camera) && s == applied);
        if !same {
            self.renderer.reset_accumulation();
            self.last_view = Some((*camera, applied.clone()));
        }
        if !self.controls.accumulate {
            return applied.clone();
        }
        let k = self.renderer.accumulated_frames();
        RenderSettings {
            jitter: Some(super::controls::jitter_offset(k)),
            pixel_offset: Some(super::controls::pixel_jitter(k)),
            texture_lod_bias: super::controls::ACCUMULATED_LOD_BIAS,
            ..applied.clone()
        }
    }

    /// Writes the renderer's display image (without the panel) to `screenshot-<n>.png`.
    fn screenshot(&self) -> Result<std::path::PathBuf> {
        let (w, h) = self.renderer.size().context("nothing rendered yet")?;
        let rgba = self.renderer.read_ldr()?;
        let img = image::RgbaImage::from_raw(w, h, rgba).context("readback has the wrong size")?;
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, image::ImageFormat::Png).context("encoding PNG")?;
        let dir = std::env::current_dir().context("finding the current directory")?;
        let path = next_screenshot_path(&dir);
        compare::atomic::write_atomic(&path, bytes.get_ref())
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    }
}

/// Bit-for-bit the same view (any change, however small, makes the old mean wrong).
fn same_camera(a: &scene::Camera, b: &scene::Camera) -> bool {
    a.transform.to_cols_array().map(f32::to_bits) == b.transform.to_cols_array().map(f32::to_bits)
        && [a.yfov, a.znear, a.zfar].map(f32::to_bits) == [b.yfov, b.znear, b.zfar].map(f32::to_bits)
}
