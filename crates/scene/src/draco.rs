//! `KHR_draco_mesh_compression`: a primitive whose geometry is stored as a Draco bitstream is
//! decoded (with the pure-Rust `draco-core` decoder) before any accessor is read, and the
//! decoded values are written into a buffer of their own, each accessor the extension names
//! pointed at its part. The rest of the loader then reads the file as if it had been stored
//! uncompressed: accessor checks, `KHR_mesh_quantization` types, skins and morph targets need
//! nothing of their own.
//!
//! The extension says the accessors describe the *decoded* data (their component type, type
//! and count), so the values are converted to what each accessor declares, and a count or
//! component count that disagrees with the bitstream is an error naming the accessor rather
//! than a guess. A primitive whose accessors all still have their uncompressed data
//! (`extensionsUsed` without `extensionsRequired`) is read from it, as the writer kept it exact.

use std::collections::HashSet;

use draco_core::decoder_buffer::DecoderBuffer;
use draco_core::draco_types::DataType;
use draco_core::geometry_attribute::PointAttribute;
use draco_core::geometry_indices::{FaceIndex, PointIndex};
use draco_core::mesh::Mesh;
use draco_core::mesh_decoder::MeshDecoder;
use serde_json::{Map, Value, json};

use crate::accessors::MAX_ACCESSOR_ELEMENTS;
use crate::context::Ctx;
use crate::error::SceneError;

const EXT: &str = "KHR_draco_mesh_compression";

/// glTF component types.
const BYTE: u64 = 5120;
const UNSIGNED_BYTE: u64 = 5121;
const SHORT: u64 = 5122;
const UNSIGNED_SHORT: u64 = 5123;
const UNSIGNED_INT: u64 = 5125;
const FLOAT: u64 = 5126;

/// Whether any primitive of `raw` (the document's JSON) has the extension.
pub(crate) fn used(raw: &Value) -> bool {
    let list = |v: &Value, k: &str| v.get(k).and_then(Value::as_array).cloned().unwrap_or_default();
    list(raw, "meshes")
        .iter()
        .any(|m| list(m, "primitives").iter().any(|p| p.pointer(&format!("/extensions/{EXT}")).is_some()))
}

/// Decodes every Draco-compressed primitive of `raw` (the document's JSON): the decoded values
/// are appended to `buffers` as one new buffer, and the returned document points the
/// primitives' accessors at them. `None` when nothing needed decoding.
pub(crate) fn decode(
    ctx: &Ctx,
    raw: &Value,
    buffers: &mut Vec<Vec<u8>>,
) -> Result<Option<Value>, SceneError> {
    let arr = |v: &Value, k: &str| v.get(k).and_then(Value::as_array).cloned().unwrap_or_default();
    let meshes = arr(raw, "meshes");
    let mut out: Option<Value> = None;
    let mut data: Vec<u8> = Vec::new();
    let new_buffer = buffers.len();
    let mut claimed: HashSet<usize> = HashSet::new();
    for (mi, m) in meshes.iter().enumerate() {
        for (pi, p) in arr(m, "primitives").iter().enumerate() {
            let Some(ext) = p.pointer(&format!("/extensions/{EXT}")) else { continue };
            let pat = format!("meshes[{mi}].primitives[{pi}]");
            let at = format!("{pat}.extensions.{EXT}");
            // Points and lines are skipped by the loader, which needs none of their data; Draco
            // itself stores only triangles and points.
            match p.get("mode").map(Value::as_u64) {
                None | Some(Some(4)) => {}
                Some(Some(0..=3)) => continue,
                Some(_) => {
                    return Err(ctx.invalid(
                        format!("{pat}.mode"),
                        format!(
                            "{}: a Draco-compressed primitive holds triangles (4) or points (0)",
                            p["mode"]
                        ),
                    ));
                }
            }
            let doc = out.get_or_insert_with(|| raw.clone());
            let names = ext.get("attributes").and_then(Value::as_object).ok_or_else(|| {
                ctx.invalid(format!("{at}.attributes"), "is required (an object of attribute ids)")
            })?;
            let prim_attr = |name: &str| -> Result<usize, SceneError> {
                let field = format!("{pat}.attributes.{name}");
                let v = p.pointer(&format!("/attributes/{name}")).ok_or_else(|| {
                    ctx.invalid(
                        format!("{at}.attributes.{name}"),
                        "names an attribute the primitive does not have",
                    )
                })?;
                v.as_u64()
                    .map(|a| a as usize)
                    .filter(|&a| a < doc["accessors"].as_array().map_or(0, Vec::len))
                    .ok_or_else(|| ctx.invalid(field, format!("{v} is not the index of an accessor")))
            };
            let mut targets: Vec<(String, usize, u32)> = Vec::new();
            for (name, id) in names {
                let uid = id.as_u64().and_then(|u| u32::try_from(u).ok()).ok_or_else(|| {
                    ctx.invalid(format!("{at}.attributes.{name}"), format!("{id} is not an attribute id"))
                })?;
                targets.push((name.clone(), prim_attr(name)?, uid));
            }
            let indices = match p.get("indices") {
                None => None,
                Some(v) => Some(
                    v.as_u64()
                        .map(|a| a as usize)
                        .filter(|&a| a < doc["accessors"].as_array().map_or(0, Vec::len))
                        .ok_or_else(|| {
                            ctx.invalid(
                                format!("{pat}.indices"),
                                format!("{v} is not the index of an accessor"),
                            )
                        })?,
                ),
            };
            let has_data = |a: usize| raw.pointer(&format!("/accessors/{a}/bufferView")).is_some();
            if targets.iter().all(|t| has_data(t.1)) && indices.is_none_or(has_data) {
                continue;
            }
            let mesh = decode_bitstream(ctx, &at, raw, ext, buffers)?;
            for (name, mut a, uid) in targets {
                let att = mesh.attribute_by_unique_id(uid).ok_or_else(|| {
                    ctx.invalid(
                        format!("{at}.attributes.{name}"),
                        format!("{uid} names no attribute of the decoded Draco data"),
                    )
                })?;
                if !claimed.insert(a) {
                    // Another Draco primitive's accessor: its decoded order is its own.
                    a = clone_accessor(doc, a);
                    doc["meshes"][mi]["primitives"][pi]["attributes"][&name] = json!(a);
                }
                let bytes = attribute_bytes(ctx, doc, a, &mesh, att)?;
                let stride = padded(element_size(doc, a));
                let view = push_view(doc, &mut data, new_buffer, bytes, Some(stride));
                point_accessor(doc, a, view);
            }
            let count = mesh.num_faces() * 3;
            let a = match indices {
                Some(a) if !claimed.contains(&a) => a,
                Some(a) => clone_accessor(doc, a),
                None => {
                    let list = doc["accessors"].as_array_mut().expect("checked above");
                    list.push(json!({"componentType": UNSIGNED_INT, "type": "SCALAR", "count": count}));
                    list.len() - 1
                }
            };
            claimed.insert(a);
            doc["meshes"][mi]["primitives"][pi]["indices"] = json!(a);
            let bytes = index_bytes(ctx, doc, a, &mesh)?;
            let view = push_view(doc, &mut data, new_buffer, bytes, None);
            point_accessor(doc, a, view);
        }
    }
    let Some(mut doc) = out else { return Ok(None) };
    if data.is_empty() {
        return Ok(None);
    }
    let len = data.len();
    match doc.get_mut("buffers").and_then(Value::as_array_mut) {
        Some(b) => b.push(json!({"byteLength": len})),
        None => doc["buffers"] = json!([{"byteLength": len}]),
    }
    buffers.push(data);
    Ok(Some(doc))
}

/// Decodes the bitstream the extension's `bufferView` holds.
fn decode_bitstream(
    ctx: &Ctx,
    at: &str,
    raw: &Value,
    ext: &Value,
    buffers: &[Vec<u8>],
) -> Result<Mesh, SceneError> {
    let vi = ext.get("bufferView").ok_or_else(|| ctx.invalid(format!("{at}.bufferView"), "is required"))?;
    let view = vi.as_u64().and_then(|v| raw.pointer(&format!("/bufferViews/{v}"))).ok_or_else(|| {
        ctx.invalid(format!("{at}.bufferView"), format!("{vi} is not the index of a bufferView"))
    })?;
    let vat = format!("bufferViews[{vi}]");
    let field = |k: &str, default: Option<u64>| -> Result<usize, SceneError> {
        match view.get(k) {
            None => {
                default.map(|d| d as usize).ok_or_else(|| ctx.invalid(format!("{vat}.{k}"), "is required"))
            }
            Some(v) => v.as_u64().and_then(|x| usize::try_from(x).ok()).ok_or_else(|| {
                ctx.invalid(format!("{vat}.{k}"), format!("must be a non-negative integer, got {v}"))
            }),
        }
    };
    let (b, off, len) = (field("buffer", None)?, field("byteOffset", Some(0))?, field("byteLength", None)?);
    let bytes = buffers.get(b).and_then(|d| d.get(off..off.checked_add(len)?)).ok_or_else(|| {
        ctx.invalid(&vat, format!("bytes {off}+{len} of buffers[{b}] do not exist (the Draco data)"))
    })?;
    // The decoder checks its input and returns errors; a panic on some input nobody has tried
    // yet must still not end the process.
    let decoded = std::panic::catch_unwind(|| {
        let mut input = DecoderBuffer::new(bytes);
        let mut mesh = Mesh::new();
        MeshDecoder::new().decode(&mut input, &mut mesh).map(|()| mesh).map_err(|e| e.to_string())
    })
    .unwrap_or_else(|_| Err("the decoder failed".into()));
    decoded.map_err(|e| ctx.invalid(at, format!("the Draco data in {vat} cannot be decoded: {e}")))
}

/// Components per element of an accessor `type`.
fn components(ty: &str) -> Option<usize> {
    Some(match ty {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => return None,
    })
}

fn component_size(ct: u64) -> Option<usize> {
    Some(match ct {
        BYTE | UNSIGNED_BYTE => 1,
        SHORT | UNSIGNED_SHORT => 2,
        UNSIGNED_INT | FLOAT => 4,
        _ => return None,
    })
}

fn element_size(doc: &Value, a: usize) -> usize {
    let acc = &doc["accessors"][a];
    let n = acc["type"].as_str().and_then(components).unwrap_or(1);
    n * acc["componentType"].as_u64().and_then(component_size).unwrap_or(4)
}

/// Vertex attribute elements start on 4-byte boundaries (glTF 2.0 §3.6.2.4).
fn padded(size: usize) -> usize {
    size.div_ceil(4) * 4
}

/// An accessor's declared shape: (component type, components, normalized, count).
fn shape(ctx: &Ctx, doc: &Value, a: usize) -> Result<(u64, usize, bool, usize), SceneError> {
    let acc = &doc["accessors"][a];
    let aat = format!("accessors[{a}]");
    let ct = acc
        .get("componentType")
        .and_then(Value::as_u64)
        .filter(|c| component_size(*c).is_some())
        .ok_or_else(|| ctx.invalid(format!("{aat}.componentType"), "is not a glTF component type"))?;
    let n = acc
        .get("type")
        .and_then(Value::as_str)
        .and_then(components)
        .ok_or_else(|| ctx.invalid(format!("{aat}.type"), "is not a glTF accessor type"))?;
    let count = acc
        .get("count")
        .and_then(Value::as_u64)
        .and_then(|c| usize::try_from(c).ok())
        .ok_or_else(|| ctx.invalid(format!("{aat}.count"), "is required (a non-negative integer)"))?;
    if count > MAX_ACCESSOR_ELEMENTS {
        return Err(ctx.invalid(
            format!("{aat}.count"),
            format!("{count} elements is more than the {MAX_ACCESSOR_ELEMENTS} accepted"),
        ));
    }
    Ok((ct, n, acc.get("normalized").and_then(Value::as_bool).unwrap_or(false), count))
}

/// One decoded component as a number: normalized integers scaled to [0, 1] or [−1, 1], others
/// as their values.
fn read_component(att: &PointAttribute, bytes: &[u8], normalized: bool) -> f64 {
    let le = |n: usize| -> [u8; 8] {
        let mut b = [0u8; 8];
        b[..n].copy_from_slice(&bytes[..n]);
        b
    };
    let (v, max) = match att.data_type() {
        DataType::Int8 => (bytes[0] as i8 as f64, i8::MAX as f64),
        DataType::Uint8 | DataType::Bool => (bytes[0] as f64, u8::MAX as f64),
        DataType::Int16 => (i16::from_le_bytes([bytes[0], bytes[1]]) as f64, i16::MAX as f64),
        DataType::Uint16 => (u16::from_le_bytes([bytes[0], bytes[1]]) as f64, u16::MAX as f64),
        DataType::Int32 => {
            (i32::from_le_bytes(bytes[..4].try_into().expect("4 bytes")) as f64, i32::MAX as f64)
        }
        DataType::Uint32 => {
            (u32::from_le_bytes(bytes[..4].try_into().expect("4 bytes")) as f64, u32::MAX as f64)
        }
        DataType::Int64 => (i64::from_le_bytes(le(8)) as f64, i64::MAX as f64),
        DataType::Uint64 => (u64::from_le_bytes(le(8)) as f64, u64::MAX as f64),
        DataType::Float32 => return f32::from_le_bytes(bytes[..4].try_into().expect("4 bytes")) as f64,
        DataType::Float64 => return f64::from_le_bytes(le(8)),
        _ => return f64::NAN,
    };
    if normalized { (v / max).max(-1.0) } else { v }
}

/// Writes `v` as one component of type `ct`; `None` when it does not fit.
fn write_component(out: &mut Vec<u8>, ct: u64, normalized: bool, v: f64) -> Option<()> {
    if ct == FLOAT {
        out.extend_from_slice(&(v as f32).to_le_bytes());
        return Some(());
    }
    let (lo, hi) = match ct {
        BYTE => (i8::MIN as f64, i8::MAX as f64),
        UNSIGNED_BYTE => (0.0, u8::MAX as f64),
        SHORT => (i16::MIN as f64, i16::MAX as f64),
        UNSIGNED_SHORT => (0.0, u16::MAX as f64),
        _ => (0.0, u32::MAX as f64),
    };
    let x = if normalized { (v.clamp(-1.0, 1.0) * hi).round() } else { v };
    if !(x.fract() == 0.0 && (lo..=hi).contains(&x)) {
        return None;
    }
    match ct {
        BYTE => out.push(x as i8 as u8),
        UNSIGNED_BYTE => out.push(x as u8),
        SHORT => out.extend_from_slice(&(x as i16).to_le_bytes()),
        UNSIGNED_SHORT => out.extend_from_slice(&(x as u16).to_le_bytes()),
        _ => out.extend_from_slice(&(x as u32).to_le_bytes()),
    }
    Some(())
}

/// The decoded values of `att`, one per point, as accessor `a` declares them, each element
/// padded to 4 bytes.
fn attribute_bytes(
    ctx: &Ctx,
    doc: &Value,
    a: usize,
    mesh: &Mesh,
    att: &PointAttribute,
) -> Result<Vec<u8>, SceneError> {
    let aat = format!("accessors[{a}]");
    let (ct, n, normalized, count) = shape(ctx, doc, a)?;
    let points = mesh.num_points();
    if count != points {
        return Err(ctx.invalid(
            format!("{aat}.count"),
            format!("{count}, but its Draco attribute decodes {points} vertices"),
        ));
    }
    if n != att.num_components() as usize {
        return Err(ctx.invalid(
            format!("{aat}.type"),
            format!("has {n} components, but its Draco attribute has {}", att.num_components()),
        ));
    }
    let csize = att.data_type().byte_length();
    // A decoded attribute's values start at its buffer's first byte.
    let stride = att.byte_stride().max(0) as usize;
    let src = att.buffer().data();
    let size = n * component_size(ct).expect("checked by shape");
    let mut out = Vec::with_capacity(points * padded(size));
    for p in 0..points {
        let vi = att.mapped_index(PointIndex(p as u32)).0 as usize;
        let start = vi.checked_mul(stride);
        let element = start.and_then(|s| src.get(s..s.checked_add(n * csize)?)).filter(|_| csize > 0);
        let Some(element) = element else {
            return Err(ctx.invalid(&aat, format!("vertex {p} has no value in the decoded Draco data")));
        };
        for c in 0..n {
            let v = read_component(att, &element[c * csize..], att.normalized());
            write_component(&mut out, ct, normalized, v).ok_or_else(|| {
                ctx.invalid(
                    format!("{aat}.componentType"),
                    format!("{ct} cannot hold the decoded value {v} (vertex {p})"),
                )
            })?;
        }
        out.resize(out.len() + padded(size) - size, 0);
    }
    Ok(out)
}

/// The decoded triangles as index accessor `a` declares them.
fn index_bytes(ctx: &Ctx, doc: &Value, a: usize, mesh: &Mesh) -> Result<Vec<u8>, SceneError> {
    let aat = format!("accessors[{a}]");
    let (ct, n, _, count) = shape(ctx, doc, a)?;
    if n != 1 || !matches!(ct, UNSIGNED_BYTE | UNSIGNED_SHORT | UNSIGNED_INT) {
        return Err(ctx.invalid(&aat, "indices are SCALAR UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT"));
    }
    let faces = mesh.num_faces();
    if count != faces * 3 {
        return Err(ctx.invalid(
            format!("{aat}.count"),
            format!("{count}, but the Draco data decodes {faces} triangles ({} indices)", faces * 3),
        ));
    }
    let mut out = Vec::with_capacity(count * component_size(ct).expect("an index type"));
    for f in 0..faces {
        for i in mesh.face(FaceIndex(f as u32)) {
            write_component(&mut out, ct, false, i.0 as f64).ok_or_else(|| {
                ctx.invalid(format!("{aat}.componentType"), format!("{ct} cannot hold the index {}", i.0))
            })?;
        }
    }
    Ok(out)
}

/// Appends `bytes` at a 4-byte boundary of the new buffer and a bufferView of them; its index.
fn push_view(
    doc: &mut Value,
    data: &mut Vec<u8>,
    buffer: usize,
    bytes: Vec<u8>,
    stride: Option<usize>,
) -> usize {
    data.resize(padded(data.len()), 0);
    let mut view = Map::new();
    view.insert("buffer".into(), json!(buffer));
    view.insert("byteOffset".into(), json!(data.len()));
    view.insert("byteLength".into(), json!(bytes.len()));
    if let Some(s) = stride.filter(|&s| (4..=252).contains(&s)) {
        view.insert("byteStride".into(), json!(s));
    }
    data.extend_from_slice(&bytes);
    match doc.get_mut("bufferViews").and_then(Value::as_array_mut) {
        Some(v) => {
            v.push(Value::Object(view));
            v.len() - 1
        }
        None => {
            doc["bufferViews"] = json!([Value::Object(view)]);
            0
        }
    }
}

fn point_accessor(doc: &mut Value, a: usize, view: usize) {
    let acc = &mut doc["accessors"][a];
    acc["bufferView"] = json!(view);
    if let Some(o) = acc.as_object_mut() {
        o.remove("byteOffset");
    }
}

/// A copy of accessor `a` appended to the document; its index.
fn clone_accessor(doc: &mut Value, a: usize) -> usize {
    let list = doc["accessors"].as_array_mut().expect("an accessor index was checked");
    let copy = list[a].clone();
    list.push(copy);
    list.len() - 1
}
