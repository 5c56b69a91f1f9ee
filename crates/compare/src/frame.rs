//! Where an EXR's pixels sit in the frame and what made them: the OpenEXR display window (the
//! full frame) and data window (the pixels the file holds, a crop of it), and text attributes
//! spectra's renderers record (`spectra.*`: the render's identity, settings, sample range), so
//! that `spectra merge` can tell what may be combined. Other tools keep unknown attributes and
//! read the data window as any cropped EXR.

use std::io::Cursor;
use std::path::Path;

use exr::meta::attribute::{AttributeValue, IntegerBounds, Text};
use exr::prelude::Vec2;

use crate::error::{CompareError, Result};

/// The display and data windows and the `spectra.*` text attributes of an EXR.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ExrFrame {
    /// The full frame's size (the display window, from (0, 0)).
    pub display: (u32, u32),
    /// The top-left pixel of the data within the frame.
    pub origin: (u32, u32),
    /// `spectra.*` attributes, in the order written (keys include the prefix).
    pub attributes: Vec<(String, String)>,
}

/// Prefix of the attributes [`ExrFrame`] reads and writes.
pub const PREFIX: &str = "spectra.";

impl ExrFrame {
    /// The value of attribute `key` (with its prefix).
    pub fn get(&self, key: &str) -> Option<&str> {
        self.attributes.iter().find(|(k, _)| k == key).map(|(_, v)| v.as_str())
    }

    /// Sets the windows of an EXR image about to be written and adds the attributes to its
    /// layer; `size` is the data's. Errors if the data does not fit the frame.
    pub(crate) fn apply(
        &self,
        path: &Path,
        size: (u32, u32),
        attributes: &mut exr::meta::header::LayerAttributes,
    ) -> Result<exr::meta::header::ImageAttributes> {
        let fits = |o: u32, s: u32, d: u32| u64::from(o) + u64::from(s) <= u64::from(d);
        if !fits(self.origin.0, size.0, self.display.0) || !fits(self.origin.1, size.1, self.display.1) {
            return Err(CompareError::InvalidImage(format!(
                "{}: a {}×{} image at ({}, {}) does not fit its {}×{} frame",
                path.display(),
                size.0,
                size.1,
                self.origin.0,
                self.origin.1,
                self.display.0,
                self.display.1
            )));
        }
        attributes.layer_position = Vec2(self.origin.0 as i32, self.origin.1 as i32);
        for (k, v) in &self.attributes {
            // UTF-8, as OpenEXR's own tools read text (its Python bindings refuse to open a file
            // whose text is Latin-1 beyond ASCII); a file name in any script can be recorded.
            attributes.other.insert(
                Text::from_slice_unchecked(k.as_bytes()),
                AttributeValue::Text(Text::from_slice_unchecked(v.as_bytes())),
            );
        }
        let display = IntegerBounds::new(Vec2(0, 0), Vec2(self.display.0 as usize, self.display.1 as usize));
        Ok(exr::meta::header::ImageAttributes::new(display))
    }
}

/// An attribute's text: UTF-8 as written now, else Latin-1 (a byte a character) as earlier
/// versions wrote it, so that their renders still read as they did.
fn text(t: &Text) -> String {
    String::from_utf8(t.bytes().to_vec()).unwrap_or_else(|_| t.to_string())
}

/// The frame of the EXR at `path`, from its headers (the first layer's data window): cheap,
/// no pixels are decoded.
pub fn read_exr_frame(path: impl AsRef<Path>) -> Result<ExrFrame> {
    let path = path.as_ref();
    let bytes = color::input::read_regular(path, crate::io::MAX_INPUT_BYTES)
        .map_err(|e| CompareError::io(path, e))?;
    decode_exr_frame(path, &bytes)
}

/// [`read_exr_frame`] and the size of the data window (the pixels the file holds), from the
/// headers alone.
pub fn read_exr_frame_and_size(path: impl AsRef<Path>) -> Result<(ExrFrame, (u32, u32))> {
    let path = path.as_ref();
    let bytes = color::input::read_regular(path, crate::io::MAX_INPUT_BYTES)
        .map_err(|e| CompareError::io(path, e))?;
    let frame = decode_exr_frame(path, &bytes)?;
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes), false)
        .map_err(|e| CompareError::Decode { path: path.into(), format: "OpenEXR", reason: e.to_string() })?;
    let size = meta.headers.first().map_or((0, 0), |h| (h.layer_size.0 as u32, h.layer_size.1 as u32));
    Ok((frame, size))
}

/// [`read_exr_frame`] of the bytes of an EXR (`path` names it in messages).
pub fn decode_exr_frame(path: &Path, bytes: &[u8]) -> Result<ExrFrame> {
    let decode = |reason: String| CompareError::Decode { path: path.into(), format: "OpenEXR", reason };
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| decode(e.to_string()))?;
    let header = meta.headers.first().ok_or_else(|| decode("no layers".into()))?;
    let display = header.shared_attributes.display_window;
    let data_pos = header.own_attributes.layer_position;
    let (dx, dy) = (data_pos.0 - display.position.0, data_pos.1 - display.position.1);
    if dx < 0 || dy < 0 {
        return Err(decode(format!(
            "the data window starts at ({}, {}), outside the display window at ({}, {})",
            data_pos.0, data_pos.1, display.position.0, display.position.1
        )));
    }
    let mut attributes: Vec<(String, String)> = header
        .own_attributes
        .other
        .iter()
        .chain(header.shared_attributes.other.iter())
        .filter_map(|(k, v)| match v {
            AttributeValue::Text(t) if k.to_string().starts_with(PREFIX) => Some((k.to_string(), text(t))),
            _ => None,
        })
        .collect();
    attributes.sort();
    Ok(ExrFrame {
        display: (display.size.0 as u32, display.size.1 as u32),
        origin: (dx as u32, dy as u32),
        attributes,
    })
}
