//! Bounds checks on glTF accessors before the `gltf` crate's reader touches them.
//!
//! The reader slices buffers with unchecked arithmetic (`count - 1`, `stride * count`) and reads
//! elements with slice indexing, so a file that lies about counts, strides or types would panic
//! inside it. Every accessor is checked here first, so malformed files become errors naming the
//! accessor instead.

use gltf::accessor::{DataType, Dimensions};

use crate::context::Ctx;
use crate::error::SceneError;

/// What an attribute may be stored as.
pub(crate) struct Expect {
    pub dims: Dimensions,
    pub types: &'static [DataType],
}

pub(crate) const POSITION: Expect = Expect { dims: Dimensions::Vec3, types: &[DataType::F32] };
pub(crate) const NORMAL: Expect = Expect { dims: Dimensions::Vec3, types: &[DataType::F32] };
pub(crate) const TANGENT: Expect = Expect { dims: Dimensions::Vec4, types: &[DataType::F32] };
pub(crate) const TEXCOORD: Expect =
    Expect { dims: Dimensions::Vec2, types: &[DataType::F32, DataType::U8, DataType::U16] };
pub(crate) const INDEX: Expect =
    Expect { dims: Dimensions::Scalar, types: &[DataType::U8, DataType::U16, DataType::U32] };

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

/// Checks that `acc` has the expected type and lies inside its buffer.
pub(crate) fn check(
    ctx: &Ctx,
    at: &str,
    acc: &gltf::Accessor,
    want: &Expect,
    buffers: &[Vec<u8>],
) -> Result<(), SceneError> {
    let at = format!("{at} (accessors[{}])", acc.index());
    if acc.dimensions() != want.dims || !want.types.contains(&acc.data_type()) {
        return Err(ctx.invalid(
            &at,
            format!(
                "stored as {:?} {:?}, expected {:?} of {:?}",
                acc.dimensions(),
                acc.data_type(),
                want.dims,
                want.types
            ),
        ));
    }
    if acc.count() == 0 {
        return Err(ctx.invalid(&at, "count is 0"));
    }
    let size = acc.size();
    match (acc.view(), acc.sparse()) {
        (Some(v), _) => range_in(ctx, &at, &v, buffers, acc.offset(), acc.count(), size)?,
        (None, None) => {
            return Err(ctx.invalid(&at, "has no bufferView (all-zero accessors are not supported)"));
        }
        (None, Some(_)) => {}
    }
    if let Some(sp) = acc.sparse() {
        let n = sp.count();
        if n == 0 {
            return Err(ctx.invalid(&at, "sparse count is 0"));
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
