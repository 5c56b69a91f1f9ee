//! `EXT_mesh_gpu_instancing`: a node's mesh drawn once per instance, each instance placed by its
//! own TRANSLATION / ROTATION / SCALE (defaults: none, identity, 1) within the node's frame. The
//! loader expands the instances into meshes (both renderers draw flat mesh lists), within the
//! scene's triangle budget.

use glam::{Mat4, Quat, Vec3};
use serde_json::Value;

use crate::accessors::{self, Expect};
use crate::context::Ctx;
use crate::error::SceneError;

/// The instance transforms of node `ni` (relative to the node), or `None` when the node does not
/// use the extension.
pub(crate) fn transforms(
    ctx: &Ctx,
    raw: &Value,
    doc: &gltf::Document,
    ni: usize,
    buffers: &[Vec<u8>],
) -> Result<Option<Vec<Mat4>>, SceneError> {
    let Some(ext) = raw.pointer(&format!("/nodes/{ni}/extensions/EXT_mesh_gpu_instancing")) else {
        return Ok(None);
    };
    let at = format!("nodes[{ni}].extensions.EXT_mesh_gpu_instancing");
    let attrs = ext
        .get("attributes")
        .and_then(Value::as_object)
        .ok_or_else(|| ctx.invalid(&at, "needs an `attributes` object"))?;
    let mut count: Option<usize> = None;
    let mut read = |name: &str, want: &Expect| -> Result<Option<Vec<f32>>, SceneError> {
        let Some(v) = attrs.get(name) else { return Ok(None) };
        let f = format!("{at}.attributes.{name}");
        let acc = v
            .as_u64()
            .and_then(|i| doc.accessors().nth(i as usize))
            .ok_or_else(|| ctx.invalid(&f, format!("{v} is not an accessor index")))?;
        accessors::check(ctx, &f, &acc, want, buffers)?;
        match count {
            Some(c) if c != acc.count() => {
                return Err(ctx
                    .invalid(&f, format!("has {} elements but the other attributes have {c}", acc.count())));
            }
            _ => count = Some(acc.count()),
        }
        accessors::read_f32(ctx, &f, &acc, buffers).map(Some)
    };
    let t = read("TRANSLATION", &accessors::TRANSLATION)?;
    let r = read("ROTATION", &accessors::ROTATION)?;
    let s = read("SCALE", &accessors::SCALE)?;
    let Some(n) = count else {
        return Err(
            ctx.invalid(format!("{at}.attributes"), "needs at least one of TRANSLATION, ROTATION and SCALE")
        );
    };
    (0..n)
        .map(|i| {
            let tr = t.as_ref().map_or(Vec3::ZERO, |t| Vec3::from_slice(&t[i * 3..]));
            let sc = s.as_ref().map_or(Vec3::ONE, |s| Vec3::from_slice(&s[i * 3..]));
            let rot = match &r {
                None => Quat::IDENTITY,
                Some(r) => {
                    let q = Quat::from_slice(&r[i * 4..]);
                    let len = q.length();
                    if !(len > 1e-6 && len.is_finite()) {
                        return Err(ctx.invalid(
                            format!("{at}.attributes.ROTATION"),
                            format!("instance {i} has no rotation (a zero or non-finite quaternion)"),
                        ));
                    }
                    q / len
                }
            };
            Ok(Mat4::from_scale_rotation_translation(sc, rot, tr))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}
