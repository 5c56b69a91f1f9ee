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
use crate::image::Image;

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

/// Where an image's pixels lie in the frame they belong to: the OpenEXR display window (the
/// frame) and data window (the pixels the file holds). A PNG, and an EXR whose data window is its
/// display window, hold the whole frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    /// The frame's size (the display window's).
    pub frame: (u32, u32),
    /// The top-left pixel held, from the frame's top-left (negative for overscan).
    pub origin: (i64, i64),
    /// The size of the pixels held (the data window's).
    pub size: (u32, u32),
}

impl Placement {
    /// An image that is its whole frame.
    pub fn whole(size: (u32, u32)) -> Placement {
        Placement { frame: size, origin: (0, 0), size }
    }

    /// Whether the image holds exactly its frame.
    pub fn is_whole(&self) -> bool {
        self.origin == (0, 0) && self.size == self.frame
    }

    /// From an EXR layer's data window position and size and the image's display window.
    pub(crate) fn of_exr(display: &IntegerBounds, position: Vec2<i32>, size: (usize, usize)) -> Placement {
        Placement {
            frame: (display.size.0 as u32, display.size.1 as u32),
            origin: (
                i64::from(position.0) - i64::from(display.position.0),
                i64::from(position.1) - i64::from(display.position.1),
            ),
            size: (size.0 as u32, size.1 as u32),
        }
    }

    fn describe(&self) -> String {
        if self.is_whole() {
            format!("the whole of a {}×{} frame", self.frame.0, self.frame.1)
        } else {
            format!(
                "{}×{} pixels at ({}, {}) of a {}×{} frame (its data window)",
                self.size.0, self.size.1, self.origin.0, self.origin.1, self.frame.0, self.frame.1
            )
        }
    }
}

/// The part of a frame two images are compared over, where it is not simply both images.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Region {
    /// The frame's size.
    pub frame: (u32, u32),
    /// The region's top-left pixel in the frame.
    pub origin: (i64, i64),
    pub size: (u32, u32),
}

/// Lines up a reference and a test image by where their pixels lie in their frames, so that the
/// same pixel of the frame is compared with itself: images that hold the same pixels (the same
/// size at the same place) are returned as they are (`None`); images of one frame that hold
/// different parts of it (a crop and the full frame, two overlapping crops, an overscan) are cut
/// to the pixels both hold, and that region is returned. Anything else — different frames with
/// the pixels at different places, crops that share no pixel — is an error that says where each
/// image's pixels lie (the size check of the comparison itself is left to it).
pub fn align(
    reference: Image,
    rp: Placement,
    test: Image,
    tp: Placement,
) -> Result<(Image, Image, Option<Region>)> {
    let same = rp.origin == tp.origin && rp.size == tp.size;
    if same || (rp.is_whole() && tp.is_whole()) {
        return Ok((reference, test, None));
    }
    let both = || format!("the reference holds {}, the test {}", rp.describe(), tp.describe());
    if rp.frame != tp.frame {
        return Err(CompareError::Misplaced(format!(
            "the images hold different parts of different frames: {}",
            both()
        )));
    }
    let x0 = rp.origin.0.max(tp.origin.0);
    let y0 = rp.origin.1.max(tp.origin.1);
    let x1 = (rp.origin.0 + i64::from(rp.size.0)).min(tp.origin.0 + i64::from(tp.size.0));
    let y1 = (rp.origin.1 + i64::from(rp.size.1)).min(tp.origin.1 + i64::from(tp.size.1));
    if x1 <= x0 || y1 <= y0 {
        return Err(CompareError::Misplaced(format!("the images share no pixel of their frame: {}", both())));
    }
    let (w, h) = ((x1 - x0) as u32, (y1 - y0) as u32);
    let cut = |im: &Image, p: &Placement| {
        let (dx, dy) = ((x0 - p.origin.0) as u32, (y0 - p.origin.1) as u32);
        Image::from_fn(w, h, |x, y| im.get(x + dx, y + dy))
    };
    Ok((
        cut(&reference, &rp)?,
        cut(&test, &tp)?,
        Some(Region { frame: rp.frame, origin: (x0, y0), size: (w, h) }),
    ))
}
