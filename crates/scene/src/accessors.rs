//! Checking and reading glTF accessors.
//!
//! Every accessor is checked here before it is read: its type against what its use allows (glTF
//! 2.0 and `KHR_mesh_quantization`), and its element range against its buffer view and buffer, so
//! a file that lies about counts, strides or types gives an error naming the accessor instead of
//! a panic. Reading converts any stored component type to `f32` the glTF way (normalized integers
//! to [0, 1] or [-1, 1], other integers as their values), which is all dequantization needs; the
//! node transform does the rest.

use gltf::accessor::{DataType, Dimensions};

use crate::context::Ctx;
use crate::error::SceneError;

/// Most elements any accessor may have: three vertices per triangle at the scene's triangle cap
/// ([`crate::MAX_TRIANGLES`]), the most an un-indexed mesh at that cap needs.
pub const MAX_ACCESSOR_ELEMENTS: usize = 3 * crate::MAX_TRIANGLES;
/// Most elements of a sparse accessor without a bufferView (zeros except for its sparse
/// values): no data in the file backs its count, so a few bytes could otherwise ask for
/// gigabytes. Real uses (a few morph-like edits of a small mesh) are far below it.
pub const MAX_ZERO_FILLED_ELEMENTS: usize = 1 << 20;

/// What an accessor may be stored as for one use.
pub(crate) struct Expect {
    pub dims: &'static [Dimensions],
    pub types: &'static [DataType],
    /// Integer types that must carry `"normalized": true` for this use.
    pub normalized: &'static [DataType],
}

use DataType::{F32, I8, I16, U8, U16, U32};

/// Integer types `KHR_mesh_quantization` allows where values need not be normalized.
const ANY_INT: &[DataType] = &[F32, I8, U8, I16, U16];

pub(crate) const POSITION: Expect = Expect { dims: &[Dimensions::Vec3], types: ANY_INT, normalized: &[] };
pub(crate) const NORMAL: Expect =
    Expect { dims: &[Dimensions::Vec3], types: &[F32, I8, I16], normalized: &[I8, I16] };
pub(crate) const TANGENT: Expect =
    Expect { dims: &[Dimensions::Vec4], types: &[F32, I8, I16], normalized: &[I8, I16] };
pub(crate) const TEXCOORD: Expect = Expect { dims: &[Dimensions::Vec2], types: ANY_INT, normalized: &[] };
pub(crate) const COLOR: Expect =
    Expect { dims: &[Dimensions::Vec3, Dimensions::Vec4], types: &[F32, U8, U16], normalized: &[U8, U16] };
pub(crate) const INDEX: Expect =
    Expect { dims: &[Dimensions::Scalar], types: &[U8, U16, U32], normalized: &[] };
/// `EXT_mesh_gpu_instancing` (with `KHR_mesh_quantization`).
pub(crate) const TRANSLATION: Expect = Expect { dims: &[Dimensions::Vec3], types: ANY_INT, normalized: &[] };
pub(crate) const ROTATION: Expect =
    Expect { dims: &[Dimensions::Vec4], types: &[F32, I8, I16], normalized: &[I8, I16] };
pub(crate) const SCALE: Expect = Expect { dims: &[Dimensions::Vec3], types: ANY_INT, normalized: &[] };

/// The glTF spelling of a component type, for messages.
pub(crate) fn type_name(t: DataType) -> &'static str {
    match t {
        I8 => "BYTE",
        U8 => "UNSIGNED_BYTE",
        I16 => "SHORT",
        U16 => "UNSIGNED_SHORT",
        U32 => "UNSIGNED_INT",
        F32 => "FLOAT",
    }
}

fn dims_name(d: Dimensions) -> &'static str {
    match d {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    }
}

fn list<T: Copy>(items: &[T], name: fn(T) -> &'static str) -> String {
    items.iter().map(|&t| name(t)).collect::<Vec<_>>().join(" or ")
}

fn range_in(
    ctx: &Ctx,
    at: &str,
    view: &gltf::buffer::View,
    buffers: &[Vec<u8>],
    offset: usize,
    count: usize,
    size: usize,
) -> Result<(), SceneError> {
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(ctx.invalid(at, format!("byteStride {stride} is smaller than the element size {size}")));
    }
    let need = count
        .checked_sub(1)
        .and_then(|c| c.checked_mul(stride))
        .and_then(|b| b.checked_add(offset))
        .and_then(|b| b.checked_add(size));
    let vi = view.index();
    match need {
        Some(n) if n <= view.length() => {}
        _ => {
            return Err(ctx.invalid(
                at,
                format!("{count} elements of {size} bytes (stride {stride}, offset {offset}) overrun bufferViews[{vi}] of {} bytes", view.length()),
            ));
        }
    }
    let b = view.buffer().index();
    let have = buffers.get(b).map_or(0, Vec::len);
    match view.offset().checked_add(view.length()) {
        Some(end) if end <= have => Ok(()),
        _ => Err(ctx.invalid(
            format!("bufferViews[{vi}]"),
            format!("bytes {}+{} overrun buffers[{b}], which has {have} bytes", view.offset(), view.length()),
        )),
    }
}

/// Checks that `acc` has a type `want` allows and lies inside its buffer. `at` names the use
/// (`meshes[0].primitives[1].attributes.NORMAL`).
pub(crate) fn check(
    ctx: &Ctx,
    at: &str,
    acc: &gltf::Accessor,
    want: &Expect,
    buffers: &[Vec<u8>],
) -> Result<(), SceneError> {
    let ai = acc.index();
    let at = format!("{at} (accessors[{ai}])");
    let (dims, ty) = (acc.dimensions(), acc.data_type());
    if !want.dims.contains(&dims) || !want.types.contains(&ty) {
        return Err(ctx.invalid(
            &at,
            format!(
                "stored as {} of {}, expected {} of {}",
                dims_name(dims),
                type_name(ty),
                list(want.dims, dims_name),
                list(want.types, type_name)
            ),
        ));
    }
    if want.normalized.contains(&ty) && !acc.normalized() {
        return Err(ctx.invalid(
            format!("accessors[{ai}].normalized"),
            format!(
                "{at} is stored as {}, which must be normalized (\"normalized\": true; glTF 2.0 and KHR_mesh_quantization)",
                type_name(ty)
            ),
        ));
    }
    if acc.count() == 0 {
        return Err(ctx.invalid(&at, "count is 0"));
    }
    if acc.count() > MAX_ACCESSOR_ELEMENTS {
        return Err(ctx.invalid(
            format!("accessors[{ai}].count"),
            format!("{} elements is more than the {MAX_ACCESSOR_ELEMENTS} accepted", acc.count()),
        ));
    }
    let size = acc.size();
    match (acc.view(), acc.sparse()) {
        (Some(v), _) => range_in(ctx, &at, &v, buffers, acc.offset(), acc.count(), size)?,
        (None, None) => {
            return Err(ctx.invalid(&at, "has no bufferView (all-zero accessors are not supported)"));
        }
        (None, Some(_)) => {
            if acc.count() > MAX_ZERO_FILLED_ELEMENTS {
                return Err(ctx.invalid(
                    format!("accessors[{ai}].count"),
                    format!(
                        "{} elements without a bufferView (zeros but for the sparse values) is more than \
                         the {MAX_ZERO_FILLED_ELEMENTS} accepted",
                        acc.count()
                    ),
                ));
            }
        }
    }
    if let Some(sp) = acc.sparse() {
        let n = sp.count();
        if n == 0 {
            return Err(ctx.invalid(&at, "sparse count is 0"));
        }
        if n > acc.count() {
            return Err(ctx.invalid(
                format!("accessors[{ai}].sparse.count"),
                format!("{n} is more than the accessor's count {} (glTF 2.0 §5.1.8)", acc.count()),
            ));
        }
        let idx = sp.indices();
        range_in(
            ctx,
            &format!("{at}.sparse.indices"),
            &idx.view(),
            buffers,
            idx.offset(),
            n,
            idx.index_type().size(),
        )?;
        let val = sp.values();
        range_in(ctx, &format!("{at}.sparse.values"), &val.view(), buffers, val.offset(), n, size)?;
    }
    Ok(())
}

/// The bytes of `view` (already range-checked by [`check`]).
fn view_bytes<'a>(view: &gltf::buffer::View, buffers: &'a [Vec<u8>]) -> &'a [u8] {
    &buffers[view.buffer().index()][view.offset()..view.offset() + view.length()]
}

/// One component at the start of `b`, converted the glTF way.
fn component(b: &[u8], ty: DataType, normalized: bool) -> f32 {
    let v = match ty {
        F32 => return f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        I8 => b[0] as i8 as f32,
        U8 => b[0] as f32,
        I16 => i16::from_le_bytes([b[0], b[1]]) as f32,
        U16 => u16::from_le_bytes([b[0], b[1]]) as f32,
        U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
    };
    if !normalized {
        return v;
    }
    // glTF 2.0 §3.11: signed values map to [-1, 1] with the most negative clamped.
    match ty {
        I8 => (v / 127.0).max(-1.0),
        U8 => v / 255.0,
        I16 => (v / 32767.0).max(-1.0),
        U16 => v / 65535.0,
        U32 => (v as f64 / u32::MAX as f64) as f32,
        F32 => v,
    }
}

fn index_at(b: &[u8], ty: &gltf::accessor::sparse::IndexType) -> usize {
    use gltf::accessor::sparse::IndexType as T;
    match ty {
        T::U8 => b[0] as usize,
        T::U16 => u16::from_le_bytes([b[0], b[1]]) as usize,
        T::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
    }
}

/// Reads a checked accessor as `count × components` floats (sparse substitution applied).
pub(crate) fn read_f32(
    ctx: &Ctx,
    at: &str,
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<f32>, SceneError> {
    let n = acc.dimensions().multiplicity();
    let (ty, norm, count) = (acc.data_type(), acc.normalized(), acc.count());
    let csize = ty.size();
    let mut out = vec![0.0f32; count * n];
    if let Some(view) = acc.view() {
        let data = &view_bytes(&view, buffers)[acc.offset()..];
        let stride = view.stride().unwrap_or(csize * n);
        for (i, e) in out.chunks_exact_mut(n).enumerate() {
            let el = &data[i * stride..];
            for (c, v) in e.iter_mut().enumerate() {
                *v = component(&el[c * csize..], ty, norm);
            }
        }
    }
    sparse(ctx, at, acc, buffers, count, |k, i, vb| {
        for c in 0..n {
            out[i * n + c] = component(&vb[(k * n + c) * csize..], ty, norm);
        }
    })?;
    Ok(out)
}

/// Calls `set(k, i, values)` for each sparse substitution k of `acc` (target element i, the
/// values' bytes), refusing an index past `count`.
fn sparse(
    ctx: &Ctx,
    at: &str,
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
    count: usize,
    mut set: impl FnMut(usize, usize, &[u8]),
) -> Result<(), SceneError> {
    let Some(sp) = acc.sparse() else { return Ok(()) };
    let (idx, val) = (sp.indices(), sp.values());
    let ib = &view_bytes(&idx.view(), buffers)[idx.offset()..];
    let vb = &view_bytes(&val.view(), buffers)[val.offset()..];
    let (it, isz) = (idx.index_type(), idx.index_type().size());
    for k in 0..sp.count() {
        let i = index_at(&ib[k * isz..], &it);
        if i >= count {
            // The position, not the value: the bytes may come from a file that is not ours.
            return Err(ctx.invalid(
                format!("{at} (accessors[{}]).sparse.indices", acc.index()),
                format!("sparse index number {k} is out of range (not below the {count} elements)"),
            ));
        }
        set(k, i, vb);
    }
    Ok(())
}

/// Reads a checked SCALAR accessor of unsigned integers (indices) exactly.
pub(crate) fn read_u32(
    ctx: &Ctx,
    at: &str,
    acc: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<u32>, SceneError> {
    let ty = acc.data_type();
    let size = ty.size();
    let get = |b: &[u8]| match ty {
        U8 => b[0] as u32,
        U16 => u16::from_le_bytes([b[0], b[1]]) as u32,
        _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
    };
    let count = acc.count();
    let mut out = vec![0u32; count];
    if let Some(view) = acc.view() {
        let data = &view_bytes(&view, buffers)[acc.offset()..];
        let stride = view.stride().unwrap_or(size);
        for (i, v) in out.iter_mut().enumerate() {
            *v = get(&data[i * stride..]);
        }
    }
    sparse(ctx, at, acc, buffers, count, |k, i, vb| out[i] = get(&vb[k * size..]))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_integers_follow_the_spec() {
        assert_eq!(component(&[127], I8, true), 1.0);
        assert_eq!(component(&[0x80], I8, true), -1.0);
        assert_eq!(component(&[0x81], I8, true), -1.0);
        assert_eq!(component(&[255], U8, true), 1.0);
        assert_eq!(component(&(-32767i16).to_le_bytes(), I16, true), -1.0);
        assert_eq!(component(&65535u16.to_le_bytes(), U16, true), 1.0);
        assert_eq!(component(&(-300i16).to_le_bytes(), I16, false), -300.0);
        assert_eq!(component(&200u8.to_le_bytes(), U8, false), 200.0);
        assert_eq!(component(&1.5f32.to_le_bytes(), F32, false), 1.5);
    }
}
