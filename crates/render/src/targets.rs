//! The size-dependent render targets of one frame.

use crate::passes::accumulate::ACCUM_FORMAT;
use crate::passes::back_faces::BACK_FACES_FORMAT;
use crate::passes::{
    DEPTH_FORMAT, GBUFFER_COAT_FORMAT, GBUFFER_FILM_FORMAT, GBUFFER_FORMATS, GBUFFER_LAYER_FORMAT,
    HDR_FORMAT, LDR_FORMAT,
};

/// A 2D render target that passes also sample, with its view.
pub(crate) fn target(
    device: &wgpu::Device,
    (width, height): (u32, u32),
    label: &str,
    format: wgpu::TextureFormat,
    extra: wgpu::TextureUsages,
) -> (wgpu::Texture, wgpu::TextureView) {
    let t = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING | extra,
        view_formats: &[],
    });
    let v = t.create_view(&Default::default());
    (t, v)
}

/// G-buffer, depth, HDR and display targets at one size. Recreated on resize.
pub struct Targets {
    pub width: u32,
    pub height: u32,
    pub gbuffer: [wgpu::Texture; 3],
    pub gbuffer_views: [wgpu::TextureView; 3],
    /// The thin film per pixel (written only for scenes with a film).
    pub gbuffer_film: wgpu::Texture,
    pub gbuffer_film_view: wgpu::TextureView,
    /// The film's values and the anisotropy per pixel, in place of `gbuffer_film` for scenes
    /// with `KHR_materials_anisotropy` (`passes::GBUFFER_FILM_ANISOTROPY_FORMAT`), made at the
    /// first such scene ([`Self::bind_film_anisotropy`]).
    pub gbuffer_film_anisotropy: Option<(wgpu::Texture, wgpu::TextureView)>,
    /// Whether the shading inputs bind `gbuffer_film_anisotropy` where the film's target is read
    /// (the bind groups made while it is set do).
    pub film_anisotropy: bool,
    /// The clear coat per pixel (written only for scenes with a coat).
    pub gbuffer_coat: wgpu::Texture,
    pub gbuffer_coat_view: wgpu::TextureView,
    /// The specular strength and colour per pixel (written only for scenes with
    /// `KHR_materials_specular`).
    pub gbuffer_specular: wgpu::Texture,
    pub gbuffer_specular_view: wgpu::TextureView,
    /// The specular's values and the diffuse transmission per pixel, in place of
    /// `gbuffer_specular` for scenes with `KHR_materials_diffuse_transmission`
    /// (`passes::GBUFFER_SPECULAR_DT_FORMAT`), made at the first such scene
    /// ([`Self::bind_specular_dt`]).
    pub gbuffer_specular_dt: Option<(wgpu::Texture, wgpu::TextureView)>,
    /// Whether the shading inputs bind `gbuffer_specular_dt` where the specular's target is read.
    pub specular_dt: bool,
    /// The sheen per pixel (written only for scenes with `KHR_materials_sheen`).
    pub gbuffer_sheen: wgpu::Texture,
    pub gbuffer_sheen_view: wgpu::TextureView,
    pub depth: wgpu::Texture,
    pub depth_view: wgpu::TextureView,
    /// The ambient light's screen-space occlusion (`passes::occlusion`), written only in frames
    /// with ambient light to occlude.
    pub occlusion: wgpu::Texture,
    pub occlusion_view: wgpu::TextureView,
    /// Shading output (pass 2).
    pub hdr_shaded: wgpu::Texture,
    pub hdr_shaded_view: wgpu::TextureView,
    /// Custom-pass output (pass 3): the linear HDR image EXR output stores.
    pub hdr: wgpu::Texture,
    pub hdr_view: wgpu::TextureView,
    /// The accumulation's, made at the first accumulated frame (most renderers never
    /// accumulate: at 1920×1080 these are 83 MB).
    pub accum: Option<AccumTargets>,
    /// Tone-mapped, sRGB-encoded display image (pass 4).
    pub ldr: wgpu::Texture,
    pub ldr_view: wgpu::TextureView,
    /// The transmissive layer's, once a scene needs them.
    pub layer: Option<LayerTargets>,
}

impl Targets {
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let make = |label: &str, format: wgpu::TextureFormat, extra: wgpu::TextureUsages| {
            target(device, (width, height), label, format, wgpu::TextureUsages::COPY_SRC | extra)
        };
        let none = wgpu::TextureUsages::empty();
        let g: [(wgpu::Texture, wgpu::TextureView); 3] = [
            make("gbuffer base", GBUFFER_FORMATS[0], none),
            make("gbuffer normal", GBUFFER_FORMATS[1], none),
            make("gbuffer emission", GBUFFER_FORMATS[2], none),
        ];
        let [(g0, v0), (g1, v1), (g2, v2)] = g;
        let (gbuffer_film, gbuffer_film_view) = make("gbuffer film", GBUFFER_FILM_FORMAT, none);
        let (gbuffer_coat, gbuffer_coat_view) = make("gbuffer coat", GBUFFER_COAT_FORMAT, none);
        let (gbuffer_specular, gbuffer_specular_view) =
            make("gbuffer specular", crate::passes::GBUFFER_SPECULAR_FORMAT, none);
        let (gbuffer_sheen, gbuffer_sheen_view) =
            make("gbuffer sheen", crate::passes::GBUFFER_SHEEN_FORMAT, none);
        let (depth, depth_view) = make("depth", DEPTH_FORMAT, none);
        // Written by the occlusion pass in its compute stage, like the HDR targets below.
        let storage = wgpu::TextureUsages::STORAGE_BINDING;
        let (occlusion, occlusion_view) =
            make("occlusion", crate::passes::occlusion::OCCLUSION_FORMAT, storage);
        // Written by the shading's compute pass (either, as the custom pass runs or not).
        let (hdr_shaded, hdr_shaded_view) = make("hdr shaded", HDR_FORMAT, storage);
        let (hdr, hdr_view) = make("hdr", HDR_FORMAT, storage);
        let (ldr, ldr_view) = make("ldr", LDR_FORMAT, none);
        Targets {
            width,
            height,
            gbuffer: [g0, g1, g2],
            gbuffer_views: [v0, v1, v2],
            gbuffer_film,
            gbuffer_film_view,
            gbuffer_film_anisotropy: None,
            film_anisotropy: false,
            gbuffer_coat,
            gbuffer_coat_view,
            gbuffer_specular,
            gbuffer_specular_view,
            gbuffer_specular_dt: None,
            specular_dt: false,
            gbuffer_sheen,
            gbuffer_sheen_view,
            depth,
            depth_view,
            occlusion,
            occlusion_view,
            hdr_shaded,
            hdr_shaded_view,
            hdr,
            hdr_view,
            accum: None,
            ldr,
            ldr_view,
            layer: None,
        }
    }
}

impl Targets {
    /// Makes the film's target the anisotropic scenes' (`on`) or the others', making the
    /// former at its first use; true when that changed which one is bound (the caller then
    /// remakes the shading inputs).
    pub fn bind_film_anisotropy(&mut self, device: &wgpu::Device, on: bool) -> bool {
        if on && self.gbuffer_film_anisotropy.is_none() {
            self.gbuffer_film_anisotropy = Some(target(
                device,
                (self.width, self.height),
                "gbuffer film and anisotropy",
                crate::passes::GBUFFER_FILM_ANISOTROPY_FORMAT,
                wgpu::TextureUsages::COPY_SRC,
            ));
        }
        let changed = self.film_anisotropy != on;
        self.film_anisotropy = on;
        changed
    }

    /// [`Self::bind_film_anisotropy`] for the specular's target of scenes with a diffuse
    /// transmission.
    pub fn bind_specular_dt(&mut self, device: &wgpu::Device, on: bool) -> bool {
        if on && self.gbuffer_specular_dt.is_none() {
            self.gbuffer_specular_dt = Some(target(
                device,
                (self.width, self.height),
                "gbuffer specular and diffuse transmission",
                crate::passes::GBUFFER_SPECULAR_DT_FORMAT,
                wgpu::TextureUsages::COPY_SRC,
            ));
        }
        let changed = self.specular_dt != on;
        self.specular_dt = on;
        changed
    }

    /// The specular's target the G-buffer writes and the shading reads ([`Self::bind_specular_dt`]).
    pub fn specular_view(&self) -> &wgpu::TextureView {
        match (&self.gbuffer_specular_dt, self.specular_dt) {
            (Some((_, view)), true) => view,
            _ => &self.gbuffer_specular_view,
        }
    }

    /// The film's target the G-buffer writes and the shading reads ([`Self::bind_film_anisotropy`]).
    pub fn film_view(&self) -> &wgpu::TextureView {
        match (&self.gbuffer_film_anisotropy, self.film_anisotropy) {
            (Some((_, view)), true) => view,
            _ => &self.gbuffer_film_view,
        }
    }
}

/// The running mean of `hdr` over the accumulated frames (f32), the previous frame's mean
/// (copied aside each frame, read by the accumulation pass), and the mean in the HDR format
/// (post's input while accumulating).
pub struct AccumTargets {
    pub accum: wgpu::Texture,
    pub accum_view: wgpu::TextureView,
    pub accum_prev: wgpu::Texture,
    pub accum_prev_view: wgpu::TextureView,
    pub accum_display: wgpu::Texture,
    pub accum_display_view: wgpu::TextureView,
}

impl AccumTargets {
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let make = |label: &str, format: wgpu::TextureFormat, extra: wgpu::TextureUsages| {
            target(device, (width, height), label, format, wgpu::TextureUsages::COPY_SRC | extra)
        };
        let none = wgpu::TextureUsages::empty();
        let (accum, accum_view) = make("accum", ACCUM_FORMAT, none);
        let (accum_prev, accum_prev_view) = make("accum prev", ACCUM_FORMAT, wgpu::TextureUsages::COPY_DST);
        let (accum_display, accum_display_view) = make("accum display", HDR_FORMAT, none);
        AccumTargets { accum, accum_view, accum_prev, accum_prev_view, accum_display, accum_display_view }
    }
}

/// The transmissive layer's targets (`passes::gbuffer::Layer::Transmissive`), made at the
/// first frame of a scene with see-through materials: its own G-buffer (four targets, the
/// fourth holding the transmission and the film, and a fifth, the coat, written only where a
/// see-through material has one) and depth, and the background — the opaque layer's shaded
/// image, which the transmissive layer's shading samples where refracted rays leave the surface.
pub struct LayerTargets {
    pub gbuffer_views: [wgpu::TextureView; 5],
    pub depth: wgpu::Texture,
    pub depth_view: wgpu::TextureView,
    pub background: wgpu::Texture,
    pub background_view: wgpu::TextureView,
    /// The see-through meshes' nearest back faces (`passes::back_faces`) and their depth.
    pub back_faces_view: wgpu::TextureView,
    pub back_depth_view: wgpu::TextureView,
}

impl LayerTargets {
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Self {
        let make = |label: &str, format: wgpu::TextureFormat, extra: wgpu::TextureUsages| {
            target(device, (width, height), label, format, extra)
        };
        let none = wgpu::TextureUsages::empty();
        let views = [
            make("layer gbuffer base", GBUFFER_FORMATS[0], none).1,
            make("layer gbuffer normal", GBUFFER_FORMATS[1], none).1,
            make("layer gbuffer emission", GBUFFER_FORMATS[2], none).1,
            make("layer gbuffer transmission and film", GBUFFER_LAYER_FORMAT, none).1,
            make("layer gbuffer coat", GBUFFER_COAT_FORMAT, none).1,
        ];
        let (depth, depth_view) = make("layer depth", DEPTH_FORMAT, wgpu::TextureUsages::COPY_DST);
        let (background, background_view) = make("background", HDR_FORMAT, wgpu::TextureUsages::COPY_DST);
        let back_faces_view = make("back faces", BACK_FACES_FORMAT, none).1;
        let back_depth_view = make("back-face depth", DEPTH_FORMAT, none).1;
        LayerTargets {
            gbuffer_views: views,
            depth,
            depth_view,
            background,
            background_view,
            back_faces_view,
            back_depth_view,
        }
    }
}
