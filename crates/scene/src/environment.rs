//! Environment light: radiance arriving from infinitely far away, as an equirectangular image of
//! linear RGB radiance in the scene's colour space (linear sRGB), read by both renderers.
//!
//! # Convention (one home: both renderers call [`Environment::direction`] / [`Environment::uv`])
//!
//! Image coordinates (u, v) ∈ [0, 1)², u to the right, v down (row 0 at the top):
//!
//! ```text
//! θ = π·v            (0 = straight up, +Y)
//! φ = 2π·(u − ½)
//! d = (sin θ sin φ, cos θ, −sin θ cos φ)   then rotated by `rotation` about +Y
//! ```
//!
//! so the centre of the image is the horizon seen looking down −Z (the default glTF camera)
//! and +X is to its right, as in every glTF viewer. Each texel is a constant radiance over its
//! patch of sphere (solid angle `Δφ·(cos θ₀ − cos θ₁)`); the path tracer integrates exactly that
//! piecewise-constant function, the real-time renderer filters it (bilinear, prefiltered mips).
//!
//! The colour of a texel is a radiance, upsampled to a spectrum as an illuminant (the
//! "unbounded" variant both renderers use for RGB lights and emissive surfaces): `s·ρ(rgb/s)·W(λ)`
//! with `s = 2·max(rgb)` and W the colour space's white, so RGB (1, 1, 1) is exactly the white
//! (D65 for sRGB) and RGB and spectral modes see the same light.
//!
//! Input is refused, with the file and the reason, when it is not a regular file, not an HDR
//! image (`.hdr` Radiance RGBE or `.exr` OpenEXR), larger than [`MAX_INPUT_WIDTH`] ×
//! [`MAX_INPUT_HEIGHT`], not 2:1, empty, or has a negative, non-finite or brighter than
//! [`MAX_RADIANCE`] texel. Images wider than
//! [`WORKING_WIDTH`] are box-filtered down (exactly: the mean radiance of each block, so the
//! integral over the sphere is kept), which is what both renderers then see.

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

/// Widest equirectangular image accepted on input.
pub const MAX_INPUT_WIDTH: u32 = 16384;
/// Tallest equirectangular image accepted on input.
pub const MAX_INPUT_HEIGHT: u32 = 8192;
/// Largest input file (bytes): an HDR of the largest accepted size, uncompressed, fits easily.
pub const MAX_INPUT_BYTES: u64 = 1 << 30;
/// Most a decoder may allocate for one map: the largest accepted map as RGBA f32 (2 GiB). A map
/// of that size needs about 3.5 GB while it loads (decoded, then as texels), then is reduced to
/// [`WORKING_WIDTH`].
pub const MAX_DECODED_BYTES: u64 = 16 * MAX_INPUT_WIDTH as u64 * MAX_INPUT_HEIGHT as u64;
/// Width both renderers work at: larger images are box-filtered down to at most this.
pub const WORKING_WIDTH: u32 = 2048;
/// Largest accepted `intensity`.
pub const MAX_INTENSITY: f32 = 1e6;
/// Brightest texel accepted (radiance in the map's units): far above any sky (the sun's disc is
/// ~10⁷–10⁹ in photometric units), and low enough that the prefiltered maps (sums of π × the
/// brightest texel) and [`MAX_INTENSITY`] × it stay finite in f32.
pub const MAX_RADIANCE: f32 = 1e15;
/// Largest |rotation| accepted, degrees.
pub const MAX_ROTATION_DEGREES: f32 = 1e6;

/// The radiance of the default environment's sky (its ground is [`DEFAULT_GROUND`] × this).
pub const DEFAULT_SKY: f32 = 1.0;
/// Albedo of the default environment's ground: a Lambertian ground of this albedo under the
/// uniform sky has exactly this fraction of the sky's radiance.
pub const DEFAULT_GROUND: f32 = 0.25;

/// An environment map could not be used; the message names the file and the problem.
#[derive(Debug, thiserror::Error)]
#[error("environment {}: {message}", file.display())]
pub struct EnvironmentError {
    pub file: PathBuf,
    pub message: String,
}

/// An equirectangular environment (see the module docs for the convention).
#[derive(Clone, Debug)]
pub struct Environment {
    /// Where it came from: a path, `default` or `uniform`; used in messages and reports.
    pub source: String,
    pub width: u32,
    pub height: u32,
    /// Linear RGB radiance, row-major from the top row (+Y), before `intensity`.
    pub texels: Vec<Vec3>,
    /// Multiplies every texel.
    pub intensity: f32,
    /// Rotation about +Y, radians (positive turns the image towards +X... counter-clockwise seen
    /// from above).
    pub rotation: f32,
    /// Whether a renderer that cannot shadow environment light lights with the map's sun
    /// ([`Environment::sun`]) as a shadowed directional light, the rest as the map (default;
    /// `--no-env-sun`: false). The path tracer samples the whole map either way.
    pub sun_light: bool,
    /// The share of the map's light a compact bright region must give to be its sun
    /// ([`SUN_MIN_SHARE`] unless `--env-sun-share` says otherwise).
    pub sun_min_share: f32,
}

impl Environment {
    /// Validates an image of linear RGB radiance; `source` names it in errors.
    pub fn from_rgb(
        source: &str,
        width: u32,
        height: u32,
        texels: Vec<Vec3>,
    ) -> Result<Self, EnvironmentError> {
        let err = |message: String| EnvironmentError { file: PathBuf::from(source), message };
        if width == 0 || height == 0 {
            return Err(err(format!("the image is empty ({width}×{height})")));
        }
        if width > MAX_INPUT_WIDTH || height > MAX_INPUT_HEIGHT {
            return Err(err(format!(
                "{width}×{height} is larger than the {MAX_INPUT_WIDTH}×{MAX_INPUT_HEIGHT} accepted"
            )));
        }
        if width.abs_diff(2 * height) > 1 {
            return Err(err(format!(
                "an equirectangular (latitude-longitude) map is twice as wide as it is tall; this one is \
                 {width}×{height}"
            )));
        }
        if texels.len() != width as usize * height as usize {
            return Err(err(format!("{} texels for {width}×{height}", texels.len())));
        }
        if let Some(i) = texels.iter().position(|t| !t.is_finite() || t.min_element() < 0.0) {
            let (x, y) = (i as u32 % width, i as u32 / width);
            return Err(err(format!(
                "texel ({x}, {y}) is {} — radiance must be finite and not negative",
                texels[i]
            )));
        }
        if let Some(i) = texels.iter().position(|t| t.max_element() > MAX_RADIANCE) {
            let (x, y) = (i as u32 % width, i as u32 / width);
            return Err(err(format!(
                "texel ({x}, {y}) is {} — radiance must be at most {MAX_RADIANCE:e}",
                texels[i]
            )));
        }
        let env = Environment {
            source: source.to_string(),
            width,
            height,
            texels,
            intensity: 1.0,
            rotation: 0.0,
            sun_light: true,
            sun_min_share: SUN_MIN_SHARE,
        };
        Ok(env.reduced(WORKING_WIDTH))
    }

    /// Reads an equirectangular `.hdr` (Radiance RGBE) or `.exr` (OpenEXR, first RGB(A) layer)
    /// of linear radiance.
    pub fn load(path: &Path) -> Result<Self, EnvironmentError> {
        let err = |message: String| EnvironmentError { file: path.to_path_buf(), message };
        // What kind of file it is before what its name says (a directory named x.hdr).
        color::input::open_regular(path).map_err(|e| err(format!("cannot read it: {e}")))?;
        let format = Self::format_of(path)?;
        let bytes = color::input::read_regular(path, MAX_INPUT_BYTES)
            .map_err(|e| err(format!("cannot read it: {e}")))?;
        Self::decode(path, format, &bytes)
    }

    /// An environment from the bytes of a `.hdr` or `.exr` file; `name` (its extension picks the
    /// format) names it in messages. What [`Self::load`] does after reading, for tools and the
    /// fuzz harness.
    pub fn from_bytes(name: &Path, bytes: &[u8]) -> Result<Self, EnvironmentError> {
        Self::decode(name, Self::format_of(name)?, bytes)
    }

    fn format_of(path: &Path) -> Result<image::ImageFormat, EnvironmentError> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("hdr") => Ok(image::ImageFormat::Hdr),
            Some("exr") => Ok(image::ImageFormat::OpenExr),
            _ => Err(EnvironmentError {
                file: path.to_path_buf(),
                message: "not an HDR environment: give an equirectangular .hdr (Radiance) or .exr (OpenEXR) \
                          file of linear radiance"
                    .into(),
            }),
        }
    }

    fn decode(path: &Path, format: image::ImageFormat, bytes: &[u8]) -> Result<Self, EnvironmentError> {
        let err = |message: String| EnvironmentError { file: path.to_path_buf(), message };
        let mut header = None;
        // A Radiance file in any of its eight orientations, or with another magic line than
        // `#?RADIANCE`, as the standard one the decoder reads, and how to put its pixels back.
        let (bytes, layout) = match format {
            image::ImageFormat::Hdr => radiance_layout(bytes),
            _ => (std::borrow::Cow::Borrowed(bytes), None),
        };
        let bytes = &*bytes;
        if format == image::ImageFormat::OpenExr {
            // The `image` crate applies its limits only after the `exr` crate has decoded the
            // blocks, which allocate what the header claims (a 685-byte file asked for 35 GB;
            // found by crates/fuzz). So the headers are checked here first.
            let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
                .map_err(|e| err(format!("not a readable OpenExr image: {e}")))?;
            if meta.headers.len() > 16 {
                return Err(err(format!("{} layers; at most 16 are read", meta.headers.len())));
            }
            for h in &meta.headers {
                let (w, ht) = (h.layer_size.width(), h.layer_size.height());
                if w > MAX_INPUT_WIDTH as usize
                    || ht > MAX_INPUT_HEIGHT as usize
                    || h.channels.list.len() > 16
                {
                    return Err(err(format!(
                        "a layer is {w}×{ht} with {} channels; at most {MAX_INPUT_WIDTH}×{MAX_INPUT_HEIGHT} and 16 \
                         channels are accepted",
                        h.channels.list.len()
                    )));
                }
                // The map is the display window (the decoder fills it around the data window):
                // one larger than accepted said only "Memory limit exceeded".
                let d = h.shared_attributes.display_window.size;
                if d.width() > MAX_INPUT_WIDTH as usize || d.height() > MAX_INPUT_HEIGHT as usize {
                    return Err(err(format!(
                        "the display window is {}×{}; at most {MAX_INPUT_WIDTH}×{MAX_INPUT_HEIGHT} is accepted",
                        d.width(),
                        d.height()
                    )));
                }
            }
            header = exr_chromaticities(path, &meta)?;
        }
        if format == image::ImageFormat::Hdr {
            header = radiance_header(path, bytes, layout.is_some_and(|l| l.x_major))?;
        }
        let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes));
        reader.set_format(format);
        let mut limits = image::Limits::default();
        // (A picture stored column by column is decoded as its transpose.)
        let transposed = layout.is_some_and(|l| l.x_major);
        limits.max_image_width = Some(if transposed { MAX_INPUT_HEIGHT } else { MAX_INPUT_WIDTH });
        limits.max_image_height = Some(if transposed { MAX_INPUT_WIDTH } else { MAX_INPUT_HEIGHT });
        // The decoded image of the largest accepted size, as RGBA f32 (the EXR decoder's form; a
        // limit of half that refused the 16384×8192 maps promised above).
        limits.max_alloc = Some(MAX_DECODED_BYTES);
        reader.limits(limits);
        let img = reader.decode().map_err(|e| err(format!("not a readable {format:?} image: {e}")))?;
        let (w, h) = (img.width(), img.height());
        // Straight from the decoder's f32 buffer where it has one: a converted copy on the way
        // would add 1.5 GB at the largest size.
        let texels: Vec<Vec3> = match img {
            image::DynamicImage::ImageRgb32F(b) => b.as_raw().chunks_exact(3).map(Vec3::from_slice).collect(),
            image::DynamicImage::ImageRgba32F(b) => {
                b.as_raw().chunks_exact(4).map(Vec3::from_slice).collect()
            }
            other => other.into_rgb32f().pixels().map(|p| Vec3::from_array(p.0)).collect(),
        };
        let texels = match header {
            // Colours outside sRGB's gamut have no non-negative radiance in it: clipped to its
            // edge, as any sRGB renderer shows them.
            Some(m) => texels.into_iter().map(|t| (m * t).max(Vec3::ZERO)).collect(),
            None => texels,
        };
        let (w, h, texels) = match layout {
            Some(l) => l.to_standard(w, h, &texels),
            None => (w, h, texels),
        };
        Self::from_rgb(&path.display().to_string(), w, h, texels)
    }

    /// A constant radiance in every direction (the white furnace).
    pub fn uniform(rgb: Vec3) -> Self {
        Environment {
            source: "uniform".into(),
            width: 8,
            height: 4,
            texels: vec![rgb; 32],
            intensity: 1.0,
            rotation: 0.0,
            sun_light: true,
            sun_min_share: SUN_MIN_SHARE,
        }
    }

    /// The default environment: a uniform white sky of radiance [`DEFAULT_SKY`] (RGB (1, 1, 1),
    /// i.e. exactly the colour space's white, D65 for sRGB) above the horizon and a grey ground of
    /// albedo [`DEFAULT_GROUND`] below it. A neutral studio light that shows materials as they
    /// are, like the neutral environments glTF viewers light with.
    pub fn default_sky() -> Self {
        let (w, h) = (64u32, 32u32);
        let texels = (0..h)
            .flat_map(|y| {
                let v = if y < h / 2 { DEFAULT_SKY } else { DEFAULT_SKY * DEFAULT_GROUND };
                std::iter::repeat_n(Vec3::splat(v), w as usize)
            })
            .collect();
        Environment {
            source: "default".into(),
            width: w,
            height: h,
            texels,
            intensity: 1.0,
            rotation: 0.0,
            sun_light: true,
            sun_min_share: SUN_MIN_SHARE,
        }
    }

    pub fn with_intensity(mut self, k: f32) -> Result<Self, EnvironmentError> {
        if !k.is_finite() || !(0.0..=MAX_INTENSITY).contains(&k) {
            return Err(EnvironmentError {
                file: PathBuf::from(&self.source),
                message: format!("intensity must be between 0 and {MAX_INTENSITY} (got {k})"),
            });
        }
        self.intensity = k;
        Ok(self)
    }

    /// The share of the map's light that makes a compact bright region its sun, in (0, 1].
    pub fn with_sun_min_share(mut self, share: f32) -> Result<Self, EnvironmentError> {
        if !(share.is_finite() && share > 0.0 && share <= 1.0) {
            return Err(EnvironmentError {
                file: PathBuf::from(&self.source),
                message: format!("the sun's share of the map's light must be in (0, 1] (got {share})"),
            });
        }
        self.sun_min_share = share;
        Ok(self)
    }

    /// Rotation about +Y in degrees.
    pub fn with_rotation_degrees(mut self, deg: f32) -> Result<Self, EnvironmentError> {
        // Past 10⁶ an f32 holds the angle to worse than 0.1°: 1e30 degrees turned it arbitrarily.
        if !(deg.is_finite() && deg.abs() <= MAX_ROTATION_DEGREES) {
            return Err(EnvironmentError {
                file: PathBuf::from(&self.source),
                message: format!(
                    "rotation must be a finite number of degrees within ±{MAX_ROTATION_DEGREES:e} (got {deg})"
                ),
            });
        }
        self.rotation = deg.rem_euclid(360.0).to_radians();
        Ok(self)
    }

    /// Box-filters down by an integer factor until the width is at most `max_width`.
    fn reduced(self, max_width: u32) -> Self {
        if self.width <= max_width {
            return self;
        }
        let f = self.width.div_ceil(max_width);
        let (w, h) = (self.width / f, (self.height / f).max(1));
        let mut texels = vec![Vec3::ZERO; (w * h) as usize];
        // Each output texel is the solid-angle-weighted mean of its block, so ∫L dω is kept.
        for y in 0..h {
            for x in 0..w {
                let (mut sum, mut wsum) = (Vec3::ZERO, 0.0f32);
                for sy in y * f..((y + 1) * f).min(self.height) {
                    let s = self.row_solid_angle(sy);
                    for sx in x * f..(x + 1) * f {
                        sum += self.texels[(sy * self.width + sx) as usize] * s;
                        wsum += s;
                    }
                }
                texels[(y * w + x) as usize] = if wsum > 0.0 { sum / wsum } else { Vec3::ZERO };
            }
        }
        Environment { width: w, height: h, texels, ..self }
    }

    /// Solid angle of one texel of row `y` (all texels of a row are equal).
    pub fn row_solid_angle(&self, y: u32) -> f32 {
        let t0 = PI * y as f32 / self.height as f32;
        let t1 = PI * (y + 1) as f32 / self.height as f32;
        2.0 * PI / self.width as f32 * (t0.cos() - t1.cos())
    }

    /// World direction of image coordinates (u, v) ∈ [0, 1]², rotation applied.
    pub fn direction(&self, uv: Vec2) -> Vec3 {
        let theta = PI * uv.y;
        let phi = 2.0 * PI * (uv.x - 0.5) + self.rotation;
        let s = theta.sin();
        Vec3::new(s * phi.sin(), theta.cos(), -s * phi.cos())
    }

    /// Image coordinates of a unit world direction (inverse of [`Self::direction`]).
    pub fn uv(&self, d: Vec3) -> Vec2 {
        let phi = d.x.atan2(-d.z) - self.rotation;
        let u = (phi / (2.0 * PI) + 0.5).rem_euclid(1.0);
        let v = d.y.clamp(-1.0, 1.0).acos() / PI;
        Vec2::new(u, v)
    }

    /// Index into `texels` of the texel that direction `d` falls in.
    pub fn texel_index(&self, d: Vec3) -> usize {
        let uv = self.uv(d);
        let x = ((uv.x * self.width as f32) as u32).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as u32).min(self.height - 1);
        (y * self.width + x) as usize
    }

    /// Radiance (linear RGB, intensity applied) arriving from direction `d` (unit, pointing
    /// away from the scene): the texel's constant value.
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        self.texels[self.texel_index(d)] * self.intensity
    }

    /// ∫ L dω over the sphere per channel (intensity applied).
    pub fn integral(&self) -> Vec3 {
        (0..self.height)
            .map(|y| {
                let row: Vec3 =
                    self.texels[(y * self.width) as usize..((y + 1) * self.width) as usize].iter().sum();
                row * self.row_solid_angle(y)
            })
            .sum::<Vec3>()
            * self.intensity
    }

    /// Whether every texel is black (or the intensity is 0): such an environment lights nothing.
    pub fn is_black(&self) -> bool {
        self.intensity == 0.0 || self.texels.iter().all(|t| *t == Vec3::ZERO)
    }
}

/// Angular radius (degrees) around the brightest texel within which a sun is looked for.
pub const SUN_MAX_RADIUS_DEG: f32 = 6.0;
/// A texel belongs to the sun when its luminance is at least this fraction of the brightest's.
pub const SUN_THRESHOLD: f32 = 0.02;
/// A map has a sun when that region gives at least this share of the map's ∫ Y dω.
pub const SUN_MIN_SHARE: f32 = 0.15;
/// ... and when it is at most this solid angle (sr; a disc of 1.45° radius): a wider bright
/// region (a studio's soft box) is an area light, not a sun, and is left in the map.
pub const SUN_MAX_SOLID_ANGLE: f32 = 0.002;

/// The compact bright region of an environment map that a renderer without shadowed environment
/// light lights with as a shadowed directional light, its energy taken out of the map
/// ([`Environment::sun`], [`Environment::without_sun`]; the real-time renderer's
/// `set_environment`). The path tracer samples the full map.
#[derive(Clone, Debug, PartialEq)]
pub struct Sun {
    /// Unit direction towards the sun (rotation applied): the power-weighted mean of its texels'.
    pub direction: Vec3,
    /// ∫ L dω over the region, linear RGB, intensity not applied: the irradiance it gives a face
    /// turned to it (the region is small: cos ≈ 1 over it).
    pub irradiance: Vec3,
    /// Its solid angle, sr.
    pub solid_angle: f32,
    /// Its share of the map's ∫ Y dω.
    pub share: f32,
    /// Its texels (indices into `texels`).
    pub texels: Vec<usize>,
}

impl Sun {
    /// The angular radius (radians) of the disc of the region's solid angle, Ω = 2π(1 − cos ρ):
    /// what a renderer that lights with the sun as a direction widens its specular lobes by,
    /// since a smooth surface mirrors the whole disc, not a point.
    pub fn angular_radius(&self) -> f32 {
        (1.0 - self.solid_angle / std::f32::consts::TAU).clamp(-1.0, 1.0).acos()
    }
}

impl Environment {
    /// The map's sun, if it has one: the texels within [`SUN_MAX_RADIUS_DEG`] of the brightest
    /// (by luminance) whose luminance is at least [`SUN_THRESHOLD`] of its, when they give at least
    /// `sun_min_share` ([`SUN_MIN_SHARE`] by default) of the map's ∫ Y dω within at most
    /// [`SUN_MAX_SOLID_ANGLE`]. A uniform or
    /// overcast sky has none; neither has a studio's soft box (wider) or a sun so low that the sky
    /// outshines it.
    pub fn sun(&self) -> Option<Sun> {
        let y = |t: Vec3| 0.2126 * t.x + 0.7152 * t.y + 0.0722 * t.z;
        let (peak, peak_y) =
            self.texels.iter().enumerate().map(|(i, t)| (i, y(*t))).max_by(|a, b| a.1.total_cmp(&b.1))?;
        if peak_y <= 0.0 {
            return None;
        }
        let centre = |i: usize| {
            let (x, yy) = (i as u32 % self.width, i as u32 / self.width);
            self.direction(Vec2::new(
                (x as f32 + 0.5) / self.width as f32,
                (yy as f32 + 0.5) / self.height as f32,
            ))
        };
        let axis = centre(peak);
        let cos_max = SUN_MAX_RADIUS_DEG.to_radians().cos();
        let (mut total, mut power, mut irradiance, mut omega, mut dir) =
            (0.0f64, 0.0f64, Vec3::ZERO, 0.0f32, Vec3::ZERO);
        let mut texels = Vec::new();
        for row in 0..self.height {
            let w = self.row_solid_angle(row);
            for x in 0..self.width {
                let i = (row * self.width + x) as usize;
                let t = self.texels[i];
                let ly = y(t);
                total += f64::from(ly * w);
                if ly >= SUN_THRESHOLD * peak_y && centre(i).dot(axis) >= cos_max {
                    power += f64::from(ly * w);
                    irradiance += t * w;
                    omega += w;
                    dir += centre(i) * ly * w;
                    texels.push(i);
                }
            }
        }
        let share = (power / total.max(1e-30)) as f32;
        (share >= self.sun_min_share && omega <= SUN_MAX_SOLID_ANGLE).then(|| Sun {
            direction: dir.try_normalize().unwrap_or(axis),
            irradiance,
            solid_angle: omega,
            share,
            texels,
        })
    }

    /// This map with `sun`'s texels replaced by the mean of the texels around it (a ring as wide
    /// again), so that a renderer lighting with the sun as a light and the rest as the map counts
    /// its energy once.
    pub fn without_sun(&self, sun: &Sun) -> Environment {
        let inside: std::collections::HashSet<usize> = sun.texels.iter().copied().collect();
        let r = sun.solid_angle.max(1e-8).sqrt() * 2.0;
        let cos_ring = r.min(std::f32::consts::PI).cos();
        let (mut sum, mut wsum) = (Vec3::ZERO, 0.0f32);
        for row in 0..self.height {
            let w = self.row_solid_angle(row);
            for x in 0..self.width {
                let i = (row * self.width + x) as usize;
                let d = self.direction(Vec2::new(
                    (x as f32 + 0.5) / self.width as f32,
                    (row as f32 + 0.5) / self.height as f32,
                ));
                if !inside.contains(&i) && d.dot(sun.direction) >= cos_ring {
                    sum += self.texels[i] * w;
                    wsum += w;
                }
            }
        }
        let fill = if wsum > 0.0 { sum / wsum } else { Vec3::ZERO };
        let mut out = self.clone();
        for &i in &sun.texels {
            out.texels[i] = fill;
        }
        out
    }
}

/// Mean irradiance (in the units where the default sky gives π on an upward face) below which
/// emissive surfaces are glow, not lighting: 1 % of the default sky's.
pub const EMISSIVE_LIGHTING_THRESHOLD: f64 = 0.01 * std::f64::consts::PI;

/// What lights a scene, for the "is anything lit at all" decision both renderers share.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightSources {
    /// Punctual lights (sky stand-ins included).
    pub punctual: usize,
    /// Emissive polygons (`crate::emitters`).
    pub emitters: usize,
    /// The flux the untextured emissive surfaces emit (π·L·A each), spread over the scene's
    /// bounding sphere: the mean irradiance they give. A lamp (bevy's CornellBox.glb: ≈ 1.5)
    /// lights the scene; textured emitters (DamagedHelmet's glowing details, MultiUVTest's
    /// logos) never count: they are glow, shown but not lit with by glTF viewers.
    pub emissive_irradiance: f64,
    /// Whether a non-black environment surrounds the scene.
    pub environment: bool,
}

impl LightSources {
    pub fn of(scene: &crate::Scene) -> Self {
        let emitters = crate::emitters::emitters(scene);
        // Lamps are uniform emitters; a textured emitter (a screen, a logo, glowing details) is
        // glow that viewers show but do not light with, however bright.
        let lamp = |e: &&crate::emitters::Emitter| {
            let m = scene.meshes[e.mesh].material;
            scene.materials.get(m).is_some_and(|m| m.emissive_texture.is_none())
        };
        let flux: f64 = emitters.iter().filter(lamp).map(|e| std::f64::consts::PI * e.power()).sum();
        let radius = scene.bounds().map_or(0.0, |(lo, hi)| 0.5 * (hi - lo).length() as f64);
        let emissive_irradiance = if radius > 0.0 {
            flux / (4.0 * std::f64::consts::PI * radius * radius)
        } else if flux > 0.0 {
            f64::INFINITY
        } else {
            0.0
        };
        LightSources {
            punctual: scene.lights.len(),
            emitters: emitters.len(),
            emissive_irradiance,
            environment: scene.environment.as_ref().is_some_and(|e| !e.is_black()),
        }
    }

    /// Whether emissive surfaces are bright enough to count as the scene's lighting.
    pub fn emitters_light(&self) -> bool {
        self.emissive_irradiance >= EMISSIVE_LIGHTING_THRESHOLD
    }

    pub fn any(&self) -> bool {
        self.punctual > 0 || self.emitters_light() || self.environment
    }
}

/// The environment asked for on a command line: `--env`, `--env-intensity`, `--env-rotation`.
#[derive(Clone, Debug, Default)]
pub struct EnvironmentChoice {
    /// `none`, `default`, or a path to an equirectangular `.hdr`/`.exr`; `None` keeps the scene's
    /// own (`extras.environment`), or the default one when the scene has no light at all.
    pub env: Option<String>,
    pub intensity: Option<f32>,
    /// Degrees about +Y.
    pub rotation: Option<f32>,
    /// `--no-env-sun`: renderers light with the whole map, the sun included, unshadowed.
    pub no_sun: bool,
    /// `--env-sun-share`: the share of the map's light that makes a region its sun.
    pub sun_share: Option<f32>,
    /// The scene will be rendered under water (`--water`; a scene's own water settings count
    /// without it): a scene with no lights then gets a sun, not the default environment, which
    /// the path tracer cannot let in through the water's surface.
    pub under_water: bool,
}

/// The sun a scene with no lights gets under water ([`EnvironmentChoice::apply`]): the built-in
/// underwater scene's, white (RGB 1, 1, 1) with irradiance π on a plane facing it, from the
/// direction (0.45, 0.8, 0.3) above the surface, refracted into the water.
pub fn default_sun_under_water() -> crate::Light {
    let to_sun = glam::DVec3::new(0.45, 0.8, 0.3).normalize();
    // Snell at the flat surface: the horizontal part shrinks by the index, the rest points down.
    let h = glam::DVec3::new(-to_sun.x, 0.0, -to_sun.z) / crate::water::WATER_IOR;
    let direction = (h - glam::DVec3::Y * (1.0 - h.length_squared()).sqrt()).as_vec3();
    crate::Light {
        name: "sun (default, under water)".into(),
        kind: crate::LightKind::Directional { direction },
        emission: crate::Emission { rgb: glam::Vec3::ONE, intensity: std::f32::consts::PI, spectrum: None },
        stands_in_for: None,
    }
}

impl EnvironmentChoice {
    /// Sets `scene.environment` as asked and returns a message for the user when the choice was
    /// made for them (the default environment for a scene with no lights) or when nothing lights
    /// the scene at all (a warning: the image will be black).
    pub fn apply(&self, scene: &mut crate::Scene) -> Result<Option<String>, EnvironmentError> {
        let mut note = None;
        match self.env.as_deref() {
            Some("none") => scene.environment = None,
            Some("default") => scene.environment = Some(Environment::default_sky()),
            Some(path) => scene.environment = Some(Environment::load(Path::new(path))?),
            None => {
                if !LightSources::of(scene).any() && (self.under_water || scene.water.is_some()) {
                    scene.lights.push(default_sun_under_water());
                    crate::sky::sync(scene).map_err(|e| EnvironmentError {
                        file: PathBuf::from(&scene.source),
                        message: format!("water.sky: {e}"),
                    })?;
                    note = Some(format!(
                        "note: {} has no lights: under water, lighting it with a sun overhead (white, \
                         irradiance π; the built-in underwater scene's), not the default environment, which \
                         no light reaches through the water's surface in the path tracer (--env default \
                         for the real-time renderer's environment lighting)",
                        scene.source
                    ));
                } else if !LightSources::of(scene).any() {
                    scene.environment = Some(Environment::default_sky());
                    note = Some(format!(
                        "note: {} has no lights: lighting it with the default environment (a uniform white \
                         sky over a grey ground; --env FILE.hdr for another, --env none for none)",
                        scene.source
                    ));
                } else if LightSources::of(scene).punctual == 0 && !LightSources::of(scene).environment {
                    // Not an error, but a dark image a user may not expect: say what lights it.
                    note = Some(format!(
                        "note: {} has no lights and no environment: it is lit by its emissive surfaces \
                         alone (their light reaches only what they face; --env default adds a sky around \
                         it)",
                        scene.source
                    ));
                }
            }
        }
        if self.intensity.is_some() || self.rotation.is_some() || self.sun_share.is_some() {
            let Some(env) = scene.environment.take() else {
                return Err(EnvironmentError {
                    file: PathBuf::from(self.env.as_deref().unwrap_or("none")),
                    message:
                        "--env-intensity / --env-rotation / --env-sun-share given, but the scene has no \
                              environment (give --env FILE or --env default)"
                            .into(),
                });
            };
            // Named by their flags, as the message above.
            let flag = |name: &'static str| {
                move |e: EnvironmentError| EnvironmentError { message: format!("{name}: {}", e.message), ..e }
            };
            let env = match self.intensity {
                Some(k) => env.with_intensity(k).map_err(flag("--env-intensity"))?,
                None => env,
            };
            let env = match self.rotation {
                Some(r) => env.with_rotation_degrees(r).map_err(flag("--env-rotation"))?,
                None => env,
            };
            let env = match self.sun_share {
                Some(share) => env.with_sun_min_share(share).map_err(flag("--env-sun-share"))?,
                None => env,
            };
            scene.environment = Some(env);
        }
        if let Some(env) = scene.environment.as_mut() {
            env.sun_light = !self.no_sun;
        }
        if !LightSources::of(scene).any() {
            // An environment scaled to nothing, or black in every texel, is there, and says so;
            // otherwise there is none.
            note = Some(match scene.environment.as_ref() {
                Some(e) if e.intensity == 0.0 => format!(
                    "warning: nothing lights {}: it has no lights and no emissive surface bright enough to \
                     light it, and its environment ({}) is scaled to 0 by --env-intensity, so the \
                     image will be (nearly) black",
                    scene.source, e.source
                ),
                Some(e) => format!(
                    "warning: nothing lights {}: it has no lights and no emissive surface bright enough to \
                     light it, and its environment ({}) is black in every texel, so the image will be \
                     (nearly) black",
                    scene.source, e.source
                ),
                None => format!(
                    "warning: nothing lights {}: it has no lights, no environment and no emissive surface \
                     bright enough to light it, so the image will be (nearly) black (drop --env none, or give \
                     --env FILE.hdr)",
                    scene.source
                ),
            });
        }
        Ok(note)
    }
}

/// An OpenEXR's `chromaticities` attribute (its RGB's primaries and white), as the matrix to
/// linear sRGB (`None`: absent or Rec. 709's, the assumed default).
fn exr_chromaticities(
    path: &Path,
    meta: &exr::meta::MetaData,
) -> Result<Option<glam::Mat3>, EnvironmentError> {
    let Some(c) = meta.headers.first().and_then(|h| h.shared_attributes.chromaticities) else {
        return Ok(None);
    };
    let n: Vec<f64> =
        [c.red, c.green, c.blue, c.white].iter().flat_map(|v| [f64::from(v.0), f64::from(v.1)]).collect();
    let m = color::colorspace::to_srgb_from_chromaticities(&n).ok_or_else(|| EnvironmentError {
        file: path.to_path_buf(),
        message: format!(
            "attribute chromaticities: {n:?} are not the x y of red, green, blue and white of a colour space"
        ),
    })?;
    Ok((m != glam::DMat3::IDENTITY).then(|| m.as_mat3()))
}

/// How a Radiance file lays out its scanlines (its resolution line, such as `+Y 512 +X 1024`),
/// when that is not the standard `-Y H +X W` (top to bottom, each left to right).
#[derive(Clone, Copy, Debug, PartialEq)]
struct RadianceLayout {
    /// Scanlines are columns (`±X n ±Y m`), not rows.
    x_major: bool,
    /// Columns run right to left (`-X`).
    x_decreasing: bool,
    /// Rows run bottom to top (`+Y`; Radiance's Y points up).
    y_increasing: bool,
}

impl RadianceLayout {
    /// The picture, row 0 at the top and each row left to right, from the decoded scanlines
    /// (`n` of `len` pixels: the decoder's width × height).
    fn to_standard(self, len: u32, n: u32, px: &[Vec3]) -> (u32, u32, Vec<Vec3>) {
        let (w, h) = if self.x_major { (n, len) } else { (len, n) };
        let mut out = vec![Vec3::ZERO; px.len()];
        for i in 0..n {
            for j in 0..len {
                let (x, y) = if self.x_major { (i, j) } else { (j, i) };
                let x = if self.x_decreasing { w - 1 - x } else { x };
                let y = if self.y_increasing { h - 1 - y } else { y };
                out[(y * w + x) as usize] = px[(i * len + j) as usize];
            }
        }
        (w, h, out)
    }
}

/// A Radiance file as the `image` decoder reads it (which knows only `#?RADIANCE` and `-Y H +X W`),
/// with the layout to undo afterwards. Radiance writes pictures in eight orientations (`pflip`,
/// `protate`, other writers: `+Y H +X W` is upside down, `+X W -Y H` column by column) and other
/// programs' files begin with another magic line such as `#?RGBE` (stb_image reads both); they
/// were refused ("does not support the format features Orientation +Y +X", "signature not
/// found"). Anything unexpected is left for the decoder to report.
fn radiance_layout(bytes: &[u8]) -> (std::borrow::Cow<'_, [u8]>, Option<RadianceLayout>) {
    use std::borrow::Cow;
    let unchanged = (Cow::Borrowed(bytes), None);
    let line_end = |from: usize| bytes[from..].iter().position(|&b| b == b'\n').map(|i| from + i);
    let Some(magic_end) = line_end(0) else { return unchanged };
    if !bytes.starts_with(b"#?") {
        return unchanged;
    }
    // The header's lines up to the empty one, then the resolution line.
    let mut at = magic_end + 1;
    loop {
        let Some(end) = line_end(at) else { return unchanged };
        let empty = end == at;
        at = end + 1;
        if empty {
            break;
        }
    }
    let Some(res_end) = line_end(at) else { return unchanged };
    let Ok(res) = std::str::from_utf8(&bytes[at..res_end]) else { return unchanged };
    let f: Vec<&str> = res.split_whitespace().collect();
    let [a, n1, b, n2] = f[..] else { return unchanged };
    let (Ok(n1), Ok(n2)) = (n1.parse::<u32>(), n2.parse::<u32>()) else { return unchanged };
    let layout = match (a, b) {
        ("-Y" | "+Y", "-X" | "+X") => {
            RadianceLayout { x_major: false, x_decreasing: b == "-X", y_increasing: a == "+Y" }
        }
        ("-X" | "+X", "-Y" | "+Y") => {
            RadianceLayout { x_major: true, x_decreasing: a == "-X", y_increasing: b == "+Y" }
        }
        _ => return unchanged,
    };
    let standard = RadianceLayout { x_major: false, x_decreasing: false, y_increasing: false };
    if layout == standard && &bytes[..magic_end] == b"#?RADIANCE" {
        return unchanged;
    }
    let mut out = b"#?RADIANCE".to_vec();
    out.extend_from_slice(&bytes[magic_end..at]);
    out.extend_from_slice(format!("-Y {n1} +X {n2}").as_bytes());
    out.extend_from_slice(&bytes[res_end..]);
    (Cow::Owned(out), (layout != standard).then_some(layout))
}

/// What a Radiance header says about its pixels, as the matrix that takes them to linear sRGB
/// radiance, or `None` where they already are: `EXPOSURE` (every factor the file's writers
/// applied; the pixels are divided by their product, per the Radiance file format) and
/// `COLORCORR` (the same, per channel), and `PRIMARIES` other than Rec. 709's (converted, with
/// Bradford adaptation from the file's white to D65). These used to be ignored: a file written
/// with `EXPOSURE=4` rendered four times too bright.
fn radiance_header(
    path: &Path,
    bytes: &[u8],
    transposed: bool,
) -> Result<Option<glam::Mat3>, EnvironmentError> {
    use glam::{DMat3, DVec3};
    let err = |message: String| EnvironmentError { file: path.to_path_buf(), message };
    // The header ends at the first empty line; Radiance's own tools write a few hundred bytes.
    let head = &bytes[..bytes.len().min(1 << 16)];
    let xyze = head
        .split(|&b| b == b'\n')
        .take_while(|l| !l.is_empty())
        .any(|l| std::str::from_utf8(l).is_ok_and(|l| l.trim().replace(' ', "") == "FORMAT=32-bit_rle_xyze"));
    if xyze {
        return Err(err(
            "header FORMAT=32-bit_rle_xyze: CIE XYZ pixels are not supported; convert to RGB with Radiance's \
             `ra_xyze -r in.hdr out.hdr`"
                .into(),
        ));
    }
    let meta = image::codecs::hdr::HdrDecoder::new(std::io::Cursor::new(bytes))
        .map_err(|e| err(format!("not a readable Hdr image: {e}")))?
        .metadata();
    // The decoder's own limit would say only "Memory limit exceeded".
    let (w, h) = if transposed { (meta.height, meta.width) } else { (meta.width, meta.height) };
    if w > MAX_INPUT_WIDTH || h > MAX_INPUT_HEIGHT {
        return Err(err(format!("{w}×{h} is larger than the {MAX_INPUT_WIDTH}×{MAX_INPUT_HEIGHT} accepted")));
    }
    let positive = |v: f32| v.is_finite() && v > 0.0;
    let mut scale = DVec3::ONE;
    if let Some(e) = meta.exposure {
        if !positive(e) {
            return Err(err(format!(
                "header EXPOSURE: the product of its values is {e}; it must be a positive number"
            )));
        }
        scale /= f64::from(e);
    }
    if let Some((r, g, b)) = meta.color_correction {
        if ![r, g, b].into_iter().all(positive) {
            return Err(err(format!("header COLORCORR: {r} {g} {b}; each factor must be a positive number")));
        }
        scale /= DVec3::new(r.into(), g.into(), b.into());
    }
    let mut m = DMat3::from_diagonal(scale);
    if let Some((_, v)) = meta.custom_attributes.iter().rev().find(|(k, _)| k == "PRIMARIES") {
        let n: Vec<f64> = v.split_whitespace().filter_map(|x| x.parse().ok()).collect();
        let Some(c) = color::colorspace::to_srgb_from_chromaticities(&n) else {
            return Err(err(format!(
                "header PRIMARIES: '{}' is not eight chromaticities (x y of red, green, blue, white) of a colour space",
                v.trim()
            )));
        };
        m = c * m;
    }
    Ok((m != DMat3::IDENTITY).then(|| m.as_mat3()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_and_uv_are_inverse_and_follow_the_convention() {
        let mut e = Environment::default_sky();
        for rot in [0.0f32, 0.7, 3.0] {
            e.rotation = rot;
            for (u, v) in [(0.1, 0.2), (0.5, 0.5), (0.9, 0.7), (0.3, 0.95)] {
                let d = e.direction(Vec2::new(u, v));
                assert!((d.length() - 1.0).abs() < 1e-5);
                let back = e.uv(d);
                assert!((back - Vec2::new(u, v)).abs().max_element() < 1e-5, "{u} {v} {back}");
            }
        }
        e.rotation = 0.0;
        assert!((e.direction(Vec2::new(0.5, 0.5)) - Vec3::NEG_Z).length() < 1e-6);
        assert!((e.direction(Vec2::new(0.75, 0.5)) - Vec3::X).length() < 1e-6);
        assert!((e.direction(Vec2::new(0.3, 0.0)) - Vec3::Y).length() < 1e-6);
    }

    #[test]
    fn solid_angles_cover_the_sphere() {
        let e = Environment::default_sky();
        let total: f32 = (0..e.height).map(|y| e.row_solid_angle(y) * e.width as f32).sum();
        assert!((total - 4.0 * PI).abs() < 1e-4);
        let u = Environment::uniform(Vec3::ONE);
        assert!((u.integral() - Vec3::splat(4.0 * PI)).abs().max_element() < 1e-4);
    }

    #[test]
    fn default_sky_is_white_above_and_ground_below() {
        let e = Environment::default_sky();
        assert_eq!(e.radiance(Vec3::new(0.1, 0.9, 0.2).normalize()), Vec3::ONE);
        assert_eq!(e.radiance(Vec3::new(0.1, -0.9, 0.2).normalize()), Vec3::splat(DEFAULT_GROUND));
    }

    #[test]
    fn reduction_keeps_the_integral() {
        let (w, h) = (WORKING_WIDTH * 3, WORKING_WIDTH * 3 / 2);
        let texels = (0..w * h).map(|i| Vec3::splat(((i as u64 * 7919) % 13) as f32)).collect();
        let big = Environment {
            source: "t".into(),
            width: w,
            height: h,
            texels,
            intensity: 1.0,
            rotation: 0.0,
            sun_light: true,
            sun_min_share: SUN_MIN_SHARE,
        };
        let want = big.integral();
        let small = big.reduced(WORKING_WIDTH);
        assert!(small.width <= WORKING_WIDTH);
        assert!(((small.integral() - want) / want).abs().max_element() < 1e-3);
    }

    #[test]
    fn bad_images_are_refused_with_the_reason() {
        let e = |w, h, t: Vec<Vec3>| Environment::from_rgb("sky.hdr", w, h, t).unwrap_err().to_string();
        assert!(e(0, 0, vec![]).contains("empty"));
        let m = e(100000, 1, vec![Vec3::ONE; 100000]);
        assert!(m.contains("sky.hdr") && m.contains("100000"), "{m}");
        assert!(e(4, 4, vec![Vec3::ONE; 16]).contains("twice as wide"));
        let mut t = vec![Vec3::ONE; 8];
        t[5] = Vec3::new(f32::NAN, 0.0, 0.0);
        assert!(e(4, 2, t.clone()).contains("(1, 1)"));
        t[5] = Vec3::new(-1.0, 0.0, 0.0);
        assert!(e(4, 2, t.clone()).contains("negative"));
        t[5] = Vec3::new(0.0, 2.0 * MAX_RADIANCE, 0.0);
        let m = e(4, 2, t.clone());
        assert!(m.contains("(1, 1)") && m.contains("at most"), "{m}");
        t[5] = Vec3::splat(MAX_RADIANCE);
        assert!(Environment::from_rgb("sky.hdr", 4, 2, t).is_ok());
        let env = Environment::uniform(Vec3::ONE);
        assert!(env.clone().with_intensity(f32::NAN).unwrap_err().to_string().contains("intensity"));
        assert!(env.with_rotation_degrees(f32::INFINITY).is_err());
    }

    /// Under water the path tracer lets no environment in through the surface (it refuses
    /// one), so a scene with no lights gets a sun there — in both renderers, which read the same
    /// scene — and keeps it out of the air. A sun refracted into water: steeper than in air,
    /// still a unit vector.
    #[test]
    fn a_scene_without_lights_gets_a_sun_under_water() {
        let mut s = crate::builtin("cornell").unwrap();
        s.lights.clear();
        s.materials.iter_mut().for_each(|m| m.emissive = Vec3::ZERO);
        let mut wet = s.clone();
        let choice = EnvironmentChoice { under_water: true, ..Default::default() };
        let note = choice.apply(&mut wet).unwrap().unwrap();
        assert!(note.contains("under water") && note.contains("sun"), "{note}");
        assert!(wet.environment.is_none());
        assert_eq!(wet.lights.len(), 1);
        let crate::LightKind::Directional { direction } = wet.lights[0].kind else { panic!("a sun") };
        assert!((direction.length() - 1.0).abs() < 1e-6 && direction.y < -0.8, "{direction}");
        // The scene's own water counts as under water; an explicit choice is kept.
        let mut own = crate::builtin("underwater").unwrap();
        own.lights.clear();
        own.materials.iter_mut().for_each(|m| m.emissive = Vec3::ZERO);
        EnvironmentChoice::default().apply(&mut own).unwrap();
        assert!(own.environment.is_none() && !own.lights.is_empty());
        let mut asked = s.clone();
        let choice =
            EnvironmentChoice { under_water: true, env: Some("default".into()), ..Default::default() };
        choice.apply(&mut asked).unwrap();
        assert!(asked.environment.is_some() && asked.lights.is_empty());
    }

    #[test]
    fn a_scene_without_lights_gets_the_default_environment_and_none_warns() {
        let mut s = crate::builtin("cornell").unwrap();
        s.lights.clear();
        s.materials.iter_mut().for_each(|m| m.emissive = Vec3::ZERO);
        let mut auto = s.clone();
        let note = EnvironmentChoice::default().apply(&mut auto).unwrap().unwrap();
        assert!(note.contains("default environment"), "{note}");
        assert_eq!(auto.environment.as_ref().unwrap().source, "default");
        let mut none = s.clone();
        let choice = EnvironmentChoice { env: Some("none".into()), ..Default::default() };
        assert!(choice.apply(&mut none).unwrap().unwrap().contains("black"));
        let lit = crate::builtin("cornell").unwrap();
        let mut kept = lit.clone();
        assert!(EnvironmentChoice::default().apply(&mut kept).unwrap().is_none());
        assert!(kept.environment.is_none());
        let turned = EnvironmentChoice {
            env: Some("default".into()),
            intensity: Some(2.0),
            rotation: Some(90.0),
            no_sun: false,
            sun_share: None,
            under_water: false,
        };
        let mut t = lit.clone();
        turned.apply(&mut t).unwrap();
        let e = t.environment.unwrap();
        assert_eq!(e.intensity, 2.0);
        assert!((e.rotation - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        // Lit by an emissive lamp alone (its stand-in light removed): no default environment;
        // the same lamp dimmed to a glow: the default environment.
        let mut lamp_only = lit.clone();
        lamp_only.lights.clear();
        assert!(LightSources::of(&lamp_only).emitters_light(), "{:?}", LightSources::of(&lamp_only));
        let mut lit_by_lamp = lamp_only.clone();
        let note = EnvironmentChoice::default().apply(&mut lit_by_lamp).unwrap().unwrap();
        assert!(note.contains("emissive surfaces alone") && note.contains("--env default"), "{note}");
        assert!(lit_by_lamp.environment.is_none());
        let mut glow = lamp_only.clone();
        glow.materials.iter_mut().for_each(|m| m.emissive *= 1e-4);
        assert!(!LightSources::of(&glow).emitters_light());
        assert!(EnvironmentChoice::default().apply(&mut glow).unwrap().is_some());
        // The same lamp with an emissive texture (white, so it is as bright): a textured emitter
        // is glow, not a lamp.
        let mut textured = lamp_only.clone();
        textured.textures.push(crate::Texture {
            name: "white".into(),
            width: 1,
            height: 1,
            rgba8: vec![255; 4],
            srgb: true,
            sampler: Default::default(),
        });
        let t = textured.textures.len() - 1;
        textured.materials.iter_mut().filter(|m| m.emissive.max_element() > 0.0).for_each(|m| {
            m.emissive_texture = Some(crate::TextureRef::new(t));
        });
        assert!(!LightSources::of(&textured).emitters_light());
        let orphan = EnvironmentChoice {
            env: Some("none".into()),
            intensity: Some(2.0),
            rotation: None,
            no_sun: false,
            sun_share: None,
            under_water: false,
        };
        assert!(orphan.apply(&mut lit.clone()).unwrap_err().to_string().contains("--env-intensity"));
    }

    #[test]
    fn an_hdr_larger_than_accepted_says_its_size() {
        for (w, h) in [(32768u32, 16384u32), (16384, 8193), (i32::MAX as u32, 2)] {
            let bytes = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
            let e = Environment::from_bytes(Path::new("big.hdr"), &bytes).unwrap_err().to_string();
            assert!(
                e.contains("big.hdr") && e.contains(&format!("{w}×{h}")) && e.contains("16384×8192"),
                "{e}"
            );
        }
    }

    #[test]
    fn an_hdr_file_round_trips() {
        let dir = std::env::temp_dir().join(format!("spectra-env-hdr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.hdr");
        let px: Vec<image::Rgb<f32>> = (0..32).map(|i| image::Rgb([i as f32 * 0.5, 1.0, 0.25])).collect();
        let f = std::fs::File::create(&p).unwrap();
        image::codecs::hdr::HdrEncoder::new(f).encode(&px, 8, 4).unwrap();
        let e = Environment::load(&p).unwrap();
        assert_eq!((e.width, e.height), (8, 4));
        assert!((e.texels[3] - Vec3::new(1.5, 1.0, 0.25)).abs().max_element() < 0.02);
        std::fs::remove_dir_all(&dir).ok();
    }

    /// Radiance headers are honoured (they used to be ignored): EXPOSURE divides, cumulatively,
    /// COLORCORR per channel, PRIMARIES other than Rec. 709's are converted; bad values name
    /// the header field.
    /// Radiance pictures stored in any of the eight orientations, or under another magic line
    /// (`#?RGBE`), read as the same picture (all but `-Y H +X W` under `#?RADIANCE` were refused).
    #[test]
    fn radiance_files_in_every_orientation_read_as_the_same_picture() {
        let (w, h) = (16u32, 8u32);
        // Exact RGBE texels: red says the column, green the row (value = byte / 128).
        let px = |x: u32, y: u32| [16 + x as u8, 16 + y as u8, 100, 129];
        let want: Vec<Vec3> =
            (0..h * w).map(|i| Vec3::new((16 + i % w) as f32, (16 + i / w) as f32, 100.0) / 128.0).collect();
        let file = |magic: &str, res: &str| {
            let f: Vec<&str> = res.split_whitespace().collect();
            let (major, minor) = (f[0], f[2]);
            let (n1, n2) = (f[1].parse::<u32>().unwrap(), f[3].parse::<u32>().unwrap());
            let mut b = format!("{magic}\nFORMAT=32-bit_rle_rgbe\n\n{res}\n").into_bytes();
            for i in 0..n1 {
                for j in 0..n2 {
                    // Radiance's X points right and Y up: "-Y" is top to bottom.
                    let at = |axis: &str, k: u32| match axis {
                        "+X" | "-Y" => k,
                        "-X" => w - 1 - k,
                        _ => h - 1 - k,
                    };
                    let (x, y) = if major.ends_with('Y') {
                        (at(minor, j), at(major, i))
                    } else {
                        (at(major, i), at(minor, j))
                    };
                    b.extend_from_slice(&px(x, y));
                }
            }
            b
        };
        for res in [
            "-Y 8 +X 16",
            "+Y 8 +X 16",
            "-Y 8 -X 16",
            "+Y 8 -X 16",
            "+X 16 -Y 8",
            "+X 16 +Y 8",
            "-X 16 -Y 8",
            "-X 16 +Y 8",
        ] {
            for magic in ["#?RADIANCE", "#?RGBE"] {
                let e = Environment::from_bytes(Path::new("o.hdr"), &file(magic, res))
                    .unwrap_or_else(|e| panic!("{magic} {res}: {e}"));
                assert_eq!((e.width, e.height), (w, h), "{magic} {res}");
                assert_eq!(e.texels, want, "{magic} {res}");
            }
        }
        // A picture stored column by column is limited by its own size, not its transpose's.
        let big = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n+X 16385 -Y 8192\n";
        let m = Environment::from_bytes(Path::new("big.hdr"), big.as_bytes()).unwrap_err().to_string();
        assert!(m.contains("16385×8192") && m.contains("16384×8192"), "{m}");
    }

    /// An EXR whose display window (the map the decoder makes) is larger than accepted around a
    /// small data window is refused with its size, not the decoder's "Memory limit exceeded".
    #[test]
    fn an_exr_display_window_larger_than_accepted_says_its_size() {
        use exr::prelude::*;
        let px = SpecificChannels::rgb(|_: Vec2<usize>| (1.0f32, 1.0f32, 1.0f32));
        let mut layer = Layer::new((2, 1), LayerAttributes::default(), Encoding::UNCOMPRESSED, px);
        layer.attributes.layer_position = Vec2(0, 0);
        let mut image = Image::from_layer(layer);
        image.attributes.display_window = IntegerBounds::new((0, 0), (40000, 20000));
        let mut b = std::io::Cursor::new(Vec::new());
        image.write().to_buffered(&mut b).unwrap();
        let m = Environment::from_bytes(Path::new("crop.exr"), b.get_ref()).unwrap_err().to_string();
        assert!(m.contains("crop.exr") && m.contains("display window is 40000×20000"), "{m}");
    }

    #[test]
    fn radiance_headers_are_honoured() {
        let px: Vec<image::Rgb<f32>> = (0..32).map(|_| image::Rgb([0.5, 1.0, 0.25])).collect();
        let mut plain = Vec::new();
        image::codecs::hdr::HdrEncoder::new(&mut plain).encode(&px, 8, 4).unwrap();
        let with = |lines: &str| {
            let text = String::from_utf8_lossy(&plain[..plain.len().min(64)]).to_string();
            let end = text.find("\n\n").unwrap();
            [&plain[..end + 1], lines.as_bytes(), &plain[end + 1..]].concat()
        };
        let load = |b: &[u8]| Environment::from_bytes(Path::new("sky.hdr"), b);
        let base = load(&plain).unwrap().texels[5];
        let t = load(&with("EXPOSURE=2\nEXPOSURE=4\n")).unwrap().texels[5];
        assert!((t * 8.0 - base).abs().max_element() < 1e-6, "{t} vs {base}/8");
        let t = load(&with("COLORCORR=1 2 4\n")).unwrap().texels[5];
        assert!((t * Vec3::new(1.0, 2.0, 4.0) - base).abs().max_element() < 1e-6, "{t}");
        let srgb = load(&with("PRIMARIES=0.64 0.33 0.3 0.6 0.15 0.06 0.3127 0.329\n")).unwrap().texels[5];
        assert!((srgb - base).abs().max_element() < 1e-6, "Rec. 709 primaries change nothing");
        // Radiance's own standard primaries and equal-energy white: against the same matrices
        // built independently (colour space from chromaticities, then Bradford to D65).
        let rad =
            load(&with("PRIMARIES=0.640 0.330 0.290 0.600 0.150 0.060 0.333 0.333\n")).unwrap().texels[5];
        let space = color::RgbColorSpace::new(
            "r",
            [[0.64, 0.33], [0.29, 0.6], [0.15, 0.06]],
            [0.333, 0.333],
            "",
            color::colorspace::TransferFunction::Linear,
        );
        let want = space.conversion_to(&color::RgbColorSpace::srgb()) * base.as_dvec3();
        assert!((rad.as_dvec3() - want.max(glam::DVec3::ZERO)).abs().max_element() < 1e-5, "{rad} vs {want}");
        assert!((rad - base).abs().max_element() > 0.01, "they differ from sRGB's");
        for (line, field) in [
            ("EXPOSURE=0\n", "EXPOSURE"),
            ("EXPOSURE=-1\n", "EXPOSURE"),
            ("COLORCORR=1 0 1\n", "COLORCORR"),
            ("PRIMARIES=0.64 0.33\n", "PRIMARIES"),
            ("PRIMARIES=0.3 0.3 0.3 0.3 0.3 0.3 0.3 0.3\n", "PRIMARIES"),
            ("FORMAT=32-bit_rle_xyze\n", "ra_xyze -r"),
        ] {
            let m = load(&with(line)).unwrap_err().to_string();
            assert!(m.contains("sky.hdr") && m.contains(field), "{line}: {m}");
        }
    }

    /// Found by a sweep: an EXR's `chromaticities` (ACES AP0, Rec. 2020…) were ignored while a
    /// Radiance file's PRIMARIES were converted. Converted the same way now: checked against the
    /// matrix built independently from the chromaticities (then Bradford to D65).
    #[test]
    fn exr_chromaticities_are_honoured() {
        use exr::prelude::*;
        let write = |chroma: Option<exr::meta::attribute::Chromaticities>| {
            let channels = SpecificChannels::rgb(|_: Vec2<usize>| (0.5f32, 1.0f32, 0.25f32));
            let mut image = Image::from_channels((8, 4), channels);
            image.attributes.chromaticities = chroma;
            let mut bytes = std::io::Cursor::new(Vec::new());
            image.write().to_buffered(&mut bytes).unwrap();
            bytes.into_inner()
        };
        let load = |b: &[u8]| Environment::from_bytes(Path::new("sky.exr"), b);
        let base = load(&write(None)).unwrap().texels[5];
        let c = |r: (f32, f32), g: (f32, f32), b: (f32, f32), w: (f32, f32)| {
            exr::meta::attribute::Chromaticities {
                red: Vec2(r.0, r.1),
                green: Vec2(g.0, g.1),
                blue: Vec2(b.0, b.1),
                white: Vec2(w.0, w.1),
            }
        };
        let rec709 = c((0.64, 0.33), (0.3, 0.6), (0.15, 0.06), (0.3127, 0.329));
        assert!((load(&write(Some(rec709))).unwrap().texels[5] - base).abs().max_element() < 1e-6);
        let p3 = c((0.68, 0.32), (0.265, 0.69), (0.15, 0.06), (0.3127, 0.329));
        let got = load(&write(Some(p3))).unwrap().texels[5];
        let space = color::RgbColorSpace::new(
            "p3",
            [[0.68, 0.32], [0.265, 0.69], [0.15, 0.06]],
            [0.3127, 0.329],
            "",
            color::colorspace::TransferFunction::Linear,
        );
        let want = space.conversion_to(&color::RgbColorSpace::srgb()) * base.as_dvec3();
        assert!((got.as_dvec3() - want.max(glam::DVec3::ZERO)).abs().max_element() < 1e-4, "{got} vs {want}");
        assert!((got - base).abs().max_element() > 0.01);
        let flat = c((0.3, 0.3), (0.3, 0.3), (0.3, 0.3), (0.3, 0.3));
        let e = load(&write(Some(flat))).unwrap_err().to_string();
        assert!(e.contains("sky.exr") && e.contains("chromaticities"), "{e}");
    }

    /// The largest map the documentation promises is not refused by the decoder's memory limit
    /// (16384×8192 was, "Memory limit exceeded"): a header of that size with a few scanlines
    /// fails as a truncated file, not for its size.
    #[test]
    fn the_largest_promised_size_is_not_refused_for_memory() {
        let (w, h) = (MAX_INPUT_WIDTH, MAX_INPUT_HEIGHT);
        let mut b = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
        b.extend(std::iter::repeat_n([0x80u8, 0x80, 0x80, 0x81], 4 * w as usize).flatten());
        let m = Environment::from_bytes(Path::new("big.hdr"), &b).unwrap_err().to_string();
        assert!(!m.to_lowercase().contains("memory") && !m.contains("larger than"), "{m}");
        let mut over = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {}\n", w * 2).into_bytes();
        over.extend_from_slice(&[0x80; 64]);
        let m = Environment::from_bytes(Path::new("big.hdr"), &over).unwrap_err().to_string();
        assert!(m.contains("big.hdr"), "{m}");
    }

    #[test]
    fn files_that_are_not_environments_are_refused_naming_the_file() {
        let dir = std::env::temp_dir().join(format!("spectra-env-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let missing = Environment::load(&dir.join("missing.hdr")).unwrap_err().to_string();
        assert!(missing.contains("missing.hdr"), "{missing}");
        let png = dir.join("sky.png");
        std::fs::write(&png, b"x").unwrap();
        assert!(Environment::load(&png).unwrap_err().to_string().contains("not an HDR"));
        let corrupt = dir.join("corrupt.hdr");
        std::fs::write(&corrupt, b"#?RADIANCE\ngarbage").unwrap();
        let m = Environment::load(&corrupt).unwrap_err().to_string();
        assert!(m.contains("corrupt.hdr") && m.contains("not a readable"), "{m}");
        let bad_exr = dir.join("corrupt.exr");
        std::fs::write(&bad_exr, [0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0, 1, 2, 3]).unwrap();
        assert!(Environment::load(&bad_exr).unwrap_err().to_string().contains("corrupt.exr"));
        assert!(Environment::load(&dir).unwrap_err().to_string().contains("a directory"));
        std::fs::remove_dir_all(&dir).ok();
    }

    /// The shipped HDRs: rooitou_park's low sun (4 texels, 0.0006 sr, 65 % of ∫ Y dω) is one;
    /// venice_sunset's sun at the horizon gives 2.4 % (the sky outshines it) and studio_small_03's
    /// brightest soft box is 0.0185 sr wide: neither; nor the default sky. The sun's energy goes
    /// to its light and out of the map.
    #[test]
    fn the_sun_of_a_map() {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/environments/");
        for (file, has) in
            [("rooitou_park.hdr", true), ("venice_sunset.hdr", false), ("studio_small_03.hdr", false)]
        {
            let e = Environment::load(&std::path::PathBuf::from(root).join(file)).unwrap();
            let sun = e.sun();
            eprintln!(
                "{file}: {:?}",
                sun.as_ref().map(|s| (s.direction, s.irradiance, s.solid_angle, s.share, s.texels.len()))
            );
            assert_eq!(sun.is_some(), has, "{file}");
            if let Some(s) = sun {
                let rest = e.without_sun(&s);
                let y = |v: Vec3| 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
                let (before, after) = (y(e.integral()), y(rest.integral()));
                let sun_y = y(s.irradiance);
                assert!(
                    after < before && (after + sun_y) > before * 0.98,
                    "{file}: {before} → {after} + {sun_y}"
                );
                assert!(rest.sun().is_none_or(|t| t.share < s.share), "{file}: the sun is gone");
            }
        }
        assert!(Environment::default_sky().sun().is_none());
        // The share that makes a sun (`--env-sun-share`): venice_sunset's 2.4 % is one at 0.02,
        // rooitou_park's 65 % is none at 0.7; out of (0, 1] is refused naming the value.
        let venice = Environment::load(&std::path::PathBuf::from(root).join("venice_sunset.hdr")).unwrap();
        assert!(venice.clone().with_sun_min_share(0.02).unwrap().sun().is_some());
        let park = Environment::load(&std::path::PathBuf::from(root).join("rooitou_park.hdr")).unwrap();
        assert!(park.clone().with_sun_min_share(0.7).unwrap().sun().is_none());
        for bad in [0.0f32, -0.1, 1.5, f32::NAN, f32::INFINITY] {
            let m = park.clone().with_sun_min_share(bad).unwrap_err().to_string();
            assert!(m.contains("rooitou_park.hdr") && m.contains(&format!("(got {bad})")), "{m}");
        }
        assert!(Environment::uniform(Vec3::ONE).sun().is_none());
    }
}
