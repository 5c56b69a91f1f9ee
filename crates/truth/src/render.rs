//! Rendering an image: pixels in parallel (rayon), each with its own random stream so the
//! result depends only on the seed; progress reported per row; cancellable between rows.

use crate::camera::RayCamera;
use crate::error::{Result, TruthError};
use crate::integrator::Integrator;
use crate::medium::Medium;
use crate::rng::Sampler;
use crate::spectral::{Wavelengths, XyzSensor};
use crate::upsample::RgbToSpectrum;
use crate::world::World;
use color::{Observer, Spectrum, WavelengthRange};
use glam::Vec2;
use rayon::prelude::*;
use scene::Scene;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The s-th point of the R2 sequence shifted by `shift`, in [0, 1)².
fn r2(shift: [f32; 2], s: u64) -> [f32; 2] {
    const A: [f64; 2] = [0.754_877_666_246_692_8, 0.569_840_290_998_053_3];
    std::array::from_fn(|i| {
        let x = if s < 1 << 32 {
            shift[i] as f64 + s as f64 * A[i]
        } else {
            // s·A itself would keep no fraction near 2⁵³ (every sample on the pixel's corner):
            // frac(s·A) = frac(hi·frac(2³²·A) + lo·A), each part with its fraction intact.
            // 2³²·A is exact (a power of two), so this is the same sequence, not another.
            let (hi, lo) = ((s >> 32) as f64, (s & 0xffff_ffff) as f64);
            shift[i] as f64 + (hi * (A[i] * 4_294_967_296.0).fract()).fract() + lo * A[i]
        };
        (x.fract() as f32).min(0.999_999_94)
    })
}

/// Owen's nested uniform scrambling of the binary fraction `x` (bit 31 first), keyed by
/// `key`: Burley 2020, "Practical Hash-based Owen Scrambling" (the Laine–Karras permutation on
/// the reversed bits flips each bit depending only on the bits before it). Keeps every
/// elementary-interval stratification of the sequence it scrambles; each point is uniform.
fn owen(x: u32, key: u32) -> u32 {
    let mut v = x.reverse_bits().wrapping_add(key);
    v ^= v.wrapping_mul(0x6c50_b47c);
    v ^= v.wrapping_mul(0xb82f_1e52);
    v ^= v.wrapping_mul(0xc7af_e638);
    v ^= v.wrapping_mul(0x8d22_f6e6);
    v.reverse_bits()
}

/// The second Sobol' dimension of point `i` (direction numbers v_k = v_{k−1} ⊕ v_{k−1}/2):
/// with the radical inverse, a (0, 2)-sequence.
fn sobol1(mut i: u32) -> u32 {
    let (mut v, mut r) = (1u32 << 31, 0u32);
    while i != 0 {
        if i & 1 != 0 {
            r ^= v;
        }
        i >>= 1;
        v ^= v >> 1;
    }
    r
}

/// The hero wavelength's u for sample `s` of a pixel with key `key`, in [0, 1). A path's four
/// wavelengths are the hero and its rotations by a quarter of the range, so two things matter:
/// t = frac(4u), which decides the four, and the lane, which of them is the hero (it drives
/// distance and direction sampling, in media above all). They are the two dimensions of an
/// Owen-scrambled Sobol' (0, 2)-sequence: any 2^k samples starting at a multiple of 2^k fall
/// one in each elementary interval of area 2^−k — t stratified, the lanes balanced, jointly —
/// so a power-of-two chunk (`--sample-offset`) is stratified by itself, as the jittered strata
/// over the whole pixel were before issue 31. Measured (eval --quick truth noise, ΔE2000):
/// a shifted golden-ratio u doubled the dry colour noise; only t stratified, with a random
/// lane, made under-water truth 15 % noisier; u itself one scrambled radical inverse made the
/// dry cases noisier. Samples past 2³² repeat the pattern under other scrambles.
fn hero_u(s: u64, key: u64) -> f32 {
    let k = key ^ (s >> 32).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    let i = s as u32;
    let t = owen(i.reverse_bits(), k as u32);
    let lane = owen(sobol1(i), (k >> 32) as u32) >> 30;
    let u = (f64::from(lane) + f64::from(t) / 4_294_967_296.0) * 0.25;
    (u as f32).min(0.999_999_94)
}

/// Samples between two looks at the cancellation token (a few hundred microseconds at most).
const CANCEL_POLL_SAMPLES: u32 = 64;

/// The largest image side `truth` renders, in pixels.
pub const MAX_SIDE: u32 = 32_768;
/// The most pixels `truth` renders: 8192² (the XYZ image alone is 12 bytes a pixel, 0.8 GB).
pub const MAX_PIXELS: u64 = 1 << 26;

/// Whether `truth` renders a whole `width`×`height` frame ([`MAX_SIDE`], [`MAX_PIXELS`]), for
/// callers that check their sizes before any work.
pub fn check_size(width: u32, height: u32) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(TruthError::BadSize(width, height));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width as u64 * height as u64 > MAX_PIXELS {
        return Err(TruthError::TooLarge(width, height));
    }
    Ok(())
}

/// Most memory the binned spectral image may take (f32 samples).
pub const MAX_SPECTRAL_BYTES: u64 = 1 << 31;

/// A pixel rectangle of the full frame (`--crop X,Y,W,H`): origin at the top-left pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Crop {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// What to render and how.
#[derive(Clone, Debug)]
pub struct Settings {
    /// The full frame (the camera's image), also when only a crop of it is rendered.
    pub width: u32,
    pub height: u32,
    /// Samples per pixel in this render: samples `sample_offset` … `sample_offset + spp − 1`
    /// of each pixel's sequence.
    pub spp: u32,
    /// The first sample rendered (0 for a whole render; chunk i of n renders from i·spp).
    pub sample_offset: u64,
    /// Only this rectangle of the frame (the same per-pixel samples as the full render).
    pub crop: Option<Crop>,
    pub seed: u64,
    pub range: WavelengthRange,
    pub observer: Observer,
    /// The scene white (reference white of the XYZ normalisation), default D65.
    pub white: Spectrum,
    pub direct_only: bool,
    pub max_depth: u32,
    pub medium: Option<Medium>,
    /// Uniform background radiance (see [`World::with_environment`]); none by default.
    pub environment: Option<Spectrum>,
    /// Lambertian BRDF instead of glTF's (for comparison with Mitsuba's `diffuse`).
    pub lambert: bool,
    /// Also bin the radiance by wavelength ([`XyzImage::spectral`]): box bands with these
    /// edges (nm, strictly increasing, from `range.min` to `range.max`).
    pub spectral_bands: Option<Vec<f64>>,
}

impl Settings {
    /// The matrix from this render's tristimulus values to linear sRGB
    /// ([`crate::spectral::display_matrix`]).
    pub fn display_matrix(&self, view: color::film::CameraView) -> Result<glam::DMat3> {
        Ok(crate::spectral::display_matrix(&self.observer, &self.white, self.range, view)?)
    }

    pub fn new(width: u32, height: u32, spp: u32) -> Result<Self> {
        Ok(Settings {
            width,
            height,
            spp,
            sample_offset: 0,
            crop: None,
            seed: 0,
            range: WavelengthRange::VISIBLE,
            observer: Observer::cie1931(),
            white: color::illuminant::by_name("D65")?,
            direct_only: false,
            max_depth: 1024,
            medium: None,
            environment: None,
            lambert: false,
            spectral_bands: None,
        })
    }

    pub fn validate(&self) -> Result<()> {
        if self.spp == 0 {
            return Err(TruthError::NoSamples);
        }
        if self.width == 0 || self.height == 0 {
            return Err(TruthError::BadSize(self.width, self.height));
        }
        // Checked before anything is allocated: `4294967295x1` used to try. A crop may come
        // from a larger frame (up to MAX_SIDE a side): the pixel budget is the crop's.
        let c = self.window();
        if self.width > MAX_SIDE
            || self.height > MAX_SIDE
            || (self.crop.is_none() && self.width as u64 * self.height as u64 > MAX_PIXELS)
        {
            return Err(TruthError::TooLarge(self.width, self.height));
        }
        if c.width == 0
            || c.height == 0
            || u64::from(c.x) + u64::from(c.width) > u64::from(self.width)
            || u64::from(c.y) + u64::from(c.height) > u64::from(self.height)
        {
            return Err(TruthError::BadCrop(format!(
                "{},{},{},{} (x, y, width, height) is not a non-empty rectangle inside the {}×{} frame",
                c.x, c.y, c.width, c.height, self.width, self.height
            )));
        }
        if c.width as u64 * c.height as u64 > MAX_PIXELS {
            return Err(TruthError::BadCrop(format!(
                "{},{},{},{} is {}×{} pixels: at most {MAX_PIXELS} (8192×8192) are rendered at once; split it into \
                 smaller crops and merge them",
                c.x, c.y, c.width, c.height, c.width, c.height
            )));
        }
        if self.sample_offset.checked_add(u64::from(self.spp)).is_none_or(|end| end > MAX_SAMPLE_INDEX) {
            return Err(TruthError::BadSamples(format!(
                "samples {} … {} pass the last sample index, {MAX_SAMPLE_INDEX}",
                self.sample_offset,
                self.sample_offset as u128 + u128::from(self.spp) - 1
            )));
        }
        if let Some(m) = &self.medium {
            m.validate(self.range)?;
        }
        if let Some(edges) = &self.spectral_bands {
            color::SampledWavelengths::from_edges(edges)?;
            let (lo, hi) = (edges[0], edges[edges.len() - 1]);
            if (lo - self.range.min).abs() > 1e-9 || (hi - self.range.max).abs() > 1e-9 {
                return Err(TruthError::BadBands(format!(
                    "the bands span {lo}–{hi} nm but the render range is {}–{} nm; they must cover it exactly",
                    self.range.min, self.range.max
                )));
            }
            let bytes = c.width as u64 * c.height as u64 * (edges.len() as u64 - 1) * 4;
            if bytes > MAX_SPECTRAL_BYTES {
                return Err(TruthError::BadBands(format!(
                    "{}×{} pixels × {} bands is {} MiB of samples; at most {} MiB: use wider bands or a smaller image",
                    c.width,
                    c.height,
                    edges.len() - 1,
                    bytes >> 20,
                    MAX_SPECTRAL_BYTES >> 20
                )));
            }
        }
        Ok(())
    }

    /// The rectangle rendered: the crop, or the whole frame.
    pub fn window(&self) -> Crop {
        self.crop.unwrap_or(Crop { x: 0, y: 0, width: self.width, height: self.height })
    }
}

/// Version of the per-pixel sample sequence (the pixel's shift, each sample's stream): renders
/// of different versions do not merge.
pub const SAMPLER_VERSION: u32 = 3;

/// Hash of the source this crate's images depend on (its own, `scene`'s and `color`'s; see
/// build.rs): stored truths are reused only by a tracer of the same code.
pub const CODE_HASH: &str = env!("TRUTH_CODE_HASH");

/// One past the largest sample index (2⁵³: the sequences' arithmetic is exact in f64 below it).
pub const MAX_SAMPLE_INDEX: u64 = 1 << 53;

/// A rendered image: CIE XYZ per pixel, row-major from the top-left.
#[derive(Clone, Debug)]
pub struct XyzImage {
    /// The rendered rectangle's size ([`Settings::window`]; the frame's without a crop).
    pub width: u32,
    pub height: u32,
    pub xyz: Vec<[f32; 3]>,
    /// Samples whose estimate was not finite and were dropped (should be 0).
    pub dropped: u64,
    /// With [`Settings::spectral_bands`]: per pixel (row-major), the mean radiance over each band,
    /// `spectral[(y * width + x) * bands + b]`, estimated from the same samples as `xyz`.
    pub spectral: Option<Vec<f32>>,
}

impl XyzImage {
    /// Linear RGB in `space` through its bare matrix (no chromatic adaptation, and not the
    /// display convention: for ratios of two images, as tests take). For a CIE observer only;
    /// images are shown by [`Self::to_display`].
    pub fn to_rgb(&self, space: &color::RgbColorSpace) -> Vec<[f32; 3]> {
        self.xyz.iter().map(|p| space.xyz_to_rgb(p.map(|c| c as f64)).map(|c| c as f32)).collect()
    }

    /// Linear sRGB by the display convention every renderer shares ([`color::film`]): CIE XYZ
    /// balanced onto sRGB's white, then the sRGB matrix; any other observer white balanced (and with
    /// [`color::film::CameraView::Display`] through its fitted matrix to XYZ).
    pub fn to_display(&self, settings: &Settings, view: color::film::CameraView) -> Result<Vec<[f32; 3]>> {
        let m = settings.display_matrix(view)?;
        Ok(self
            .xyz
            .iter()
            .map(|p| {
                let rgb = m * glam::DVec3::from_array(p.map(|c| c as f64));
                [rgb.x as f32, rgb.y as f32, rgb.z as f32]
            })
            .collect())
    }

    /// Mean XYZ over the image.
    pub fn mean(&self) -> [f64; 3] {
        let mut m = [0.0f64; 3];
        for p in &self.xyz {
            (0..3).for_each(|c| m[c] += p[c] as f64);
        }
        m.map(|v| v / self.xyz.len().max(1) as f64)
    }
}

/// Renders `scene`. `progress` is called with the number of rows finished so far; setting
/// `cancel` makes the render stop within a row and return [`TruthError::Cancelled`].
pub fn render(
    scene: &Scene,
    upsampler: &dyn RgbToSpectrum,
    settings: &Settings,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<XyzImage> {
    settings.validate()?;
    let mut world = World::new(scene, upsampler, &settings.white, settings.range, settings.medium.as_ref())?;
    if let Some(env) = &settings.environment {
        world = world.with_environment(env);
    }
    render_world(&world, settings, cancel, progress)
}

/// Renders a prepared world (lets callers time or reuse the preparation).
pub fn render_world(
    world: &World,
    settings: &Settings,
    cancel: &AtomicBool,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<XyzImage> {
    let mut acc = Accumulator::new(settings)?;
    render_pass(world, settings, cancel, &mut acc, settings.spp, progress)?;
    Ok(acc.finish(settings))
}

/// The running sums of a render done in passes (for checkpoints): per pixel of the window, the
/// sums over the samples so far of XYZ and of the bins, in f64. Each pixel's sums grow in
/// sample order whatever the passes, so a render in passes — or resumed from a checkpoint of
/// these sums — is bit-identical to one in a single pass.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulator {
    /// Samples summed, from `settings.sample_offset`.
    pub done: u32,
    pub xyz: Vec<[f64; 3]>,
    /// `bins[(pixel) * bands + b]`; empty without bins.
    pub bins: Vec<f64>,
    pub dropped: u64,
}

impl Accumulator {
    /// No samples yet, for `settings` (validated).
    pub fn new(settings: &Settings) -> Result<Self> {
        settings.validate()?;
        let win = settings.window();
        let n = win.width as usize * win.height as usize;
        let nb = settings.spectral_bands.as_ref().map_or(0, |e| e.len() - 1);
        Ok(Accumulator { done: 0, xyz: vec![[0.0; 3]; n], bins: vec![0.0; n * nb], dropped: 0 })
    }

    /// The image of the samples so far (all of `settings.spp` for a finished render): the sums
    /// over `settings.spp`, as f32.
    pub fn finish(&self, settings: &Settings) -> XyzImage {
        let win = settings.window();
        let spp = settings.spp as f64;
        XyzImage {
            width: win.width,
            height: win.height,
            xyz: self.xyz.iter().map(|p| p.map(|v| (v / spp) as f32)).collect(),
            dropped: self.dropped,
            spectral: settings
                .spectral_bands
                .as_ref()
                .map(|_| self.bins.iter().map(|v| (v / spp) as f32).collect()),
        }
    }
}

/// Adds the next `samples` samples of every pixel (from `acc.done`, at most to `settings.spp`)
/// to `acc`. `progress` is called with the rows finished in this pass. Cancelled, it leaves
/// `acc` as it was (the pass's work is discarded, the earlier passes' kept).
pub fn render_pass(
    world: &World,
    settings: &Settings,
    cancel: &AtomicBool,
    acc: &mut Accumulator,
    samples: u32,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<()> {
    settings.validate()?;
    let (full_w, full_h) = (settings.width, settings.height);
    let win = settings.window();
    let (w, h) = (win.width, win.height);
    let first = acc.done;
    let last = first.saturating_add(samples).min(settings.spp);
    let camera = RayCamera::new(&world.scene.camera, full_w, full_h);
    let sensor = XyzSensor::new(&settings.observer, &settings.white, settings.range);
    let integ = Integrator {
        world,
        direct_only: settings.direct_only,
        max_depth: settings.max_depth,
        lambert: settings.lambert,
    };
    let rows_done = AtomicU64::new(0);
    let dropped = AtomicU64::new(0);
    let bins = settings.spectral_bands.as_deref().map(|e| Bins::new(e, settings.range));
    let nb = bins.as_ref().map_or(0, |b| b.len());
    // A row's sums (colour, and bands when binning), continued from the accumulator's.
    type Row = (Vec<[f64; 3]>, Vec<f64>);
    let acc_ref = &*acc;
    let rows: Vec<Option<Row>> = (0..h)
        .into_par_iter()
        .map(|ry| {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let y = win.y + ry;
            let base = ry as usize * w as usize;
            let mut row = acc_ref.xyz[base..base + w as usize].to_vec();
            let mut spectral_row = acc_ref.bins[base * nb..(base + w as usize) * nb].to_vec();
            for rx in 0..w {
                let x = win.x + rx;
                // Pixels are numbered in the full frame, so a crop draws what its pixels draw
                // in the full render.
                let pixel = y as u64 * full_w as u64 + x as u64;
                let mut rng = Sampler::new(settings.seed, pixel);
                let acc = &mut row[rx as usize];
                let bin_acc = &mut spectral_row[rx as usize * nb..(rx as usize + 1) * nb];
                // Pixel positions from the R2 rank-1 lattice (Roberts 2018) with a random
                // per-pixel shift (Cranley–Patterson rotation): well spread over the pixel, and
                // each sample still uniform, so the estimate stays unbiased.
                let shift = rng.next2();
                let lambda_key = rng.key();
                for i in first..last {
                    // Polled every few samples, not only per pixel: at `--spp 10⁸` one pixel
                    // takes minutes.
                    if i % CANCEL_POLL_SAMPLES == 0 && i > first && cancel.load(Ordering::Relaxed) {
                        return None;
                    }
                    // Sample s of the pixel's sequence: its position, wavelengths and stream
                    // depend on (seed, pixel, s) alone.
                    let s = settings.sample_offset + u64::from(i);
                    let mut rng = Sampler::for_sample(settings.seed, pixel, s);
                    let jitter = r2(shift, s);
                    let ray = camera.ray(Vec2::new(x as f32 + jitter[0], y as f32 + jitter[1]));
                    // Hero wavelengths stratified over the pixel's samples (see `hero_u`):
                    // spiky spectra such as F11 need far fewer samples for the same colour
                    // noise. Unbiased: u is uniform and independent of the sample's other
                    // dimensions.
                    let wl = sensor.sample(hero_u(s, lambda_key));
                    let l = integ.camera_radiance(ray, &wl, &mut rng);
                    if !l.is_finite() {
                        dropped.fetch_add(1, Ordering::Relaxed);
                        continue;
                    }
                    let xyz = sensor.to_xyz(&wl, l);
                    (0..3).for_each(|c| acc[c] += xyz[c]);
                    if let Some(b) = &bins {
                        b.add(bin_acc, &wl, l);
                    }
                }
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
            }
            progress(rows_done.fetch_add(1, Ordering::Relaxed) + 1);
            Some((row, spectral_row))
        })
        .collect();
    if cancel.load(Ordering::Relaxed) || rows.iter().any(Option::is_none) {
        return Err(TruthError::Cancelled);
    }
    for (ry, (r, sp)) in rows.into_iter().flatten().enumerate() {
        let base = ry * w as usize;
        acc.xyz[base..base + w as usize].copy_from_slice(&r);
        acc.bins[base * nb..(base + w as usize) * nb].copy_from_slice(&sp);
    }
    acc.dropped += dropped.into_inner();
    acc.done = last;
    Ok(())
}

/// Box bands over the render range, accumulating per-band mean radiance. With wavelengths drawn
/// uniformly over the range (density 1/W), four per path, `L(λ)·W / (4·Δλ_b)` for each λ in band
/// b is an unbiased estimate of the band's mean radiance.
struct Bins {
    edges: Vec<f64>,
    /// W / (4·Δλ_b).
    scale: Vec<f64>,
}

impl Bins {
    fn new(edges: &[f64], range: WavelengthRange) -> Self {
        let scale = edges.windows(2).map(|e| range.width() / (4.0 * (e[1] - e[0]))).collect();
        Bins { edges: edges.to_vec(), scale }
    }

    fn len(&self) -> usize {
        self.scale.len()
    }

    fn add(&self, acc: &mut [f64], wl: &Wavelengths, l: glam::Vec4) {
        for (lambda, v) in wl.0.to_array().into_iter().zip(l.to_array()) {
            // The upper edge belongs to the last band (the sampler stays below it anyway).
            let b = self.edges.partition_point(|&e| e <= f64::from(lambda)).clamp(1, self.len()) - 1;
            acc[b] += f64::from(v) * self.scale[b];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Chunks far out in the sequence (`--sample-offset` up to 2⁵³) jitter as well as the first:
    /// 4096 points from 2⁵² and from 2⁵³ − 4096 fill the pixel's 64 × 64 cells nearly as evenly
    /// as the first 4096, where s·A in f64 had put them all on the pixel's corner.
    #[test]
    fn r2_is_exact_far_out_in_the_sequence() {
        let cells = |start: u64| {
            let mut hit = vec![false; 64 * 64];
            for s in start..start + 4096 {
                let [x, y] = r2([0.3, 0.7], s);
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                hit[(y * 64.0) as usize * 64 + (x * 64.0) as usize] = true;
            }
            hit.iter().filter(|&&h| h).count()
        };
        let first = cells(0);
        assert!(first > 2400, "{first}");
        for start in [1 << 32, 1 << 40, 1 << 52, MAX_SAMPLE_INDEX - 4096] {
            let n = cells(start);
            assert!(n as f64 > 0.9 * first as f64, "from {start}: {n} cells of {first}");
        }
        // Below 2³² the points are the ones every stored truth was rendered with.
        let s = (1u64 << 32) - 1;
        let old = ((0.3f32 as f64 + s as f64 * 0.754_877_666_246_692_8).fract() as f32).min(0.999_999_94);
        assert_eq!(r2([0.3, 0.7], s)[0], old);
    }
    use crate::testing::{inward_box, quad, scene_with};
    use crate::upsample::GreyOnly;
    use glam::Vec3;
    use scene::{Camera, Emission, Light, LightKind, Material};

    fn small_scene() -> Scene {
        let walls = Material { base_color: glam::Vec4::new(0.6, 0.6, 0.6, 1.0), ..Default::default() };
        let lamp = Material { emissive: Vec3::splat(4.0), ..Default::default() };
        let mut s = scene_with(
            vec![inward_box(1.0, 0), quad(Vec3::new(0.0, 0.99, 0.0), -Vec3::Y, 0.3, 1)],
            vec![walls, lamp],
            vec![Light {
                name: "p".into(),
                kind: LightKind::Point { position: Vec3::new(0.3, 0.2, 0.1), range: None },
                emission: Emission { rgb: Vec3::ONE, intensity: 0.5, spectrum: None },
                stands_in_for: None,
            }],
        );
        s.camera = Camera::look_at(Vec3::new(0.0, 0.0, 0.9), Vec3::ZERO, Vec3::Y, 1.2);
        s
    }

    #[test]
    fn deterministic_regardless_of_threads() {
        let scene = small_scene();
        let mut st = Settings::new(12, 8, 4).unwrap();
        st.seed = 5;
        let no = AtomicBool::new(false);
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| render(&scene, &GreyOnly, &st, &no, &|_| {}).unwrap())
        };
        let (a, b) = (run(1), run(3));
        assert_eq!(a.xyz, b.xyz);
        assert!(a.mean()[1] > 0.0 && a.dropped == 0);
        st.seed = 6;
        let c = pool_free_render(&scene, &st);
        assert_ne!(a.xyz, c.xyz);
    }

    /// Stochastic opacity (a BLEND quad in front of the lamp, seen and crossed by shadow rays)
    /// draws its decisions from the pixels' streams: still independent of the thread count.
    #[test]
    fn blend_is_deterministic_regardless_of_threads() {
        let mut scene = small_scene();
        scene.materials.push(Material {
            base_color: glam::Vec4::new(0.9, 0.2, 0.2, 0.5),
            alpha_mode: scene::AlphaMode::Blend,
            double_sided: false,
            ..Default::default()
        });
        scene.meshes.push(quad(Vec3::new(0.0, 0.5, 0.0), -Vec3::Y, 0.5, 2));
        let st = Settings { seed: 2, ..Settings::new(12, 8, 4).unwrap() };
        let no = AtomicBool::new(false);
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| render(&scene, &GreyOnly, &st, &no, &|_| {}).unwrap())
        };
        let a = run(1);
        assert_eq!(a.xyz, run(3).xyz);
        assert!(a.mean()[1] > 0.0 && a.dropped == 0);
    }

    fn pool_free_render(scene: &Scene, st: &Settings) -> XyzImage {
        render(scene, &GreyOnly, st, &AtomicBool::new(false), &|_| {}).unwrap()
    }

    /// Ctrl-C at a huge sample count stops inside the pixel, not after it (which would take
    /// hours at `--spp 10⁸`).
    #[test]
    fn cancel_stops_within_a_pixel() {
        let scene = small_scene();
        let st = Settings::new(1, 1, u32::MAX).unwrap();
        let cancel: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(false)));
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let _ = tx
                .send(matches!(render(&scene, &GreyOnly, &st, cancel, &|_| {}), Err(TruthError::Cancelled)));
        });
        std::thread::sleep(std::time::Duration::from_millis(200));
        cancel.store(true, Ordering::SeqCst);
        let t = std::time::Instant::now();
        let cancelled =
            rx.recv_timeout(std::time::Duration::from_secs(5)).expect("still rendering 5 s after cancel");
        assert!(cancelled);
        assert!(t.elapsed().as_secs_f64() < 1.0, "{:?}", t.elapsed());
    }

    #[test]
    fn cancel_and_bad_settings_are_errors() {
        let scene = small_scene();
        let st = Settings::new(8, 8, 2).unwrap();
        let r = render(&scene, &GreyOnly, &st, &AtomicBool::new(true), &|_| {});
        assert!(matches!(r, Err(TruthError::Cancelled)));
        for (w, h) in [(u32::MAX, 1), (MAX_SIDE + 1, 1), (8193, 8192)] {
            let e = Settings::new(w, h, 1).unwrap().validate().unwrap_err().to_string();
            assert!(e.contains(&format!("{w}×{h}")) && e.contains("8192"), "{e}");
        }
        assert!(Settings::new(MAX_SIDE, 2048, 1).unwrap().validate().is_ok());
        let zero = Settings { spp: 0, ..st.clone() };
        assert!(matches!(
            render(&scene, &GreyOnly, &zero, &AtomicBool::new(false), &|_| {}),
            Err(TruthError::NoSamples)
        ));
        let bad = Settings {
            medium: Some(Medium {
                sigma_a: Spectrum::Constant(f64::NAN),
                sigma_s: Spectrum::Constant(0.0),
                phase: crate::Phase::Isotropic,
                region: crate::Region::Everywhere,
                surface_ior: None,
            }),
            ..st
        };
        let e = render(&scene, &GreyOnly, &bad, &AtomicBool::new(false), &|_| {}).unwrap_err();
        assert!(e.to_string().contains("sigma_a"), "{e}");
    }

    /// Binning leaves the colour estimate untouched (the same samples, the same XYZ), and the
    /// bins, integrated by `color`'s integrator, land on it up to 5 nm quadrature and noise.
    #[test]
    fn spectral_bins_leave_xyz_alone() {
        let scene = small_scene();
        let st = Settings { seed: 3, ..Settings::new(6, 4, 256).unwrap() };
        let edges = st.range.bin_edges(5.0).unwrap();
        let plain = pool_free_render(&scene, &st);
        let binned =
            pool_free_render(&scene, &Settings { spectral_bands: Some(edges.clone()), ..st.clone() });
        assert_eq!(plain.xyz, binned.xyz);
        assert!(plain.spectral.is_none());
        let spectral = binned.spectral.clone().unwrap();
        let n = edges.len() - 1;
        assert_eq!(spectral.len(), 6 * 4 * n);
        let wl = color::SampledWavelengths::from_edges(&edges).unwrap();
        let integ = color::SpectralIntegrator::emission(&st.observer, &st.white, &wl);
        let mut mean = [0.0; 3];
        for px in spectral.chunks_exact(n) {
            let v: Vec<f64> = px.iter().map(|&x| f64::from(x)).collect();
            let t = integ.integrate_samples(&v);
            (0..3).for_each(|c| mean[c] += t[c] / 24.0);
        }
        let want = binned.mean();
        for c in 0..3 {
            assert!((mean[c] - want[c]).abs() < 0.01 * want[c], "{mean:?} vs {want:?}");
        }
    }

    /// Fed a fine grid of hero wavelengths, the bins hold the band means of the spectrum.
    #[test]
    fn bins_estimate_band_means() {
        let f11 = color::illuminant::by_name("F11").unwrap();
        let range = WavelengthRange::VISIBLE;
        let edges = range.bin_edges(5.0).unwrap();
        let bins = Bins::new(&edges, range);
        let sensor = XyzSensor::new(&Observer::cie1931(), &Spectrum::Constant(1.0), range);
        let n = 70_000;
        let mut acc = vec![0.0; bins.len()];
        for i in 0..n {
            let wl = sensor.sample((i as f32 + 0.5) / n as f32);
            let l = glam::Vec4::from_array(wl.0.to_array().map(|x| f11.eval(f64::from(x)) as f32));
            bins.add(&mut acc, &wl, l);
        }
        for (b, e) in edges.windows(2).enumerate() {
            let m = 1000;
            let exact: f64 =
                (0..m).map(|k| f11.eval(e[0] + (k as f64 + 0.5) * (e[1] - e[0]) / m as f64)).sum::<f64>()
                    / m as f64;
            let got = acc[b] / n as f64;
            assert!((got - exact).abs() < 2e-3 * exact.max(1.0), "band {e:?}: {got} vs {exact}");
        }
    }

    /// Chunks of one sample sequence, merged weighted by their sample counts, are the render
    /// of all their samples: to f32 rounding (the means are stored as f32; the sum's order
    /// differs), for colour and bins, direct and full transport, with and without a medium.
    #[test]
    fn chunks_merge_into_the_full_render() {
        let scene = small_scene();
        let fog = Medium {
            sigma_a: Spectrum::Constant(0.2),
            sigma_s: Spectrum::Constant(0.6),
            phase: crate::Phase::HenyeyGreenstein { g: 0.3 },
            region: crate::Region::Everywhere,
            surface_ior: None,
        };
        for (direct_only, medium) in [(true, None), (false, None), (false, Some(fog))] {
            let base = Settings {
                seed: 9,
                direct_only,
                medium,
                spectral_bands: Some(WavelengthRange::VISIBLE.bin_edges(50.0).unwrap()),
                ..Settings::new(7, 5, 12).unwrap()
            };
            let full = pool_free_render(&scene, &base);
            let sizes = [3u32, 1, 5, 3];
            let mut offset = 0;
            let mut sum = vec![0.0f64; full.xyz.len() * 3];
            let mut bins = vec![0.0f64; full.spectral.as_ref().unwrap().len()];
            for n in sizes {
                let c = pool_free_render(&scene, &Settings { spp: n, sample_offset: offset, ..base.clone() });
                offset += u64::from(n);
                for (a, v) in sum.iter_mut().zip(c.xyz.iter().flatten()) {
                    *a += f64::from(*v) * f64::from(n);
                }
                for (a, v) in bins.iter_mut().zip(c.spectral.as_ref().unwrap()) {
                    *a += f64::from(*v) * f64::from(n);
                }
            }
            let want: Vec<f32> = full.xyz.iter().flatten().copied().collect();
            let close = |got: &[f64], want: &[f32], what: &str| {
                let mut worst: f64 = 0.0;
                for (g, w) in got.iter().zip(want) {
                    let g = g / 12.0;
                    let rel = (g - f64::from(*w)).abs() / f64::from(w.abs()).max(1e-6);
                    worst = worst.max(rel);
                }
                assert!(worst <= 1e-6, "{what}, direct {direct_only}: worst relative difference {worst:e}");
            };
            close(&sum, &want, "xyz");
            close(&bins, full.spectral.as_ref().unwrap(), "bins");
            assert!(full.mean()[1] > 0.0);
        }
    }

    /// The wavelength sequence is stratified over every aligned power-of-two block of samples,
    /// whatever the pixel's scramble: t = frac(4u) one per stratum, and (lane, t) one per
    /// elementary interval (here 4 lanes × n/4 strata of t); and u is uniform over many keys.
    #[test]
    fn wavelength_sequence_is_stratified_in_aligned_blocks() {
        for seed in [0u64, 1, 0xdead_beef_1234_5678] {
            for (start, n) in [(0u64, 16u64), (64, 64), (1 << 20, 256), (3 << 32, 32)] {
                let (mut t_hit, mut joint) = (vec![false; n as usize], vec![false; n as usize]);
                for s in start..start + n {
                    let u = hero_u(s, seed);
                    assert!((0.0..1.0).contains(&u));
                    let t = (4.0 * u).fract();
                    t_hit[(t * n as f32) as usize] = true;
                    let lane = (4.0 * u).floor() as usize;
                    joint[lane * (n as usize / 4) + (t * (n / 4) as f32) as usize] = true;
                }
                assert!(t_hit.iter().all(|&h| h), "t, seed {seed}, samples {start}..{}", start + n);
                assert!(joint.iter().all(|&h| h), "lane × t, seed {seed}, samples {start}..{}", start + n);
            }
        }
        let mut bins = [0u32; 16];
        for key in 0..4000u64 {
            bins[(hero_u(5, key.wrapping_mul(0x2545_f491_4f6c_dd1d)) * 16.0) as usize] += 1;
        }
        assert!(bins.iter().all(|&b| (180..=320).contains(&b)), "one sample over many pixels: {bins:?}");
    }

    /// A render in passes (as checkpoints make it) is bit-identical to one pass, and a
    /// cancelled pass leaves the accumulator as it was.
    #[test]
    fn passes_are_bit_identical_to_one_render() {
        let scene = small_scene();
        let st = Settings {
            seed: 8,
            spectral_bands: Some(WavelengthRange::VISIBLE.bin_edges(35.0).unwrap()),
            ..Settings::new(6, 5, 11).unwrap()
        };
        let one = pool_free_render(&scene, &st);
        let world = World::new(&scene, &GreyOnly, &st.white, st.range, None).unwrap();
        let no = AtomicBool::new(false);
        let mut acc = Accumulator::new(&st).unwrap();
        for n in [1, 4, 2, 100] {
            render_pass(&world, &st, &no, &mut acc, n, &|_| {}).unwrap();
        }
        assert_eq!(acc.done, 11);
        let passes = acc.finish(&st);
        assert_eq!(passes.xyz, one.xyz);
        assert_eq!(passes.spectral, one.spectral);
        let before = acc.clone();
        let mut again = acc.clone();
        again.done = 3;
        let kept = again.clone();
        assert!(matches!(
            render_pass(&world, &st, &AtomicBool::new(true), &mut again, 4, &|_| {}),
            Err(TruthError::Cancelled)
        ));
        assert_eq!(again, kept);
        assert_eq!(acc, before);
    }

    /// A tiling of crops is the full render, bit for bit: each pixel draws the same samples.
    #[test]
    fn crops_tile_the_full_render_exactly() {
        let scene = small_scene();
        let base = Settings {
            seed: 4,
            spectral_bands: Some(WavelengthRange::VISIBLE.bin_edges(70.0).unwrap()),
            ..Settings::new(9, 6, 4).unwrap()
        };
        let full = pool_free_render(&scene, &base);
        let nb = base.spectral_bands.as_ref().unwrap().len() - 1;
        for (x, y, w, h) in [(0, 0, 5, 4), (5, 0, 4, 4), (0, 4, 5, 2), (5, 4, 4, 2), (3, 2, 1, 1)] {
            let crop = Crop { x, y, width: w, height: h };
            let t = pool_free_render(&scene, &Settings { crop: Some(crop), ..base.clone() });
            assert_eq!((t.width, t.height), (w, h));
            for ty in 0..h {
                for tx in 0..w {
                    let f = ((y + ty) * 9 + x + tx) as usize;
                    let c = (ty * w + tx) as usize;
                    assert_eq!(t.xyz[c], full.xyz[f], "crop {crop:?} pixel ({tx}, {ty})");
                    assert_eq!(
                        t.spectral.as_ref().unwrap()[c * nb..(c + 1) * nb],
                        full.spectral.as_ref().unwrap()[f * nb..(f + 1) * nb]
                    );
                }
            }
        }
        for bad in [Crop { x: 5, y: 0, width: 5, height: 1 }, Crop { x: 0, y: 0, width: 0, height: 1 }] {
            let e = Settings { crop: Some(bad), ..base.clone() }.validate().unwrap_err().to_string();
            assert!(e.contains("crop") && e.contains("9×6"), "{e}");
        }
        let e =
            Settings { sample_offset: MAX_SAMPLE_INDEX, ..base.clone() }.validate().unwrap_err().to_string();
        assert!(e.contains("sample"), "{e}");
        // A crop of a large frame over the pixel budget is the crop's fault, named as such (the
        // message read as if the frame's size were wrong).
        let big = Crop { x: 0, y: 0, width: 8192, height: 8193 };
        let e = Settings { width: MAX_SIDE, height: MAX_SIDE, crop: Some(big), ..base }
            .validate()
            .unwrap_err()
            .to_string();
        assert!(e.contains("crop") && e.contains("8192×8193") && !e.contains("image size"), "{e}");
    }

    /// Direct lighting never exceeds full transport, and both see the lamp.
    #[test]
    fn direct_only_is_a_lower_bound() {
        let scene = small_scene();
        let st = Settings { seed: 1, ..Settings::new(8, 8, 64).unwrap() };
        let full = pool_free_render(&scene, &st).mean()[1];
        let direct = pool_free_render(&scene, &Settings { direct_only: true, ..st }).mean()[1];
        assert!(direct > 0.0 && direct < full * 0.95, "direct {direct} full {full}");
    }
}
