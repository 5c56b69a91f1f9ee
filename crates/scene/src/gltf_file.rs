//! Loading a `.gltf` / `.glb` file into a [`Scene`].

use std::collections::HashMap;
use std::path::Path;

use glam::{Mat4, Vec3, Vec4};
use gltf::khr_lights_punctual::Kind;

use crate::context::Ctx;
use crate::error::SceneError;
use crate::extras::{self, SceneExtras};
use crate::{
    Camera, Emission, Light, LightKind, Material, Scene, SpectralReflectance, Texture, TextureRef, primitive,
    uri,
};

/// Extensions whose meaning this loader implements; a file that *requires* any other is refused
/// rather than drawn wrongly.
const SUPPORTED_REQUIRED: &[&str] = &["KHR_lights_punctual", "KHR_materials_emissive_strength"];

/// Loads a glTF 2.0 file (`.gltf` with external or embedded buffers, or binary `.glb`).
///
/// Geometry is flattened to world space; spectral `extras` are resolved; errors name the file
/// and the glTF index or JSON field at fault. See `docs/scene-format.md`.
pub fn load(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
    let path = path.as_ref();
    let ctx = Ctx::file(path);
    let bytes = std::fs::read(path).map_err(|e| ctx.io(path, e))?;
    from_slice(&ctx, &bytes)
}

/// Loads a glTF document held in memory; relative URIs resolve against `base_dir` when given.
/// `name` is used in messages in place of a path.
pub fn load_slice(name: &str, bytes: &[u8], base_dir: Option<&Path>) -> Result<Scene, SceneError> {
    let ctx = Ctx { path: name.into(), dir: base_dir.map(Path::to_path_buf) };
    from_slice(&ctx, bytes)
}

pub(crate) fn from_slice(ctx: &Ctx, bytes: &[u8]) -> Result<Scene, SceneError> {
    let gltf_err = |e| SceneError::Gltf { path: ctx.path.clone(), source: e };
    let g = gltf::Gltf::from_slice_without_validation(bytes).map_err(gltf_err)?;
    let root = g.document.into_json();
    precheck(ctx, &root)?;
    let document = gltf::Document::from_json(root).map_err(gltf_err)?;
    let doc = &document;
    if let Some(ext) = doc.extensions_required().find(|e| !SUPPORTED_REQUIRED.contains(e)) {
        return Err(ctx.invalid(
            "extensionsRequired",
            format!("extension {ext} is required by the file but not supported"),
        ));
    }
    let buffers = load_buffers(ctx, doc, g.blob.as_deref())?;
    let gscene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| ctx.invalid("scenes", "the file has no scene to render"))?;
    let sx = scene_extras(ctx, doc, &gscene)?;

    let mut loader = Loader {
        ctx,
        buffers: &buffers,
        textures: Vec::new(),
        tex_map: HashMap::new(),
        images: HashMap::new(),
    };
    let mut materials = doc.materials().map(|m| loader.material(&m)).collect::<Result<Vec<_>, _>>()?;
    let default_material = materials.len();
    let mut uses_default = false;

    let mut meshes = Vec::new();
    let mut lights = Vec::new();
    let mut camera = None;
    // Depth-first over the scene graph in file order; "first camera" means first in this order.
    let mut stack: Vec<(gltf::Node, Mat4)> = gscene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    let mut seen = vec![false; doc.nodes().len()];
    let mut first_mesh_of_node: HashMap<usize, usize> = HashMap::new();
    // (index in `lights`, glTF light index, node it stands in for)
    let mut stand_ins: Vec<(usize, usize, usize)> = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        let at = format!("nodes[{}]", node.index());
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(ctx.invalid(at, "node is reached twice: the node hierarchy must be a tree"));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if !world.is_finite() {
            return Err(ctx.invalid(at, "transform is not finite"));
        }
        if let Some(mesh) = node.mesh() {
            first_mesh_of_node.insert(node.index(), meshes.len());
            for prim in mesh.primitives() {
                let pat = format!("meshes[{}].primitives[{}]", mesh.index(), prim.index());
                let mi = match prim.material().index() {
                    Some(i) => i,
                    None => {
                        uses_default = true;
                        default_material
                    }
                };
                let needs_tangents = materials.get(mi).is_some_and(|m| m.normal_texture.is_some());
                meshes.push(primitive::build(ctx, &pat, &prim, world, &buffers, mi, needs_tangents)?);
            }
        }
        if let (Some(cam), None) = (node.camera(), &camera) {
            camera = Some(camera_of(ctx, &cam, world)?);
        }
        if let Some(light) = node.light() {
            let (l, stand_in) = light_of(ctx, &light, &node, world)?;
            if let Some(n) = stand_in {
                stand_ins.push((lights.len(), light.index(), n));
            }
            lights.push(l);
        }
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, world));
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
    if uses_default {
        materials.push(Material { name: "default".into(), ..Material::default() });
    }
    let camera = camera.unwrap_or_else(|| Camera::framing(crate::framing::bounds(&meshes)));
    let mut scene = Scene {
        warnings: vec![],
        source: ctx.path.display().to_string(),
        meshes,
        materials,
        textures: loader.textures,
        lights,
        camera,
        spectral: sx.spectral,
        water: sx.water,
        environment: sx.environment,
    };
    crate::sky::sync(&mut scene).map_err(|m| ctx.extras("water.sky", m))?;
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

fn load_buffers(ctx: &Ctx, doc: &gltf::Document, blob: Option<&[u8]>) -> Result<Vec<Vec<u8>>, SceneError> {
    doc.buffers()
        .map(|b| {
            let at = format!("buffers[{}]", b.index());
            let data = match b.source() {
                gltf::buffer::Source::Bin => blob
                    .ok_or_else(|| ctx.invalid(&at, "refers to the GLB binary chunk, but the file has none"))?
                    .to_vec(),
                gltf::buffer::Source::Uri(u) => uri::read(ctx, &format!("{at}.uri"), u)?.0,
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
        ("asset".to_string(), extras::object(ctx, "asset", &root.asset.extras)?),
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

fn camera_of(ctx: &Ctx, cam: &gltf::Camera, world: Mat4) -> Result<Camera, SceneError> {
    let at = format!("cameras[{}]", cam.index());
    let gltf::camera::Projection::Perspective(p) = cam.projection() else {
        return Err(ctx.invalid(at, "orthographic cameras are not supported; use a perspective camera"));
    };
    let (yfov, znear) = (p.yfov(), p.znear());
    if !(yfov > 0.0 && yfov < std::f32::consts::PI && znear > 0.0 && znear.is_finite()) {
        return Err(
            ctx.invalid(at, format!("needs 0 < yfov < π and znear > 0, got yfov {yfov}, znear {znear}"))
        );
    }
    let zfar = p.zfar().unwrap_or(1.0e4);
    if zfar.partial_cmp(&znear) != Some(std::cmp::Ordering::Greater) {
        return Err(ctx.invalid(at, format!("zfar {zfar} must exceed znear {znear}")));
    }
    let aspect = p.aspect_ratio();
    if aspect.is_some_and(|a| !(a > 0.0 && a.is_finite())) {
        return Err(ctx.invalid(at, "aspectRatio must be positive"));
    }
    // A camera's frame is rigid; drop any scale the node hierarchy carries.
    let (_, rot, pos) = world.to_scale_rotation_translation();
    Ok(Camera {
        ortho: None,
        transform: Mat4::from_rotation_translation(rot.normalize(), pos),
        yfov,
        znear,
        zfar,
        aspect,
    })
}

fn light_of(
    ctx: &Ctx,
    l: &gltf::khr_lights_punctual::Light,
    node: &gltf::Node,
    world: Mat4,
) -> Result<(Light, Option<usize>), SceneError> {
    let at = format!("KHR_lights_punctual.lights[{}]", l.index());
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(-Vec3::Z).try_normalize().ok_or_else(|| {
        ctx.invalid(format!("nodes[{}]", node.index()), "light node transform collapses its direction")
    })?;
    let range = l.range();
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
    buffers: &'a [Vec<u8>],
    textures: Vec<Texture>,
    /// (glTF texture index, sRGB?) → index in `textures`.
    tex_map: HashMap<(usize, bool), usize>,
    /// glTF image index → decoded RGBA8.
    images: HashMap<usize, (u32, u32, Vec<u8>)>,
}

impl Loader<'_> {
    fn material(&mut self, m: &gltf::Material) -> Result<Material, SceneError> {
        let idx = m.index().expect("document materials have indices");
        let at = format!("materials[{idx}]");
        let pbr = m.pbr_metallic_roughness();
        let mut out = Material {
            name: m.name().map_or_else(|| format!("material {idx}"), str::to_string),
            base_color: Vec4::from(pbr.base_color_factor()),
            metallic: pbr.metallic_factor(),
            roughness: pbr.roughness_factor(),
            emissive: Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0),
            ..Material::default()
        };
        if let Some(t) = pbr.base_color_texture() {
            out.base_color_texture = Some(self.texture(
                &format!("{at}.pbrMetallicRoughness.baseColorTexture"),
                t.texture(),
                t.tex_coord(),
                true,
            )?);
        }
        if let Some(t) = pbr.metallic_roughness_texture() {
            out.metallic_roughness_texture = Some(self.texture(
                &format!("{at}.pbrMetallicRoughness.metallicRoughnessTexture"),
                t.texture(),
                t.tex_coord(),
                false,
            )?);
        }
        if let Some(t) = m.normal_texture() {
            out.normal_texture =
                Some(self.texture(&format!("{at}.normalTexture"), t.texture(), t.tex_coord(), false)?);
            out.normal_scale = t.scale();
        }
        if let Some(t) = m.occlusion_texture() {
            out.occlusion_texture =
                Some(self.texture(&format!("{at}.occlusionTexture"), t.texture(), t.tex_coord(), false)?);
            out.occlusion_strength = t.strength().clamp(0.0, 1.0);
        }
        if let Some(t) = m.emissive_texture() {
            out.emissive_texture =
                Some(self.texture(&format!("{at}.emissiveTexture"), t.texture(), t.tex_coord(), true)?);
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
        let Some(map) = extras::object(self.ctx, &at, m.extras())? else { return Ok(out) };
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
                return Err(self
                    .ctx
                    .extras(f, "the material's emissiveFactor is zero, so the spectrum would emit nothing"));
            }
            let e = Emission::new(out.emissive, 1.0, Some(&shape)).map_err(|msg| self.ctx.extras(&f, msg))?;
            out.emission_spectrum = e.spectrum;
        }
        Ok(out)
    }

    fn texture(
        &mut self,
        at: &str,
        t: gltf::Texture,
        tex_coord: u32,
        srgb: bool,
    ) -> Result<TextureRef, SceneError> {
        if tex_coord != 0 {
            return Err(self
                .ctx
                .invalid(at, format!("uses TEXCOORD_{tex_coord}; only TEXCOORD_0 is supported")));
        }
        if let Some(&index) = self.tex_map.get(&(t.index(), srgb)) {
            return Ok(TextureRef { transform: None, index, tex_coord });
        }
        let img = t.source();
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
                gltf::image::Source::Uri { uri, .. } => uri::read(self.ctx, &format!("{iat}.uri"), uri)?.0,
            };
            let decoded = image::ImageReader::new(std::io::Cursor::new(&bytes))
                .with_guessed_format()
                .map_err(|e| self.ctx.invalid(&iat, format!("cannot read image: {e}")))?
                .decode()
                .map_err(|e| self.ctx.invalid(&iat, format!("cannot decode image: {e}")))?
                .into_rgba8();
            self.images.insert(img.index(), (decoded.width(), decoded.height(), decoded.into_raw()));
        }
        let (width, height, rgba8) = self.images[&img.index()].clone();
        let name = t.name().or(img.name()).map_or_else(|| format!("texture {}", t.index()), str::to_string);
        let index = self.textures.len();
        self.textures.push(Texture { sampler: Default::default(), name, width, height, rgba8, srgb });
        self.tex_map.insert((t.index(), srgb), index);
        Ok(TextureRef { transform: None, index, tex_coord })
    }
}
