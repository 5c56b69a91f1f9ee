//! Spectral images in the OpenEXR layout of Fichet, Pacanowski & Wilkie 2021 ("An OpenEXR Layout
//! for Spectral Images", JCGT 10(3)), as pbrt-v4's `SpectralFilm` writes it.
//!
//! One channel per band, the band's wavelength spelled into the name with a comma for the decimal
//! point (a dot separates OpenEXR layers): `S0.562,500nm` is the emissive (unpolarised, Stokes 0)
//! radiance at 562.5 nm, `T.562,500nm` a reflectance (transmittance) at 562.5 nm. The header
//! carries `spectralLayoutVersion` = "1.0" and, for emissive images, `emissiveUnits`. pbrt-v4
//! writes its bucket centres with three decimals and R, G, B beside them; so does spectra.
//!
//! The layout does not store band widths. spectra writes its box bins' edges in an extra header
//! attribute, [`BAND_EDGES_ATTRIBUTE`] (other readers ignore it); a file without it gets bands
//! that meet half-way between neighbouring wavelengths, the outer two as wide as their
//! neighbour's spacing, which is the bucket layout of pbrt-v4 and of any uniform sampling.
//!
//! Integration (observer, white, the convention for non-CIE observers) is `color`'s:
//! [`color::SpectralIntegrator`] on [`color::SampledWavelengths::from_edges`].

use std::io::Cursor;
use std::path::Path;

use color::{Observer, SampledWavelengths, SpectralIntegrator, Spectrum};
use exr::meta::attribute::{AttributeValue, Text};
use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Layer, LayerAttributes, Vec2, WritableImage,
};

use crate::atomic::write_atomic;
use crate::error::{CompareError, Result};
use crate::image::Image;

/// Header attribute holding the band edges in nm, N + 1 numbers separated by spaces.
pub const BAND_EDGES_ATTRIBUTE: &str = "spectra.bandEdgesNm";
/// Header attribute naming the scene white the radiances are normalised against (informative).
pub const WHITE_ATTRIBUTE: &str = "spectra.white";
/// Most spectral channels read (1 nm over 360–830 nm is 471): as many as are written.
pub const MAX_BANDS: usize = color::wavelengths::MAX_BINS;

/// What the band values are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectralKind {
    /// Radiance (Stokes component 0): channels `S0.<λ>nm`.
    Emissive,
    /// Reflectance: channels `T.<λ>nm`.
    Reflective,
}

impl SpectralKind {
    fn prefix(self) -> &'static str {
        match self {
            SpectralKind::Emissive => "S0",
            SpectralKind::Reflective => "T",
        }
    }
}

/// A spectral image: `data[(y * width + x) * bands + b]` is band `b` of pixel (x, y), the mean
/// of the quantity over the band (for radiance: per nm, in the scene's units).
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralImage {
    pub width: u32,
    pub height: u32,
    pub kind: SpectralKind,
    /// Band edges in nm, strictly increasing, one more than there are bands.
    pub edges: Vec<f64>,
    pub data: Vec<f32>,
    /// Name of the white the values are normalised against ([`WHITE_ATTRIBUTE`]), if known.
    pub white: Option<String>,
    /// The bands' own wavelengths where they are not the centres of their edges: a file
    /// without [`BAND_EDGES_ATTRIBUTE`] whose channels are unevenly spaced (each band is then
    /// integrated at its channel's wavelength, weighted by the band's width, and written back
    /// without the attribute). `None`: the centres of the edges.
    pub centres: Option<Vec<f64>>,
}

impl SpectralImage {
    pub fn bands(&self) -> usize {
        self.edges.len().saturating_sub(1)
    }

    /// The wavelengths and widths of the bands.
    pub fn wavelengths(&self) -> Result<SampledWavelengths> {
        let mut wl = SampledWavelengths::from_edges(&self.edges)
            .map_err(|e| CompareError::InvalidImage(e.to_string()))?;
        if let Some(c) = &self.centres {
            let inside = c.len() == wl.lambda.len()
                && c.iter().zip(self.edges.windows(2)).all(|(&l, e)| l >= e[0] && l <= e[1]);
            if !inside {
                return Err(CompareError::InvalidImage(format!(
                    "{} band wavelengths for {} bands, or one outside its band",
                    c.len(),
                    wl.lambda.len()
                )));
            }
            wl.lambda = c.clone();
        }
        Ok(wl)
    }

    fn validate(&self) -> Result<()> {
        let n = self.bands();
        self.wavelengths()?;
        let want = self.width as usize * self.height as usize * n;
        if self.width == 0 || self.height == 0 || self.data.len() != want {
            return Err(CompareError::InvalidImage(format!(
                "{}×{} with {n} bands needs {want} samples, got {}",
                self.width,
                self.height,
                self.data.len()
            )));
        }
        Ok(())
    }

    /// Integrates every pixel with `observer` against `white` (for emissive images the white
    /// normalises: a radiance equal to `white` has Y = 1; for reflective ones it is the
    /// illuminant) and converts to linear sRGB by [`color::film::to_linear_srgb`] (a camera's
    /// channels balanced and shown as they are).
    pub fn to_linear_srgb(&self, observer: &Observer, white: &Spectrum) -> Result<Image> {
        self.to_display(observer, white, color::film::CameraView::Balanced)
    }

    /// [`Self::to_linear_srgb`] with a camera shown as `view` says (`--camera-to-display`).
    pub fn to_display(
        &self,
        observer: &Observer,
        white: &Spectrum,
        view: color::film::CameraView,
    ) -> Result<Image> {
        self.validate()?;
        let wl = self.wavelengths()?;
        let integ = match self.kind {
            SpectralKind::Emissive => SpectralIntegrator::emission(observer, white, &wl),
            SpectralKind::Reflective => SpectralIntegrator::reflectance(observer, white, &wl),
        };
        // A camera is balanced by the white an RGB (1, 1, 1) light emits, as the path tracer
        // that wrote the bands balances it (`truth::spectral::display_matrix`): the colour
        // space's illuminant at the scene white's CIE luminance (the scene white itself when
        // that is D65); a reflectance image by the illuminant.
        let srgb = color::RgbColorSpace::srgb();
        let (white_response, balance_white) = match self.kind {
            SpectralKind::Emissive => {
                let cie = SpectralIntegrator::emission(&Observer::cie1931(), white, &wl);
                let rgb_white = srgb.emission_white(white, |s| cie.integrate(|l| s.eval(l))[1]);
                (integ.integrate(|l| rgb_white.eval(l)), rgb_white)
            }
            SpectralKind::Reflective => (integ.white(), white.clone()),
        };
        let m = color::film::to_linear_srgb(observer, white_response, &balance_white, view)
            .map_err(|e| CompareError::InvalidOption(e.to_string()))?;
        let n = self.bands();
        let mut values = vec![0.0f64; n];
        let data = self
            .data
            .chunks_exact(n)
            .map(|px| {
                values.iter_mut().zip(px).for_each(|(v, &p)| *v = f64::from(p));
                let t = integ.integrate_samples(&values);
                let rgb = m * glam::DVec3::from(t);
                [rgb.x as f32, rgb.y as f32, rgb.z as f32]
            })
            .collect();
        Image::new(self.width, self.height, data)
    }
}

/// The channel name of a band at `lambda` nm, as pbrt-v4 spells it: three decimals, comma.
pub fn channel_name(kind: SpectralKind, lambda: f64) -> String {
    format!("{}.{}nm", kind.prefix(), format!("{lambda:.3}").replace('.', ","))
}

/// Parses a spectral channel name: `None` if the name is not in the layout's namespace (R, G, B,
/// A, other layers), an error naming the channel if it is but cannot be read.
fn parse_channel(name: &str) -> Option<std::result::Result<(SpectralKind, f64), String>> {
    let (prefix, rest) = name.split_once('.')?;
    let kind = match prefix {
        "S0" => SpectralKind::Emissive,
        "T" => SpectralKind::Reflective,
        "S1" | "S2" | "S3" => {
            return Some(Err("polarised (Stokes 1–3) channels are not supported".into()));
        }
        _ => return None,
    };
    let Some(number) = rest.strip_suffix("nm") else {
        return Some(Err(format!("expected the wavelength in nm, like {}", channel_name(kind, 550.0))));
    };
    // A dot would be a layer separator, so a bi-spectral (re-radiation) channel lands here too.
    let ok = !number.is_empty()
        && number.chars().all(|c| c.is_ascii_digit() || c == ',')
        && number.matches(',').count() <= 1
        && !number.starts_with(',');
    let lambda = if ok { number.replace(',', ".").parse::<f64>().ok() } else { None };
    match lambda {
        // Up to a millimetre: a 25-digit "wavelength" made bands reaching −5e22 nm.
        Some(l) if l > 1e6 => {
            Some(Err(format!("{number} nm is longer than a millimetre: not a wavelength in nm")))
        }
        Some(l) if l.is_finite() && l > 0.0 => Some(Ok((kind, l))),
        _ => Some(Err(format!("'{number}' is not a wavelength (digits with a comma decimal separator)"))),
    }
}

fn is_layout_attribute(name: &Text) -> bool {
    name.eq("spectralLayoutVersion")
}

/// Whether EXR bytes hold a spectral image (a channel named `S0.<λ>nm`/`T.<λ>nm`, or the
/// layout's `spectralLayoutVersion` attribute). Reads the header only.
pub fn is_spectral_exr(bytes: &[u8]) -> bool {
    let Ok(meta) = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false) else {
        return false;
    };
    meta.headers.iter().any(|h| {
        h.own_attributes.other.keys().any(is_layout_attribute)
            || h.shared_attributes.other.keys().any(is_layout_attribute)
            || h.channels.list.iter().any(|c| parse_channel(&c.name.to_string()).is_some())
    })
}

/// Reads a spectral EXR file ([`decode_spectral_exr`]).
pub fn read_spectral_exr(path: impl AsRef<Path>) -> Result<SpectralImage> {
    let path = path.as_ref();
    let bytes = color::input::read_regular(path, crate::io::MAX_INPUT_BYTES)
        .map_err(|e| CompareError::io(path, e))?;
    decode_spectral_exr(path, &bytes)
}

/// Decodes a spectral EXR: the first valid layer's `S0.<λ>nm` or `T.<λ>nm` channels, sorted by
/// wavelength (other channels are ignored). Errors name the offending channel: unreadable
/// wavelengths, two channels at one wavelength, a mix of emissive and reflective channels,
/// polarised or subsampled channels, band edges that are unsorted, of zero or negative width, or
/// do not hold their channel's wavelength at their centre.
pub fn decode_spectral_exr(path: impl AsRef<Path>, bytes: &[u8]) -> Result<SpectralImage> {
    decode_spectral_exr_placed(path, bytes).map(|(image, _)| image)
}

/// [`decode_spectral_exr`], and where the pixels lie in the image's frame (its data and display
/// windows), for comparing images pixel for pixel ([`crate::frame::align`]).
pub fn decode_spectral_exr_placed(
    path: impl AsRef<Path>,
    bytes: &[u8],
) -> Result<(SpectralImage, crate::frame::Placement)> {
    let path = path.as_ref();
    let decode =
        |reason: String| CompareError::Decode { path: path.into(), format: "spectral OpenEXR", reason };
    crate::io::check_exr_headers(path, bytes, MAX_BANDS as u64 + 8)?;
    let image = crate::io::read_flat_exr(bytes).map_err(|e| decode(e.to_string()))?;
    let layer = image.layer_data;
    let attr = |name: &str| {
        layer
            .attributes
            .other
            .iter()
            .chain(image.attributes.other.iter())
            .find(|(k, _)| (*k).eq(name))
            .map(|(_, v)| v.clone())
    };
    let text = |name: &str| match attr(name) {
        Some(AttributeValue::Text(t)) => Some(t.to_string()),
        _ => None,
    };

    let mut bands: Vec<(f64, &AnyChannel<FlatSamples>, String)> = Vec::new();
    let mut kind: Option<(SpectralKind, String)> = None;
    for c in &layer.channel_data.list {
        let name = c.name.to_string();
        let Some(parsed) = parse_channel(&name) else { continue };
        let (k, lambda) = parsed.map_err(|why| decode(format!("channel {name}: {why}")))?;
        match &kind {
            None => kind = Some((k, name.clone())),
            Some((k0, first)) if *k0 != k => {
                return Err(decode(format!(
                    "channel {name} and channel {first}: emissive (S0) and reflective (T) bands in one image \
                     are not supported"
                )));
            }
            _ => {}
        }
        if c.sampling != Vec2(1, 1) {
            return Err(decode(format!("channel {name} is subsampled, which is not supported")));
        }
        bands.push((lambda, c, name));
    }
    let Some((kind, _)) = kind else {
        let present: Vec<String> = layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
        return Err(decode(format!(
            "no spectral channel (named like S0.550,000nm or T.550,000nm); the file has: {}",
            if present.is_empty() { "none".into() } else { present.join(", ") }
        )));
    };
    bands.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in bands.windows(2) {
        // Wavelengths are written with three decimals: closer than that is the same band.
        if (w[1].0 - w[0].0).abs() < 5e-4 {
            return Err(decode(format!(
                "channels {} and {} give the same wavelength ({} nm)",
                w[0].2, w[1].2, w[0].0
            )));
        }
    }
    let (edges, centres) = match text(BAND_EDGES_ATTRIBUTE) {
        Some(s) => (edges_from_attribute(&s, &bands, &decode)?, None),
        None => {
            let edges = edges_from_centres(&bands, &decode)?;
            // Unevenly spaced channels are not their bands' centres: keep their wavelengths.
            let own: Vec<f64> = bands.iter().map(|b| b.0).collect();
            let centred =
                own.iter().zip(edges.windows(2)).all(|(&l, e)| (l - 0.5 * (e[0] + e[1])).abs() <= 1e-3);
            (edges, (!centred).then_some(own))
        }
    };
    // Bands that no observer sees would integrate to a black image, silently: 4000–7000 "nm"
    // (Ångström) or an infrared-only file.
    let (lo, hi) = (edges[0], edges[edges.len() - 1]);
    if hi <= color::spectrum::LAMBDA_MIN || lo >= color::spectrum::LAMBDA_MAX {
        return Err(decode(format!(
            "its bands span {}–{} nm, outside the {}–{} nm the observers cover: nothing in it can be seen \
             (are the wavelengths in nm?)",
            color::error::show(lo),
            color::error::show(hi),
            color::spectrum::LAMBDA_MIN,
            color::spectrum::LAMBDA_MAX
        )));
    }
    let (w, h) = (layer.size.width(), layer.size.height());
    let (width, height) = (
        u32::try_from(w).map_err(|_| decode(format!("width {w} too large")))?,
        u32::try_from(h).map_err(|_| decode(format!("height {h} too large")))?,
    );
    let n = bands.len();
    let mut data = vec![0.0f32; w * h * n];
    for (b, (_, c, _)) in bands.iter().enumerate() {
        for i in 0..w * h {
            data[i * n + b] = c.sample_data.value_by_flat_index(i).to_f32();
        }
    }
    let img = SpectralImage { width, height, kind, edges, data, white: text(WHITE_ATTRIBUTE), centres };
    img.validate().map_err(|e| decode(e.to_string()))?;
    let placement = crate::frame::Placement::of_exr(
        &image.attributes.display_window,
        layer.attributes.layer_position,
        (w, h),
    );
    Ok((img, placement))
}

fn edges_from_attribute(
    s: &str,
    bands: &[(f64, &AnyChannel<FlatSamples>, String)],
    decode: &dyn Fn(String) -> CompareError,
) -> Result<Vec<f64>> {
    let edges: Vec<f64> = s
        .split_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| decode(format!("attribute {BAND_EDGES_ATTRIBUTE} '{s}': not a list of numbers")))?;
    if edges.len() != bands.len() + 1 {
        return Err(decode(format!(
            "attribute {BAND_EDGES_ATTRIBUTE} has {} edges for {} spectral channels (want {}): a channel \
             is missing or the edges are wrong",
            edges.len(),
            bands.len(),
            bands.len() + 1
        )));
    }
    for (i, (lambda, _, name)) in bands.iter().enumerate() {
        let (lo, hi) = (edges[i], edges[i + 1]);
        if hi <= lo {
            return Err(decode(format!(
                "channel {name}: its band {lo}–{hi} nm (attribute {BAND_EDGES_ATTRIBUTE}) has a width of {} nm; \
                 edges must be sorted and widths positive",
                hi - lo
            )));
        }
        let centre = 0.5 * (lo + hi);
        if (centre - lambda).abs() > 1e-3 {
            return Err(decode(format!(
                "channel {name}: its band {lo}–{hi} nm (attribute {BAND_EDGES_ATTRIBUTE}) is centred at \
                 {centre} nm, not at the channel's wavelength"
            )));
        }
    }
    Ok(edges)
}

fn edges_from_centres(
    bands: &[(f64, &AnyChannel<FlatSamples>, String)],
    decode: &dyn Fn(String) -> CompareError,
) -> Result<Vec<f64>> {
    let l: Vec<f64> = bands.iter().map(|b| b.0).collect();
    if l.len() < 2 {
        return Err(decode(format!(
            "channel {}: a single band without attribute {BAND_EDGES_ATTRIBUTE} has no known width",
            bands[0].2
        )));
    }
    let n = l.len();
    let mut edges = Vec::with_capacity(n + 1);
    edges.push(l[0] - 0.5 * (l[1] - l[0]));
    edges.extend(l.windows(2).map(|w| 0.5 * (w[0] + w[1])));
    edges.push(l[n - 1] + 0.5 * (l[n - 1] - l[n - 2]));
    Ok(edges)
}

/// Writes `image` as a spectral EXR, atomically, with `rgb` (linear sRGB, e.g. the same run's
/// colour image) as R, G, B beside the bands so viewers without spectral support show it. f32
/// samples, ZIP compression.
pub fn write_spectral_exr(path: impl AsRef<Path>, image: &SpectralImage, rgb: Option<&Image>) -> Result<()> {
    write_spectral_exr_framed(path, image, rgb, None)
}

/// [`write_spectral_exr`] with the pixels placed in `frame` (display and data windows,
/// `spectra.*` attributes): a crop or sample chunk of a render.
pub fn write_spectral_exr_framed(
    path: impl AsRef<Path>,
    image: &SpectralImage,
    rgb: Option<&Image>,
    frame: Option<&crate::frame::ExrFrame>,
) -> Result<()> {
    let path = path.as_ref();
    write_atomic(path, &encode_spectral_exr_framed(path, image, rgb, frame)?)
}

/// The bytes [`write_spectral_exr_framed`] writes to `path` (`frame` None for
/// [`write_spectral_exr`]'s), for a command that stages them beside its colour image and puts
/// both in place together ([`crate::atomic::stage`]).
pub fn encode_spectral_exr_framed(
    path: impl AsRef<Path>,
    image: &SpectralImage,
    rgb: Option<&Image>,
    frame: Option<&crate::frame::ExrFrame>,
) -> Result<Vec<u8>> {
    let path = path.as_ref();
    image.validate()?;
    let (w, h) = (image.width as usize, image.height as usize);
    if let Some(rgb) = rgb
        && rgb.size() != (image.width, image.height)
    {
        return Err(CompareError::SizeMismatch { reference: (image.width, image.height), test: rgb.size() });
    }
    let wl = image.wavelengths()?;
    let n = image.bands();
    let mut list: Vec<AnyChannel<FlatSamples>> = Vec::with_capacity(n + 3);
    let mut names = std::collections::HashSet::new();
    for (b, &lambda) in wl.lambda.iter().enumerate() {
        let name = channel_name(image.kind, lambda);
        if !names.insert(name.clone()) {
            return Err(CompareError::InvalidImage(format!(
                "two bands are named {name}: bands narrower than 0.002 nm cannot be told apart"
            )));
        }
        let samples = (0..w * h).map(|i| image.data[i * n + b]).collect();
        list.push(AnyChannel::new(name.as_str(), FlatSamples::F32(samples)));
    }
    if let Some(rgb) = rgb {
        for (c, name) in ["R", "G", "B"].into_iter().enumerate() {
            list.push(AnyChannel::new(name, FlatSamples::F32(rgb.data.iter().map(|p| p[c]).collect())));
        }
    }
    let mut attributes = LayerAttributes::default();
    let mut set = |k: &str, v: &str| {
        attributes.other.insert(Text::new_or_panic(k), AttributeValue::Text(Text::new_or_panic(v)));
    };
    set("spectralLayoutVersion", "1.0");
    if image.kind == SpectralKind::Emissive {
        set("emissiveUnits", "W.m^-2.sr^-1");
    }
    // Bands off their edges' centres are read back from their channels' wavelengths alone.
    if image.centres.is_none() {
        let edges: Vec<String> = image.edges.iter().map(|e| format!("{e}")).collect();
        set(BAND_EDGES_ATTRIBUTE, &edges.join(" "));
    }
    if let Some(white) = &image.white {
        set(WHITE_ATTRIBUTE, white);
    }
    let image_attributes = match frame {
        Some(f) => Some(f.apply(path, (image.width, image.height), &mut attributes)?),
        None => None,
    };
    let layer = Layer::new((w, h), attributes, Encoding::SMALL_LOSSLESS, AnyChannels::sort(list.into()));
    let mut buf = Cursor::new(Vec::new());
    let image = match image_attributes {
        Some(ia) => exr::prelude::Image::new(ia, layer),
        None => exr::prelude::Image::from_layer(layer),
    };
    image.write().to_buffered(&mut buf).map_err(|e| CompareError::Encode {
        path: path.into(),
        format: "spectral OpenEXR",
        reason: e.to_string(),
    })?;
    Ok(buf.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(kind: SpectralKind) -> SpectralImage {
        let edges = color::WavelengthRange::new(380.0, 730.0).unwrap().bin_edges(5.0).unwrap();
        let n = edges.len() - 1;
        let (w, h) = (5u32, 3u32);
        let data = (0..w * h)
            .flat_map(|p| (0..n).map(move |b| 0.1 + 0.8 * (((p as usize * 7 + b * 3) % 11) as f32 / 10.0)))
            .collect();
        SpectralImage { width: w, height: h, kind, edges, data, white: Some("D65".into()), centres: None }
    }

    #[test]
    fn names_follow_pbrt() {
        assert_eq!(channel_name(SpectralKind::Emissive, 562.5), "S0.562,500nm");
        assert_eq!(channel_name(SpectralKind::Reflective, 400.0), "T.400,000nm");
        assert_eq!(parse_channel("S0.562,500nm"), Some(Ok((SpectralKind::Emissive, 562.5))));
        assert_eq!(parse_channel("S0.550nm"), Some(Ok((SpectralKind::Emissive, 550.0))));
        assert_eq!(parse_channel("R"), None);
        assert_eq!(parse_channel("diffuse.R"), None);
        assert!(parse_channel("S0.550,5Hz").unwrap().is_err());
        assert!(parse_channel("S0.55,0,1nm").unwrap().is_err());
        assert!(parse_channel("S1.550nm").unwrap().is_err());
    }

    /// Written, read back: the same bands, values and metadata; integration of the file equals
    /// integration of the image in memory.
    #[test]
    fn round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        for kind in [SpectralKind::Emissive, SpectralKind::Reflective] {
            let img = sample(kind);
            let p = dir.path().join("s.exr");
            let rgb = Image::filled(5, 3, [0.25, 0.5, 0.75]).unwrap();
            write_spectral_exr(&p, &img, Some(&rgb)).unwrap();
            let bytes = std::fs::read(&p).unwrap();
            assert!(is_spectral_exr(&bytes));
            let back = read_spectral_exr(&p).unwrap();
            assert_eq!(back, img);
            let d65 = color::illuminant::by_name("D65").unwrap();
            let obs = Observer::cie1931();
            assert_eq!(back.to_linear_srgb(&obs, &d65).unwrap(), img.to_linear_srgb(&obs, &d65).unwrap());
        }
        let rgb_only = dir.path().join("rgb.exr");
        crate::io::write_image(&rgb_only, &Image::filled(2, 2, [0.5; 3]).unwrap(), Default::default())
            .unwrap();
        assert!(!is_spectral_exr(&std::fs::read(&rgb_only).unwrap()));
    }

    /// A spectrally flat emitter, normalised by itself, integrates to its colour against the
    /// RGB white (D65) on the file's bands, for CIE observers and a camera alike (the
    /// convention in `color::film`).
    #[test]
    fn white_integrates_to_white() {
        let mut img = sample(SpectralKind::Emissive);
        let wl = img.wavelengths().unwrap();
        let e = Spectrum::Constant(1.0);
        let n = img.bands();
        for (i, v) in img.data.iter_mut().enumerate() {
            *v = e.eval(wl.lambda[i % n]) as f32;
        }
        for obs in [Observer::cie1931(), Observer::cie1964(), Observer::nikon_d5100()] {
            let rgb = img.to_linear_srgb(&obs, &e).unwrap();
            // Balanced by the white an RGB (1, 1, 1) light emits (D65's shape at the white's
            // luminance, as in both renderers), integrated on the file's bands: a flat emitter
            // is not white to either. A camera's balanced channels are shown as they are; a CIE
            // observer's XYZ is scaled so that the white lands on sRGB's white, then through
            // sRGB's matrix.
            let d65 = color::illuminant::by_name("D65").unwrap();
            let on_bands = |o: &Observer, s: &Spectrum| {
                SpectralIntegrator::emission(o, &e, &wl).integrate(|l| s.eval(l))
            };
            let (r, w) = (on_bands(&obs, &e), on_bands(&obs, &d65));
            let cie = Observer::cie1931();
            let y = on_bands(&cie, &e)[1] / on_bands(&cie, &d65)[1];
            let balanced = [0, 1, 2].map(|c| r[c] / (w[c] * y));
            let want = if obs.name == "nikon_d5100" {
                balanced
            } else {
                let srgb = color::RgbColorSpace::srgb();
                let white = srgb.white_xyz();
                srgb.xyz_to_rgb([0, 1, 2].map(|c| balanced[c] * white[c]))
            };
            for k in 0..3 {
                assert!(
                    (f64::from(rgb.data[4][k]) - want[k]).abs() < 1e-6,
                    "{} {:?} {want:?}",
                    obs.name,
                    rgb.data[4]
                );
            }
        }
    }

    fn write_raw(path: &Path, names: &[&str], attrs: &[(&str, &str)]) {
        let list: Vec<AnyChannel<FlatSamples>> =
            names.iter().map(|n| AnyChannel::new(*n, FlatSamples::F32(vec![0.5; 4]))).collect();
        let mut a = LayerAttributes::default();
        for (k, v) in attrs {
            a.other.insert(Text::new_or_panic(*k), AttributeValue::Text(Text::new_or_panic(*v)));
        }
        let layer = Layer::new((2, 2), a, Encoding::UNCOMPRESSED, AnyChannels::sort(list.into()));
        exr::prelude::Image::from_layer(layer).write().to_file(path).unwrap();
    }

    #[test]
    fn bad_layouts_name_the_channel() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.exr");
        let err = |names: &[&str], attrs: &[(&str, &str)]| {
            write_raw(&p, names, attrs);
            read_spectral_exr(&p).unwrap_err().to_string()
        };
        let e = err(&["R", "G", "B"], &[("spectralLayoutVersion", "1.0")]);
        assert!(e.contains("bad.exr") && e.contains("no spectral channel") && e.contains("B, G, R"), "{e}");
        let e = err(&["S0.500nm", "S0.510,abcnm"], &[]);
        assert!(e.contains("channel S0.510,abcnm") && e.contains("not a wavelength"), "{e}");
        // Bands no observer sees (Ångström taken for nm): an error, not a black image.
        let e = err(&["S0.4000nm", "S0.5500nm", "S0.7000nm"], &[]);
        assert!(e.contains("bad.exr") && e.contains("3250–7750 nm") && e.contains("360–830"), "{e}");
        let e = err(&["S0.500nm", "S0.99999999999999999999999nm"], &[]);
        assert!(e.contains("S0.99999999999999999999999nm") && e.contains("millimetre"), "{e}");
        let e = err(&["S0.500nm", "S0.500,000nm", "S0.510nm"], &[]);
        assert!(e.contains("S0.500,000nm") && e.contains("S0.500nm") && e.contains("same wavelength"), "{e}");
        let e = err(&["S0.500nm", "T.510nm"], &[]);
        assert!(e.contains("T.510nm") && e.contains("S0.500nm") && e.contains("emissive"), "{e}");
        let e = err(&["S0.500nm", "S1.500nm"], &[]);
        assert!(e.contains("channel S1.500nm") && e.contains("polarised"), "{e}");
        let e = err(&["S0.500nm"], &[]);
        assert!(e.contains("channel S0.500nm") && e.contains("width"), "{e}");
        // A missing channel against the written edges.
        let e = err(&["S0.502,500nm", "S0.512,500nm"], &[(BAND_EDGES_ATTRIBUTE, "500 505 510 515")]);
        assert!(e.contains("3 edges") || e.contains("4 edges"), "{e}");
        assert!(e.contains("missing"), "{e}");
        // Unsorted edges: a negative width, named by its channel.
        let e = err(&["S0.502,500nm", "S0.507,500nm"], &[(BAND_EDGES_ATTRIBUTE, "500 505 500")]);
        assert!(e.contains("channel S0.507,500nm") && e.contains("width of -5"), "{e}");
        let e = err(&["S0.502,500nm", "S0.508,000nm"], &[(BAND_EDGES_ATTRIBUTE, "500 505 510")]);
        assert!(e.contains("channel S0.508,000nm") && e.contains("centred at 507.5"), "{e}");
        let e = err(&["S0.502,500nm", "S0.507,500nm"], &[(BAND_EDGES_ATTRIBUTE, "500 x 510")]);
        assert!(e.contains(BAND_EDGES_ATTRIBUTE) && e.contains("not a list"), "{e}");
        // Without edges, uneven spacing is legitimate (bands meet half-way).
        write_raw(&p, &["S0.500nm", "S0.510nm", "S0.530nm"], &[]);
        let ok = read_spectral_exr(&p).unwrap();
        assert_eq!(ok.edges, vec![495.0, 505.0, 520.0, 540.0]);
        // Each band is integrated at its channel's wavelength, not at its edges' centre (510,
        // not 512.5), weighted by its width; written back without edges, it reads the same.
        let wl = ok.wavelengths().unwrap();
        assert_eq!(wl.lambda, vec![500.0, 510.0, 530.0]);
        assert_eq!(wl.weight, vec![10.0, 15.0, 20.0]);
        let again = dir.path().join("again.exr");
        write_spectral_exr(&again, &ok, None).unwrap();
        let back = read_spectral_exr(&again).unwrap();
        assert_eq!((back.edges.clone(), back.centres.clone()), (ok.edges.clone(), ok.centres.clone()));
        // Evenly spaced channels are their bands' centres.
        write_raw(&p, &["S0.500nm", "S0.510nm", "S0.520nm"], &[]);
        assert_eq!(read_spectral_exr(&p).unwrap().centres, None);
    }
}
