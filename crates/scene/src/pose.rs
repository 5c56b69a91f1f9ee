//! Skins, morph targets and animations (glTF 2.0 §3.7.2.2, §3.7.3, §3.11). Both renderers draw
//! flat lists of world-space triangles, so the scene is posed once, here, at load time: every
//! node's local transform and morph weights at the chosen animation's time (or as the file
//! gives them, "at rest"), then each skinned primitive's vertices by its joints' matrices. One
//! pose serves both renderers, so they cannot disagree about it.
//!
//! Sampling follows the specification's Appendix C: times before the first key hold the first
//! value and after the last key the last (no looping), STEP holds the earlier key, LINEAR
//! interpolates linearly (rotations by slerp along the shorter arc), CUBICSPLINE is the
//! Hermite spline of the (in-tangent, value, out-tangent) triples with tangents scaled by the
//! key interval; rotations are renormalised.

use glam::{Mat3, Mat4, Quat, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::animation::{Interpolation, Property};

use crate::AnimationRef;
use crate::accessors::{self, Expect};
use crate::context::Ctx;
use crate::error::SceneError;

use DataType::{F32, I8, I16, U8, U16};

const TIMES: Expect = Expect { dims: &[Dimensions::Scalar], types: &[F32], normalized: &[] };
const VEC3_OUT: Expect = Expect { dims: &[Dimensions::Vec3], types: &[F32], normalized: &[] };
const ROTATION_OUT: Expect =
    Expect { dims: &[Dimensions::Vec4], types: &[F32, I8, U8, I16, U16], normalized: &[I8, U8, I16, U16] };
const WEIGHTS_OUT: Expect =
    Expect { dims: &[Dimensions::Scalar], types: &[F32, I8, U8, I16, U16], normalized: &[I8, U8, I16, U16] };
const INVERSE_BIND: Expect = Expect { dims: &[Dimensions::Mat4], types: &[F32], normalized: &[] };
pub(crate) const JOINTS: Expect = Expect { dims: &[Dimensions::Vec4], types: &[U8, U16], normalized: &[] };
pub(crate) const WEIGHTS: Expect =
    Expect { dims: &[Dimensions::Vec4], types: &[F32, U8, U16], normalized: &[U8, U16] };
/// Morph target displacements (with `KHR_mesh_quantization`: positions as any signed type,
/// normals and tangents as normalized signed ones).
pub(crate) const MORPH_POSITION: Expect =
    Expect { dims: &[Dimensions::Vec3], types: &[F32, I8, I16], normalized: &[] };
pub(crate) const MORPH_DIRECTION: Expect =
    Expect { dims: &[Dimensions::Vec3], types: &[F32, I8, I16], normalized: &[I8, I16] };

/// Largest `--time` accepted, in seconds (about 11.6 days): far beyond any animation, and small
/// enough that f32 key times still resolve it.
pub const MAX_TIME: f64 = 1e6;

/// The animation and time chosen (`--animation`, `--time`), resolved against the file.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Chosen {
    pub animation: usize,
    pub time: f32,
}

/// `1 'Walk'`, or `0 (unnamed)`: what `--animation` accepts.
impl Chosen {
    /// The choice as [`crate::Scene::choices`] records it.
    pub(crate) fn describe(&self, doc: &gltf::Document) -> [(String, String); 2] {
        let a = doc.animations().nth(self.animation).expect("chosen is checked");
        [("animation".into(), animation_name(&a)), ("time".into(), format!("{} s", self.time))]
    }
}

fn animation_name(a: &gltf::Animation) -> String {
    match a.name() {
        Some(n) => format!("{} '{n}'", a.index()),
        None => format!("{} (unnamed)", a.index()),
    }
}

/// Seconds to the millisecond, without trailing zeros.
fn seconds(t: f32) -> String {
    let s = format!("{t:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The end of `anim`: its last key over every sampler (the pointer channels' too).
fn end_of(ctx: &Ctx, anim: &gltf::Animation, buffers: &[Vec<u8>]) -> Result<f32, SceneError> {
    let mut end = 0.0f32;
    for (k, sampler) in anim.samplers().enumerate() {
        let input = sampler.input();
        let at = format!("animations[{}].samplers[{k}].input", anim.index());
        accessors::check(ctx, &at, &input, &TIMES, buffers)?;
        let times = accessors::read_f32(ctx, &at, &input, buffers)?;
        end = end.max(times.last().copied().filter(|t| t.is_finite()).unwrap_or(0.0));
    }
    Ok(end)
}

/// The file's animations as `--animation` names them, each with its length where its key times
/// can be read (an animation not chosen is not otherwise checked): `0 'Survey' of 3.417 s`.
fn names(ctx: &Ctx, doc: &gltf::Document, buffers: &[Vec<u8>]) -> String {
    let all: Vec<String> = doc
        .animations()
        .map(|a| match end_of(ctx, &a, buffers) {
            Ok(end) => format!("{} of {} s", animation_name(&a), seconds(end)),
            Err(_) => animation_name(&a),
        })
        .collect();
    match all.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => all.join(""),
    }
}

/// Resolves `--animation` (a name, exactly and then in any case, else an index) and `--time`
/// (default 0 when an animation is named; the first animation when only a time is given).
/// Without either, `None` and a warning when the file has animations.
pub(crate) fn choose(
    ctx: &Ctx,
    doc: &gltf::Document,
    animation: Option<&AnimationRef>,
    time: Option<f64>,
    buffers: &[Vec<u8>],
    warnings: &mut Vec<String>,
) -> Result<Option<Chosen>, SceneError> {
    let count = doc.animations().len();
    if let Some(t) = time
        && !(t.is_finite() && (0.0..=MAX_TIME).contains(&t))
    {
        return Err(ctx.invalid("animations", format!("--time {t}: must be seconds from 0 to {MAX_TIME:e}")));
    }
    if animation.is_none() && time.is_none() {
        if count > 0 {
            let s = if count == 1 { "" } else { "s" };
            warnings.push(format!(
                "the file has {count} animation{s} ({}); drawn at rest, as its nodes stand (choose one \
                 with --animation NAME and a moment with --time SECONDS)",
                names(ctx, doc, buffers)
            ));
        }
        return Ok(None);
    }
    let flag = match (animation, time) {
        (Some(AnimationRef::NameOrIndex(a)), _) => format!("--animation {a}"),
        (Some(AnimationRef::Index(i)), _) => format!("--animation {i}"),
        (None, Some(t)) => format!("--time {t}"),
        (None, None) => unreachable!(),
    };
    if count == 0 {
        return Err(ctx.invalid("animations", format!("{flag}: the file has no animations")));
    }
    let no_such = || {
        ctx.invalid(
            "animations",
            format!("{flag}: the file has no such animation; it has {}", names(ctx, doc, buffers)),
        )
    };
    let index = match animation {
        None => 0,
        Some(AnimationRef::Index(i)) => Some(*i).filter(|&i| i < count).ok_or_else(no_such)?,
        Some(AnimationRef::NameOrIndex(a)) => {
            let all: Vec<gltf::Animation> = doc.animations().collect();
            all.iter()
                .position(|x| x.name() == Some(a))
                .or_else(|| all.iter().position(|x| x.name().is_some_and(|n| n.eq_ignore_ascii_case(a))))
                .or_else(|| a.parse::<usize>().ok().filter(|&i| i < count))
                .ok_or_else(|| {
                    ctx.invalid(
                        "animations",
                        format!(
                            "{flag}: the file has no such animation; it has {}",
                            names(ctx, doc, buffers)
                        ),
                    )
                })?
        }
    };
    let time = time.unwrap_or(0.0) as f32;
    Ok(Some(Chosen { animation: index, time }))
}

/// Checks what the `gltf` crate's validation leaves to its accessors, which would panic: each
/// animation channel's target node (an index of one of the file's nodes) and path (of the
/// four glTF defines; `KHR_animation_pointer`'s "pointer" channels are removed before this).
pub(crate) fn check_targets(ctx: &Ctx, raw: &serde_json::Value) -> Result<(), SceneError> {
    let nodes = raw.get("nodes").and_then(serde_json::Value::as_array).map_or(0, Vec::len);
    let Some(anims) = raw.get("animations").and_then(serde_json::Value::as_array) else { return Ok(()) };
    for (a, anim) in anims.iter().enumerate() {
        let Some(channels) = anim.get("channels").and_then(serde_json::Value::as_array) else { continue };
        for (c, ch) in channels.iter().enumerate() {
            let at = format!("animations[{a}].channels[{c}].target");
            let node = ch.pointer("/target/node");
            if let Some(n) = node
                && n.as_u64().is_none_or(|n| n as usize >= nodes)
            {
                return Err(ctx.invalid(
                    format!("{at}.node"),
                    format!("{n} is not the index of one of the file's {nodes} nodes"),
                ));
            }
            let path = ch.pointer("/target/path");
            if node.is_some()
                && !path
                    .and_then(serde_json::Value::as_str)
                    .is_some_and(|p| ["translation", "rotation", "scale", "weights"].contains(&p))
            {
                let shown = path.map_or("missing".to_string(), |p| p.to_string());
                return Err(ctx.invalid(
                    format!("{at}.path"),
                    format!("{shown}: expected \"translation\", \"rotation\", \"scale\" or \"weights\""),
                ));
            }
        }
    }
    Ok(())
}

/// What a `KHR_animation_pointer` pointer animates, where the loader reads it: `Some(rotation)`
/// (a unit quaternion, slerped) for the properties both renderers draw, `None` for the rest.
fn drawn_pointer(tokens: &[String]) -> Option<bool> {
    let t: Vec<&str> = tokens.iter().map(String::as_str).collect();
    match t.as_slice() {
        ["nodes", _, "rotation"] => Some(true),
        ["nodes", _, "translation" | "scale" | "weights"] | ["meshes", _, "weights"] => Some(false),
        ["nodes", _, "extensions", "KHR_node_visibility", "visible"] => Some(false),
        ["materials", _, ..] | ["cameras", _, ..] => Some(false),
        ["extensions", "KHR_lights_punctual", "lights", _, ..] => Some(false),
        _ => None,
    }
}

/// A JSON pointer's reference tokens (RFC 6901: `~1` is `/`, `~0` is `~`).
fn pointer_tokens(p: &str) -> Option<Vec<String>> {
    let rest = p.strip_prefix('/')?;
    Some(rest.split('/').map(|t| t.replace("~1", "/").replace("~0", "~")).collect())
}

/// Sets the property `tokens` names in `doc` to `value`: the objects and arrays on the way must
/// exist (a pointer names a property of the file, or one with a default in an object it has).
fn set_pointer(
    doc: &mut serde_json::Value,
    tokens: &[String],
    value: serde_json::Value,
) -> Result<(), String> {
    let (last, path) = tokens.split_last().ok_or("is empty")?;
    let mut at = doc;
    for (k, t) in path.iter().enumerate() {
        let next = match at {
            serde_json::Value::Object(o) => o.get_mut(t),
            serde_json::Value::Array(a) => t.parse::<usize>().ok().and_then(|i| a.get_mut(i)),
            _ => None,
        };
        at = next.ok_or_else(|| format!("names nothing in the file: no '/{}'", tokens[..=k].join("/")))?;
    }
    match at {
        serde_json::Value::Object(o) => {
            o.insert(last.clone(), value);
            Ok(())
        }
        serde_json::Value::Array(a) => {
            let slot = last
                .parse::<usize>()
                .ok()
                .and_then(|i| a.get_mut(i))
                .ok_or("names no element of its array")?;
            *slot = value;
            Ok(())
        }
        _ => Err("names a property inside a value that is not an object".into()),
    }
}

/// `KHR_animation_pointer`: the chosen animation's pointer channels sampled at its time and
/// written into a copy of the document, or `None` when it has none. Pointers the renderers do
/// not read (other extensions, `extras`) are skipped with a warning.
pub(crate) fn pointer_values(
    ctx: &Ctx,
    doc: &gltf::Document,
    raw: &serde_json::Value,
    buffers: &[Vec<u8>],
    chosen: Chosen,
    warnings: &mut Vec<String>,
) -> Result<Option<serde_json::Value>, SceneError> {
    let a = chosen.animation;
    let Some(channels) =
        raw.pointer(&format!("/animations/{a}/channels")).and_then(serde_json::Value::as_array)
    else {
        return Ok(None);
    };
    let anim = doc.animations().nth(a).expect("chosen is checked");
    let samplers: Vec<gltf::animation::Sampler> = anim.samplers().collect();
    let mut out: Option<serde_json::Value> = None;
    let mut skipped = Vec::new();
    for (c, ch) in channels.iter().enumerate() {
        if ch.pointer("/target/node").is_some() {
            continue;
        }
        let at = format!("animations[{a}].channels[{c}]");
        let pat = format!("{at}.target.extensions.KHR_animation_pointer.pointer");
        let Some(ext) = ch.pointer("/target/extensions/KHR_animation_pointer") else {
            // Neither a node nor a pointer: an extension this loader does not know animates it.
            skipped.push(format!("{at} (no node, no pointer)"));
            continue;
        };
        let pointer = ext
            .get("pointer")
            .and_then(serde_json::Value::as_str)
            .ok_or_else(|| ctx.invalid(&pat, "is missing or not a string"))?;
        let tokens = pointer_tokens(pointer).ok_or_else(|| {
            ctx.invalid(&pat, format!("'{pointer}' is not a JSON pointer (it starts with '/')"))
        })?;
        let Some(rotation) = drawn_pointer(&tokens) else {
            skipped.push(format!("'{pointer}'"));
            continue;
        };
        let sampler = ch
            .get("sampler")
            .and_then(serde_json::Value::as_u64)
            .and_then(|s| samplers.get(s as usize))
            .ok_or_else(|| {
                ctx.invalid(
                    format!("{at}.sampler"),
                    format!("is not the index of one of the animation's {} samplers", samplers.len()),
                )
            })?;
        let sat = format!("animations[{a}].samplers[{}]", sampler.index());
        let k = pointer_keys(ctx, &sat, sampler, buffers)?;
        let v = k.at(chosen.time, rotation && k.width == 4);
        let output = sampler.output();
        let integers = !output.normalized() && output.data_type() != F32;
        let number = |x: f32| -> serde_json::Value {
            if integers {
                serde_json::Value::from(x.round() as i64)
            } else {
                serde_json::Value::from(f64::from(x))
            }
        };
        let boolean = tokens.iter().any(|t| t == "KHR_node_visibility");
        let value = if boolean {
            // A bool property: unsigned bytes, 0 false and anything else true (STEP).
            serde_json::Value::Bool(v[0] != 0.0)
        } else if k.width == 1 && !matches!(tokens.last().map(String::as_str), Some("weights")) {
            number(v[0])
        } else {
            serde_json::Value::Array(v.iter().map(|&x| number(x)).collect())
        };
        if let [n, i, "translation" | "rotation" | "scale"] =
            tokens.iter().map(String::as_str).collect::<Vec<_>>().as_slice()
            && *n == "nodes"
            && raw.pointer(&format!("/nodes/{i}/matrix")).is_some()
        {
            return Err(ctx.invalid(&pat, format!("'{pointer}' animates a node given by its matrix (glTF 2.0 §3.7.2.1: an animated node has TRS)")));
        }
        let doc_out = out.get_or_insert_with(|| raw.clone());
        set_pointer(doc_out, &tokens, value).map_err(|m| ctx.invalid(&pat, format!("'{pointer}' {m}")))?;
    }
    if !skipped.is_empty() {
        warnings.push(format!(
            "KHR_animation_pointer: {} not drawn (neither renderer reads what {} point{} at); the rest of the animation is",
            skipped.join(", "),
            if skipped.len() == 1 { "it" } else { "they" },
            if skipped.len() == 1 { "s" } else { "" }
        ));
    }
    Ok(out)
}

/// A sampler's key times, checked: finite, not negative, increasing.
fn key_times(
    ctx: &Ctx,
    at: &str,
    sampler: &gltf::animation::Sampler,
    buffers: &[Vec<u8>],
) -> Result<Vec<f32>, SceneError> {
    let input = sampler.input();
    let in_at = format!("{at}.input");
    accessors::check(ctx, &in_at, &input, &TIMES, buffers)?;
    let times = accessors::read_f32(ctx, &in_at, &input, buffers)?;
    if let Some(k) = times.iter().position(|t| !t.is_finite() || *t < 0.0) {
        return Err(ctx.invalid(&in_at, format!("key time {k} is negative or not finite")));
    }
    if let Some(k) = times.windows(2).position(|w| w[1] <= w[0]) {
        return Err(ctx.invalid(&in_at, format!("key times must increase, and key {} does not", k + 1)));
    }
    Ok(times)
}

/// A pointer channel's keys: any scalar or vector output (floats or integers, normalized or
/// not), its width the output's components per key (a SCALAR output of n per key is an array
/// of n, as morph weights are).
fn pointer_keys(
    ctx: &Ctx,
    at: &str,
    sampler: &gltf::animation::Sampler,
    buffers: &[Vec<u8>],
) -> Result<Keys, SceneError> {
    const OUT: Expect = Expect {
        dims: &[Dimensions::Scalar, Dimensions::Vec2, Dimensions::Vec3, Dimensions::Vec4],
        types: &[F32, I8, U8, I16, U16, DataType::U32],
        normalized: &[],
    };
    let times = key_times(ctx, at, sampler, buffers)?;
    let output = sampler.output();
    let out_at = format!("{at}.output");
    accessors::check(ctx, &out_at, &output, &OUT, buffers)?;
    let interpolation = sampler.interpolation();
    let per_key = times.len() * if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
    let m = output.dimensions().multiplicity();
    let width = if m == 1 { output.count() / per_key } else { m };
    if width == 0 || output.count() * m != per_key * width {
        return Err(ctx.invalid(
            &out_at,
            format!(
                "has {} elements for {} keys; expected a whole number of values per key",
                output.count(),
                times.len()
            ),
        ));
    }
    let values = accessors::read_f32(ctx, &out_at, &output, buffers)?;
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(ctx.invalid(&out_at, format!("value {} is not finite", k / width)));
    }
    Ok(Keys { times, values, width, interpolation })
}

/// The posed scene graph: each node's local transform and morph weights.
pub(crate) struct Pose {
    /// The chosen animation's end ([`crate::Scene::animation_end`]).
    pub(crate) animation_end: Option<f32>,
    local: Vec<Mat4>,
    world: Vec<Mat4>,
    /// Morph weights set by an animation or by `node.weights`; `None`: the mesh's own.
    weights: Vec<Option<Vec<f32>>>,
}

/// A channel's keyframes, read and checked.
struct Keys {
    times: Vec<f32>,
    values: Vec<f32>,
    width: usize,
    interpolation: Interpolation,
}

impl Keys {
    /// The value at `t` (`width` numbers); `rotation` renormalises and interpolates as a
    /// quaternion.
    fn at(&self, t: f32, rotation: bool) -> Vec<f32> {
        let w = self.width;
        let cubic = self.interpolation == Interpolation::CubicSpline;
        // Element k of the output: in cubic splines the value sits between its two tangents.
        let value = |k: usize| -> &[f32] {
            let at = if cubic { (3 * k + 1) * w } else { k * w };
            &self.values[at..at + w]
        };
        let n = self.times.len();
        let out: Vec<f32> = if n == 1 || t <= self.times[0] {
            value(0).to_vec()
        } else if t >= self.times[n - 1] {
            value(n - 1).to_vec()
        } else {
            // The last key at or before t.
            let k = self.times.partition_point(|&x| x <= t) - 1;
            let (t0, t1) = (self.times[k], self.times[k + 1]);
            let u = (t - t0) / (t1 - t0);
            match self.interpolation {
                Interpolation::Step => value(k).to_vec(),
                Interpolation::Linear if rotation => {
                    // Keys rounded in the file (0.707 for √½) are made unit first: slerp's
                    // angle is only right between unit quaternions.
                    let unit = |q: Quat| if q.length() > 1e-12 { q.normalize() } else { Quat::IDENTITY };
                    let a = unit(Quat::from_slice(value(k)));
                    let b = unit(Quat::from_slice(value(k + 1)));
                    slerp(a, b, u).to_array().to_vec()
                }
                Interpolation::Linear => {
                    value(k).iter().zip(value(k + 1)).map(|(a, b)| a + (b - a) * u).collect()
                }
                Interpolation::CubicSpline => {
                    let d = t1 - t0;
                    let out_tangent = &self.values[(3 * k + 2) * w..(3 * k + 3) * w];
                    let in_tangent = &self.values[(3 * (k + 1)) * w..(3 * (k + 1) + 1) * w];
                    let (u2, u3) = (u * u, u * u * u);
                    let h00 = 2.0 * u3 - 3.0 * u2 + 1.0;
                    let h10 = u3 - 2.0 * u2 + u;
                    let h01 = -2.0 * u3 + 3.0 * u2;
                    let h11 = u3 - u2;
                    (0..w)
                        .map(|c| {
                            h00 * value(k)[c]
                                + h10 * d * out_tangent[c]
                                + h01 * value(k + 1)[c]
                                + h11 * d * in_tangent[c]
                        })
                        .collect()
                }
            }
        };
        if rotation {
            let q = Quat::from_slice(&out);
            let len = q.length();
            return if len > 1e-12 && len.is_finite() {
                (q / len).to_array().to_vec()
            } else {
                vec![0.0, 0.0, 0.0, 1.0]
            };
        }
        out
    }
}

/// Spherical linear interpolation along the shorter arc (Appendix C), linear where the two
/// are nearly the same rotation.
fn slerp(a: Quat, b: Quat, u: f32) -> Quat {
    let mut d = a.dot(b);
    let b = if d < 0.0 {
        d = -d;
        -b
    } else {
        b
    };
    if d > 0.9995 {
        return (a + (b - a) * u).normalize();
    }
    let theta = d.clamp(-1.0, 1.0).acos();
    let s = theta.sin();
    a * (((1.0 - u) * theta).sin() / s) + b * ((u * theta).sin() / s)
}

/// Reads and checks an animation sampler's keys for `property` (`targets`: the morph target
/// count, for weights).
fn keys(
    ctx: &Ctx,
    at: &str,
    sampler: &gltf::animation::Sampler,
    property: Property,
    targets: usize,
    buffers: &[Vec<u8>],
) -> Result<Keys, SceneError> {
    let times = key_times(ctx, at, sampler, buffers)?;
    let (want, width) = match property {
        Property::Translation | Property::Scale => (&VEC3_OUT, 3),
        Property::Rotation => (&ROTATION_OUT, 4),
        Property::MorphTargetWeights => (&WEIGHTS_OUT, targets.max(1)),
    };
    let output = sampler.output();
    let out_at = format!("{at}.output");
    accessors::check(ctx, &out_at, &output, want, buffers)?;
    let interpolation = sampler.interpolation();
    let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 } * width;
    let elements = if property == Property::MorphTargetWeights { 1 } else { width };
    let expected = times.len() * per_key / elements;
    if output.count() != expected {
        let what =
            match (interpolation == Interpolation::CubicSpline, property == Property::MorphTargetWeights) {
                (false, false) => "one value per key".to_string(),
                (true, false) => {
                    "three values per key (in-tangent, value, out-tangent; CUBICSPLINE)".to_string()
                }
                (false, true) => format!("one weight per morph target ({targets}) per key"),
                (true, true) => format!("three weights per morph target ({targets}) per key (CUBICSPLINE)"),
            };
        return Err(ctx.invalid(
            &out_at,
            format!("has {} elements for {} keys; expected {expected} ({what})", output.count(), times.len()),
        ));
    }
    let values = accessors::read_f32(ctx, &out_at, &output, buffers)?;
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(ctx.invalid(&out_at, format!("value {} is not finite", k / width)));
    }
    Ok(Keys { times, values, width, interpolation })
}

/// The number of morph targets of a mesh (the same for every primitive, glTF 2.0 §3.7.2.2).
fn target_count(ctx: &Ctx, mesh: &gltf::Mesh) -> Result<usize, SceneError> {
    let mut count = None;
    for p in mesh.primitives() {
        let n = p.morph_targets().len();
        match count {
            Some(c) if c != n => {
                return Err(ctx.invalid(
                    format!("meshes[{}].primitives[{}].targets", mesh.index(), p.index()),
                    format!("has {n} morph targets but the mesh's first primitive has {c}; every primitive must have the same number"),
                ));
            }
            _ => count = Some(n),
        }
    }
    Ok(count.unwrap_or(0))
}

impl Pose {
    /// The file's scene graph posed at `chosen` (or at rest).
    pub(crate) fn new(
        ctx: &Ctx,
        doc: &gltf::Document,
        buffers: &[Vec<u8>],
        chosen: Option<Chosen>,
        warnings: &mut Vec<String>,
    ) -> Result<Pose, SceneError> {
        let n = doc.nodes().len();
        let mut local: Vec<Mat4> =
            doc.nodes().map(|node| Mat4::from_cols_array_2d(&node.transform().matrix())).collect();
        let mut weights: Vec<Option<Vec<f32>>> = vec![None; n];
        for node in doc.nodes() {
            if let Some(w) = node.weights() {
                weights[node.index()] = Some(w.to_vec());
            }
        }
        let mut animation_end = None;
        if let Some(ch) = chosen {
            let anim = doc.animations().nth(ch.animation).expect("chosen is checked");
            // Each node's TRS, from its own (decomposed) transform, overridden by the channels.
            let mut trs: Vec<Option<(Vec3, Quat, Vec3)>> = vec![None; n];
            let end = end_of(ctx, &anim, buffers)?;
            animation_end = Some(end);
            for channel in anim.channels() {
                let target = channel.target();
                let node = target.node();
                let ni = node.index();
                let at = format!("animations[{}].samplers[{}]", anim.index(), channel.sampler().index());
                let property = target.property();
                let targets = match (property, node.mesh()) {
                    (Property::MorphTargetWeights, Some(m)) => match target_count(ctx, &m)? {
                        0 => {
                            return Err(ctx.invalid(
                                format!("animations[{}].channels[{}].target", anim.index(), channel.index()),
                                format!("animates the morph weights of nodes[{ni}], whose mesh has no morph targets"),
                            ));
                        }
                        t => t,
                    },
                    (Property::MorphTargetWeights, None) => {
                        return Err(ctx.invalid(
                            format!("animations[{}].channels[{}].target", anim.index(), channel.index()),
                            format!("animates the morph weights of nodes[{ni}], which has no mesh"),
                        ));
                    }
                    _ => 0,
                };
                let k = keys(ctx, &at, &channel.sampler(), property, targets, buffers)?;
                let v = k.at(ch.time, property == Property::Rotation);
                if property == Property::MorphTargetWeights {
                    weights[ni] = Some(v);
                    continue;
                }
                let (t, r, s) = trs[ni].get_or_insert_with(|| {
                    let (t, r, s) = node.transform().decomposed();
                    (Vec3::from(t), Quat::from_array(r), Vec3::from(s))
                });
                match property {
                    Property::Translation => *t = Vec3::from_slice(&v),
                    Property::Rotation => *r = Quat::from_slice(&v),
                    Property::Scale => *s = Vec3::from_slice(&v),
                    Property::MorphTargetWeights => unreachable!(),
                }
            }
            if ch.time > end {
                warnings.push(format!(
                    "--time {}: past the end of animation {} ({end} s): drawn at its last keyframes \
                     (an animation holds its ends; it is not looped)",
                    ch.time,
                    animation_name(&anim)
                ));
            }
            for (ni, p) in trs.iter().enumerate() {
                if let Some((t, r, s)) = p {
                    local[ni] = Mat4::from_scale_rotation_translation(*s, *r, *t);
                }
            }
        }
        // World transforms through the parent links (only joints need them before the
        // loader's own walk of the scene tree); a cycle is the walk's error, so here it only
        // stops the climb.
        let mut parent = vec![None; n];
        for node in doc.nodes() {
            for c in node.children() {
                parent[c.index()].get_or_insert(node.index());
            }
        }
        // Each node's world transform once, from its root down (a deep chain costs its length,
        // not its square).
        let mut world: Vec<Option<Mat4>> = vec![None; n];
        for i in 0..n {
            let mut chain = vec![i];
            let mut at = parent[i];
            while let Some(p) = at {
                if world[p].is_some() {
                    break;
                }
                if chain.len() > n {
                    return Err(ctx.invalid(
                        format!("nodes[{i}]"),
                        "its ancestors form a cycle: the node hierarchy must be a tree",
                    ));
                }
                chain.push(p);
                at = parent[p];
            }
            let mut m = at.and_then(|p| world[p]).unwrap_or(Mat4::IDENTITY);
            for &c in chain.iter().rev() {
                m *= local[c];
                world[c] = Some(m);
            }
        }
        let world: Vec<Mat4> = world.into_iter().map(|m| m.expect("every node is reached")).collect();
        Ok(Pose { animation_end, local, world, weights })
    }

    /// Node `i`'s local transform in this pose.
    pub(crate) fn local(&self, i: usize) -> Mat4 {
        self.local[i]
    }

    /// The morph weights `node` draws its mesh with: animated, else the node's, else the
    /// mesh's, else zeros; checked against the mesh's target count.
    pub(crate) fn morph_weights(
        &self,
        ctx: &Ctx,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
    ) -> Result<Vec<f32>, SceneError> {
        let targets = target_count(ctx, mesh)?;
        let (w, at) = match (&self.weights[node.index()], mesh.weights()) {
            (Some(w), _) => (w.clone(), format!("nodes[{}].weights", node.index())),
            (None, Some(w)) => (w.to_vec(), format!("meshes[{}].weights", mesh.index())),
            (None, None) => return Ok(vec![0.0; targets]),
        };
        if w.len() != targets {
            return Err(
                ctx.invalid(at, format!("has {} weights but the mesh has {targets} morph targets", w.len()))
            );
        }
        if let Some(k) = w.iter().position(|x| !x.is_finite()) {
            return Err(ctx.invalid(at, format!("weight {k} is not finite")));
        }
        Ok(w)
    }

    /// Each joint's skinning matrix: its world transform times its inverse bind matrix. The
    /// skinned mesh's own node transform plays no part (glTF 2.0 §3.7.3).
    pub(crate) fn joint_matrices(
        &self,
        ctx: &Ctx,
        skin: &gltf::Skin,
        buffers: &[Vec<u8>],
    ) -> Result<Vec<Mat4>, SceneError> {
        let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
        let at = format!("skins[{}]", skin.index());
        if joints.is_empty() {
            return Err(ctx.invalid(format!("{at}.joints"), "is empty"));
        }
        let inverse: Vec<Mat4> = match skin.inverse_bind_matrices() {
            None => vec![Mat4::IDENTITY; joints.len()],
            Some(acc) => {
                let f = format!("{at}.inverseBindMatrices");
                accessors::check(ctx, &f, &acc, &INVERSE_BIND, buffers)?;
                if acc.count() < joints.len() {
                    return Err(
                        ctx.invalid(&f, format!("has {} matrices for {} joints", acc.count(), joints.len()))
                    );
                }
                let m = accessors::read_f32(ctx, &f, &acc, buffers)?;
                m.chunks_exact(16).take(joints.len()).map(Mat4::from_cols_slice).collect()
            }
        };
        let out: Vec<Mat4> = joints.iter().zip(&inverse).map(|(&j, ib)| self.world[j] * *ib).collect();
        if let Some(k) = out.iter().position(|m| !m.is_finite()) {
            return Err(ctx.invalid(format!("{at}.joints[{k}]"), "the joint's matrix is not finite"));
        }
        Ok(out)
    }
}

/// How a primitive is deformed before it is placed: morph weights (one per target) and, for a
/// skinned node, its joints' matrices (the vertices then come out in world space).
pub(crate) struct Deform<'a> {
    pub weights: &'a [f32],
    pub joints: Option<&'a [Mat4]>,
    /// Where a skinned vertex without any weight stays: the node's own transform.
    pub fallback: Mat4,
    /// Counts the skinned vertices that had no weight (for one warning per node).
    pub unweighted: std::cell::Cell<usize>,
}

impl Deform<'_> {
    /// Whether it changes anything.
    pub(crate) fn morphs(&self) -> bool {
        self.weights.iter().any(|&w| w != 0.0)
    }
}

/// The vertex data a deformation moves: positions, normals (when the file has them), tangents
/// (empty when it has none).
pub(crate) struct Vertices<'a> {
    pub positions: &'a mut [Vec3],
    pub normals: Option<&'a mut [Vec3]>,
    pub tangents: &'a mut [Vec4],
}

/// Adds the weighted morph target displacements of `prim` to its vertex data.
pub(crate) fn morph(
    ctx: &Ctx,
    at: &str,
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    weights: &[f32],
    v: Vertices,
) -> Result<(), SceneError> {
    let Vertices { positions, normals, tangents } = v;
    let n = positions.len();
    let mut normals = normals;
    for (k, target) in prim.morph_targets().enumerate() {
        let w = weights.get(k).copied().unwrap_or(0.0);
        if w == 0.0 {
            continue;
        }
        let read = |acc: Option<gltf::Accessor>,
                    name: &str,
                    want: &Expect|
         -> Result<Option<Vec<Vec3>>, SceneError> {
            let Some(acc) = acc else { return Ok(None) };
            let f = format!("{at}.targets[{k}].{name}");
            accessors::check(ctx, &f, &acc, want, buffers)?;
            if acc.count() != n {
                return Err(ctx.invalid(&f, format!("has {} elements but POSITION has {n}", acc.count())));
            }
            let d = accessors::read_f32(ctx, &f, &acc, buffers)?;
            if let Some(i) = d.iter().position(|x| !x.is_finite()) {
                return Err(ctx.invalid(&f, format!("displacement {} is not finite", i / 3)));
            }
            Ok(Some(d.chunks_exact(3).map(Vec3::from_slice).collect()))
        };
        if let Some(d) = read(target.positions(), "POSITION", &MORPH_POSITION)? {
            positions.iter_mut().zip(&d).for_each(|(p, d)| *p += w * *d);
        }
        if let Some(d) = read(target.normals(), "NORMAL", &MORPH_DIRECTION)?
            && let Some(ns) = normals.as_deref_mut()
        {
            ns.iter_mut().zip(&d).for_each(|(v, d)| *v += w * *d);
        }
        if let Some(d) = read(target.tangents(), "TANGENT", &MORPH_DIRECTION)?
            && !tangents.is_empty()
        {
            tangents.iter_mut().zip(&d).for_each(|(t, d)| *t += (w * *d).extend(0.0));
        }
    }
    if let Some(ns) = normals {
        ns.iter_mut().for_each(|v| *v = v.try_normalize().unwrap_or(Vec3::Z));
    }
    Ok(())
}

/// Each vertex's blended skinning matrix Σ wᵢ·Jᵢ over its `JOINTS_n`/`WEIGHTS_n` sets (weights
/// renormalised to sum 1; a vertex with none keeps `fallback`, the node's own transform).
/// Returns the matrices and how many vertices had no weight.
pub(crate) fn skin_matrices(
    ctx: &Ctx,
    at: &str,
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    joints: &[Mat4],
    fallback: Mat4,
) -> Result<(Vec<Mat4>, usize), SceneError> {
    use gltf::Semantic as S;
    let n = prim.get(&S::Positions).map_or(0, |a| a.count());
    let mut sum = vec![Mat4::ZERO; n];
    let mut total = vec![0.0f32; n];
    let mut set = 0;
    while let (Some(ja), Some(wa)) = (prim.get(&S::Joints(set)), prim.get(&S::Weights(set))) {
        let jf = format!("{at}.attributes.JOINTS_{set}");
        let wf = format!("{at}.attributes.WEIGHTS_{set}");
        accessors::check(ctx, &jf, &ja, &JOINTS, buffers)?;
        accessors::check(ctx, &wf, &wa, &WEIGHTS, buffers)?;
        for (f, a) in [(&jf, &ja), (&wf, &wa)] {
            if a.count() != n {
                return Err(ctx.invalid(f, format!("has {} elements but POSITION has {n}", a.count())));
            }
        }
        let j = accessors::read_f32(ctx, &jf, &ja, buffers)?;
        let w = accessors::read_f32(ctx, &wf, &wa, buffers)?;
        for v in 0..n {
            for c in 0..4 {
                let wt = w[v * 4 + c];
                if !(wt.is_finite() && wt >= 0.0) {
                    return Err(ctx.invalid(&wf, format!("vertex {v} has a negative or non-finite weight")));
                }
                if wt == 0.0 {
                    continue;
                }
                let ji = j[v * 4 + c] as usize;
                let m = joints.get(ji).ok_or_else(|| {
                    ctx.invalid(
                        &jf,
                        format!("vertex {v} names joint {ji}, but the skin has {} joints", joints.len()),
                    )
                })?;
                sum[v] += *m * wt;
                total[v] += wt;
            }
        }
        set += 1;
    }
    if set == 0 {
        return Err(ctx.invalid(
            at,
            "is drawn by a skinned node but has no JOINTS_0 and WEIGHTS_0 attributes (glTF 2.0 §3.7.3)",
        ));
    }
    let mut unweighted = 0;
    for (m, t) in sum.iter_mut().zip(&total) {
        if *t > 0.0 {
            *m *= 1.0 / *t;
        } else {
            *m = fallback;
            unweighted += 1;
        }
    }
    Ok((sum, unweighted))
}

/// Skins vertex data by per-vertex matrices: positions by the matrix, normals by its inverse
/// transpose, tangents by its linear part (handedness flipped where it mirrors); a triangle
/// whose corners are mostly mirrored has its winding reversed.
pub(crate) fn apply_skin(
    m: &[Mat4],
    positions: &mut [Vec3],
    normals: &mut [Vec3],
    tangents: &mut [Vec4],
    indices: &mut [u32],
) {
    let mut mirrored = vec![false; m.len()];
    for (i, mat) in m.iter().enumerate() {
        let lin = Mat3::from_mat4(*mat);
        let det = lin.determinant();
        mirrored[i] = det < 0.0;
        positions[i] = mat.transform_point3(positions[i]);
        if let Some(n) = normals.get_mut(i) {
            let nm = if det.abs() > f32::MIN_POSITIVE { lin.inverse().transpose() } else { lin };
            *n = (nm * *n).try_normalize().unwrap_or(Vec3::Z);
        }
        if let Some(t) = tangents.get_mut(i) {
            let x = (lin * t.truncate()).try_normalize().unwrap_or(Vec3::X);
            let sign = if det < 0.0 { -1.0 } else { 1.0 };
            *t = x.extend(if t.w < 0.0 { -sign } else { sign });
        }
    }
    for tri in indices.chunks_exact_mut(3) {
        if tri.iter().filter(|&&v| mirrored[v as usize]).count() >= 2 {
            tri.swap(1, 2);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(times: &[f32], values: &[f32], width: usize, interpolation: Interpolation) -> Keys {
        Keys { times: times.to_vec(), values: values.to_vec(), width, interpolation }
    }

    #[test]
    fn linear_keys_hold_their_ends_and_interpolate_between() {
        let k = keys(&[1.0, 2.0, 4.0], &[0.0, 10.0, 30.0], 1, Interpolation::Linear);
        assert_eq!(k.at(0.0, false), [0.0]);
        assert_eq!(k.at(1.5, false), [5.0]);
        assert_eq!(k.at(3.0, false), [20.0]);
        assert_eq!(k.at(2.0, false), [10.0]);
        assert_eq!(k.at(9.0, false), [30.0]);
        let s = keys(&[1.0, 2.0, 4.0], &[0.0, 10.0, 30.0], 1, Interpolation::Step);
        assert_eq!(s.at(1.99, false), [0.0]);
        assert_eq!(s.at(2.0, false), [10.0]);
        assert_eq!(s.at(3.9, false), [10.0]);
    }

    #[test]
    fn cubic_splines_are_hermite_with_tangents_scaled_by_the_interval() {
        // p(t) over [0, 2] from 0 to 1 with out-tangent 3 and in-tangent −1 (per second): the
        // Hermite basis with m0 = 2·3 and m1 = 2·(−1).
        let k = keys(&[0.0, 2.0], &[9.0, 0.0, 3.0, -1.0, 1.0, 7.0], 1, Interpolation::CubicSpline);
        for &t in &[0.0f32, 0.5, 1.0, 1.5, 2.0] {
            let u = t / 2.0;
            let want = (2.0 * u.powi(3) - 3.0 * u * u + 1.0) * 0.0
                + (u.powi(3) - 2.0 * u * u + u) * 6.0
                + (-2.0 * u.powi(3) + 3.0 * u * u) * 1.0
                + (u.powi(3) - u * u) * -2.0;
            assert!((k.at(t, false)[0] - want).abs() < 1e-6, "t {t}");
        }
        // At the keys, the values themselves (never the tangents).
        assert_eq!(k.at(0.0, false), [0.0]);
        assert_eq!(k.at(5.0, false), [1.0]);
    }

    #[test]
    fn rotations_slerp_along_the_shorter_arc() {
        let a = Quat::IDENTITY;
        let b = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        // The same rotation stored with the opposite sign must not go the long way round.
        let nb = -b;
        let k = keys(&[0.0, 1.0], &[a.x, a.y, a.z, a.w, nb.x, nb.y, nb.z, nb.w], 4, Interpolation::Linear);
        let q = Quat::from_slice(&k.at(0.5, true));
        let want = Quat::from_rotation_z(std::f32::consts::FRAC_PI_4);
        assert!(q.dot(want).abs() > 1.0 - 1e-6, "{q:?}");
        assert!((q.length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn skinning_blends_matrices_and_mirrors_windings() {
        let r = Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let t = Mat4::from_translation(Vec3::new(2.0, 0.0, 0.0));
        let m = vec![(r * 0.5 + t * 0.5), Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)), Mat4::IDENTITY];
        let mut p = vec![Vec3::X, Vec3::X, Vec3::Y];
        let mut n = vec![Vec3::X, Vec3::X, Vec3::Z];
        let mut tg = vec![Vec4::new(0.0, 1.0, 0.0, 1.0); 3];
        let mut idx = vec![0, 1, 2];
        apply_skin(&m, &mut p, &mut n, &mut tg, &mut idx);
        // Half of R·x = (0,1,0) and half of x + (2,0,0) = (3,0,0).
        assert!((p[0] - Vec3::new(1.5, 0.5, 0.0)).length() < 1e-6);
        assert!((p[1] - Vec3::new(-1.0, 0.0, 0.0)).length() < 1e-6);
        assert_eq!(n[1], Vec3::new(-1.0, 0.0, 0.0));
        assert_eq!(tg[1].w, -1.0);
        // One mirrored corner of three: the winding stays.
        assert_eq!(idx, [0, 1, 2]);
    }
}
