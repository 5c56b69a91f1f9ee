//! Loading a `.gltf` / `.glb` file into a [`Scene`].

use std::collections::{HashMap, HashSet};
use std::path::Path;

use glam::{Mat4, Vec3, Vec4};
use gltf::khr_lights_punctual::Kind;
use serde_json::Value;

use crate::context::Ctx;
use crate::error::SceneError;
use crate::extras::{self, SceneExtras};
use crate::pose;
use crate::primitive::Needs;
use crate::spec_gloss;
use crate::{
    AlphaMode, Camera, Emission, Filter, Light, LightKind, Material, Mesh, Sampler, Scene,
    SpectralReflectance, Texture, TextureRef, Wrap, draco, gltf_ext, instancing, meshopt_decode, primitive,
    uri,
};

/// The most triangles a scene may have after instancing and node flattening: a small hostile
/// file (one mesh referenced by many instances) must not exhaust memory.
pub const MAX_TRIANGLES: usize = 20_000_000;

/// Largest `.gltf`/`.glb` file, and largest external buffer (`.bin`), read (bytes). A scene at
/// [`MAX_TRIANGLES`] fits; the cap keeps a hostile reference (a huge or growing file) from
/// exhausting memory.
pub const MAX_FILE_BYTES: u64 = 1 << 30;
/// Largest encoded image file (PNG/JPEG) read for a texture (bytes).
pub const MAX_IMAGE_FILE_BYTES: u64 = 256 << 20;
/// Largest texture width or height, read from the image header before decoding.
pub const MAX_IMAGE_DIMENSION: u32 = 16384;
/// Largest decoded texture (bytes of RGBA8): 8192² (or 16384 × 4096).
pub const MAX_IMAGE_DECODED_BYTES: u64 = 256 << 20;

/// Largest light `intensity × max(color)` accepted (candela, lux for directional lights).
/// The sun gives about 1.2·10⁵ lux; far larger finite values only overflow the renderers' f32
/// arithmetic into black or NaN pixels.
pub const MAX_LIGHT_INTENSITY: f32 = 1.0e9;
/// Largest emissive component (`emissiveFactor × emissiveStrength`): radiance relative to the
/// default sky's 1, as generous as the environment's intensity cap.
pub const MAX_EMISSIVE: f32 = 1.0e6;

/// How a scene file may be loaded.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Let file references (buffers, images, CSV spectra, environment maps) leave the scene's
    /// folder: absolute paths, `..`, symlinks pointing elsewhere. Off by default, so a scene
    /// from elsewhere cannot read other files (`--allow-outside-scene-dir`).
    pub allow_outside_scene_dir: bool,
    /// The `KHR_materials_variants` variant to draw, by name (`--variant`); `None`: the
    /// primitives' own materials. A name the file does not have is an error listing those it has.
    pub variant: Option<String>,
    /// The animation to pose the scene by (`--animation`). `None` with a
    /// [`time`](Self::time): the first animation.
    pub animation: Option<AnimationRef>,
    /// The moment of the animation, in seconds (`--time`, default 0 when an animation is
    /// named). Without either, the scene is drawn at rest: its nodes' own transforms and morph
    /// weights, skins applied.
    pub time: Option<f64>,
}

/// An animation of a file, as a user names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AnimationRef {
    /// As `--animation` reads it: a name (exactly, then in any case), else an index.
    NameOrIndex(String),
    /// Its index in the file's `animations` (Python's `animation=2`), whatever the names.
    Index(usize),
}

/// Loads a glTF 2.0 file (`.gltf` with external or embedded buffers, or binary `.glb`).
///
/// Geometry is flattened to world space; spectral `extras` are resolved; errors name the file
/// and the glTF index or JSON field at fault. What was ignored or approximated is listed in
/// [`Scene::warnings`]. See `docs/scene-format.md`.
pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
    load_with(path, &LoadOptions::default())
}

/// [`load`] with options.
pub fn load_with(path: impl AsRef<Path>, opts: &LoadOptions) -> Result<Scene, SceneError> {
    let path = path.as_ref();
    let mut ctx = Ctx::file(path);
    ctx.allow_outside = opts.allow_outside_scene_dir;
    let bytes = color::input::read_regular(path, MAX_FILE_BYTES).map_err(|e| ctx.io(path, e))?;
    from_slice(&ctx, &bytes, opts)
}

/// Loads a glTF document held in memory; relative URIs resolve against `base_dir` when given
/// (and must stay inside it). `name` is used in messages in place of a path.
pub fn load_slice(name: &str, bytes: &[u8], base_dir: Option<&Path>) -> Result<Scene, SceneError> {
    load_slice_with(name, bytes, base_dir, &LoadOptions::default())
}

/// [`load_slice`] with options (a variant, an animation's moment; `allow_outside_scene_dir`
/// is not consulted: references stay inside `base_dir`).
pub fn load_slice_with(
    name: &str,
    bytes: &[u8],
    base_dir: Option<&Path>,
    opts: &LoadOptions,
) -> Result<Scene, SceneError> {
    let ctx = Ctx {
        path: name.into(),
        dir: base_dir.map(Path::to_path_buf),
        allow_outside: false,
        inputs: Vec::new().into(),
        stamps: Vec::new().into(),
    };
    from_slice(&ctx, bytes, opts)
}

/// The document's JSON as written (the `gltf` crate drops what it does not know, such as most
/// extension objects).
fn raw_json(ctx: &Ctx, bytes: &[u8]) -> Result<Value, SceneError> {
    let gltf_err = |e| SceneError::Gltf { path: ctx.path.clone(), cause: e };
    // The `gltf` crate subtracts the 12-byte header from the declared length unchecked (an
    // overflow panic in debug builds, found by crates/fuzz).
    if bytes.starts_with(b"glTF") {
        let declared = bytes.get(8..12).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if declared.is_none_or(|n| n < 12) {
            return Err(ctx.invalid("GLB header", "the declared length is shorter than the 12-byte header"));
        }
        // The crate reads only the declared length: bytes past it (a file cut and re-joined, or
        // two files concatenated) would be ignored without a word.
        if let Some(n) = declared
            && n as usize != bytes.len()
        {
            return Err(ctx.invalid(
                "GLB header",
                format!("the declared length is {n} bytes but the file has {}", bytes.len()),
            ));
        }
    }
    let json = if bytes.starts_with(b"glTF") {
        gltf::binary::Glb::from_slice(bytes).map_err(gltf_err)?.json.into_owned()
    } else if ctx.path.extension().is_some_and(|e| e.eq_ignore_ascii_case("glb"))
        && !bytes.trim_ascii_start().starts_with(b"{")
    {
        // Read as JSON, a damaged GLB would be reported as "expected value at line 1 column 1".
        return Err(ctx.invalid(
            "GLB header",
            "not a valid glTF 2.0 binary (GLB): it does not start with the 'glTF' magic",
        ));
    } else {
        bytes.to_vec()
    };
    serde_json::from_slice(&json).map_err(|e| gltf_err(gltf::Error::Deserialize(e)))
}

/// The typed document of `raw` (the file's JSON, or it with animated values written in):
/// without `KHR_animation_pointer`'s channels, which name no node (the `gltf` crate's typed parse
/// requires one of every channel), with the WebP and KTX2 sources filled in, checked and validated.
/// `file`: the file's bytes when `raw` is their JSON as written (the crate parses them itself).
fn document_of(ctx: &Ctx, raw: &Value, file: Option<&[u8]>) -> Result<gltf::Document, SceneError> {
    let gltf_err = |e| SceneError::Gltf { path: ctx.path.clone(), cause: e };
    let mut root: gltf::json::Root = match gltf_ext::without_pointer_channels(raw) {
        Some(cleaned) => {
            serde_json::from_value(cleaned).map_err(|e| gltf_err(gltf::Error::Deserialize(e)))?
        }
        None => match file {
            Some(bytes) => {
                gltf::Gltf::from_slice_without_validation(bytes).map_err(gltf_err)?.document.into_json()
            }
            None => serde_json::from_value(raw.clone()).map_err(|e| gltf_err(gltf::Error::Deserialize(e)))?,
        },
    };
    // Checked by `gltf_ext::precheck` against what this loader implements; the crate's own check
    // only knows the extensions it parses itself.
    root.extensions_required.clear();
    // The image extensions' indices are checked here, and a texture whose only images are in
    // them (no `source`, which the crate's validation requires) gets the preferred one as its
    // source; the loader prefers it anyway (`Loader::texture_image`).
    let images = root.images.len();
    for (i, t) in root.textures.iter_mut().enumerate() {
        let mut preferred = None;
        for (ext, what) in gltf_ext::IMAGE_EXTENSIONS {
            let Some(obj) = raw.pointer(&format!("/textures/{i}/extensions/{ext}")) else { continue };
            let at = format!("textures[{i}].extensions.{ext}.source");
            let w = match obj.get("source") {
                Some(v) => match v.as_u64().filter(|&w| (w as usize) < images) {
                    Some(w) => w as u32,
                    None => {
                        return Err(ctx.invalid(
                            at,
                            format!("{v} is not the index of one of the file's {images} images"),
                        ));
                    }
                },
                None => {
                    return Err(
                        ctx.invalid(at, format!("is missing (the extension names its {what} image there)"))
                    );
                }
            };
            preferred = preferred.or(Some(w));
        }
        if let Some(w) = preferred
            && raw.pointer(&format!("/textures/{i}/source")).is_none()
        {
            t.source = gltf::json::Index::new(w);
        }
    }
    precheck(ctx, &root)?;
    gltf::Document::from_json(root).map_err(gltf_err)
}

/// The typed document of `raw` without the crate's validation, for reading its buffers only.
fn unvalidated(ctx: &Ctx, raw: &Value) -> Result<gltf::Document, SceneError> {
    let cleaned = gltf_ext::without_pointer_channels(raw);
    let root: gltf::json::Root = serde_json::from_value(cleaned.unwrap_or_else(|| raw.clone()))
        .map_err(|e| SceneError::Gltf { path: ctx.path.clone(), cause: gltf::Error::Deserialize(e) })?;
    Ok(gltf::Document::from_json_without_validation(root))
}

pub(crate) fn from_slice(ctx: &Ctx, bytes: &[u8], opts: &LoadOptions) -> Result<Scene, SceneError> {
    let gltf_err = |e| SceneError::Gltf { path: ctx.path.clone(), cause: e };
    // Our checks of the JSON first: the `gltf` crate's typed parse would reject some of the same
    // problems (a wrong type in a sampler field) with a less helpful message.
    let raw = raw_json(ctx, bytes)?;
    gltf_ext::precheck(ctx, &raw)?;
    // Animation targets the `gltf` crate reads unchecked (it would panic).
    pose::check_targets(ctx, &raw)?;
    let blob = if bytes.starts_with(b"glTF") {
        gltf::binary::Glb::from_slice(bytes).map_err(gltf_err)?.bin.map(|b| b.into_owned())
    } else {
        None
    };
    // Draco-compressed accessors have no data until decoded, which the crate's validation
    // refuses: such a file's buffers are read from the unchecked document, and the decoded one
    // is validated.
    let compressed = draco::used(&raw);
    let document = if compressed { unvalidated(ctx, &raw)? } else { document_of(ctx, &raw, Some(bytes))? };
    let doc = &document;
    let mut warnings = gltf_ext::warnings(&raw);
    let variants = crate::variants::read(ctx, &raw, opts.variant.as_deref())?;
    warnings.extend(variants.unchosen_warning());
    let mut buffers = load_buffers(ctx, doc, blob.as_deref(), &raw)?;
    meshopt_decode::decode(ctx, &raw, &mut buffers)?;
    // KHR_draco_mesh_compression: the decoded geometry in a buffer of its own, the document's
    // accessors pointed at it.
    let (raw, document) = match draco::decode(ctx, &raw, &mut buffers)? {
        Some(decoded) => {
            let d = document_of(ctx, &decoded, None)?;
            (decoded, d)
        }
        None if compressed => {
            let d = document_of(ctx, &raw, Some(bytes))?;
            (raw, d)
        }
        None => (raw, document),
    };
    let doc = &document;
    let chosen = pose::choose(ctx, doc, opts.animation.as_ref(), opts.time, &buffers, &mut warnings)?;
    // KHR_animation_pointer: the chosen moment's values written into the document itself, which
    // is then read as if the file held them (materials, lights, cameras, nodes, weights).
    let patched = match chosen {
        Some(c) => pose::pointer_values(ctx, doc, &raw, &buffers, c, &mut warnings)?,
        None => None,
    };
    let (raw, document) = match patched {
        Some(p) => {
            let d = document_of(ctx, &p, None)?;
            (p, d)
        }
        None => (raw, document),
    };
    let doc = &document;
    let pose = pose::Pose::new(ctx, doc, &buffers, chosen, &mut warnings)?;
    let mut choices: Vec<(String, String)> = Vec::new();
    if let Some(v) = variants.chosen {
        choices.push(("variant".into(), variants.names[v].clone()));
    }
    choices.extend(chosen.map(|c| c.describe(doc)).into_iter().flatten());
    let gscene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| ctx.invalid("scenes", "the file has no scene to render"))?;
    let sx = scene_extras(ctx, doc, &gscene)?;

    let mut loader = Loader {
        ctx,
        doc,
        warnings: Vec::new(),
        raw: &raw,
        buffers: &buffers,
        textures: Vec::new(),
        tex_map: HashMap::new(),
        images: HashMap::new(),
        ktx2_srgb: HashMap::new(),
    };
    let mut materials = Vec::new();
    let mut needs = Vec::new();
    for m in doc.materials() {
        let (mat, need) = loader.material(&m)?;
        materials.push(mat);
        needs.push(need);
    }
    warnings.append(&mut loader.warnings);
    let default_material = materials.len();
    let mut uses_default = false;

    let mut meshes: Vec<Mesh> = Vec::new();
    let mut triangles = 0usize;
    let mut skipped_modes: HashSet<(usize, usize)> = HashSet::new();
    let mut lights = Vec::new();
    let mut camera = None;
    // Depth-first over the scene graph in file order; "first camera" means first in this order.
    // (node, parent's world transform, whether the parents are visible: KHR_node_visibility)
    let mut stack: Vec<(gltf::Node, Mat4, bool)> =
        gscene.nodes().map(|n| (n, Mat4::IDENTITY, true)).collect();
    stack.reverse();
    let mut seen = vec![false; doc.nodes().len()];
    let mut first_mesh_of_node: HashMap<usize, usize> = HashMap::new();
    // (index in `lights`, glTF light index, node it stands in for)
    let mut stand_ins: Vec<(usize, usize, usize)> = Vec::new();
    while let Some((node, parent, shown)) = stack.pop() {
        let at = format!("nodes[{}]", node.index());
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(ctx.invalid(at, "node is reached twice: the node hierarchy must be a tree"));
        }
        let world = parent * pose.local(node.index());
        if !world.is_finite() {
            return Err(ctx.invalid(at, "transform is not finite"));
        }
        // KHR_node_visibility: a hidden node hides its meshes and lights and its children's;
        // cameras stay.
        let visible = gltf_ext::node_visible(ctx, &raw, node.index())? && shown;
        if let Some(mesh) = node.mesh().filter(|_| visible) {
            let weights = pose.morph_weights(ctx, &node, &mesh)?;
            let joints = node.skin().map(|skin| pose.joint_matrices(ctx, &skin, &buffers)).transpose()?;
            let deform = pose::Deform {
                weights: &weights,
                joints: joints.as_deref(),
                fallback: world,
                unweighted: 0.into(),
            };
            // EXT_mesh_gpu_instancing: the mesh is drawn once per instance, each placed by its
            // own transform within the node's frame; without it, once at the node. A skinned
            // mesh comes out of its joints in world space, where the node plays no part.
            let instances = instancing::transforms(ctx, &raw, doc, node.index(), &buffers)?;
            let worlds: Vec<Mat4> = match (instances, &joints) {
                (_, Some(_)) => {
                    if raw
                        .pointer(&format!("/nodes/{}/extensions/EXT_mesh_gpu_instancing", node.index()))
                        .is_some()
                    {
                        warnings.push(format!(
                            "{at}: a skinned mesh is drawn once, where its joints place it; its EXT_mesh_gpu_instancing instances are ignored"
                        ));
                    }
                    vec![Mat4::IDENTITY]
                }
                (Some(instances), None) => instances.into_iter().map(|m| world * m).collect(),
                (None, None) => vec![world],
            };
            if let Some(bad) = worlds.iter().position(|w| !w.is_finite()) {
                return Err(ctx.invalid(&at, format!("the transform of instance {bad} is not finite")));
            }
            let first = meshes.len();
            for prim in mesh.primitives() {
                let pat = format!("meshes[{}].primitives[{}]", mesh.index(), prim.index());
                if !primitive::is_triangles(prim.mode()) {
                    if skipped_modes.insert((mesh.index(), prim.index())) {
                        warnings.push(format!(
                            "{pat}: mode {:?} (points or lines) is not drawn, having no area; skipped",
                            prim.mode()
                        ));
                    }
                    continue;
                }
                let mapped = variants.material(ctx, &raw, (mesh.index(), prim.index()), default_material)?;
                let mi = match mapped.or(prim.material().index()) {
                    Some(i) => i,
                    None => {
                        uses_default = true;
                        default_material
                    }
                };
                let need = needs.get(mi).cloned().unwrap_or_default();
                let local = primitive::build(ctx, &pat, &prim, &buffers, mi, &need, &deform)?;
                if local.indices.is_empty() {
                    // Fewer indices than one triangle: nothing to draw (the renderers had a mesh
                    // of no triangles to upload).
                    if skipped_modes.insert((mesh.index(), prim.index())) {
                        warnings.push(format!(
                            "{pat}: mode {:?} with {} index(es) makes no triangle; skipped",
                            prim.mode(),
                            prim.indices()
                                .map_or(prim.attributes().next().map_or(0, |(_, a)| a.count()), |a| a
                                    .count())
                        ));
                    }
                    continue;
                }
                let added = (local.indices.len() / 3).saturating_mul(worlds.len());
                triangles = triangles.saturating_add(added);
                if triangles > MAX_TRIANGLES {
                    return Err(ctx.invalid(
                        &at,
                        format!(
                            "{pat} drawn {} time(s) brings the scene to {triangles} triangles, more than the {MAX_TRIANGLES} this loader accepts",
                            worlds.len()
                        ),
                    ));
                }
                for w in &worlds {
                    let mut m = local.clone();
                    if joints.is_none() {
                        primitive::to_world(&mut m, *w);
                    }
                    if let Some(k) =
                        m.positions.iter().position(|p| p.abs().max_element() > crate::MAX_COORDINATE)
                    {
                        return Err(ctx.invalid(
                            &at,
                            format!(
                                "{pat}: vertex {k} lies beyond ±{:e} scene units once placed (the \
                                 node transforms applied), where the renderers' single precision fails; scale \
                                 the scene down",
                                crate::MAX_COORDINATE
                            ),
                        ));
                    }
                    meshes.push(m);
                }
            }
            if meshes.len() > first {
                first_mesh_of_node.insert(node.index(), first);
            }
            if deform.unweighted.get() > 0 {
                warnings.push(format!(
                    "{at}: {} skinned vertices have no joint weight (WEIGHTS_n all zero); they stay where the node places them",
                    deform.unweighted.get()
                ));
            }
        }
        if let (Some(cam), None) = (node.camera(), &camera) {
            let (c, warning) = camera_of(ctx, &cam, world)?;
            warnings.extend(warning);
            camera = Some((c, cam.index()));
        }
        if let Some(light) = node.light().filter(|_| visible) {
            let (l, stand_in) = light_of(ctx, &light, &node, world)?;
            if let Some(n) = stand_in {
                stand_ins.push((lights.len(), light.index(), n));
            }
            lights.push(l);
        }
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, world, visible));
        }
    }
    for (li, gl, node) in stand_ins {
        let f = format!("KHR_lights_punctual.lights[{gl}].extras.stands_in_for");
        let mesh = *first_mesh_of_node
            .get(&node)
            .ok_or_else(|| ctx.extras(&f, format!("node {node} is not a mesh node of the scene")))?;
        let emits = materials.get(meshes[mesh].material).is_some_and(|m| m.emissive.max_element() > 0.0);
        if !emits {
            return Err(ctx.extras(
                &f,
                format!("node {node}'s mesh does not emit, so there is nothing to stand in for"),
            ));
        }
        lights[li].stands_in_for = Some(mesh);
    }
    if meshes.is_empty() {
        // Both renderers would draw only the environment (or black) without saying why.
        warnings.push(
            "the scene has no triangles to draw (no mesh in its scene, or only points, lines and \
             primitives of fewer than three indices): only its environment, if any, is drawn"
                .into(),
        );
    }
    if uses_default {
        // glTF's default material: white, fully rough, dielectric, single-sided.
        materials.push(Material { name: "default".into(), double_sided: false, ..Material::default() });
    }
    let camera = match camera {
        Some((mut c, index)) => {
            warnings.extend(fit_clip_planes(&mut c, &meshes, &format!("cameras[{index}]")));
            warnings.extend(clipped_whole(&c, &meshes, &format!("cameras[{index}]")));
            c
        }
        None => Camera::framing(crate::framing::bounds(&meshes)),
    };
    let mut scene = Scene {
        warnings,
        source: ctx.path.display().to_string(),
        meshes,
        materials,
        textures: loader.textures,
        lights,
        camera,
        spectral: sx.spectral,
        water: sx.water,
        environment: sx.environment,
        medium: sx.medium,
        inputs: ctx.inputs.take(),
        input_stamps: ctx.stamps.take(),
        choices,
        animation_end: pose.animation_end.map(f64::from),
        origin: glam::DVec3::ZERO,
    };
    if scene.water.is_some() && scene.medium.is_some() {
        return Err(ctx.extras(
            "extras.medium",
            "a scene has either water (extras.water) or an RGB medium (extras.medium), not both",
        ));
    }
    crate::sky::sync(&mut scene).map_err(|m| ctx.extras("water.sky", m))?;
    scene.recentre();
    Ok(scene)
}

/// Checks what the `gltf` crate assumes without checking (it would panic): the POSITION accessor
/// index of each primitive (used by its validation), the projection object named by each
/// camera's `type`, and the `uri` or `bufferView` + `mimeType` of each image.
fn precheck(ctx: &Ctx, root: &gltf::json::Root) -> Result<(), SceneError> {
    use gltf::json::camera::Type;
    use gltf::json::validation::Checked;
    for (i, c) in root.cameras.iter().enumerate() {
        let ok = match c.type_ {
            Checked::Valid(Type::Perspective) => c.perspective.is_some(),
            Checked::Valid(Type::Orthographic) => c.orthographic.is_some(),
            Checked::Invalid => true, // validation reports it
        };
        if !ok {
            return Err(ctx.invalid(format!("cameras[{i}]"), "the object named by `type` is missing"));
        }
    }
    for (i, im) in root.images.iter().enumerate() {
        match (&im.buffer_view, &im.uri, &im.mime_type) {
            (Some(_), _, Some(_)) | (None, Some(_), _) => {}
            (Some(_), _, None) => {
                return Err(ctx.invalid(format!("images[{i}]"), "an image in a bufferView needs a mimeType"));
            }
            (None, None, _) => {
                return Err(ctx.invalid(format!("images[{i}]"), "has neither uri nor bufferView"));
            }
        }
    }
    for (mi, m) in root.meshes.iter().enumerate() {
        for (pi, p) in m.primitives.iter().enumerate() {
            if let Some(a) = p.attributes.get(&Checked::Valid(gltf::Semantic::Positions))
                && a.value() >= root.accessors.len()
            {
                return Err(ctx.invalid(
                    format!("meshes[{mi}].primitives[{pi}].attributes.POSITION"),
                    format!(
                        "accessor index {} is out of range ({} accessors)",
                        a.value(),
                        root.accessors.len()
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn load_buffers(
    ctx: &Ctx,
    doc: &gltf::Document,
    blob: Option<&[u8]>,
    raw: &Value,
) -> Result<Vec<Vec<u8>>, SceneError> {
    doc.buffers()
        .map(|b| {
            let at = format!("buffers[{}]", b.index());
            if let Some(len) = meshopt_decode::fallback_len(raw, b.index()) {
                // Filled by decoding the meshopt-compressed views that point into it.
                if len > meshopt_decode::MAX_FALLBACK_BYTES {
                    return Err(ctx.invalid(
                        format!("{at}.byteLength"),
                        format!(
                            "{len} bytes of decompressed data is more than this loader accepts ({} bytes)",
                            meshopt_decode::MAX_FALLBACK_BYTES
                        ),
                    ));
                }
                return Ok(vec![0; len as usize]);
            }
            let data = match b.source() {
                gltf::buffer::Source::Bin => blob
                    .ok_or_else(|| ctx.invalid(&at, "refers to the GLB binary chunk, but the file has none"))?
                    .to_vec(),
                gltf::buffer::Source::Uri(u) => uri::read(ctx, &format!("{at}.uri"), u, MAX_FILE_BYTES)?.0,
            };
            if data.len() < b.length() {
                return Err(ctx.invalid(
                    at,
                    format!("has {} bytes but declares byteLength {}", data.len(), b.length()),
                ));
            }
            Ok(data)
        })
        .collect()
}

/// Merges `extras` of the asset, the root and the chosen scene; a key given in two places is
/// an error, since which one should win is not obvious.
fn scene_extras(ctx: &Ctx, doc: &gltf::Document, scene: &gltf::Scene) -> Result<SceneExtras, SceneError> {
    let root = doc.as_json();
    let sources = [
        (
            "asset".to_string(),
            extras::object(ctx, "asset", &root.asset.extras)?
                .map(|m| extras::without_metadata(m, extras::SCENE_KEYS)),
        ),
        ("root".to_string(), extras::object(ctx, "root", &root.extras)?),
        (
            format!("scenes[{}]", scene.index()),
            extras::object(ctx, &format!("scenes[{}]", scene.index()), scene.extras())?,
        ),
    ];
    let mut out = SceneExtras::default();
    let mut owner: HashMap<String, String> = HashMap::new();
    for (at, map) in sources {
        let Some(map) = map else { continue };
        for k in map.keys() {
            if let Some(prev) = owner.insert(k.clone(), at.clone()) {
                return Err(ctx.extras(
                    format!("{at}.extras.{k}"),
                    format!("also given in {prev}.extras; give it once"),
                ));
            }
        }
        extras::scene(ctx, &at, &map, &mut out)?;
    }
    Ok(out)
}

/// The camera of `cam` at node transform `world`, and a warning when it had to be changed.
fn camera_of(ctx: &Ctx, cam: &gltf::Camera, world: Mat4) -> Result<(Camera, Option<String>), SceneError> {
    let at = format!("cameras[{}]", cam.index());
    // A camera's frame is rigid; drop any scale the node hierarchy carries. A zero scale leaves
    // no rotation to recover (the image would silently be black).
    let (scale, rot, pos) = world.to_scale_rotation_translation();
    if !(scale.abs().min_element() > 1e-12 && rot.is_finite() && rot.length() > 0.5) {
        return Err(ctx.invalid(
            at,
            "the camera's node transform is degenerate (a scale of 0 somewhere in its hierarchy), so it has no direction",
        ));
    }
    if pos.abs().max_element() > crate::MAX_COORDINATE {
        return Err(ctx.invalid(
            at,
            format!(
                "the camera lies beyond ±{:e} scene units, where the renderers' single precision fails",
                crate::MAX_COORDINATE
            ),
        ));
    }
    let transform = Mat4::from_rotation_translation(rot.normalize(), pos);
    let p = match cam.projection() {
        gltf::camera::Projection::Perspective(p) => p,
        gltf::camera::Projection::Orthographic(o) => {
            let (xmag, ymag, znear, zfar) = (o.xmag(), o.ymag(), o.znear(), o.zfar());
            let (lo, hi) = crate::ORTHO_MAG_RANGE;
            if !([xmag, ymag].iter().all(|m| (lo..=hi).contains(&m.abs()))) {
                return Err(ctx.invalid(
                    format!("{at}.orthographic"),
                    format!(
                        "|xmag| and |ymag| must be between {lo:e} and {hi:e} scene units, got {xmag}, {ymag}"
                    ),
                ));
            }
            if !((0.0..crate::MAX_CLIP_DISTANCE).contains(&znear) && zfar.is_finite() && zfar > znear) {
                return Err(ctx.invalid(
                    format!("{at}.orthographic"),
                    format!(
                        "needs 0 ≤ znear < zfar, finite, znear below {:e}, got znear {znear}, zfar {zfar}",
                        crate::MAX_CLIP_DISTANCE
                    ),
                ));
            }
            let warning = (xmag < 0.0 || ymag < 0.0).then(|| {
                format!("{at}: negative xmag/ymag ({xmag}, {ymag}) would mirror the image; drawn unmirrored")
            });
            let (xmag, ymag) = (xmag.abs(), ymag.abs());
            let camera = Camera {
                transform,
                yfov: crate::framing::DEFAULT_YFOV,
                znear,
                zfar,
                aspect: Some(xmag / ymag),
                ortho: Some((xmag, ymag)),
            };
            return Ok((camera, warning));
        }
    };
    let (yfov, znear) = (p.yfov(), p.znear());
    if !((crate::MIN_YFOV..std::f32::consts::PI).contains(&yfov) && znear > 0.0 && znear.is_finite()) {
        return Err(ctx.invalid(
            at,
            format!("needs {:e} ≤ yfov < π and znear > 0, got yfov {yfov}, znear {znear}", crate::MIN_YFOV),
        ));
    }
    if znear >= crate::MAX_CLIP_DISTANCE {
        return Err(ctx.invalid(
            at,
            format!(
                "znear {znear:e} clips everything: nothing in a scene lies that far (coordinates within ±{:e})",
                crate::MAX_COORDINATE
            ),
        ));
    }
    let zfar = p.zfar().unwrap_or(1.0e4);
    if zfar.partial_cmp(&znear) != Some(std::cmp::Ordering::Greater) {
        return Err(ctx.invalid(at, format!("zfar {zfar} must exceed znear {znear}")));
    }
    let aspect = p.aspect_ratio();
    if aspect.is_some_and(|a| !(a > 0.0 && a.is_finite())) {
        return Err(ctx.invalid(at, "aspectRatio must be positive"));
    }
    Ok((Camera { ortho: None, transform, yfov, znear, zfar, aspect }, None))
}

/// The far plane both renderers clip at, where the file's cannot be drawn as it is: beyond
/// [`crate::MAX_CLIP_DISTANCE`] (nothing can lie so far: it is drawn there), and for a
/// perspective camera whose znear is below zfar × [`crate::MIN_NEAR_FAR_RATIO`], more than a
/// depth buffer resolves, at the scene's farthest point (or znear / that ratio, if farther), so
/// that the near plane need not move. Nothing that lies before the file's far plane is lost
/// then, and no warning is due; where the scene reaches farther than a depth buffer allows, the
/// near plane moves out instead, with a warning (`at` names the camera).
fn fit_clip_planes(camera: &mut Camera, meshes: &[crate::Mesh], at: &str) -> Option<String> {
    camera.zfar = camera.zfar.min(crate::MAX_CLIP_DISTANCE);
    if camera.ortho.is_some() || camera.clip_near() <= camera.znear {
        return None;
    }
    let eye = camera.position();
    let reach = crate::framing::bounds(meshes).map_or(0.0, |(lo, hi)| {
        (0..8)
            .map(|i| Vec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2]))
            .map(|c| c.distance(eye))
            .fold(0.0f32, f32::max)
    });
    // A margin for the rounding of depth near the far plane.
    let fitted = (reach * 1.01).max(camera.znear / crate::MIN_NEAR_FAR_RATIO);
    let zfar = camera.zfar;
    camera.zfar = zfar.min(fitted);
    (camera.clip_near() > camera.znear).then(|| {
        format!(
            "{at}: znear {} is below {:e} × the distance to the scene's farthest point ({}), more than a \
             depth buffer resolves; both renderers clip at {}",
            short(camera.znear),
            crate::MIN_NEAR_FAR_RATIO,
            short(camera.zfar),
            short(camera.clip_near())
        )
    })
}

/// A warning where the camera's clip planes leave out the whole scene: every point of its
/// bounding box nearer than the near plane or farther than the far one (a scene shrunk by a
/// node's scale keeps its camera's clip planes, which glTF does not scale: the frame was the
/// background alone, without a word).
fn clipped_whole(camera: &Camera, meshes: &[crate::Mesh], at: &str) -> Option<String> {
    let (lo, hi) = crate::framing::bounds(meshes)?;
    let view = camera.transform.inverse();
    let depths = (0..8).map(|i| {
        let c = Vec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][i >> 1 & 1], [lo.z, hi.z][i >> 2]);
        -view.transform_point3(c).z
    });
    let (near, far) = depths.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), d| (a.min(d), b.max(d)));
    if far < camera.clip_near() {
        Some(format!(
            "{at}: every surface lies nearer than the near plane (znear {}; the scene reaches {} along the view): nothing is drawn",
            short(camera.clip_near()),
            short(far)
        ))
    } else if near > camera.zfar {
        Some(format!(
            "{at}: every surface lies beyond the far plane (zfar {}; the scene starts at {} along the view): nothing is drawn",
            short(camera.zfar),
            short(near)
        ))
    } else {
        None
    }
}

/// A distance for a message: four decimals where that reads well, else four digits and an
/// exponent.
fn short(x: f32) -> String {
    if x == 0.0 || (1e-3..1e5).contains(&x.abs()) {
        let s = format!("{x:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{x:.3e}")
    }
}

fn light_of(
    ctx: &Ctx,
    l: &gltf::khr_lights_punctual::Light,
    node: &gltf::Node,
    world: Mat4,
) -> Result<(Light, Option<usize>), SceneError> {
    let at = format!("KHR_lights_punctual.lights[{}]", l.index());
    let position = world.transform_point3(Vec3::ZERO);
    if position.abs().max_element() > crate::MAX_COORDINATE {
        return Err(ctx.invalid(
            format!("nodes[{}]", node.index()),
            format!(
                "{at} lies beyond ±{:e} scene units, where the renderers' single precision fails",
                crate::MAX_COORDINATE
            ),
        ));
    }
    let direction = world.transform_vector3(-Vec3::Z).try_normalize().ok_or_else(|| {
        ctx.invalid(format!("nodes[{}]", node.index()), "light node transform collapses its direction")
    })?;
    let range = l.range();
    if let Some(r) = range
        && !(r > 0.0 && r.is_finite())
    {
        return Err(ctx.invalid(
            format!("{at}.range"),
            format!("must be greater than 0 (KHR_lights_punctual), got {r}"),
        ));
    }
    let kind = match l.kind() {
        Kind::Point => LightKind::Point { position, range },
        Kind::Directional => LightKind::Directional { direction },
        Kind::Spot { inner_cone_angle, outer_cone_angle } => {
            if !(0.0 <= inner_cone_angle
                && inner_cone_angle < outer_cone_angle
                && outer_cone_angle <= std::f32::consts::FRAC_PI_2)
            {
                return Err(ctx.invalid(
                    at,
                    format!("spot cone angles must satisfy 0 ≤ inner < outer ≤ π/2, got {inner_cone_angle}, {outer_cone_angle}"),
                ));
            }
            LightKind::Spot {
                position,
                direction,
                inner_cone: inner_cone_angle,
                outer_cone: outer_cone_angle,
                range,
            }
        }
    };
    let rgb = Vec3::from(l.color());
    let intensity = l.intensity();
    if !(rgb.is_finite() && rgb.min_element() >= 0.0 && intensity.is_finite() && intensity >= 0.0) {
        return Err(ctx.invalid(at, "color and intensity must be finite and non-negative"));
    }
    if rgb.max_element() * intensity > MAX_LIGHT_INTENSITY {
        return Err(ctx.invalid(
            format!("{at}.intensity"),
            format!(
                "intensity × color is {:e}; at most {MAX_LIGHT_INTENSITY:e} is accepted",
                rgb.max_element() * intensity
            ),
        ));
    }
    let x = match extras::object(ctx, &at, l.extras())? {
        Some(map) => extras::light(ctx, &at, &map)?,
        None => extras::LightExtras::default(),
    };
    let emission = Emission::new(rgb, intensity, x.spectrum.as_ref())
        .map_err(|m| ctx.extras(format!("{at}.extras.spectrum"), m))?;
    let name = l.name().or(node.name()).map_or_else(|| format!("light {}", l.index()), str::to_string);
    // `stands_in_for` holds the node index until the traversal has numbered the meshes.
    Ok((Light { name, kind, emission, stands_in_for: None }, x.stands_in_for_node))
}

/// Material and texture conversion, with textures shared between materials and decoded once.
struct Loader<'a> {
    ctx: &'a Ctx,
    doc: &'a gltf::Document,
    /// What the materials lose or approximate, for [`Scene::warnings`].
    warnings: Vec<String>,
    /// The document's JSON, for extension objects the `gltf` crate does not parse.
    raw: &'a Value,
    buffers: &'a [Vec<u8>],
    textures: Vec<Texture>,
    /// (glTF texture index, sRGB?) → index in `textures`. The sampler belongs to the glTF
    /// texture, so it is part of what is shared.
    tex_map: HashMap<(usize, bool), usize>,
    /// glTF image index → decoded RGBA8.
    images: HashMap<usize, (u32, u32, Vec<u8>)>,
    /// glTF image index → whether a KTX2 image's data format descriptor says sRGB (true) or
    /// linear (false); PNG and JPEG say nothing the loader reads.
    ktx2_srgb: HashMap<usize, bool>,
}

fn wrap(w: gltf::texture::WrappingMode) -> Wrap {
    use gltf::texture::WrappingMode as W;
    match w {
        W::ClampToEdge => Wrap::ClampToEdge,
        W::MirroredRepeat => Wrap::MirroredRepeat,
        W::Repeat => Wrap::Repeat,
    }
}

/// A glTF sampler; absent filters get glTF's usual defaults (linear, mipmapped).
fn sampler_of(s: &gltf::texture::Sampler) -> Sampler {
    use gltf::texture::{MagFilter, MinFilter};
    let mag = match s.mag_filter() {
        Some(MagFilter::Nearest) => Filter::Nearest,
        _ => Filter::Linear,
    };
    let (min, mipmaps) = match s.min_filter() {
        None => (Filter::Linear, true),
        Some(MinFilter::Nearest) => (Filter::Nearest, false),
        Some(MinFilter::Linear) => (Filter::Linear, false),
        Some(MinFilter::NearestMipmapNearest | MinFilter::NearestMipmapLinear) => (Filter::Nearest, true),
        Some(MinFilter::LinearMipmapNearest | MinFilter::LinearMipmapLinear) => (Filter::Linear, true),
    };
    Sampler { wrap_s: wrap(s.wrap_s()), wrap_t: wrap(s.wrap_t()), mag, min, mipmaps }
}

impl Loader<'_> {
    /// The material and what it asks of the primitives that use it.
    fn material(&mut self, m: &gltf::Material) -> Result<(Material, Needs), SceneError> {
        let idx = m.index().expect("document materials have indices");
        let at = format!("materials[{idx}]");
        let pbr = m.pbr_metallic_roughness();
        let alpha_mode = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
            gltf::material::AlphaMode::Mask => {
                let cutoff = m.alpha_cutoff().unwrap_or(0.5);
                if !(cutoff >= 0.0 && cutoff.is_finite()) {
                    return Err(self.ctx.invalid(
                        format!("{at}.alphaCutoff"),
                        format!("must be a finite number ≥ 0, got {cutoff}"),
                    ));
                }
                AlphaMode::Mask { cutoff }
            }
        };
        // The extension's strength is a non-negative multiplier: a negative one was refused as
        // "factors must be finite (and emissive non-negative)" naming no field, and accepted
        // silently beside an emissive factor of zero (found by a sweep).
        if let Some(k) = m.emissive_strength()
            && !(k.is_finite() && k >= 0.0)
        {
            return Err(self.ctx.invalid(
                format!("{at}.extensions.KHR_materials_emissive_strength.emissiveStrength"),
                format!("{k} is not a finite number ≥ 0"),
            ));
        }
        let mut out = Material {
            name: m.name().map_or_else(|| format!("material {idx}"), str::to_string),
            base_color: Vec4::from(pbr.base_color_factor()),
            metallic: pbr.metallic_factor(),
            roughness: pbr.roughness_factor(),
            emissive: Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
            alpha_mode,
            double_sided: m.double_sided(),
            ..Material::default()
        };
        let raw = self.raw.pointer(&format!("/materials/{idx}"));
        let info = |path: &str| raw.and_then(|r| r.pointer(path));
        // An extension's value is an object: one given as anything else (an array, a number)
        // was ignored without a word (KHR_materials_transmission: [..] drew the glass opaque).
        if let Some(exts) = info("/extensions") {
            let Some(map) = exts.as_object() else {
                return Err(self.ctx.invalid(format!("{at}.extensions"), "must be an object"));
            };
            if let Some((name, _)) = map.iter().find(|(_, v)| !v.is_object()) {
                return Err(self.ctx.invalid(format!("{at}.extensions.{name}"), "must be an object"));
            }
        }
        out.unlit = info("/extensions/KHR_materials_unlit").is_some();
        if let Some(t) = pbr.base_color_texture() {
            out.base_color_texture = Some(self.texture(
                &format!("{at}.pbrMetallicRoughness.baseColorTexture"),
                t.texture(),
                t.tex_coord(),
                true,
                info("/pbrMetallicRoughness/baseColorTexture"),
            )?);
        }
        if let Some(t) = pbr.metallic_roughness_texture() {
            out.metallic_roughness_texture = Some(self.texture(
                &format!("{at}.pbrMetallicRoughness.metallicRoughnessTexture"),
                t.texture(),
                t.tex_coord(),
                false,
                info("/pbrMetallicRoughness/metallicRoughnessTexture"),
            )?);
        }
        if let Some(t) = m.normal_texture() {
            out.normal_texture = Some(self.texture(
                &format!("{at}.normalTexture"),
                t.texture(),
                t.tex_coord(),
                false,
                info("/normalTexture"),
            )?);
            out.normal_scale = t.scale();
        }
        if let Some(t) = m.occlusion_texture() {
            out.occlusion_texture = Some(self.texture(
                &format!("{at}.occlusionTexture"),
                t.texture(),
                t.tex_coord(),
                false,
                info("/occlusionTexture"),
            )?);
            out.occlusion_strength = t.strength().clamp(0.0, 1.0);
        }
        if let Some(t) = m.emissive_texture() {
            out.emissive_texture = Some(self.texture(
                &format!("{at}.emissiveTexture"),
                t.texture(),
                t.tex_coord(),
                true,
                info("/emissiveTexture"),
            )?);
        }
        if let Some(sg) = info("/extensions/KHR_materials_pbrSpecularGlossiness") {
            self.spec_gloss(&at, sg, &mut out)?;
        }
        if let Some(ir) = info("/extensions/KHR_materials_iridescence") {
            out.iridescence = self.iridescence(&at, ir)?;
        }
        if let Some(cc) = info("/extensions/KHR_materials_clearcoat") {
            out.clearcoat = self.clearcoat(&at, cc)?;
        }
        if let Some(sp) = info("/extensions/KHR_materials_specular") {
            out.specular = self.specular(&at, sp)?;
        }
        if let Some(sh) = info("/extensions/KHR_materials_sheen") {
            out.sheen = self.sheen(&at, sh)?;
        }
        if let Some(an) = info("/extensions/KHR_materials_anisotropy") {
            out.anisotropy = self.anisotropy(&at, an)?;
        }
        if let Some(dt) = info("/extensions/KHR_materials_diffuse_transmission") {
            out.diffuse_transmission = self.diffuse_transmission(&at, dt)?;
        }
        if let Some(v) = info("/extensions/KHR_materials_ior").and_then(|e| e.get("ior")) {
            out.ior = match v.as_f64() {
                Some(x) if x.is_finite() && (1.0..=f64::from(crate::MAX_IOR)).contains(&x) => x as f32,
                // The extension's compatibility mode: an infinite index, Fresnel term 1.
                Some(0.0) => crate::MAX_IOR,
                _ => {
                    return Err(self.ctx.invalid(
                        format!("{at}.extensions.KHR_materials_ior.ior"),
                        format!(
                            "{v} is not an index of refraction in [1, {}] (or 0, an infinite one)",
                            crate::MAX_IOR
                        ),
                    ));
                }
            };
        }
        let volume = info("/extensions/KHR_materials_volume");
        let dispersion = info("/extensions/KHR_materials_dispersion");
        if let Some(tr) = info("/extensions/KHR_materials_transmission") {
            out.transmission = self.transmission(&at, tr, volume, dispersion)?;
        } else if volume.is_some() || dispersion.is_some() {
            // Without transmission they change nothing here, but they are read and validated
            // as documented (a negative dispersion or thickness was accepted silently; found
            // by a sweep).
            self.transmission(&at, &Value::Object(Default::default()), volume, dispersion)?;
            // A diffuse transmission would let light into this volume, which only a
            // see-through material keeps (`Transmission::volume`): said, not silently thin.
            let thick = volume
                .and_then(|v| v.get("thicknessFactor"))
                .and_then(Value::as_f64)
                .is_some_and(|t| t > 0.0);
            if thick && out.diffuse_transmission.is_some() && !out.unlit {
                self.warnings.push(format!(
                    "{at} ('{}'): its KHR_materials_volume is not kept without KHR_materials_transmission; \
                     its diffuse transmission is drawn as a thin sheet, without the volume's absorption",
                    out.name
                ));
            }
        }
        let values = [
            out.base_color.to_array().as_slice(),
            &[out.metallic, out.roughness, out.normal_scale],
            &out.emissive.to_array(),
        ]
        .concat();
        if values.iter().any(|v| !v.is_finite()) || out.emissive.min_element() < 0.0 {
            return Err(self.ctx.invalid(&at, "factors must be finite (and emissive non-negative)"));
        }
        // glTF allows any scale; past this the renderers' normalize((n.xy·scale, n.z)) squares
        // past f32 (−1e30 made NaN normals), and no bump needs more than a few.
        if out.normal_scale.abs() > crate::MAX_NORMAL_SCALE {
            return Err(self.ctx.invalid(
                format!("{at}.normalTexture.scale"),
                format!("{} is outside ±{} (typical: 0–2)", out.normal_scale, crate::MAX_NORMAL_SCALE),
            ));
        }
        // glTF 2.0 gives these factors the range [0, 1]; outside it they are not materials
        // (a negative albedo, a roughness of 5), and the renderers' results are meaningless.
        let unit = [
            (
                "pbrMetallicRoughness.baseColorFactor",
                out.base_color.min_element(),
                out.base_color.max_element(),
            ),
            ("pbrMetallicRoughness.metallicFactor", out.metallic, out.metallic),
            ("pbrMetallicRoughness.roughnessFactor", out.roughness, out.roughness),
        ];
        for (field, lo, hi) in unit {
            if !(0.0..=1.0).contains(&lo) || !(0.0..=1.0).contains(&hi) {
                return Err(self.ctx.invalid(
                    format!("{at}.{field}"),
                    format!("must lie in [0, 1] (glTF 2.0), got values from {lo} to {hi}"),
                ));
            }
        }
        if out.emissive.max_element() > MAX_EMISSIVE {
            return Err(self.ctx.invalid(
                format!("{at}.emissiveFactor"),
                format!(
                    "emissiveFactor × emissiveStrength reaches {:e}; at most {MAX_EMISSIVE:e} is accepted",
                    out.emissive.max_element()
                ),
            ));
        }
        // The sheen extension excludes unlit and specular-glossiness materials. Dropped (after
        // its values and textures were checked) before the UV sets are gathered, so that a
        // texture nothing draws asks no TEXCOORD_1 of the meshes.
        // The anisotropy extension excludes the same two (it extends the metallic-roughness
        // specular lobe, which neither has).
        let excluded = if out.unlit {
            Some("an unlit material (KHR_materials_unlit), which reflects nothing")
        } else if info("/extensions/KHR_materials_pbrSpecularGlossiness").is_some() {
            Some("a specular-glossiness material (KHR_materials_pbrSpecularGlossiness)")
        } else {
            None
        };
        if let Some(with) = excluded {
            for (ext, on) in [
                ("KHR_materials_sheen", out.sheen.is_some()),
                ("KHR_materials_anisotropy", out.anisotropy.is_some()),
                ("KHR_materials_diffuse_transmission", out.diffuse_transmission.is_some()),
            ] {
                if on {
                    self.warnings.push(format!(
                        "{at} ('{}'): {ext} is ignored on {with}; the extension excludes the two",
                        out.name
                    ));
                }
            }
            out.sheen = None;
            out.anisotropy = None;
            out.diffuse_transmission = None;
        }
        let cc_tex =
            |f: fn(&crate::clearcoat::Clearcoat) -> Option<TextureRef>| out.clearcoat.as_ref().and_then(f);
        let sp_tex =
            |f: fn(&crate::specular::Specular) -> Option<TextureRef>| out.specular.as_ref().and_then(f);
        let sh_tex = |f: fn(&crate::sheen::Sheen) -> Option<TextureRef>| out.sheen.as_ref().and_then(f);
        let named = [
            ("pbrMetallicRoughness.baseColorTexture", &out.base_color_texture),
            ("pbrMetallicRoughness.metallicRoughnessTexture", &out.metallic_roughness_texture),
            ("normalTexture", &out.normal_texture),
            ("occlusionTexture", &out.occlusion_texture),
            ("emissiveTexture", &out.emissive_texture),
            ("extensions.KHR_materials_clearcoat.clearcoatTexture", &cc_tex(|c| c.texture)),
            (
                "extensions.KHR_materials_clearcoat.clearcoatRoughnessTexture",
                &cc_tex(|c| c.roughness_texture),
            ),
            ("extensions.KHR_materials_clearcoat.clearcoatNormalTexture", &cc_tex(|c| c.normal_texture)),
            ("extensions.KHR_materials_specular.specularTexture", &sp_tex(|s| s.texture)),
            ("extensions.KHR_materials_specular.specularColorTexture", &sp_tex(|s| s.color_texture)),
            ("extensions.KHR_materials_sheen.sheenColorTexture", &sh_tex(|s| s.color_texture)),
            ("extensions.KHR_materials_sheen.sheenRoughnessTexture", &sh_tex(|s| s.roughness_texture)),
            (
                "extensions.KHR_materials_anisotropy.anisotropyTexture",
                &out.anisotropy.as_ref().and_then(|a| a.texture),
            ),
            (
                "extensions.KHR_materials_diffuse_transmission.diffuseTransmissionTexture",
                &out.diffuse_transmission.as_ref().and_then(|d| d.texture),
            ),
            (
                "extensions.KHR_materials_diffuse_transmission.diffuseTransmissionColorTexture",
                &out.diffuse_transmission.as_ref().and_then(|d| d.color_texture),
            ),
        ];
        // The coat's normal map is oriented by the same tangents as the base's (the extension
        // asks both to share their UV set); tangents are made for it when the base has none, and
        // for an anisotropy's direction.
        let needs = Needs {
            tangents: out.tangent_need(),
            set1_user: named
                .iter()
                .find(|(_, t)| t.is_some_and(|t| t.tex_coord == 1))
                .map(|(f, _)| format!("{at}.{f}")),
        };
        if out.unlit {
            // KHR_materials_unlit: the base colour is all the surface shows; its emission would
            // otherwise be added to it and make it a light source.
            out.emissive = Vec3::ZERO;
            out.emissive_texture = None;
            // The extensions exclude a coat or a specular on an unlit material, which reflects
            // nothing.
            out.clearcoat = None;
            out.specular = None;
        }
        if out.specular.is_some() && (out.iridescence.is_some() || out.transmission.is_some()) {
            let with = if out.iridescence.is_some() {
                "a thin film (KHR_materials_iridescence)"
            } else {
                "a transmission (KHR_materials_transmission)"
            };
            self.warnings.push(format!(
                "{at} ('{}'): KHR_materials_specular is ignored on a material with {with}; its reflection comes from its index of refraction alone",
                out.name
            ));
            out.specular = None;
        }
        let Some(map) = extras::object(self.ctx, &at, m.extras())? else { return Ok((out, needs)) };
        let x = extras::material(self.ctx, &at, &map)?;
        if matches!(x.reflectance, Some(SpectralReflectance::Palette(_))) && out.base_color_texture.is_none()
        {
            return Err(self.ctx.extras(
                format!("{at}.extras.reflectance_palette"),
                "a palette is keyed by base-colour texel values, but the material has no baseColorTexture",
            ));
        }
        out.spectral = x.reflectance;
        if let Some(shape) = x.emission {
            let f = format!("{at}.extras.emission");
            if out.emissive_texture.is_some() {
                return Err(self
                    .ctx
                    .extras(f, "a spectral emission cannot be combined with an emissiveTexture"));
            }
            if out.emissive == Vec3::ZERO {
                // An unlit material's factor was dropped above: say so, not that the file's
                // factor is zero (found by a sweep).
                let why = if out.unlit {
                    "the material is unlit (KHR_materials_unlit), which shows its base colour and no emission, so the spectrum would emit nothing"
                } else {
                    "the material's emissiveFactor is zero, so the spectrum would emit nothing"
                };
                return Err(self.ctx.extras(f, why));
            }
            let e = Emission::new(out.emissive, 1.0, Some(&shape)).map_err(|msg| self.ctx.extras(&f, msg))?;
            out.emission_spectrum = e.spectrum;
        }
        Ok((out, needs))
    }

    /// The textureInfo `key` of an extension object `ext` at `at`, which the `gltf` crate does
    /// not parse: its texture (decoded as sRGB colour or as data), UV set and transform.
    fn extension_texture(
        &mut self,
        at: &str,
        ext: &Value,
        key: &str,
        srgb: bool,
    ) -> Result<Option<TextureRef>, SceneError> {
        let Some(info) = ext.get(key) else { return Ok(None) };
        let field = format!("{at}.{key}");
        let t = info
            .get("index")
            .and_then(Value::as_u64)
            .and_then(|i| self.doc.textures().nth(usize::try_from(i).ok()?))
            .ok_or_else(|| self.ctx.invalid(format!("{field}.index"), "names no texture of the file"))?;
        // A texCoord that is not a non-negative integer (-1, 1.5, "1") fell back to TEXCOORD_0
        // without a word, and 2³² was named as 4294967295 (found by a sweep); the core
        // textureInfo rejects them, so the extensions' do too.
        let tex_coord = match info.get("texCoord") {
            None => 0,
            Some(v) => v.as_u64().and_then(|n| u32::try_from(n).ok()).ok_or_else(|| {
                self.ctx.invalid(
                    format!("{field}.texCoord"),
                    format!("{v} is not a texture coordinate set (TEXCOORD_0 and TEXCOORD_1 are supported)"),
                )
            })?,
        };
        self.texture(&field, t, tex_coord, srgb, Some(info)).map(Some)
    }

    /// `KHR_materials_iridescence` (`ir` is its JSON), validated: `None` when its factor is 0
    /// (the extension's default: no film).
    fn iridescence(&mut self, at: &str, ir: &Value) -> Result<Option<crate::Iridescence>, SceneError> {
        let at = format!("{at}.extensions.KHR_materials_iridescence");
        let number = |key: &str, default: f32, lo: f32, hi: f32, what: &str| -> Result<f32, SceneError> {
            let Some(v) = ir.get(key) else { return Ok(default) };
            match v.as_f64() {
                Some(x) if x.is_finite() && (f64::from(lo)..=f64::from(hi)).contains(&x) => Ok(x as f32),
                _ => Err(self.ctx.invalid(format!("{at}.{key}"), format!("{v} is not {what}"))),
            }
        };
        let max_d = crate::MAX_FILM_THICKNESS_NM;
        let factor = number("iridescenceFactor", 0.0, 0.0, 1.0, "a number in [0, 1]")?;
        let ior =
            number("iridescenceIor", 1.3, 1.0, crate::MAX_FILM_IOR, "an index of refraction in [1, 10]")?;
        let nm = format!("a thickness in nm from 0 to {max_d}");
        let thickness_min = number("iridescenceThicknessMinimum", 100.0, 0.0, max_d, &nm)?;
        let thickness_max = number("iridescenceThicknessMaximum", 400.0, 0.0, max_d, &nm)?;
        if thickness_min > thickness_max {
            return Err(self.ctx.invalid(
                format!("{at}.iridescenceThicknessMinimum"),
                format!(
                    "{thickness_min} nm is more than iridescenceThicknessMaximum ({thickness_max} nm); the extension needs minimum ≤ maximum"
                ),
            ));
        }
        let texture_ref = self.extension_texture(&at, ir, "iridescenceTexture", false)?;
        let thickness_texture = self.extension_texture(&at, ir, "iridescenceThicknessTexture", false)?;
        if factor == 0.0 {
            return Ok(None);
        }
        Ok(Some(crate::Iridescence {
            factor,
            texture: texture_ref,
            ior,
            thickness_min,
            thickness_max,
            thickness_texture,
        }))
    }

    /// `KHR_materials_clearcoat` (`cc` is its JSON), validated: `None` when its factor is 0
    /// (the extension's default: no coat).
    fn clearcoat(&mut self, at: &str, cc: &Value) -> Result<Option<crate::clearcoat::Clearcoat>, SceneError> {
        let at = format!("{at}.extensions.KHR_materials_clearcoat");
        let number = |key: &str, default: f32, lo: f32, hi: f32, what: &str| -> Result<f32, SceneError> {
            let Some(v) = cc.get(key) else { return Ok(default) };
            match v.as_f64() {
                Some(x) if x.is_finite() && (f64::from(lo)..=f64::from(hi)).contains(&x) => Ok(x as f32),
                _ => Err(self.ctx.invalid(format!("{at}.{key}"), format!("{v} is not {what}"))),
            }
        };
        let factor = number("clearcoatFactor", 0.0, 0.0, 1.0, "a number in [0, 1]")?;
        let roughness = number("clearcoatRoughnessFactor", 0.0, 0.0, 1.0, "a number in [0, 1]")?;
        let texture = self.extension_texture(&at, cc, "clearcoatTexture", false)?;
        let roughness_texture = self.extension_texture(&at, cc, "clearcoatRoughnessTexture", false)?;
        let normal_texture = self.extension_texture(&at, cc, "clearcoatNormalTexture", false)?;
        let normal_scale = match cc.pointer("/clearcoatNormalTexture/scale") {
            None => 1.0,
            Some(v) => match v.as_f64() {
                Some(x) if x.is_finite() && x.abs() <= 1e6 => x as f32,
                _ => {
                    return Err(self.ctx.invalid(
                        format!("{at}.clearcoatNormalTexture.scale"),
                        format!("{v} is not a finite number"),
                    ));
                }
            },
        };
        if factor == 0.0 {
            return Ok(None);
        }
        Ok(Some(crate::clearcoat::Clearcoat {
            factor,
            texture,
            roughness,
            roughness_texture,
            normal_texture,
            normal_scale,
        }))
    }

    /// `field` of the extension object `ext` (at `at`): a number in [0, 1], `default` when absent.
    fn unit_factor(&self, at: &str, ext: &Value, field: &str, default: f32) -> Result<f32, SceneError> {
        match ext.get(field) {
            None => Ok(default),
            Some(v) => match v.as_f64() {
                Some(x) if (0.0..=1.0).contains(&x) => Ok(x as f32),
                _ => Err(self.ctx.invalid(format!("{at}.{field}"), format!("{v} is not a number in [0, 1]"))),
            },
        }
    }

    /// `field` of the extension object `ext` (at `at`): three numbers in [0, 1] (linear RGB),
    /// `default` when absent.
    fn unit_rgb(&self, at: &str, ext: &Value, field: &str, default: Vec3) -> Result<Vec3, SceneError> {
        let Some(v) = ext.get(field) else { return Ok(default) };
        let nums: Option<Vec<f64>> = v.as_array().and_then(|a| a.iter().map(Value::as_f64).collect());
        match nums.as_deref() {
            Some(&[r, g, b]) if [r, g, b].iter().all(|c| (0.0..=1.0).contains(c)) => {
                Ok(Vec3::new(r as f32, g as f32, b as f32))
            }
            _ => Err(self.ctx.invalid(
                format!("{at}.{field}"),
                format!("{v} is not three numbers in [0, 1] (linear RGB)"),
            )),
        }
    }

    /// `KHR_materials_specular` (`sp` is its JSON), validated: `None` at its defaults (weight 1,
    /// white, no textures), which change nothing.
    fn specular(&mut self, at: &str, sp: &Value) -> Result<Option<crate::specular::Specular>, SceneError> {
        let at = format!("{at}.extensions.KHR_materials_specular");
        let factor = self.unit_factor(&at, sp, "specularFactor", 1.0)?;
        let color = match sp.get("specularColorFactor") {
            None => Vec3::ONE,
            Some(v) => {
                let nums: Option<Vec<f64>> = v.as_array().and_then(|a| a.iter().map(Value::as_f64).collect());
                match nums.as_deref() {
                    Some(&[r, g, b])
                        if [r, g, b]
                            .iter()
                            .all(|c| (0.0..=f64::from(crate::specular::MAX_COLOR)).contains(c)) =>
                    {
                        Vec3::new(r as f32, g as f32, b as f32)
                    }
                    _ => {
                        return Err(self.ctx.invalid(
                            format!("{at}.specularColorFactor"),
                            format!(
                                "{v} is not three numbers from 0 to {:e} (linear RGB; above 1 raises F0 up to 1)",
                                crate::specular::MAX_COLOR
                            ),
                        ));
                    }
                }
            }
        };
        let texture = self.extension_texture(&at, sp, "specularTexture", false)?;
        let color_texture = self.extension_texture(&at, sp, "specularColorTexture", true)?;
        let s = crate::specular::Specular { factor, texture, color, color_texture };
        Ok((!s.is_default()).then_some(s))
    }

    /// `KHR_materials_sheen` (`sh` is its JSON), validated: `None` when its colour factor is
    /// zero (the extension's default), which turns the layer off whatever the textures hold.
    /// The colour texture is decoded as sRGB colour, the roughness texture (its A channel) as
    /// data.
    fn sheen(&mut self, at: &str, sh: &Value) -> Result<Option<crate::sheen::Sheen>, SceneError> {
        let at = format!("{at}.extensions.KHR_materials_sheen");
        let color = self.unit_rgb(&at, sh, "sheenColorFactor", Vec3::ZERO)?;
        let roughness = self.unit_factor(&at, sh, "sheenRoughnessFactor", 0.0)?;
        let color_texture = self.extension_texture(&at, sh, "sheenColorTexture", true)?;
        let roughness_texture = self.extension_texture(&at, sh, "sheenRoughnessTexture", false)?;
        let s = crate::sheen::Sheen { color, color_texture, roughness, roughness_texture };
        Ok((!s.is_off()).then_some(s))
    }

    /// `KHR_materials_diffuse_transmission` (`dt` is its JSON), validated: `None` at factor 0
    /// (the extension's default), where the diffuse BRDF is unchanged whatever the textures
    /// hold. The factor texture (its A channel) is data, the colour texture sRGB colour.
    fn diffuse_transmission(
        &mut self,
        at: &str,
        dt: &Value,
    ) -> Result<Option<crate::diffuse_transmission::DiffuseTransmission>, SceneError> {
        let at = format!("{at}.extensions.KHR_materials_diffuse_transmission");
        let factor = self.unit_factor(&at, dt, "diffuseTransmissionFactor", 0.0)?;
        let color = self.unit_rgb(&at, dt, "diffuseTransmissionColorFactor", Vec3::ONE)?;
        let texture = self.extension_texture(&at, dt, "diffuseTransmissionTexture", false)?;
        let color_texture = self.extension_texture(&at, dt, "diffuseTransmissionColorTexture", true)?;
        let d = crate::diffuse_transmission::DiffuseTransmission { factor, texture, color, color_texture };
        Ok((!d.is_off()).then_some(d))
    }

    /// `KHR_materials_anisotropy` (`an` is its JSON), validated: `None` at strength 0 (the
    /// extension's default), where the lobe is isotropic whatever the texture holds. The
    /// texture is data (linear).
    fn anisotropy(
        &mut self,
        at: &str,
        an: &Value,
    ) -> Result<Option<crate::anisotropy::Anisotropy>, SceneError> {
        let at = format!("{at}.extensions.KHR_materials_anisotropy");
        let strength = self.unit_factor(&at, an, "anisotropyStrength", 0.0)?;
        let max = crate::anisotropy::MAX_ROTATION;
        let rotation = match an.get("anisotropyRotation") {
            None => 0.0,
            Some(v) => match v.as_f64() {
                Some(x) if x.abs() <= f64::from(max) => x as f32,
                _ => {
                    return Err(self.ctx.invalid(
                        format!("{at}.anisotropyRotation"),
                        format!("{v} is not an angle in radians within ±{max:e}"),
                    ));
                }
            },
        };
        let texture = self.extension_texture(&at, an, "anisotropyTexture", false)?;
        let a = crate::anisotropy::Anisotropy { strength, rotation, texture };
        Ok((!a.is_off()).then_some(a))
    }

    /// `KHR_materials_transmission` with the material's `KHR_materials_volume` and
    /// `KHR_materials_dispersion` (their JSON), validated: `None` when the factor is 0 (the
    /// extension's default: opaque).
    fn transmission(
        &mut self,
        at: &str,
        tr: &Value,
        volume: Option<&Value>,
        dispersion: Option<&Value>,
    ) -> Result<Option<crate::transmission::Transmission>, SceneError> {
        use crate::transmission::{MAX_DISPERSION, MAX_THICKNESS, Transmission, Volume};
        let number = |ext: &str, json: &Value, key: &str, default: f32, lo: f32, hi: f32, what: &str| {
            let Some(v) = json.get(key) else { return Ok(default) };
            match v.as_f64() {
                Some(x) if x.is_finite() && (f64::from(lo)..=f64::from(hi)).contains(&x) => Ok(x as f32),
                _ => Err(self
                    .ctx
                    .invalid(format!("{at}.extensions.{ext}.{key}"), format!("{v} is not {what}"))),
            }
        };
        const T: &str = "KHR_materials_transmission";
        let factor = number(T, tr, "transmissionFactor", 0.0, 0.0, 1.0, "a number in [0, 1]")?;
        let texture =
            self.extension_texture(&format!("{at}.extensions.{T}"), tr, "transmissionTexture", false)?;
        let volume = match volume {
            None => None,
            Some(v) => {
                const V: &str = "KHR_materials_volume";
                let thickness = number(
                    V,
                    v,
                    "thicknessFactor",
                    0.0,
                    0.0,
                    MAX_THICKNESS,
                    &format!("a thickness in scene units from 0 to {MAX_THICKNESS:e}"),
                )?;
                let distance = number(
                    V,
                    v,
                    "attenuationDistance",
                    f32::INFINITY,
                    f32::MIN_POSITIVE,
                    f32::MAX,
                    "a distance > 0 in scene units",
                )?;
                let color = self
                    .unit_rgb(&format!("{at}.extensions.{V}"), v, "attenuationColor", Vec3::ONE)?
                    .to_array();
                let thickness_texture =
                    self.extension_texture(&format!("{at}.extensions.{V}"), v, "thicknessTexture", false)?;
                // The extension: thickness 0 is a thin-walled surface.
                (thickness > 0.0).then_some(Volume {
                    thickness,
                    thickness_texture,
                    attenuation_color: color,
                    attenuation_distance: distance,
                })
            }
        };
        let dispersion = match dispersion {
            None => 0.0,
            Some(d) => number(
                "KHR_materials_dispersion",
                d,
                "dispersion",
                0.0,
                0.0,
                MAX_DISPERSION,
                &format!(
                    "a dispersion (20 / Abbe number) in [0, {MAX_DISPERSION}]; an Abbe number must be > 0"
                ),
            )?,
        };
        if factor == 0.0 {
            return Ok(None);
        }
        Ok(Some(Transmission { factor, texture, volume, dispersion }))
    }

    /// `KHR_materials_pbrSpecularGlossiness` (`sg` is its JSON) converted into `out`'s
    /// metallic-roughness factors and textures (`spec_gloss`).
    fn spec_gloss(&mut self, at: &str, sg: &Value, out: &mut Material) -> Result<(), SceneError> {
        let at = format!("{at}.extensions.KHR_materials_pbrSpecularGlossiness");
        let factor = |key: &str, default: Vec4, n: usize| -> Result<Vec4, SceneError> {
            let Some(v) = sg.get(key) else { return Ok(default) };
            let nums: Option<Vec<f32>> = match v.as_array() {
                Some(a) => a.iter().map(|x| x.as_f64().map(|x| x as f32)).collect(),
                None => v.as_f64().map(|x| vec![x as f32]),
            };
            match nums {
                Some(x) if x.len() == n && x.iter().all(|c| (0.0..=1.0).contains(c)) => {
                    let mut f = default;
                    for (i, c) in x.into_iter().enumerate() {
                        f[i] = c;
                    }
                    Ok(f)
                }
                _ => Err(self.ctx.invalid(
                    format!("{at}.{key}"),
                    format!(
                        "must be {} in [0, 1]",
                        if n == 1 { "a number".to_string() } else { format!("{n} numbers") }
                    ),
                )),
            }
        };
        let diffuse = factor("diffuseFactor", Vec4::ONE, 4)?;
        let specular = factor("specularFactor", Vec4::ONE, 3)?.truncate();
        let glossiness = factor("glossinessFactor", Vec4::ONE, 1)?.x;
        let diffuse_tex = self.extension_texture(&at, sg, "diffuseTexture", true)?;
        let mut sg_tex = self.extension_texture(&at, sg, "specularGlossinessTexture", true)?;
        if let (Some(d), Some(g)) = (&diffuse_tex, &sg_tex)
            && (d.tex_coord != g.tex_coord || d.transform != g.transform)
        {
            self.warnings.push(format!(
                "{at}: the diffuse and specular-glossiness textures use different UV sets or transforms; \
                 the material is converted from the diffuse texture and the specular/glossiness factors only"
            ));
            sg_tex = None;
        }
        let converted = spec_gloss::convert(diffuse, specular, glossiness);
        out.base_color = converted.base_color;
        out.metallic = converted.metallic;
        out.roughness = converted.roughness;
        out.base_color_texture = None;
        out.metallic_roughness_texture = None;
        let Some(placement) = diffuse_tex.or(sg_tex) else { return Ok(()) };
        let source = |r: &Option<TextureRef>, factor: Vec4| spec_gloss::Source {
            texture: r.map(|r| &self.textures[r.index]),
            factor,
        };
        let (base, mr) = spec_gloss::convert_textures(
            &out.name,
            &source(&diffuse_tex, diffuse),
            &source(&sg_tex, specular.extend(glossiness)),
        );
        let placed = |index: usize| TextureRef { index, ..placement };
        out.base_color_texture = Some(placed(self.textures.len()));
        out.metallic_roughness_texture = Some(placed(self.textures.len() + 1));
        self.textures.extend([base, mr]);
        (out.base_color, out.metallic, out.roughness) = (Vec4::ONE, 1.0, 1.0);
        Ok(())
    }

    /// The image a texture shows: the first of [`gltf_ext::IMAGE_EXTENSIONS`] it has (each
    /// extension asks a client that decodes its format to prefer it; `source`, if any, is the
    /// PNG/JPEG fallback for others), else its `source`.
    fn texture_image(&self, t: &gltf::Texture) -> usize {
        gltf_ext::IMAGE_EXTENSIONS
            .iter()
            .find_map(|(ext, _)| {
                self.raw.pointer(&format!("/textures/{}/extensions/{ext}/source", t.index()))?.as_u64()
            })
            // Checked against the images in `document_of`.
            .map_or_else(|| t.source().index(), |i| i as usize)
    }

    /// The texture of a textureInfo at `at` (`info` is its JSON): decoded once per glTF texture
    /// and colour space, with its UV set and `KHR_texture_transform`.
    fn texture(
        &mut self,
        at: &str,
        t: gltf::Texture,
        tex_coord: u32,
        srgb: bool,
        info: Option<&Value>,
    ) -> Result<TextureRef, SceneError> {
        let (transform, over) = gltf_ext::texture_transform(self.ctx, at, info)?;
        let (tex_coord, field) = match over {
            Some(tc) => (tc, format!("{at}.extensions.KHR_texture_transform.texCoord")),
            None => (tex_coord, format!("{at}.texCoord")),
        };
        if tex_coord > 1 {
            return Err(self
                .ctx
                .invalid(field, format!("{tex_coord} is not supported (TEXCOORD_0 and TEXCOORD_1 are)")));
        }
        if let Some(&index) = self.tex_map.get(&(t.index(), srgb)) {
            return Ok(TextureRef { transform, index, tex_coord });
        }
        let doc = self.doc;
        let img = doc.images().nth(self.texture_image(&t)).expect("an index checked against the images");
        let iat = format!("images[{}]", img.index());
        if !self.images.contains_key(&img.index()) {
            let bytes: Vec<u8> = match img.source() {
                gltf::image::Source::View { view, .. } => {
                    let data = self.buffers.get(view.buffer().index()).map(Vec::as_slice).unwrap_or_default();
                    let end = view.offset().checked_add(view.length());
                    end.and_then(|e| data.get(view.offset()..e))
                        .ok_or_else(|| {
                            self.ctx
                                .invalid(format!("{iat}.bufferView"), "buffer view lies outside its buffer")
                        })?
                        .to_vec()
                }
                gltf::image::Source::Uri { uri, .. } => {
                    uri::read(self.ctx, &format!("{iat}.uri"), uri, MAX_IMAGE_FILE_BYTES)?.0
                }
            };
            if let Some((format, advice)) = gltf_ext::undecodable_image(&bytes) {
                return Err(self
                    .ctx
                    .invalid(&iat, format!("is a {format} image, which is not supported; {advice}")));
            }
            if bytes.starts_with(crate::ktx2::MAGIC) {
                let k = crate::ktx2::decode(&bytes).map_err(|e| self.ctx.invalid(&iat, e))?;
                if let Some(declared) = k.declared_srgb {
                    self.ktx2_srgb.insert(img.index(), declared);
                }
                self.images.insert(img.index(), (k.width, k.height, k.rgba8));
            } else {
                if image::guess_format(&bytes).ok() == Some(image::ImageFormat::Jpeg)
                    && jpeg_truncated(&bytes)
                {
                    return Err(self.ctx.invalid(
                        &iat,
                        "the JPEG ends before its end-of-image marker (a truncated file; the decoder would \
                     fill the rest in grey)",
                    ));
                }
                let reader = image::ImageReader::new(std::io::Cursor::new(&bytes))
                    .with_guessed_format()
                    .map_err(|e| self.ctx.invalid(&iat, format!("cannot read image: {e}")))?;
                // Checked against the header before any pixel buffer is allocated: a few bytes of
                // PNG can claim 2³¹ × 2³¹ pixels.
                let (w, h) = reader
                    .into_dimensions()
                    .map_err(|e| self.ctx.invalid(&iat, format!("cannot read image: {e}")))?;
                if w > MAX_IMAGE_DIMENSION
                    || h > MAX_IMAGE_DIMENSION
                    || 4 * w as u64 * h as u64 > MAX_IMAGE_DECODED_BYTES
                {
                    return Err(self.ctx.invalid(
                    &iat,
                    format!(
                        "the image is {w}×{h}; at most {MAX_IMAGE_DIMENSION} on a side and {} MiB decoded \
                         (RGBA8) are accepted",
                        MAX_IMAGE_DECODED_BYTES >> 20
                    ),
                ));
                }
                let mut reader = image::ImageReader::new(std::io::Cursor::new(&bytes))
                    .with_guessed_format()
                    .map_err(|e| self.ctx.invalid(&iat, format!("cannot read image: {e}")))?;
                let mut limits = image::Limits::default();
                limits.max_image_width = Some(MAX_IMAGE_DIMENSION);
                limits.max_image_height = Some(MAX_IMAGE_DIMENSION);
                // Decoding may hold the image at 16 bits per channel before conversion.
                limits.max_alloc = Some(2 * MAX_IMAGE_DECODED_BYTES);
                reader.limits(limits);
                let decoded = reader
                    .decode()
                    .map_err(|e| self.ctx.invalid(&iat, format!("cannot decode image: {e}")))?
                    .into_rgba8();
                self.images.insert(img.index(), (decoded.width(), decoded.height(), decoded.into_raw()));
            }
        }
        // As for PNG, the use decides how the texels are read (the glTF rule: colour textures
        // are sRGB, data textures linear); a KTX2 that declares the other transfer function is
        // read the same way, with a word, since one of the two is wrong.
        if let Some(&declared) = self.ktx2_srgb.get(&img.index())
            && declared != srgb
        {
            let (says, read) = if declared { ("sRGB", "linear data") } else { ("linear", "sRGB colour") };
            self.warnings.push(format!(
                "{iat}: the KTX2 image declares a {says} transfer function but {at} uses it as {read}; \
                 it is read as {read}"
            ));
        }
        let (width, height, rgba8) = self.images[&img.index()].clone();
        let name = t.name().or(img.name()).map_or_else(|| format!("texture {}", t.index()), str::to_string);
        let index = self.textures.len();
        let sampler = sampler_of(&t.sampler());
        self.textures.push(Texture { sampler, name, width, height, rgba8, srgb });
        self.tex_map.insert((t.index(), srgb), index);
        Ok(TextureRef { transform, index, tex_coord })
    }
}

/// Whether a JPEG lacks the end-of-image marker (FF D9) after its last start-of-scan (FF DA):
/// the JPEG decoder accepts such a file and makes up the missing image data. In the
/// entropy-coded data an FF byte is always followed by 00 or a restart marker, so neither
/// marker can appear there by chance; an embedded thumbnail's markers come before the main
/// scan, and data after the end marker is allowed.
fn jpeg_truncated(bytes: &[u8]) -> bool {
    let find_last = |m: [u8; 2]| bytes.windows(2).rposition(|w| w == m);
    match find_last([0xFF, 0xDA]) {
        None => true,
        Some(sos) => find_last([0xFF, 0xD9]).is_none_or(|eoi| eoi < sos),
    }
}
