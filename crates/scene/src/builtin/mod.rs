//! Scenes built into the binary, so demos and tests need no download.
//!
//! Every built-in uses measured spectra (ColorChecker reflectances, CIE illuminants) for ground
//! truth, and gives RGB renderers the colours those spectra actually have under D65, so RGB and
//! spectral renders describe the same physical scene.

pub mod anisotropy;
pub mod clearcoat;
mod colorchecker;
mod cornell;
mod dense;
pub mod fog;
pub mod glass;
pub mod iridescence;
mod metamerism;
pub(crate) mod shapes;
pub mod sheen;
pub mod specular;
pub mod translucent;
mod underwater;

use color::{Observer, SpectralIntegrator, Spectrum, WavelengthRange};
use glam::{DVec3, Vec3, Vec4};

use crate::context::Ctx;
use crate::error::SceneError;
use crate::{Emission, Material, Scene, SpectralReflectance, srgb};

/// Names accepted by [`builtin`], besides `dense:N` (the Cornell box with a faceted sphere of
/// about N triangles, for large-mesh measurements).
pub const BUILTIN_NAMES: &[&str] = &[
    "cornell",
    "colorchecker",
    "metamerism",
    "iridescence",
    "glass",
    "clearcoat",
    "specular",
    "sheen",
    "anisotropy",
    "translucent",
    "underwater",
    "fog",
    "tinted-fog",
];

/// Builds a built-in scene by name (case-insensitive). Its `source` is `builtin:NAME`.
pub fn builtin(name: &str) -> Result<Scene, SceneError> {
    let ctx = Ctx::builtin(&name.to_ascii_lowercase());
    let scene = match name.to_ascii_lowercase().as_str() {
        "cornell" => cornell::build(&ctx),
        "colorchecker" => colorchecker::build(&ctx),
        "metamerism" => metamerism::build(&ctx),
        "iridescence" => iridescence::build(&ctx),
        "glass" => glass::build(&ctx),
        "clearcoat" => clearcoat::build(&ctx),
        "specular" => specular::build(&ctx),
        "sheen" => sheen::build(&ctx),
        "anisotropy" => anisotropy::build(&ctx),
        "translucent" => translucent::build(&ctx),
        "underwater" => underwater::build(&ctx),
        "fog" => fog::build(&ctx, false),
        "tinted-fog" => fog::build(&ctx, true),
        other if other.starts_with("dense:") => dense::build(&ctx, &other["dense:".len()..]),
        _ => {
            return Err(SceneError::UnknownBuiltin {
                name: name.to_string(),
                known: BUILTIN_NAMES.join(", "),
            });
        }
    }?;
    Ok(scene)
}

/// An empty scene to fill in, with D65 as the white and the paper's spectral defaults left to
/// the CLI.
pub(crate) fn empty(ctx: &Ctx, camera: crate::Camera) -> Scene {
    let mut s = Scene::empty(ctx.path.display().to_string(), camera);
    s.spectral.white = Some("D65".into());
    s
}

/// Linear sRGB of a reflectance under D65 with the CIE 1931 observer (1 nm, 360–830 nm): the
/// colour an RGB renderer should give a surface with this measured spectrum.
pub(crate) fn reflectance_rgb(s: &Spectrum) -> DVec3 {
    let d65 = color::illuminant::by_name("D65").expect("D65 is tabulated");
    let integ = SpectralIntegrator::reference(&Observer::cie1931(), &d65, WavelengthRange::FULL)
        .expect("the full observer range is valid");
    srgb::xyz_to_linear(integ.integrate(|l| s.eval(l)))
}

/// A diffuse (roughness 1) material with a measured reflectance and its D65 sRGB colour as
/// base colour (clipped to the gamut).
pub(crate) fn measured_material(name: &str, s: &Spectrum) -> Material {
    let rgb = reflectance_rgb(s).clamp(DVec3::ZERO, DVec3::ONE).as_vec3();
    Material {
        name: name.into(),
        base_color: Vec4::from((rgb, 1.0)),
        spectral: Some(SpectralReflectance::Uniform(s.clone())),
        ..Material::default()
    }
}

/// A light of spectral `shape` ([`Emission::of_shape`]), errors placed at `what`.
pub(crate) fn light_emission(
    ctx: &Ctx,
    what: &str,
    shape: &Spectrum,
    intensity: f32,
) -> Result<Emission, SceneError> {
    Emission::of_shape(shape, intensity).map_err(|m| ctx.invalid(what, m))
}

/// A spot of CIE illuminant `illuminant` at `position` aimed at `target`, of `intensity`
/// (candela of the shape's luminance) and cones (inner, outer) in radians; errors placed at
/// `name`. The built-ins' studio lights.
pub(crate) fn spot_at(
    ctx: &Ctx,
    name: &str,
    illuminant: &str,
    position: Vec3,
    target: Vec3,
    intensity: f32,
    cones: (f32, f32),
) -> Result<crate::Light, SceneError> {
    let shape = color::illuminant::by_name(illuminant).map_err(|e| ctx.invalid(name, e.to_string()))?;
    Ok(crate::Light {
        name: name.into(),
        kind: crate::LightKind::Spot {
            position,
            direction: (target - position).normalize(),
            inner_cone: cones.0,
            outer_cone: cones.1,
            range: None,
        },
        emission: light_emission(ctx, name, &shape, intensity)?,
        stands_in_for: None,
    })
}

/// The stage of the material showcases (`iridescence`, `clearcoat`, `specular`, `sheen`,
/// `anisotropy`): two rows of
/// four spheres of radius 0.12, 0.3 apart (the back row at z = −0.2, the front at 0.15), on a
/// 2 m floor of ColorChecker neutral 5, seen from above and in front; two spots
/// ([`showcase_spots`]).
pub(crate) struct Showcase {
    scene: Scene,
}

impl Showcase {
    /// The camera and the floor's material (material 0).
    pub(crate) fn new(ctx: &Ctx) -> Self {
        let camera = crate::Camera::look_at(
            Vec3::new(0.0, 0.75, 1.55),
            Vec3::new(0.0, 0.12, 0.0),
            Vec3::Y,
            40f32.to_radians(),
        );
        let mut scene = empty(ctx, camera);
        scene.materials.push(measured_material(
            "floor (ColorChecker neutral 5)",
            &patch(patch_index("neutral 5 (.70 D)")),
        ));
        Showcase { scene }
    }

    /// Sphere `i` (0–3, left to right) of row `row` (0 back, 1 front), of material `m`.
    pub(crate) fn sphere(&mut self, row: usize, i: usize, m: Material) {
        let (r, step) = (0.12f32, 0.3f32);
        let z = [-0.2f32, 0.15][row];
        self.scene.materials.push(m);
        let x = (i as f32 - 1.5) * step;
        let index = self.scene.materials.len() - 1;
        self.scene.meshes.push(shapes::sphere(Vec3::new(x, r, z), r, 14, 22, index));
    }

    /// The floor's quad and the spots: the finished scene.
    pub(crate) fn finish(
        mut self,
        ctx: &Ctx,
        front: (&str, &str),
        side: (&str, &str),
    ) -> Result<Scene, SceneError> {
        let fw = 2.0f32;
        self.scene.meshes.push(shapes::quad(
            Vec3::new(-fw * 0.5, 0.0, fw * 0.5),
            Vec3::X * fw,
            -Vec3::Z * fw,
            0,
        ));
        self.scene.lights = showcase_spots(ctx, front, side)?;
        Ok(self.scene)
    }
}

/// The two spots of the material showcases (`iridescence`, `clearcoat`, `specular`, `sheen`): one above
/// and in front of the camera, one from the side, aimed at the middle of the rows at
/// (0, 0.1, 0), ≈ π lux there each; cones 40°/65°.
pub(crate) fn showcase_spots(
    ctx: &Ctx,
    front: (&str, &str),
    side: (&str, &str),
) -> Result<Vec<crate::Light>, SceneError> {
    let target = Vec3::new(0.0, 0.1, 0.0);
    [(front, Vec3::new(0.2, 1.3, 1.2)), (side, Vec3::new(-1.2, 0.9, 0.3))]
        .into_iter()
        .map(|((name, illuminant), position)| {
            let intensity = std::f32::consts::PI * (target - position).length_squared();
            spot_at(
                ctx,
                name,
                illuminant,
                position,
                target,
                intensity,
                (40f32.to_radians(), 65f32.to_radians()),
            )
        })
        .collect()
}

/// The ColorChecker patch spectrum by 0-based chart index.
pub(crate) fn patch(i: usize) -> Spectrum {
    Spectrum::from_table(&color::data::colorchecker::SPECTRA[i])
}

/// Index of a patch by its exact chart name.
pub(crate) fn patch_index(name: &str) -> usize {
    color::data::colorchecker::NAMES
        .iter()
        .position(|n| *n == name)
        .unwrap_or_else(|| panic!("no patch {name}"))
}

/// Unit vector helper for light directions.
pub(crate) fn dir(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    // Oracle: colour-science 0.4.7, ColorChecker N Ohta under D65 with the CIE 1931 2° observer,
    // restricted to the measured 380–780 nm, sRGB-encoded and rounded:
    //   sd = colour.SDS_COLOURCHECKERS['ColorChecker N Ohta'][name]
    //   xyz = colour.sd_to_XYZ(sd, cmfs, D65, method='Integration', shape=SpectralShape(380, 780, 1)) / 100
    //   np.round(np.clip(colour.XYZ_to_sRGB(xyz), 0, 1) * 255)
    #[test]
    fn patch_colours_match_colour_science() {
        let want = [
            ("dark skin", [116, 79, 63]),
            ("red", [178, 47, 58]),
            ("green", [69, 150, 70]),
            ("white 9.5 (.05 D)", [242, 242, 240]),
            ("cyan", [0, 137, 167]),
        ];
        for (name, rgb8) in want {
            let got = srgb::linear_to_srgb8(reflectance_rgb(&patch(patch_index(name))));
            for k in 0..3 {
                assert!((got[k] as i32 - rgb8[k]).abs() <= 1, "{name}: {got:?} vs colour-science {rgb8:?}");
            }
        }
    }

    #[test]
    fn every_builtin_loads_with_lights_camera_and_geometry() {
        for name in BUILTIN_NAMES {
            let s = builtin(name).unwrap();
            assert_eq!(s.source, format!("builtin:{name}"));
            assert!(!s.lights.is_empty(), "{name} has no lights");
            assert!(!s.meshes.is_empty(), "{name} has no meshes");
            let tris: usize = s.meshes.iter().map(|m| m.indices.len() / 3).sum();
            assert!(tris > 0 && tris < 5_000, "{name}: {tris} triangles");
            for (i, m) in s.meshes.iter().enumerate() {
                assert!(m.material < s.materials.len(), "{name} mesh {i}");
                assert_eq!(m.normals.len(), m.positions.len());
                assert!(m.uvs.is_empty() || m.uvs.len() == m.positions.len());
                assert!(m.indices.iter().all(|&i| (i as usize) < m.positions.len()));
                // Counter-clockwise winding agrees with the shading normals (front faces).
                for t in m.indices.chunks_exact(3) {
                    let p = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
                    let n = m.normals[t[0] as usize];
                    assert!((p[1] - p[0]).cross(p[2] - p[0]).dot(n) > 0.0, "{name} mesh {i} winding");
                }
            }
            for m in &s.materials {
                for t in
                    [m.base_color_texture, m.normal_texture, m.emissive_texture, m.metallic_roughness_texture]
                        .into_iter()
                        .flatten()
                {
                    let tex = &s.textures[t.index];
                    assert_eq!(tex.rgba8.len(), (tex.width * tex.height * 4) as usize);
                }
            }
            for l in &s.lights {
                assert!(l.emission.spectrum.is_some(), "{name}: light {} has no spectrum", l.name);
            }
            // The camera sees the scene: the bounds' centre is in front of it.
            let (lo, hi) = s.bounds().unwrap();
            let v = s.camera.transform.inverse().transform_point3((lo + hi) * 0.5);
            assert!(v.z < 0.0, "{name}: scene centre behind the camera");
        }
        let e = builtin("kitchen").unwrap_err().to_string();
        assert!(e.contains("kitchen") && e.contains("cornell") && e.contains("metamerism"), "{e}");
    }
}
