//! glTF URIs: `data:` URIs (base64) and relative file references.

use std::borrow::Cow;

use base64::Engine;

use crate::context::Ctx;
use crate::error::SceneError;

/// The bytes a glTF `uri` at field `at` refers to (a file of at most `max_bytes`), and the MIME
/// type a data URI declares.
pub(crate) fn read(
    ctx: &Ctx,
    at: &str,
    uri: &str,
    max_bytes: u64,
) -> Result<(Vec<u8>, Option<String>), SceneError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest
            .split_once(',')
            .ok_or_else(|| ctx.invalid(at, "data URI has no ',' separating header and data"))?;
        let Some(mime) = header.strip_suffix(";base64") else {
            return Err(
                ctx.invalid(at, "only base64 data URIs are supported (the header must end in ;base64)")
            );
        };
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(payload.trim())
            .map_err(|e| ctx.invalid(at, format!("data URI is not valid base64: {e}")))?;
        return Ok((bytes, (!mime.is_empty()).then(|| mime.to_string())));
    }
    if uri.contains("://") {
        return Err(ctx.invalid(
            at,
            format!("'{uri}' is a remote URI; only relative file paths and data URIs are supported"),
        ));
    }
    let decoded: Cow<str> = percent_encoding::percent_decode_str(uri)
        .decode_utf8()
        .map_err(|e| ctx.invalid(at, format!("'{uri}' is not valid percent-encoded UTF-8: {e}")))?;
    let file = ctx.resolve(at, &decoded)?;
    let bytes = color::input::read_regular(&file, max_bytes)
        .map_err(|e| ctx.invalid(at, format!("cannot read '{}' ({}): {e}", decoded, file.display())))?;
    Ok((bytes, None))
}
