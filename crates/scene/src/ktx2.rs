//! KTX2 images with Basis Universal payloads (`KHR_texture_basisu`), transcoded to RGBA8 with the
//! pure-Rust `basisu` crate.
//!
//! The header is read here before the transcoder sees the file, for two reasons: our messages
//! say what a refused file holds (a plain `VK_FORMAT_R8G8B8A8_SRGB` texture, a cube map, a
//! 100000×100000 image) where the transcoder only answers "invalid data", and a few header
//! fields make the transcoder allocate (the level's Zstandard size, the output size), so a few
//! hostile bytes must be refused before they can ask for gigabytes.

use crate::{MAX_IMAGE_DECODED_BYTES, MAX_IMAGE_DIMENSION};

/// The 12-byte KTX2 file identifier.
pub(crate) const MAGIC: &[u8; 12] = b"\xabKTX 20\xbb\r\n\x1a\n";

/// Data Format Descriptor colour models of the two Basis Universal codecs the extension allows.
const MODEL_ETC1S: u8 = 163;
const MODEL_UASTC: u8 = 166;
/// DFD transfer functions.
const TRANSFER_LINEAR: u8 = 1;
const TRANSFER_SRGB: u8 = 2;

/// A transcoded KTX2 image: level 0 as RGBA8, and the transfer function its DFD declares
/// (`Some(true)` sRGB, `Some(false)` linear, `None` anything else).
pub(crate) struct Decoded {
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
    pub declared_srgb: Option<bool>,
}

fn u32_at(b: &[u8], o: usize) -> u32 {
    u32::from_le_bytes(b[o..o + 4].try_into().expect("four bytes"))
}

fn u64_at(b: &[u8], o: usize) -> u64 {
    u64::from_le_bytes(b[o..o + 8].try_into().expect("eight bytes"))
}

/// A few common vkFormats by name, so that a refused non-Basis file says what it holds.
fn vk_format_name(vk: u32) -> String {
    let name = match vk {
        37 => "VK_FORMAT_R8G8B8A8_UNORM",
        43 => "VK_FORMAT_R8G8B8A8_SRGB",
        23 => "VK_FORMAT_R8G8B8_UNORM",
        29 => "VK_FORMAT_R8G8B8_SRGB",
        9 => "VK_FORMAT_R8_UNORM",
        16 => "VK_FORMAT_R8G8_UNORM",
        97 => "VK_FORMAT_R16G16B16A16_SFLOAT",
        109 => "VK_FORMAT_R32G32B32A32_SFLOAT",
        131..=146 => "a BCn block format",
        147..=156 => "an ETC2/EAC block format",
        157..=184 => "an ASTC block format",
        1000066000..=1000066013 => "an ASTC HDR block format",
        _ => "",
    };
    if name.is_empty() { format!("vkFormat {vk}") } else { format!("vkFormat {vk} ({name})") }
}

/// Level 0 of the KTX2 file `bytes` as RGBA8, or why not (a phrase to follow `images[i]: `).
pub(crate) fn decode(bytes: &[u8]) -> Result<Decoded, String> {
    if !bytes.starts_with(MAGIC) {
        return Err("is not a KTX2 file (it lacks the KTX2 identifier)".into());
    }
    if bytes.len() < 80 + 24 {
        return Err(format!(
            "the KTX2 file ends inside its header and level index ({} bytes; a truncated file?)",
            bytes.len()
        ));
    }
    let vk = u32_at(bytes, 12);
    let (width, height, depth) = (u32_at(bytes, 20), u32_at(bytes, 24), u32_at(bytes, 28));
    let (layers, faces, levels, scheme) =
        (u32_at(bytes, 32), u32_at(bytes, 36), u32_at(bytes, 40), u32_at(bytes, 44));
    let basis = "KHR_texture_basisu requires a Basis Universal (ETC1S or UASTC) payload";
    if vk != 0 {
        return Err(format!(
            "the KTX2 image holds {}, not Basis Universal data; {basis}",
            vk_format_name(vk)
        ));
    }
    if depth > 0 {
        return Err(format!("the KTX2 image is a 3D texture (depth {depth}); only 2D images are accepted"));
    }
    if faces != 1 {
        return Err(format!(
            "the KTX2 image is a cube map ({faces} faces); only single 2D images are accepted"
        ));
    }
    if layers > 0 {
        return Err(format!(
            "the KTX2 image is a texture array ({layers} layers); only single 2D images are accepted"
        ));
    }
    if width == 0 || height == 0 {
        return Err(format!("the KTX2 image is {width}×{height}; a 2D image has both sides ≥ 1"));
    }
    // The same limit as PNG and JPEG, checked before the transcoder allocates its output.
    if width > MAX_IMAGE_DIMENSION
        || height > MAX_IMAGE_DIMENSION
        || 4 * u64::from(width) * u64::from(height) > MAX_IMAGE_DECODED_BYTES
    {
        return Err(format!(
            "the image is {width}×{height}; at most {MAX_IMAGE_DIMENSION} on a side and {} MiB decoded \
             (RGBA8) are accepted",
            MAX_IMAGE_DECODED_BYTES >> 20
        ));
    }
    // The Data Format Descriptor's basic block: colour model, then primaries, then transfer.
    let (dfd_offset, dfd_length) = (u32_at(bytes, 48) as usize, u32_at(bytes, 52) as usize);
    if dfd_length < 16 || dfd_offset.checked_add(dfd_length).is_none_or(|end| end > bytes.len()) {
        return Err(format!(
            "the KTX2 file's data format descriptor ({dfd_length} bytes at {dfd_offset}) lies outside \
             its {} bytes (a truncated file?)",
            bytes.len()
        ));
    }
    let (model, transfer) = (bytes[dfd_offset + 12], bytes[dfd_offset + 14]);
    let codec = match model {
        MODEL_ETC1S => "ETC1S",
        MODEL_UASTC => "UASTC",
        m => {
            return Err(format!(
                "the KTX2 image's colour model is {m}, not ETC1S (163) or UASTC (166); {basis}"
            ));
        }
    };
    // Level 0's extent, checked here because the transcoder slices and inflates it unchecked:
    // a Zstandard level's recorded size is allocated before a byte is decoded.
    let (offset, length, unpacked) = (u64_at(bytes, 80), u64_at(bytes, 88), u64_at(bytes, 96));
    if offset.checked_add(length).is_none_or(|end| end > bytes.len() as u64) {
        return Err(format!(
            "the KTX2 file's level 0 ({length} bytes at {offset}) lies outside its {} bytes (a truncated \
             file?)",
            bytes.len()
        ));
    }
    if codec == "UASTC" {
        // 16 bytes per 4×4 block, one image: what level 0 holds once inflated.
        let expected = 16 * u64::from(width.div_ceil(4)) * u64::from(height.div_ceil(4));
        let stored = if scheme == 2 { unpacked } else { length };
        if stored != expected {
            return Err(format!(
                "the KTX2 image's level 0 holds {stored} bytes of UASTC data; {width}×{height} texels \
                 take {expected}"
            ));
        }
    }
    // The extension's rules: ETC1S is BasisLZ (1); UASTC is stored plain (0) or Zstandard (2).
    match (codec, scheme) {
        ("ETC1S", 1) | ("UASTC", 0 | 2) => {}
        _ => {
            return Err(format!(
                "the KTX2 image is {codec} with supercompression scheme {scheme}; KHR_texture_basisu \
                 allows BasisLZ (1) for ETC1S, none (0) or Zstandard (2) for UASTC"
            ));
        }
    }
    // The texels are used as stored: the extension allows no swizzle and only the glTF
    // orientation, and a file that says otherwise would be drawn wrong without a word.
    for (key, allowed) in [("KTXswizzle", "rgba"), ("KTXorientation", "rd")] {
        if let Some(value) = key_value(bytes, key)
            && value != allowed
        {
            return Err(format!(
                "the KTX2 image's {key} is {value:?}; KHR_texture_basisu allows only {allowed:?} (or none)"
            ));
        }
    }
    if levels > 16 {
        return Err(format!("the KTX2 file claims {levels} mip levels; a 16384-texel side has at most 15"));
    }
    let transcoded = std::panic::catch_unwind(|| -> Result<Vec<u8>, String> {
        let t = basisu::Transcoder::new(bytes)
            .map_err(|e| format!("the {codec} KTX2 image cannot be read ({})", basisu_error(&e)))?;
        if t.is_video() {
            return Err("the KTX2 image is a video (ETC1S frames); only single images are accepted".into());
        }
        t.transcode(0, basisu::TargetFormat::Rgba32, basisu::DecodeFlags::NONE)
            .map_err(|e| format!("the {codec} KTX2 image cannot be decoded ({})", basisu_error(&e)))
    });
    // The transcoder is a port of C++ that indexes freely; a malformed file that slips past its
    // checks must still come back as this image's error and not take the process down.
    let rgba8 = transcoded
        .map_err(|_| format!("the {codec} KTX2 image cannot be decoded (the transcoder failed on it)"))??;
    if rgba8.len() as u64 != 4 * u64::from(width) * u64::from(height) {
        return Err(format!(
            "the {codec} KTX2 image decoded to {} bytes, not the {width}×{height}×4 of RGBA8",
            rgba8.len()
        ));
    }
    let declared_srgb = match transfer {
        TRANSFER_SRGB => Some(true),
        TRANSFER_LINEAR => Some(false),
        _ => None,
    };
    Ok(Decoded { width, height, rgba8, declared_srgb })
}

/// The value of `key` in the KTX2 file's key/value data (without its terminating NUL), if the
/// file has it; a malformed block reads as having none (the transcoder does not need it).
fn key_value(bytes: &[u8], key: &str) -> Option<String> {
    let (offset, length) = (u32_at(bytes, 56) as usize, u32_at(bytes, 60) as usize);
    let mut kvd = bytes.get(offset..offset.checked_add(length)?)?;
    while kvd.len() >= 4 {
        let n = u32_at(kvd, 0) as usize;
        let entry = kvd.get(4..4usize.checked_add(n)?)?;
        if let Some(rest) = entry.strip_prefix(key.as_bytes())
            && let Some(value) = rest.strip_prefix(b"\0")
        {
            let value = value.strip_suffix(b"\0").unwrap_or(value);
            return Some(String::from_utf8_lossy(value).into_owned());
        }
        // Entries are padded to 4 bytes.
        kvd = kvd.get((4 + n).next_multiple_of(4)..)?;
    }
    None
}

fn basisu_error(e: &basisu::Error) -> String {
    match e {
        basisu::Error::InvalidData => "invalid or unsupported data".into(),
        basisu::Error::Truncated => "truncated".into(),
        basisu::Error::ZstdRequired => "Zstandard supercompression".into(),
        other => format!("{other:?}"),
    }
}
