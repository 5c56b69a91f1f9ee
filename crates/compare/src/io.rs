//! Reading and writing [`Image`]s: OpenEXR (linear, f16/f32) and PNG (sRGB-encoded, 8/16-bit).
//!
//! The format follows the extension (case-insensitive). EXR holds linear values, read from the
//! first part with R, G and B and converted to linear sRGB by the file's `chromaticities`
//! attribute where it names other primaries (`color::colorspace::to_srgb_from_chromaticities`);
//! PNG holds IEC 61966-2-1 sRGB-encoded values, so reading decodes them to linear and writing
//! clamps linear values to [0, 1] and encodes them. Writes are atomic ([`crate::atomic`]).

use std::io::Cursor;
use std::path::Path;

use color::colorspace::{srgb_decode, srgb_encode};
use exr::prelude::{
    AnyChannels, Encoding, FlatSamples, Layer, ReadChannels, ReadLayers, SpecificChannels, Vec2,
    WritableImage, f16,
};

use crate::atomic::write_atomic;
use crate::error::{CompareError, Result};
use crate::frame::Placement;
use crate::image::Image;

/// Sample type of written EXR files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ExrPrecision {
    /// 32-bit float: exact.
    #[default]
    F32,
    /// 16-bit half float: about 3 significant digits, values above 65504 become infinite.
    F16,
}

/// Bit depth of written PNG files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PngBitDepth {
    #[default]
    Eight,
    Sixteen,
}

/// Per-format choices for [`write_image`]; the extension picks which one applies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WriteOptions {
    pub exr: ExrPrecision,
    pub png: PngBitDepth,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Exr,
    Png,
}

fn format_of(path: &Path) -> Result<Format> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
    match ext.as_str() {
        "exr" => Ok(Format::Exr),
        "png" => Ok(Format::Png),
        _ => Err(CompareError::UnsupportedExtension { path: path.into(), ext }),
    }
}

/// Largest image file read (bytes).
pub const MAX_INPUT_BYTES: u64 = 1 << 30;
/// Largest image read, in pixels (e.g. 8192 × 8192): checked against the file's header before
/// any pixel is decoded, so a few hundred bytes claiming 100000² pixels are refused at once.
/// Held as three f32 per pixel, an image at the cap takes 768 MiB.
pub const MAX_INPUT_PIXELS: u64 = 1 << 26;
/// Most bytes of samples an EXR may decode to (all its channels, 4 bytes a sample).
pub const MAX_DECODED_BYTES: u64 = 1 << 30;
/// Largest width or height read.
pub const MAX_INPUT_DIMENSION: u64 = 1 << 16;

fn check_size(path: &Path, format: &'static str, w: u64, h: u64) -> Result<()> {
    if w > MAX_INPUT_DIMENSION || h > MAX_INPUT_DIMENSION || w.saturating_mul(h) > MAX_INPUT_PIXELS {
        return Err(CompareError::Decode {
            path: path.into(),
            format,
            reason: format!(
                "the image is {w}×{h}; at most {MAX_INPUT_DIMENSION} on a side and {MAX_INPUT_PIXELS} pixels \
                 are accepted"
            ),
        });
    }
    Ok(())
}

/// Reads an EXR or PNG file into linear sRGB.
///
/// EXR: the first valid layer at its largest resolution; channels `R`, `G`, `B` are required
/// (any other channel, e.g. `A`, is ignored); f16, f32 and u32 samples are converted to f32.
/// The data window is taken as the image; [`decode_image_placed`] also says where it lies in the
/// display window.
///
/// PNG: 8- or 16-bit, grey, grey+alpha, RGB, RGBA or palette; values are sRGB-decoded.
/// Alpha is dropped, not composited: renders and references are opaque.
pub fn read_image(path: impl AsRef<Path>) -> Result<Image> {
    read_image_placed(path).map(|(image, _)| image)
}

/// [`read_image`], and where its pixels lie in the image's frame ([`decode_image_placed`]).
pub fn read_image_placed(path: impl AsRef<Path>) -> Result<(Image, Placement)> {
    let path = path.as_ref();
    format_of(path)?;
    let bytes = color::input::read_regular(path, MAX_INPUT_BYTES).map_err(|e| CompareError::io(path, e))?;
    decode_image_placed(path, &bytes)
}

/// The bits per sample of the PNG at `path` (8 for 1–8-bit files, 16), `None` for any other
/// file or one that cannot be read.
pub fn png_bit_depth(path: impl AsRef<Path>) -> Option<u8> {
    let path = path.as_ref();
    if format_of(path).ok()? != Format::Png {
        return None;
    }
    let file = std::fs::File::open(path).ok()?;
    let reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().ok()?;
    Some(if reader.info().bit_depth == png::BitDepth::Sixteen { 16 } else { 8 })
}

/// Decodes the bytes of an EXR or PNG file as [`read_image`] does, the format chosen by the
/// extension of `path` (which only names the image in messages).
pub fn decode_image(path: impl AsRef<Path>, bytes: &[u8]) -> Result<Image> {
    decode_image_placed(path, bytes).map(|(image, _)| image)
}

/// [`decode_image`], and where the pixels lie in the image's frame (an EXR's data and display
/// windows; a PNG is its whole frame), for comparing images pixel for pixel
/// ([`crate::frame::align`]).
pub fn decode_image_placed(path: impl AsRef<Path>, bytes: &[u8]) -> Result<(Image, Placement)> {
    let path = path.as_ref();
    let format = format_of(path)?;
    match format {
        Format::Exr => read_exr_channels(path, bytes, 64),
        Format::Png => read_png(path, bytes).map(|im| {
            let size = im.size();
            (im, Placement::whole(size))
        }),
    }
}

/// An EXR in memory as its first valid layer with every channel as flat samples, plus the
/// image's attributes: what both the RGB and the spectral readers need (the caller has checked
/// the headers with [`check_exr_headers`]).
pub(crate) type FlatExr = exr::prelude::Image<Layer<AnyChannels<FlatSamples>>>;

pub(crate) fn read_flat_exr(bytes: &[u8]) -> std::result::Result<FlatExr, exr::error::Error> {
    exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
}

/// The R, G, B channels of a spectral EXR (which holds them beside its bands: more channels
/// than [`read_image`] takes).
pub fn read_spectral_exr_rgb(path: impl AsRef<Path>) -> Result<Image> {
    let path = path.as_ref();
    let bytes = color::input::read_regular(path, MAX_INPUT_BYTES).map_err(|e| CompareError::io(path, e))?;
    read_exr_channels(path, &bytes, crate::spectral::MAX_BANDS as u64 + 8).map(|(image, _)| image)
}

fn read_exr_channels(path: &Path, bytes: &[u8], max_channels: u64) -> Result<(Image, Placement)> {
    let decode = |reason: String| CompareError::Decode { path: path.into(), format: "OpenEXR", reason };
    check_exr_headers(path, bytes, max_channels)?;
    // Every part, for the first that holds R, G and B (a render's beauty pass need not be the
    // file's first part).
    let image = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| decode(e.to_string()))?;
    let to_srgb = exr_to_srgb(&image.attributes).map_err(decode)?;
    let layers = &image.layer_data;
    let has = |l: &Layer<AnyChannels<FlatSamples>>, n: &str| l.channel_data.list.iter().any(|c| c.name.eq(n));
    let Some(layer) = layers.iter().find(|l| ["R", "G", "B"].iter().all(|n| has(l, n))) else {
        let first = layers.first();
        let missing: Vec<&str> =
            ["R", "G", "B"].into_iter().filter(|n| !first.is_some_and(|l| has(l, n))).collect();
        let names = |l: &Layer<AnyChannels<FlatSamples>>| {
            let v: Vec<String> = l.channel_data.list.iter().map(|c| c.name.to_string()).collect();
            if v.is_empty() { "none".to_string() } else { v.join(", ") }
        };
        let present = match layers.len() {
            0 => "none".to_string(),
            1 => names(&layers[0]),
            _ => layers
                .iter()
                .enumerate()
                .map(|(i, l)| match &l.attributes.layer_name {
                    Some(n) => format!("part {i} ({n}): {}", names(l)),
                    None => format!("part {i}: {}", names(l)),
                })
                .collect::<Vec<_>>()
                .join("; "),
        };
        return Err(CompareError::MissingChannels {
            path: path.into(),
            missing: missing.join(", "),
            present,
        });
    };
    let channels = &layer.channel_data.list;
    let find = |name: &str| channels.iter().find(|c| c.name.eq(name)).expect("checked above");
    let (r, g, b) = (find("R"), find("G"), find("B"));
    for c in [r, g, b] {
        if c.sampling != Vec2(1, 1) {
            return Err(decode(format!("channel {} is subsampled, which is not supported", c.name)));
        }
    }
    let (w, h) = (layer.size.width(), layer.size.height());
    let (width, height) = (
        u32::try_from(w).map_err(|_| decode(format!("width {w} too large")))?,
        u32::try_from(h).map_err(|_| decode(format!("height {h} too large")))?,
    );
    let data = (0..w * h)
        .map(|i| {
            let p = [r, g, b].map(|c| c.sample_data.value_by_flat_index(i).to_f32());
            match to_srgb {
                Some(m) => (m * glam::Vec3::from(p)).to_array(),
                None => p,
            }
        })
        .collect();
    let placement =
        Placement::of_exr(&image.attributes.display_window, layer.attributes.layer_position, (w, h));
    Ok((Image::new(width, height, data).map_err(|e| decode(e.to_string()))?, placement))
}

/// The matrix from an EXR's RGB to linear sRGB by its `chromaticities` attribute (`None`: absent,
/// or Rec. 709's, which files without it are taken to hold), as the environment maps' reader
/// converts them (`color::colorspace::to_srgb_from_chromaticities`).
fn exr_to_srgb(
    attributes: &exr::meta::header::ImageAttributes,
) -> std::result::Result<Option<glam::Mat3>, String> {
    let Some(c) = attributes.chromaticities else {
        return Ok(None);
    };
    let n: Vec<f64> =
        [c.red, c.green, c.blue, c.white].iter().flat_map(|v| [f64::from(v.0), f64::from(v.1)]).collect();
    let m = color::colorspace::to_srgb_from_chromaticities(&n).ok_or_else(|| {
        format!(
            "attribute chromaticities: {n:?} are not the x y of red, green, blue and white of a colour space"
        )
    })?;
    Ok((m != glam::DMat3::IDENTITY).then(|| m.as_mat3()))
}

/// Checks an EXR's headers against the size caps before any sample is decoded: the reader
/// allocates every layer's samples from its data window, and reads every channel.
pub(crate) fn check_exr_headers(path: &Path, bytes: &[u8], max_channels: u64) -> Result<()> {
    let decode = |reason: String| CompareError::Decode { path: path.into(), format: "OpenEXR", reason };
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| decode(header_error(bytes, e)))?;
    for h in &meta.headers {
        let (w, ht) = (h.layer_size.width() as u64, h.layer_size.height() as u64);
        check_size(path, "OpenEXR", w, ht)?;
        let n = h.channels.list.len() as u64;
        if n > max_channels || w * ht * n * 4 > MAX_DECODED_BYTES {
            return Err(decode(format!(
                "{w}×{ht} with {n} channels; at most {max_channels} channels and {} MiB of samples are read",
                MAX_DECODED_BYTES >> 20
            )));
        }
    }
    if meta.headers.len() > 64 {
        return Err(decode(format!("{} layers; at most 64 are read", meta.headers.len())));
    }
    Ok(())
}

/// Why the exr crate refused an EXR's headers, said plainly where its words mislead: an empty file
/// ("reference to missing bytes"), a compression method newer than it (OpenEXR 3.4's LJ2K and
/// ZSTD, 12 and 13: "missing or invalid compression attribute", as if the file were damaged).
fn header_error(bytes: &[u8], e: exr::error::Error) -> String {
    if bytes.is_empty() {
        return "the file is empty".into();
    }
    // The attribute's name, type, size (1) and value: the first part's.
    let key = b"compression\0compression\0\x01\0\0\0";
    let method = bytes.windows(key.len()).position(|w| w == key).and_then(|at| bytes.get(at + key.len()));
    if let Some(&m) = method
        && m > 11
    {
        let name = match m {
            12 => " (LJ2K)",
            13 => " (ZSTD)",
            _ => "",
        };
        return format!(
            "compression method {m}{name} is not supported; these are: none, RLE, ZIPS, ZIP, PIZ, PXR24, B44, \
             B44A, DWAA, DWAB (rewrite it with one, e.g. `oiiotool IN --compression zip -o OUT`)"
        );
    }
    e.to_string()
}

fn read_png(path: &Path, bytes: &[u8]) -> Result<Image> {
    let decode = |reason: String| CompareError::Decode { path: path.into(), format: "PNG", reason };
    let png = || image::ImageReader::with_format(Cursor::new(bytes), image::ImageFormat::Png);
    let (w, h) = png().into_dimensions().map_err(|e| decode(e.to_string()))?;
    check_size(path, "PNG", w.into(), h.into())?;
    let mut reader = png();
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_INPUT_DIMENSION as u32);
    limits.max_image_height = Some(MAX_INPUT_DIMENSION as u32);
    // RGBA at 16 bits per channel.
    limits.max_alloc = Some(8 * MAX_INPUT_PIXELS);
    reader.limits(limits);
    let img = reader.decode().map_err(|e| decode(e.to_string()))?;
    let ct = img.color();
    let bits_per_channel = ct.bits_per_pixel() / u16::from(ct.channel_count());
    let (width, height) = (img.width(), img.height());
    let (to_linear, to_srgb) = png_transfer(bytes).map_err(decode)?;
    check_palette(bytes).map_err(decode)?;
    // Lookup tables: decoding is the same few thousand values over and over.
    let data: Vec<[f32; 3]> = if bits_per_channel > 8 {
        let lut: Vec<f32> = (0..=u16::MAX).map(|v| to_linear.decode(f64::from(v) / 65535.0) as f32).collect();
        img.to_rgb16().pixels().map(|p| p.0.map(|v| lut[v as usize])).collect()
    } else {
        let lut: Vec<f32> = (0..=u8::MAX).map(|v| to_linear.decode(f64::from(v) / 255.0) as f32).collect();
        img.to_rgb8().pixels().map(|p| p.0.map(|v| lut[v as usize])).collect()
    };
    let data = match to_srgb {
        Some(m) => data.into_iter().map(|p: [f32; 3]| (m * glam::Vec3::from(p)).to_array()).collect(),
        None => data,
    };
    Image::new(width, height, data).map_err(|e| decode(e.to_string()))
}

/// How a PNG's samples become linear light, from its colour chunks, in the PNG specification's
/// order of precedence (3rd edition, §4.3): cICP, then iCCP, then sRGB, then gAMA; with none,
/// sRGB. A gAMA of 1.0 (linear data) was read as sRGB before.
#[derive(Clone, Copy, Debug, PartialEq)]
enum PngTransfer {
    Srgb,
    /// `linear = sample^(1/gamma)`: gAMA's "image gamma" (0.45455 for a 2.2 display).
    Power(f64),
}

impl PngTransfer {
    fn decode(self, v: f64) -> f64 {
        match self {
            PngTransfer::Srgb => srgb_decode(v),
            PngTransfer::Power(g) => v.powf(1.0 / g),
        }
    }
}

/// The transfer of the PNG in `bytes` (see [`PngTransfer`]) and, from a cHRM chunk naming other
/// primaries or white than sRGB's, the matrix from its linear RGB to linear sRGB (Bradford, as
/// EXR `chromaticities`); ICC profiles are not interpreted (read as sRGB, the profile nearly
/// every PNG that carries one has); cICP is accepted for Rec. 709 primaries with the sRGB or a
/// linear transfer at full range, refused otherwise (HDR PNGs: PQ, HLG; narrow-range video).
fn png_transfer(bytes: &[u8]) -> std::result::Result<(PngTransfer, Option<glam::Mat3>), String> {
    let reader = png::Decoder::new(Cursor::new(bytes)).read_info().map_err(|e| e.to_string())?;
    let info = reader.info();
    if let Some(c) = &info.coding_independent_code_points {
        if !c.is_video_full_range_image {
            return Err("cICP chunk: narrow-range (video) samples are not supported; only full range is: \
                        write an EXR of linear sRGB instead"
                .into());
        }
        return match (c.color_primaries, c.transfer_function) {
            (1, 13) => Ok((PngTransfer::Srgb, None)),
            (1, 8) => Ok((PngTransfer::Power(1.0), None)),
            (p, t) => Err(format!(
                "cICP chunk: colour primaries {p}, transfer {t} (ITU-T H.273) are not supported; only Rec. 709 \
                 primaries (1) with the sRGB (13) or linear (8) transfer are: write an EXR of linear sRGB instead"
            )),
        };
    }
    if info.icc_profile.is_some() || info.srgb.is_some() {
        return Ok((PngTransfer::Srgb, None));
    }
    // cHRM counts only where no cICP, iCCP or sRGB chunk says otherwise (the same precedence).
    let to_srgb = match &info.chrm_chunk {
        None => None,
        Some(c) => {
            let n: Vec<f64> = [c.red, c.green, c.blue, c.white]
                .iter()
                .flat_map(|(x, y)| [f64::from(x.into_value()), f64::from(y.into_value())])
                .collect();
            let m = color::colorspace::to_srgb_from_chromaticities(&n).ok_or_else(|| {
                format!("cHRM chunk: {n:?} are not the x y of red, green, blue and white of a colour space")
            })?;
            (m != glam::DMat3::IDENTITY).then(|| m.as_mat3())
        }
    };
    let transfer = match info.gama_chunk.map(|g| f64::from(g.into_value())) {
        None => PngTransfer::Srgb,
        Some(g) if (0.01..=100.0).contains(&g) => PngTransfer::Power(g),
        Some(g) => return Err(format!("gAMA chunk: image gamma {g} is outside 0.01–100")),
    };
    Ok((transfer, to_srgb))
}

/// A palette image's indices must name palette entries (the PNG specification calls any other
/// an error; decoders show such pixels black, a colour the file never held).
fn check_palette(bytes: &[u8]) -> std::result::Result<(), String> {
    let mut decoder = png::Decoder::new(Cursor::new(bytes));
    decoder.set_transformations(png::Transformations::IDENTITY);
    let mut reader = decoder.read_info().map_err(|e| e.to_string())?;
    let info = reader.info();
    if info.color_type != png::ColorType::Indexed {
        return Ok(());
    }
    let entries = info.palette.as_ref().map_or(0, |p| p.len() / 3);
    let bits = info.bit_depth as usize;
    let (w, h) = (info.width as usize, info.height as usize);
    let mut buf = vec![0; reader.output_buffer_size().ok_or("image too large")?];
    let frame = reader.next_frame(&mut buf).map_err(|e| e.to_string())?;
    let per_byte = 8 / bits;
    for y in 0..h {
        let row = &buf[y * frame.line_size..];
        for x in 0..w {
            let byte = row[x / per_byte];
            let shift = 8 - bits * (x % per_byte + 1);
            let index = (usize::from(byte) >> shift) & ((1 << bits) - 1);
            if index >= entries {
                return Err(format!(
                    "pixel ({x}, {y}): palette index {index}, but the palette has {entries} entries"
                ));
            }
        }
    }
    Ok(())
}

/// Writes an image as EXR or PNG (by extension), atomically: on error no file is created
/// and an existing file at `path` is left untouched.
///
/// PNG output needs finite pixels (a NaN has no honest 8-bit encoding); it is an error
/// naming the first offending pixel. EXR stores NaN and ∞ as they are.
pub fn write_image(path: impl AsRef<Path>, image: &Image, opts: WriteOptions) -> Result<()> {
    let path = path.as_ref();
    write_atomic(path, &encode_image(path, image, opts)?)
}

/// The bytes [`write_image`] writes to `path` (whose extension picks the format), for a command
/// that stages several outputs before it puts any in place ([`crate::atomic::stage`]).
pub fn encode_image(path: impl AsRef<Path>, image: &Image, opts: WriteOptions) -> Result<Vec<u8>> {
    let path = path.as_ref();
    let format = format_of(path)?;
    // The fields are public, so a hand-built image may be inconsistent.
    image.validate()?;
    match format {
        Format::Exr => encode_exr(path, image, opts.exr, None),
        Format::Png => encode_png(path, image, opts.png),
    }
}

/// Writes `image` as an EXR (f32) whose pixels sit in `frame` (display and data windows,
/// `spectra.*` attributes), atomically: a crop or sample chunk of a render.
pub fn write_exr_framed(path: impl AsRef<Path>, image: &Image, frame: &crate::frame::ExrFrame) -> Result<()> {
    let path = path.as_ref();
    write_atomic(path, &encode_exr_framed(path, image, frame)?)
}

/// The bytes [`write_exr_framed`] writes to `path`, for staging beside other outputs.
pub fn encode_exr_framed(
    path: impl AsRef<Path>,
    image: &Image,
    frame: &crate::frame::ExrFrame,
) -> Result<Vec<u8>> {
    let path = path.as_ref();
    if format_of(path)? != Format::Exr {
        return Err(CompareError::InvalidImage(format!(
            "{}: a crop or sample chunk is stored as OpenEXR; give it a .exr name",
            path.display()
        )));
    }
    image.validate()?;
    encode_exr(path, image, ExrPrecision::F32, Some(frame))
}

fn encode_exr(
    path: &Path,
    image: &Image,
    precision: ExrPrecision,
    frame: Option<&crate::frame::ExrFrame>,
) -> Result<Vec<u8>> {
    let w = image.width as usize;
    let size = (w, image.height as usize);
    let px = |x: usize, y: usize| image.data[y * w + x];
    let mut attributes = exr::meta::header::LayerAttributes::default();
    let image_attributes = match frame {
        Some(f) => Some(f.apply(path, (image.width, image.height), &mut attributes)?),
        None => None,
    };
    let mut buf = Cursor::new(Vec::new());
    // ZIP over scan lines: lossless, compact, and readable by every EXR implementation.
    macro_rules! write_with {
        ($ch:expr) => {{
            let layer = exr::prelude::Layer::new(size, attributes, Encoding::SMALL_LOSSLESS, $ch);
            match image_attributes {
                Some(ia) => exr::prelude::Image::new(ia, layer).write().to_buffered(&mut buf),
                None => exr::prelude::Image::from_layer(layer).write().to_buffered(&mut buf),
            }
        }};
    }
    let res = match precision {
        ExrPrecision::F32 => write_with!(SpecificChannels::rgb(|Vec2(x, y)| {
            let p = px(x, y);
            (p[0], p[1], p[2])
        })),
        ExrPrecision::F16 => write_with!(SpecificChannels::rgb(|Vec2(x, y)| {
            let p = px(x, y).map(f16::from_f32);
            (p[0], p[1], p[2])
        })),
    };
    res.map_err(|e| CompareError::Encode { path: path.into(), format: "OpenEXR", reason: e.to_string() })?;
    Ok(buf.into_inner())
}

/// Linear → display-encoded sRGB in [0, 1]: clamp first, as a display would.
pub fn to_display(v: f32) -> f64 {
    srgb_encode(f64::from(v).clamp(0.0, 1.0))
}

fn encode_png(path: &Path, image: &Image, depth: PngBitDepth) -> Result<Vec<u8>> {
    image.check_finite(&path.display().to_string())?;
    let enc_err = |e: image::ImageError| CompareError::Encode {
        path: path.into(),
        format: "PNG",
        reason: e.to_string(),
    };
    let mut buf = Cursor::new(Vec::new());
    let (w, h) = (image.width, image.height);
    match depth {
        PngBitDepth::Eight => {
            let raw: Vec<u8> =
                image.data.iter().flat_map(|p| p.map(|v| (to_display(v) * 255.0).round() as u8)).collect();
            let img = image::RgbImage::from_raw(w, h, raw).expect("length checked by write_image");
            img.write_to(&mut buf, image::ImageFormat::Png).map_err(enc_err)?;
        }
        PngBitDepth::Sixteen => {
            let raw: Vec<u16> =
                image.data.iter().flat_map(|p| p.map(|v| (to_display(v) * 65535.0).round() as u16)).collect();
            let img = image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(w, h, raw)
                .expect("length checked by write_image");
            img.write_to(&mut buf, image::ImageFormat::Png).map_err(enc_err)?;
        }
    }
    Ok(buf.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::ImageEncoder;

    fn test_image() -> Image {
        // HDR and negative values on purpose: EXR must keep them.
        Image::from_fn(13, 7, |x, y| [x as f32 * 0.37 - 0.5, y as f32 * 1.9, (x * y) as f32 / 91.0 + 1e-4])
            .unwrap()
    }

    /// A PNG of one grey row `v` (8-bit) with the chunks `setup` adds, and `extra` chunks (type,
    /// data) after IHDR.
    fn png_with(
        v: &[u8],
        setup: impl FnOnce(&mut png::Encoder<&mut Vec<u8>>),
        extra: &[(&[u8; 4], &[u8])],
    ) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut e = png::Encoder::new(&mut out, v.len() as u32, 1);
            e.set_color(png::ColorType::Grayscale);
            setup(&mut e);
            e.write_header().unwrap().write_image_data(v).unwrap();
        }
        // After the 8-byte signature and IHDR (4 + 4 + 13 + 4 bytes).
        let mut chunks = Vec::new();
        for (kind, data) in extra {
            let crc = |b: &[u8]| {
                let mut c = 0xffff_ffffu32;
                for &x in b {
                    c ^= u32::from(x);
                    for _ in 0..8 {
                        c = if c & 1 != 0 { 0xedb8_8320 ^ (c >> 1) } else { c >> 1 };
                    }
                }
                !c
            };
            chunks.extend_from_slice(&(data.len() as u32).to_be_bytes());
            let body = [&kind[..], data].concat();
            chunks.extend_from_slice(&body);
            chunks.extend_from_slice(&crc(&body).to_be_bytes());
        }
        [&out[..33], &chunks, &out[33..]].concat()
    }

    /// An EXR of one part per `(name, channels)`, every sample of channel c `values[c]`, with
    /// `chromaticities` (x y of red, green, blue, white) if given.
    fn exr_parts(parts: &[(&str, &[(&str, f32)])], chromaticities: Option<[f32; 8]>) -> Vec<u8> {
        use exr::prelude::*;
        let layers: Vec<Layer<AnyChannels<FlatSamples>>> = parts
            .iter()
            .map(|(name, channels)| {
                let list: Vec<AnyChannel<FlatSamples>> = channels
                    .iter()
                    .map(|(n, v)| AnyChannel::new(*n, FlatSamples::F32(vec![*v; 4])))
                    .collect();
                Layer::new(
                    (2, 2),
                    LayerAttributes::named(*name),
                    Encoding::UNCOMPRESSED,
                    AnyChannels::sort(list.into()),
                )
            })
            .collect();
        let mut image = exr::prelude::Image::from_layers(
            ImageAttributes::new(IntegerBounds::from_dimensions((2, 2))),
            layers,
        );
        if let Some(c) = chromaticities {
            image.attributes.chromaticities = Some(exr::meta::attribute::Chromaticities {
                red: Vec2(c[0], c[1]),
                green: Vec2(c[2], c[3]),
                blue: Vec2(c[4], c[5]),
                white: Vec2(c[6], c[7]),
            });
        }
        let mut out = Cursor::new(Vec::new());
        image.write().to_buffered(&mut out).unwrap();
        out.into_inner()
    }

    /// An EXR's `chromaticities` converts its RGB to linear sRGB (Bradford to D65), as the
    /// environment maps' reader does: ACES AP0 (0.8, 0.2, 0.1) is colour-science 0.4.7's
    /// `RGB_to_RGB(…, 'ACES2065-1', 'sRGB', chromatic_adaptation_transform='Bradford')` with both
    /// spaces' matrices derived from their primaries (`use_derived_matrix_*`, the colour crate's
    /// convention; with the standards' rounded matrices 1.75156538, 0.04391963, 0.07398405);
    /// Rec. 709's are the identity; a white that is no colour is refused by name.
    #[test]
    fn exr_chromaticities_convert_to_srgb() {
        let rgb: &[(&str, f32)] = &[("R", 0.8), ("G", 0.2), ("B", 0.1)];
        let ap0 = [0.7347, 0.2653, 0.0, 1.0, 0.0001, -0.077, 0.32168, 0.33767];
        let img = decode_image("ap0.exr", &exr_parts(&[("rgb", rgb)], Some(ap0))).unwrap();
        let want: [f64; 3] = [1.75176723, 0.04373597, 0.07393782];
        for (got, want) in img.data[0].iter().zip(want) {
            assert!((f64::from(*got) - want).abs() < 2e-6, "{:?} vs {want:?}", img.data[0]);
        }
        let rec709 = [0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290];
        let img = decode_image("709.exr", &exr_parts(&[("rgb", rgb)], Some(rec709))).unwrap();
        assert_eq!(img.data[0], [0.8, 0.2, 0.1]);
        let bad = [0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.0, 0.0];
        let e = decode_image("bad.exr", &exr_parts(&[("rgb", rgb)], Some(bad))).unwrap_err().to_string();
        assert!(e.contains("bad.exr") && e.contains("chromaticities"), "{e}");
    }

    /// R, G, B are read from the first part that has them; without any, the error lists every
    /// part's channels.
    #[test]
    fn exr_rgb_comes_from_the_first_part_that_has_it() {
        let y: &[(&str, f32)] = &[("Y", 0.3)];
        let rgb: &[(&str, f32)] = &[("R", 0.8), ("G", 0.2), ("B", 0.1)];
        let img = decode_image("m.exr", &exr_parts(&[("lum", y), ("beauty", rgb)], None)).unwrap();
        assert_eq!(img.data[0], [0.8, 0.2, 0.1]);
        let e = decode_image("m.exr", &exr_parts(&[("lum", y), ("alpha", &[("A", 1.0)])], None))
            .unwrap_err()
            .to_string();
        assert!(e.contains("part 0 (lum): Y") && e.contains("part 1 (alpha): A"), "{e}");
    }

    /// A cHRM chunk (with no sRGB, iCCP or cICP chunk) converts to linear sRGB: Rec. 2020
    /// primaries, D65, gAMA 1.0, codes (128, 51, 26) are colour-science 0.4.7's
    /// `RGB_to_RGB(codes / 255, 'ITU-R BT.2020', 'sRGB', chromatic_adaptation_transform='Bradford')`
    /// with derived matrices: (0.70854531, 0.16320921, 0.0848398). A palette index past the
    /// palette and narrow-range cICP are errors (they were read as black and as full range).
    #[test]
    fn png_chrm_palette_and_cicp_range() {
        let rgb_png = |extra: &[(&[u8; 4], &[u8])]| {
            let mut out = Vec::new();
            {
                let mut e = png::Encoder::new(&mut out, 1, 1);
                e.set_color(png::ColorType::Rgb);
                e.set_source_gamma(png::ScaledFloat::new(1.0));
                e.write_header().unwrap().write_image_data(&[128, 51, 26]).unwrap();
            }
            let mut chunks = Vec::new();
            for (kind, data) in extra {
                let body = [&kind[..], data].concat();
                chunks.extend_from_slice(&(data.len() as u32).to_be_bytes());
                chunks.extend_from_slice(&body);
                chunks.extend_from_slice(&crc32(&body).to_be_bytes());
            }
            [&out[..33], &chunks, &out[33..]].concat()
        };
        let chrm: Vec<u8> = [0.3127, 0.3290, 0.708, 0.292, 0.170, 0.797, 0.131, 0.046]
            .iter()
            .flat_map(|v: &f64| ((v * 100000.0).round() as u32).to_be_bytes())
            .collect();
        let img = decode_image("c.png", &rgb_png(&[(b"cHRM", &chrm)])).unwrap();
        let want: [f64; 3] = [0.70854531, 0.16320921, 0.0848398];
        for (got, want) in img.data[0].iter().zip(want) {
            assert!((f64::from(*got) - want).abs() < 2e-6, "{:?} vs {want:?}", img.data[0]);
        }
        // sRGB's own primaries change nothing.
        let srgb: Vec<u8> = [0.3127, 0.3290, 0.64, 0.33, 0.30, 0.60, 0.15, 0.06]
            .iter()
            .flat_map(|v: &f64| ((v * 100000.0).round() as u32).to_be_bytes())
            .collect();
        let img = decode_image("c.png", &rgb_png(&[(b"cHRM", &srgb)])).unwrap();
        assert_eq!(img.data[0], [128.0 / 255.0, 51.0 / 255.0, 26.0 / 255.0]);
        // cICP: Rec. 709, sRGB transfer, narrow range.
        let e = decode_image("n.png", &rgb_png(&[(b"cICP", &[1, 13, 0, 0])])).unwrap_err().to_string();
        assert!(e.contains("n.png") && e.contains("narrow-range"), "{e}");

        let mut out = Vec::new();
        {
            let mut e = png::Encoder::new(&mut out, 3, 1);
            e.set_color(png::ColorType::Indexed);
            e.set_palette(vec![0u8, 0, 0, 255, 255, 255]);
            e.write_header().unwrap().write_image_data(&[0, 1, 200]).unwrap();
        }
        let e = decode_image("p.png", &out).unwrap_err().to_string();
        assert!(
            e.contains("p.png") && e.contains("pixel (2, 0): palette index 200") && e.contains("2 entries"),
            "{e}"
        );
    }

    /// PNG colour chunks decide how samples become linear (gAMA 1.0 used to be read as sRGB).
    #[test]
    fn png_colour_chunks_are_honoured() {
        let v = [0u8, 10, 64, 128, 200, 255];
        let read =
            |b: &[u8]| decode_image("t.png", b).map(|i| i.data.iter().map(|p| p[0]).collect::<Vec<f32>>());
        let srgb: Vec<f32> = v.iter().map(|&x| srgb_decode(f64::from(x) / 255.0) as f32).collect();
        assert_eq!(read(&png_with(&v, |_| {}, &[])).unwrap(), srgb, "no chunk: sRGB");
        let with_srgb = png_with(&v, |e| e.set_source_srgb(png::SrgbRenderingIntent::Perceptual), &[]);
        assert_eq!(read(&with_srgb).unwrap(), srgb, "sRGB chunk (with its fallback gAMA)");
        let linear = read(&png_with(&v, |e| e.set_source_gamma(png::ScaledFloat::new(1.0)), &[])).unwrap();
        for (&got, &x) in linear.iter().zip(&v) {
            assert!((got - f32::from(x) / 255.0).abs() < 1e-6, "gAMA 1.0: linear");
        }
        let g22 = read(&png_with(&v, |e| e.set_source_gamma(png::ScaledFloat::new(0.45455)), &[])).unwrap();
        for (&got, &x) in g22.iter().zip(&v) {
            let want = (f64::from(x) / 255.0).powf(1.0 / 0.45455) as f32;
            assert!((got - want).abs() < 1e-6, "gAMA 0.45455: a 2.2 power, {got} vs {want}");
        }
        // cICP: Rec. 709 primaries with a linear transfer is linear; PQ (16) is refused.
        let cicp = |t: u8| png_with(&v, |_| {}, &[(b"cICP", &[1, t, 0, 1])]);
        assert_eq!(read(&cicp(13)).unwrap(), srgb);
        assert!((read(&cicp(8)).unwrap()[3] - 128.0 / 255.0).abs() < 1e-6);
        let e = read(&cicp(16)).unwrap_err().to_string();
        assert!(e.contains("t.png") && e.contains("cICP") && e.contains("16"), "{e}");
        // gAMA 0 is invalid (the png decoder drops it: sRGB); an absurd one is refused.
        assert_eq!(read(&png_with(&v, |_| {}, &[(b"gAMA", &0u32.to_be_bytes())])).unwrap(), srgb);
        let huge = png_with(&v, |_| {}, &[(b"gAMA", &1_000_000_000u32.to_be_bytes())]);
        let e = read(&huge).unwrap_err().to_string();
        assert!(e.contains("gAMA") && e.contains("10000"), "{e}");
    }

    fn names(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect()
    }

    #[test]
    fn exr_f32_round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.EXR");
        let im = test_image();
        write_image(&p, &im, WriteOptions::default()).unwrap();
        assert_eq!(read_image(&p).unwrap(), im);
    }

    #[test]
    fn exr_f16_round_trip_within_half_precision() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.exr");
        let im = test_image();
        write_image(&p, &im, WriteOptions { exr: ExrPrecision::F16, ..Default::default() }).unwrap();
        let back = read_image(&p).unwrap();
        for (a, b) in im.data.iter().zip(&back.data) {
            for k in 0..3 {
                // f16 has an 11-bit significand: relative error ≤ 2⁻¹¹ (normal range).
                assert!((a[k] - b[k]).abs() <= a[k].abs() * 4.9e-4 + 6.1e-5, "{a:?} {b:?}");
            }
        }
        // Smaller than the f32 file: it really stored halves.
        let p32 = dir.path().join("f.exr");
        write_image(&p32, &im, WriteOptions::default()).unwrap();
        assert!(std::fs::metadata(&p).unwrap().len() < std::fs::metadata(&p32).unwrap().len());
    }

    #[test]
    fn png8_round_trip_on_code_values() {
        // Linear values that are exactly decoded 8-bit codes must come back unchanged, and
        // re-encoding them must give the same codes.
        let codes: Vec<u8> = (0..=255).collect();
        let im = Image::from_fn(16, 16, |x, y| {
            let c = codes[(y * 16 + x) as usize];
            let v = srgb_decode(f64::from(c) / 255.0) as f32;
            [v, srgb_decode(f64::from(255 - c) / 255.0) as f32, 0.0]
        })
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("c.png");
        write_image(&p, &im, WriteOptions::default()).unwrap();
        let raw = image::open(&p).unwrap();
        assert_eq!(raw.color(), image::ColorType::Rgb8);
        let raw = raw.to_rgb8();
        assert!(raw.pixels().enumerate().all(|(i, px)| px.0 == [i as u8, 255 - i as u8, 0]));
        assert_eq!(read_image(&p).unwrap(), im);
    }

    #[test]
    fn png_clamps_and_16_bit_is_finer() {
        let im = Image::from_fn(5, 2, |x, _| [x as f32 * 0.3 - 0.2, 0.123_456, 2.0]).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let p8 = dir.path().join("a.png");
        let p16 = dir.path().join("b.png");
        write_image(&p8, &im, WriteOptions::default()).unwrap();
        write_image(&p16, &im, WriteOptions { png: PngBitDepth::Sixteen, ..Default::default() }).unwrap();
        assert_eq!(image::open(&p16).unwrap().color(), image::ColorType::Rgb16);
        let (b8, b16) = (read_image(&p8).unwrap(), read_image(&p16).unwrap());
        assert_eq!(b8.get(0, 0)[0], 0.0);
        assert_eq!(b16.get(0, 1)[2], 1.0);
        // Half a code step of slope: 8-bit error ≤ 0.5/255 in encoded terms, 16-bit ≤ 0.5/65535.
        let e8 = (srgb_encode(f64::from(b8.get(2, 0)[1])) - srgb_encode(0.123_456)).abs();
        let e16 = (srgb_encode(f64::from(b16.get(2, 0)[1])) - srgb_encode(0.123_456)).abs();
        assert!(e8 <= 0.5 / 255.0 + 1e-7 && e16 <= 0.5 / 65535.0 + 1e-7, "{e8} {e16}");
        assert!(e16 < e8);
    }

    #[test]
    fn reads_grey_and_rgba_png() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("g.png");
        image::GrayImage::from_raw(2, 1, vec![0, 188]).unwrap().save(&p).unwrap();
        let g = read_image(&p).unwrap();
        let v = srgb_decode(188.0 / 255.0) as f32;
        assert_eq!(g.data, vec![[0.0; 3], [v; 3]]);
        let p = dir.path().join("rgba.png");
        image::RgbaImage::from_raw(1, 1, vec![255, 0, 188, 7]).unwrap().save(&p).unwrap();
        assert_eq!(read_image(&p).unwrap().data, vec![[1.0, 0.0, v]]);
    }

    #[test]
    fn errors_name_the_file_and_the_problem() {
        let dir = tempfile::tempdir().unwrap();
        let im = test_image();
        let e = write_image(dir.path().join("x.tiff"), &im, WriteOptions::default()).unwrap_err().to_string();
        assert!(e.contains("x.tiff") && e.contains("unsupported") && e.contains("tiff"), "{e}");
        let e = read_image(dir.path().join("noext")).unwrap_err().to_string();
        assert!(e.contains("noext") && e.contains("unsupported"), "{e}");
        let e = read_image(dir.path().join("missing.exr")).unwrap_err().to_string();
        assert!(e.contains("missing.exr"), "{e}");
        for name in ["text.png", "text.exr"] {
            let p = dir.path().join(name);
            std::fs::write(&p, b"hello, not an image").unwrap();
            let e = read_image(&p).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains("not a valid"), "{e}");
        }
        // A truncated EXR.
        let good = dir.path().join("good.exr");
        write_image(&good, &im, WriteOptions::default()).unwrap();
        let bytes = std::fs::read(&good).unwrap();
        let cut = dir.path().join("cut.exr");
        std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
        let e = read_image(&cut).unwrap_err().to_string();
        assert!(e.contains("cut.exr"), "{e}");
    }

    /// An empty file and a compression method the exr crate does not know (OpenEXR 3.4's ZSTD,
    /// written by its Python package 3.5) are said as such; they read as a damaged file ("reference
    /// to missing bytes", "missing or invalid compression attribute").
    #[test]
    fn empty_files_and_newer_compressions_are_named() {
        let e = decode_image("e.exr", &[]).unwrap_err().to_string();
        assert!(e.contains("e.exr") && e.contains("the file is empty"), "{e}");
        let mut buf = Cursor::new(Vec::new());
        exr::prelude::Image::from_channels(
            (2, 2),
            SpecificChannels::rgb(|_: Vec2<usize>| (0.5f32, 0.5f32, 0.5f32)),
        )
        .write()
        .to_buffered(&mut buf)
        .unwrap();
        let mut bytes = buf.into_inner();
        let key = b"compression\0compression\0\x01\0\0\0";
        let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len();
        assert!(decode_image("z.exr", &bytes).is_ok());
        bytes[at] = 13;
        let e = decode_image("z.exr", &bytes).unwrap_err().to_string();
        assert!(e.contains("z.exr") && e.contains("compression method 13 (ZSTD) is not supported"), "{e}");
    }

    /// `bytes` of an EXR with its dataWindow replaced by (0, 0)–(w−1, h−1).
    fn claim_size(bytes: &[u8], w: i32, h: i32) -> Vec<u8> {
        let key = b"dataWindow\0box2i\0";
        let at = bytes.windows(key.len()).position(|x| x == key).unwrap() + key.len() + 4;
        let mut out = bytes.to_vec();
        for (i, v) in [0i32, 0, w - 1, h - 1].iter().enumerate() {
            out[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
        }
        out
    }

    #[test]
    fn huge_claimed_sizes_are_refused_before_decoding() {
        // A few hundred bytes claiming 100000² pixels made the old reader allocate 40 GB.
        let dir = tempfile::tempdir().unwrap();
        let small = dir.path().join("small.exr");
        write_image(&small, &Image::filled(2, 2, [0.5; 3]).unwrap(), WriteOptions::default()).unwrap();
        let bytes = std::fs::read(&small).unwrap();
        let huge = dir.path().join("huge.exr");
        std::fs::write(&huge, claim_size(&bytes, 100_000, 100_000)).unwrap();
        let t = std::time::Instant::now();
        let e = read_image(&huge).unwrap_err().to_string();
        assert!(e.contains("huge.exr") && e.contains("100000×100000") && e.contains("accepted"), "{e}");
        assert!(t.elapsed() < std::time::Duration::from_secs(2));

        let png = dir.path().join("huge.png");
        let mut b = Vec::new();
        image::codecs::png::PngEncoder::new(&mut b)
            .write_image(&[0; 16], 2, 2, image::ExtendedColorType::Rgba8)
            .unwrap();
        // IHDR width and height sit right after the signature, the length and "IHDR".
        b[16..20].copy_from_slice(&100_000u32.to_be_bytes());
        b[20..24].copy_from_slice(&100_000u32.to_be_bytes());
        let crc = crc32(&b[12..29]);
        b[29..33].copy_from_slice(&crc.to_be_bytes());
        std::fs::write(&png, b).unwrap();
        let e = read_image(&png).unwrap_err().to_string();
        assert!(e.contains("huge.png") && e.contains("100000×100000") && e.contains("accepted"), "{e}");
    }

    fn crc32(data: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in data {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
            }
        }
        !c
    }

    #[cfg(unix)]
    #[test]
    fn devices_and_directories_are_not_read() {
        let e = read_image("/dev/zero.exr").unwrap_err().to_string();
        assert!(e.contains("/dev/zero.exr"), "{e}");
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path().join("d.exr");
        std::fs::create_dir(&d).unwrap();
        let e = read_image(&d).unwrap_err().to_string();
        assert!(e.contains("d.exr") && e.contains("a directory"), "{e}");
        let link = dir.path().join("zero.png");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        let e = read_image(&link).unwrap_err().to_string();
        assert!(e.contains("zero.png") && e.contains("a device"), "{e}");
    }

    #[test]
    fn exr_without_rgb_lists_channels() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("lum.exr");
        let ch = SpecificChannels::build()
            .with_channel("Y")
            .with_channel("G")
            .with_pixel_fn(|Vec2(x, _y)| (x as f32, 0.5f32));
        exr::prelude::Image::from_channels((3, 2), ch).write().to_file(&p).unwrap();
        let e = read_image(&p).unwrap_err().to_string();
        assert!(e.contains("lum.exr") && e.contains("missing channel(s) R, B") && e.contains("G, Y"), "{e}");
    }

    #[test]
    fn failed_write_leaves_no_file() {
        let dir = tempfile::tempdir().unwrap();
        let mut im = test_image();
        im.get_mut(4, 5)[2] = f32::NAN;
        let p = dir.path().join("nan.png");
        let e = write_image(&p, &im, WriteOptions::default()).unwrap_err().to_string();
        assert!(e.contains("nan.png") && e.contains("(4, 5)"), "{e}");
        assert!(names(dir.path()).is_empty());
        // An existing file survives a failed overwrite untouched.
        let good = Image::filled(2, 2, [0.5; 3]).unwrap();
        write_image(&p, &good, WriteOptions::default()).unwrap();
        let before = std::fs::read(&p).unwrap();
        assert!(write_image(&p, &im, WriteOptions::default()).is_err());
        assert_eq!(std::fs::read(&p).unwrap(), before);
        assert_eq!(names(dir.path()), vec!["nan.png"]);
        // Inconsistent hand-built image.
        let bad = Image { width: 3, height: 3, data: vec![[0.0; 3]; 2] };
        assert!(write_image(dir.path().join("bad.exr"), &bad, WriteOptions::default()).is_err());
        assert_eq!(names(dir.path()), vec!["nan.png"]);
    }
}
