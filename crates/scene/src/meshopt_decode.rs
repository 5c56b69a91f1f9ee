//! `EXT_meshopt_compression` and its Khronos successor `KHR_meshopt_compression` (the same
//! bitstreams, plus the COLOR filter and version 1 of the attribute codec): buffer views whose
//! bytes are stored compressed in another buffer are decoded (with the `meshopt` crate, the
//! reference decoder, which reads both attribute codec versions) into the place the view names,
//! before any accessor is read. The view's own buffer is usually a "fallback" buffer without
//! data, which [`fallback_len`] makes the loader allocate instead of reading.
//!
//! The decoder is safe on untrusted input (it may produce garbage, which the accessor checks then
//! see as any other data), but asserts its arguments, so each is checked here first; sizes are
//! bounded by buffers that already exist, so a hostile count cannot allocate without limit.

use serde_json::Value;

use crate::context::Ctx;
use crate::error::SceneError;

/// The largest buffer allocated for decoded data: a scene this renderer can draw is far smaller.
pub(crate) const MAX_FALLBACK_BYTES: u64 = 1 << 30;

/// `Some(byteLength)` when `buffers[i]` is an `EXT_meshopt_compression` fallback buffer without
/// data of its own (its contents come from decoding).
pub(crate) fn fallback_len(raw: &Value, i: usize) -> Option<u64> {
    let b = raw.get("buffers")?.get(i)?;
    let fallback =
        NAMES.iter().find_map(|n| b.pointer(&format!("/extensions/{n}/fallback"))).and_then(Value::as_bool);
    (fallback == Some(true) && b.get("uri").is_none()).then(|| b.get("byteLength").and_then(Value::as_u64))?
}

/// The two extensions, the Khronos one first.
const NAMES: [&str; 2] = ["KHR_meshopt_compression", "EXT_meshopt_compression"];

#[derive(Clone)]
struct Elem<const N: usize>([u8; N]);

impl<const N: usize> Default for Elem<N> {
    fn default() -> Self {
        Elem([0; N])
    }
}

fn vertices<const N: usize>(enc: &[u8], count: usize) -> Option<Vec<u8>> {
    let v = meshopt::decode_vertex_buffer::<Elem<N>>(enc, count).ok()?;
    Some(v.into_iter().flat_map(|e| e.0).collect())
}

/// Decodes an ATTRIBUTES stream: the codec is byte-interleaved by the stride, which must be a
/// multiple of 4 up to 256 (the decoder asserts it), so each one is its own instantiation.
fn decode_vertices(enc: &[u8], count: usize, stride: usize) -> Option<Vec<u8>> {
    macro_rules! by_stride {
        ($($k:literal)*) => {
            match stride {
                $($k => vertices::<$k>(enc, count),)*
                _ => None,
            }
        };
    }
    by_stride!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108 112 116
        120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196 200 204 208 212
        216 220 224 228 232 236 240 244 248 252 256)
}

fn decode_indices(enc: &[u8], count: usize, stride: usize, triangles: bool) -> Option<Vec<u8>> {
    let bytes = match (stride, triangles) {
        (2, true) => meshopt::decode_index_buffer::<u16>(enc, count)
            .ok()?
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect(),
        (4, true) => meshopt::decode_index_buffer::<u32>(enc, count)
            .ok()?
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect(),
        (2, false) => meshopt::decode_index_sequence::<u16>(enc, count)
            .ok()?
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect(),
        (4, false) => meshopt::decode_index_sequence::<u32>(enc, count)
            .ok()?
            .iter()
            .flat_map(|i| i.to_le_bytes())
            .collect(),
        _ => return None,
    };
    Some(bytes)
}

/// Applies a vertex filter in place; `None` when the stride does not suit the filter.
fn filter(name: &str, data: &mut [u8], stride: usize) -> Option<()> {
    fn i8s(d: &[u8]) -> Vec<[i8; 4]> {
        d.chunks_exact(4).map(|c| [c[0] as i8, c[1] as i8, c[2] as i8, c[3] as i8]).collect()
    }
    fn i16s(d: &[u8]) -> Vec<[i16; 4]> {
        d.chunks_exact(8)
            .map(|c| std::array::from_fn(|k| i16::from_le_bytes([c[2 * k], c[2 * k + 1]])))
            .collect()
    }
    fn put<T: Copy, const N: usize>(d: &mut [u8], v: &[[T; N]], bytes: impl Fn(T) -> Vec<u8>) {
        let flat: Vec<u8> = v.iter().flat_map(|e| e.iter().flat_map(|&x| bytes(x))).collect();
        d.copy_from_slice(&flat);
    }
    match (name, stride) {
        ("NONE", _) => {}
        ("OCTAHEDRAL", 4) => {
            let mut v = i8s(data);
            meshopt::decode_filter_oct(&mut v);
            put(data, &v, |x: i8| vec![x as u8]);
        }
        ("OCTAHEDRAL", 8) | ("QUATERNION", 8) => {
            let mut v = i16s(data);
            if name == "OCTAHEDRAL" {
                meshopt::decode_filter_oct(&mut v);
            } else {
                meshopt::decode_filter_quat(&mut v);
            }
            put(data, &v, |x: i16| x.to_le_bytes().to_vec());
        }
        ("COLOR", 4) => {
            let mut v: Vec<[u8; 4]> = data.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]).collect();
            meshopt::decode_filter_color(&mut v);
            put(data, &v, |x: u8| vec![x]);
        }
        ("COLOR", 8) => {
            let mut v: Vec<[u16; 4]> = data
                .chunks_exact(8)
                .map(|c| std::array::from_fn(|k| u16::from_le_bytes([c[2 * k], c[2 * k + 1]])))
                .collect();
            meshopt::decode_filter_color(&mut v);
            put(data, &v, |x: u16| x.to_le_bytes().to_vec());
        }
        ("EXPONENTIAL", s) if s % 4 == 0 => {
            // Each 32-bit component is decoded on its own, so any stride is a run of [u32; 1].
            let mut v: Vec<[u32; 1]> =
                data.chunks_exact(4).map(|c| [u32::from_le_bytes([c[0], c[1], c[2], c[3]])]).collect();
            meshopt::decode_filter_exp(&mut v);
            put(data, &v, |x: u32| x.to_le_bytes().to_vec());
        }
        _ => return None,
    }
    Some(())
}

/// Decodes every compressed buffer view of `raw` (the document's JSON) into `buffers`.
pub(crate) fn decode(ctx: &Ctx, raw: &Value, buffers: &mut [Vec<u8>]) -> Result<(), SceneError> {
    let Some(views) = raw.get("bufferViews").and_then(Value::as_array) else { return Ok(()) };
    for (vi, view) in views.iter().enumerate() {
        let found: Vec<(&str, &Value)> =
            NAMES.iter().filter_map(|n| Some((*n, view.pointer(&format!("/extensions/{n}"))?))).collect();
        let (name, ext) = match found[..] {
            [] => continue,
            [one] => one,
            _ => {
                return Err(ctx.invalid(
                    format!("bufferViews[{vi}].extensions"),
                    "has both KHR_meshopt_compression and EXT_meshopt_compression, which the extension forbids",
                ));
            }
        };
        let at = format!("bufferViews[{vi}].extensions.{name}");
        let uint = |obj: &Value, k: &str, default: Option<u64>, at: &str| -> Result<usize, SceneError> {
            match obj.get(k) {
                None => {
                    default.map(|d| d as usize).ok_or_else(|| ctx.invalid(format!("{at}.{k}"), "is required"))
                }
                Some(v) => v.as_u64().and_then(|x| usize::try_from(x).ok()).ok_or_else(|| {
                    ctx.invalid(format!("{at}.{k}"), format!("must be a non-negative integer, got {v}"))
                }),
            }
        };
        let vat = format!("bufferViews[{vi}]");
        let src_buf = uint(ext, "buffer", None, &at)?;
        let src_off = uint(ext, "byteOffset", Some(0), &at)?;
        let src_len = uint(ext, "byteLength", None, &at)?;
        let stride = uint(ext, "byteStride", None, &at)?;
        let count = uint(ext, "count", None, &at)?;
        let mode = ext.get("mode").and_then(Value::as_str).unwrap_or("");
        let filter_name = ext.get("filter").and_then(Value::as_str).unwrap_or("NONE");
        let dst_buf = uint(view, "buffer", None, &vat)?;
        let dst_off = uint(view, "byteOffset", Some(0), &vat)?;
        let dst_len = uint(view, "byteLength", None, &vat)?;

        let src = buffers
            .get(src_buf)
            .and_then(|b| b.get(src_off..src_off.checked_add(src_len)?))
            .ok_or_else(|| {
                ctx.invalid(
                    &at,
                    format!(
                        "bytes {src_off}+{src_len} of buffers[{src_buf}] do not exist (the compressed data)"
                    ),
                )
            })?;
        let size = count.checked_mul(stride).filter(|&s| s <= dst_len).ok_or_else(|| {
            ctx.invalid(
                &at,
                format!("count {count} × byteStride {stride} exceeds the view's byteLength {dst_len}"),
            )
        })?;
        let dst_ok =
            buffers.get(dst_buf).is_some_and(|b| dst_off.checked_add(size).is_some_and(|e| e <= b.len()));
        if !dst_ok {
            return Err(ctx.invalid(&vat, format!("bytes {dst_off}+{size} overrun buffers[{dst_buf}]")));
        }
        let bad = |what: &str| ctx.invalid(&at, format!("the compressed data cannot be decoded ({what})"));
        let mut data = match mode {
            "ATTRIBUTES" => {
                if stride == 0 || stride > 256 || stride % 4 != 0 {
                    return Err(ctx.invalid(
                        format!("{at}.byteStride"),
                        format!("{stride}: ATTRIBUTES need a multiple of 4 up to 256"),
                    ));
                }
                decode_vertices(src, count, stride).ok_or_else(|| bad("ATTRIBUTES"))?
            }
            "TRIANGLES" | "INDICES" => {
                if stride != 2 && stride != 4 {
                    return Err(
                        ctx.invalid(format!("{at}.byteStride"), format!("{stride}: indices need 2 or 4"))
                    );
                }
                if mode == "TRIANGLES" && count % 3 != 0 {
                    return Err(ctx
                        .invalid(format!("{at}.count"), format!("{count}: TRIANGLES need a multiple of 3")));
                }
                decode_indices(src, count, stride, mode == "TRIANGLES").ok_or_else(|| bad(mode))?
            }
            other => {
                return Err(ctx.invalid(
                    format!("{at}.mode"),
                    format!("'{other}' is not a mode (ATTRIBUTES, TRIANGLES or INDICES)"),
                ));
            }
        };
        if mode == "ATTRIBUTES" {
            if filter_name == "COLOR" && name == "EXT_meshopt_compression" {
                return Err(ctx.invalid(
                    format!("{at}.filter"),
                    "COLOR is a filter of KHR_meshopt_compression, not of EXT_meshopt_compression",
                ));
            }
            filter(filter_name, &mut data, stride).ok_or_else(|| {
                ctx.invalid(
                    format!("{at}.filter"),
                    format!(
                        "'{filter_name}' with byteStride {stride} is not supported (NONE; OCTAHEDRAL with 4 or 8; QUATERNION with 8; EXPONENTIAL with a multiple of 4; COLOR with 4 or 8)"
                    ),
                )
            })?;
        } else if filter_name != "NONE" {
            return Err(
                ctx.invalid(format!("{at}.filter"), format!("'{filter_name}' cannot apply to {mode}"))
            );
        }
        buffers[dst_buf][dst_off..dst_off + size].copy_from_slice(&data);
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A compressed vertex stream and index buffer as a test fixture (the encoder is the same
    /// library).
    pub(crate) fn encode_vertices<const N: usize>(v: &[[u8; N]]) -> Vec<u8> {
        meshopt::encode_vertex_buffer(v).unwrap()
    }

    pub(crate) fn encode_triangles(idx: &[u32], vertices: usize) -> Vec<u8> {
        meshopt::encode_index_buffer(idx, vertices).unwrap()
    }

    #[test]
    fn vertex_and_index_streams_round_trip() {
        let v: Vec<[u8; 12]> = (0..10u8).map(|i| std::array::from_fn(|k| i * 7 + k as u8)).collect();
        let enc = encode_vertices(&v);
        let dec = decode_vertices(&enc, 10, 12).unwrap();
        assert_eq!(dec, v.concat());
        assert!(decode_vertices(&enc, 10, 6).is_none(), "stride not a multiple of 4");
        let idx = [0u32, 1, 2, 2, 1, 3];
        let enc = encode_triangles(&idx, 4);
        let dec = decode_indices(&enc, 6, 2, true).unwrap();
        assert_eq!(dec, idx.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect::<Vec<_>>());
        assert!(decode_indices(&enc[..3], 6, 2, true).is_none(), "truncated");
    }

    #[test]
    fn octahedral_filter_restores_unit_vectors() {
        let n = [[0.0f32, 0.0, 1.0, 0.0], [0.6, 0.0, -0.8, 0.0]];
        let enc: Vec<[i8; 4]> = meshopt::encode_filter_oct(&n, 8);
        let mut bytes: Vec<u8> = enc.iter().flat_map(|e| e.map(|x| x as u8)).collect();
        filter("OCTAHEDRAL", &mut bytes, 4).unwrap();
        let z = bytes[2] as i8 as f32 / 127.0;
        assert!((z - 1.0).abs() < 0.02, "{bytes:?}");
        assert!(filter("QUATERNION", &mut bytes, 4).is_none());
        // COLOR decodes 4 components of 1 or 2 bytes, nothing else.
        assert!(filter("COLOR", &mut [0u8; 12], 12).is_none());
        assert!(filter("COLOR", &mut [0u8; 16], 16).is_none());
        assert!(filter("COLOR", &mut [0u8; 8], 8).is_some());
    }
}
