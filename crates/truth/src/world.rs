//! A scene prepared for path tracing: the BVH, per-material spectra, lights in tracer units,
//! the optional medium, and the surface queries the integrator makes at a hit.

use crate::accel::{Geometry, Hit};
use crate::env_map::EnvMap;
use crate::error::{Result, TruthError};
use crate::lights::{DeltaLight, EmissionUnits, EmitterDistribution, luminance};
use crate::material::{self, PreparedMaterial};
use crate::medium::{Medium, PreparedMedium};
use crate::spectral::DenseSpectrum;
use crate::upsample::RgbToSpectrum;
use crate::water_surface::Surface;
use color::{Spectrum, WavelengthRange};
use glam::{Vec2, Vec3, Vec4};
use scene::Scene;

/// Everything about a surface point the integrator needs.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3,
    /// Geometric normal from the winding (counter-clockwise = front, as in glTF).
    pub ng: Vec3,
    /// Interpolated vertex normal (before normal mapping); defines the emitting side.
    pub n_vertex: Vec3,
    pub uv: Vec2,
    pub tangent: Option<Vec4>,
    pub material: usize,
    pub tri: u32,
}

pub struct World<'s> {
    pub scene: &'s Scene,
    pub geometry: Geometry,
    pub upsampler: &'s dyn RgbToSpectrum,
    pub units: EmissionUnits,
    pub materials: Vec<PreparedMaterial>,
    pub delta_lights: Vec<DeltaLight>,
    pub emitters: EmitterDistribution,
    pub medium: Option<PreparedMedium>,
    /// Per material: its measured emission spectrum in tracer units, if it has one.
    pub emission_spectra: Vec<Option<crate::spectral::DenseSpectrum>>,
    /// Triangle areas (for area-light pdfs).
    pub areas: Vec<f32>,
    /// Uniform radiance arriving from infinity along rays that escape the scene.
    pub environment: Option<crate::spectral::DenseSpectrum>,
    /// The scene's environment map ([`scene::Scene::environment`]), sampled by next-event
    /// estimation and seen by escaping rays; `None` when it has none or it is black.
    pub env_map: Option<EnvMap<'s>>,
    /// The water surface above the medium, with the sky seen through it (see
    /// [`crate::water_surface`]); from the medium's `surface_ior` and the scene's sky stand-ins.
    pub surface: Option<Surface>,
}

impl<'s> World<'s> {
    /// Prepares `scene` for rendering over `range` with `white` as the scene white.
    pub fn new(
        scene: &'s Scene,
        upsampler: &'s dyn RgbToSpectrum,
        white: &Spectrum,
        range: WavelengthRange,
        medium: Option<&Medium>,
    ) -> Result<Self> {
        let bad = |why: String| TruthError::BadScene { scene: scene.source.clone(), why };
        let geometry = Geometry::new(scene).map_err(bad)?;
        for (i, t) in scene.textures.iter().enumerate() {
            if t.rgba8.len() != 4 * t.width as usize * t.height as usize {
                return Err(bad(format!(
                    "texture {i} ('{}') has {} bytes for {}×{} RGBA8",
                    t.name,
                    t.rgba8.len(),
                    t.width,
                    t.height
                )));
            }
        }
        let units = EmissionUnits::new(white, range);
        let materials = scene.materials.iter().map(|m| PreparedMaterial::new(m, range)).collect();
        // Stand-ins approximate emissive meshes for rasterisers; the meshes themselves are
        // sampled here, so counting the stand-ins too would light the scene twice.
        let delta_lights = scene
            .lights
            .iter()
            .filter(|l| l.stands_in_for.is_none())
            .map(|l| DeltaLight::new(l, units.light(&l.emission, upsampler)))
            .collect();
        let emission_spectra = scene
            .materials
            .iter()
            .map(|m| {
                m.emission_spectrum.as_ref().map(|s| {
                    units.light(
                        &scene::Emission { rgb: m.emissive, intensity: 1.0, spectrum: Some(s.clone()) },
                        upsampler,
                    )
                })
            })
            .collect();
        let areas: Vec<f32> =
            geometry.verts.iter().map(|v| 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length()).collect();
        let emitters = EmitterDistribution::new(
            geometry.refs.iter().zip(&areas).map(|(r, a)| {
                let m = &scene.materials[scene.meshes[r.mesh as usize].material];
                a * luminance(m.emissive.max(Vec3::ZERO)).max(0.0)
            }),
            geometry.len(),
        );
        let surface = water_surface(scene, medium, &units, upsampler, range).map_err(bad)?;
        let env_map = match &scene.environment {
            Some(env) if !env.is_black() => {
                if surface.is_some() {
                    // Its light would have to come in through the water surface (Fresnel, Snell's
                    // window); the surface shows the scene's uniform sky only.
                    return Err(bad(format!(
                        "an environment map ({}) cannot light a scene under a water surface: the \
                         surface shows the water settings' sky (drop the environment, e.g. --env none)",
                        env.source
                    )));
                }
                Some(EnvMap::new(env, &units, upsampler).map_err(bad)?)
            }
            _ => None,
        };
        let medium = medium.map(|m| PreparedMedium::new(m, range)).transpose()?;
        Ok(World {
            scene,
            geometry,
            upsampler,
            units,
            materials,
            delta_lights,
            emitters,
            medium,
            emission_spectra,
            areas,
            environment: None,
            env_map,
            surface,
        })
    }

    /// Surrounds the scene with a uniform background radiance `s(λ)` in tracer units (a
    /// spectrum equal to the scene white has Y = 1). Reached by BRDF/phase sampling only.
    /// This is the classic white-furnace illumination, and a flat sky.
    pub fn with_environment(mut self, s: &Spectrum) -> Self {
        self.environment = Some(crate::spectral::DenseSpectrum::new(s, self.units.range));
        self
    }

    fn vertex_attrs(&self, tri: u32, b1: f32, b2: f32) -> (Vec3, Vec2, Option<Vec4>) {
        let r = self.geometry.refs[tri as usize];
        let m = &self.scene.meshes[r.mesh as usize];
        let idx = &m.indices[r.first as usize..r.first as usize + 3];
        let b0 = 1.0 - b1 - b2;
        let lerp3 = |a: &[Vec3]| -> Option<Vec3> {
            Some(a.get(idx[0] as usize)? * b0 + *a.get(idx[1] as usize)? * b1 + *a.get(idx[2] as usize)? * b2)
        };
        let v = &self.geometry.verts[tri as usize];
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let n = lerp3(&m.normals).and_then(|n| n.try_normalize()).unwrap_or(ng);
        let uv = (|| {
            Some(
                m.uvs.get(idx[0] as usize)? * b0
                    + *m.uvs.get(idx[1] as usize)? * b1
                    + *m.uvs.get(idx[2] as usize)? * b2,
            )
        })()
        .unwrap_or(Vec2::ZERO);
        let tangent = (|| {
            let t = &m.tangents;
            Some(t.get(idx[0] as usize)? * b0 + *t.get(idx[1] as usize)? * b1 + *t.get(idx[2] as usize)? * b2)
        })()
        .or_else(|| self.uv_tangent(tri, n));
        (n, uv, tangent)
    }

    /// A tangent from the triangle's UV gradients, for normal-mapped meshes without tangents.
    fn uv_tangent(&self, tri: u32, n: Vec3) -> Option<Vec4> {
        let r = self.geometry.refs[tri as usize];
        let m = &self.scene.meshes[r.mesh as usize];
        m.normal_texture_or_none(&self.scene.materials)?;
        let idx = &m.indices[r.first as usize..r.first as usize + 3];
        let uv = [m.uvs.get(idx[0] as usize)?, m.uvs.get(idx[1] as usize)?, m.uvs.get(idx[2] as usize)?];
        let v = &self.geometry.verts[tri as usize];
        let (e1, e2) = (v[1] - v[0], v[2] - v[0]);
        let (d1, d2) = (*uv[1] - *uv[0], *uv[2] - *uv[0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det.abs() < 1e-12 {
            return None;
        }
        let t = (e1 * d2.y - e2 * d1.y) / det;
        let b = (e2 * d1.x - e1 * d2.x) / det;
        let w = if n.cross(t).dot(b) < 0.0 { -1.0 } else { 1.0 };
        Some(t.extend(w))
    }

    pub fn surface(&self, hit: &Hit) -> SurfacePoint {
        let v = &self.geometry.verts[hit.tri as usize];
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let (n_vertex, uv, tangent) = self.vertex_attrs(hit.tri, hit.b1, hit.b2);
        // The barycentric point is more precise than o + t·d far from the origin.
        let p = v[0] * (1.0 - hit.b1 - hit.b2) + v[1] * hit.b1 + v[2] * hit.b2;
        let r = self.geometry.refs[hit.tri as usize];
        SurfacePoint {
            p,
            ng,
            n_vertex,
            uv,
            tangent,
            material: self.scene.meshes[r.mesh as usize].material,
            tri: hit.tri,
        }
    }

    /// A point on triangle `tri` at barycentrics (b1, b2).
    pub fn point_on(&self, tri: u32, b1: f32, b2: f32) -> SurfacePoint {
        self.surface(&Hit { t: 0.0, tri, b1, b2 })
    }

    /// Radiance leaving `s` towards `wo` (unit, away from the surface); emission is one-sided,
    /// on the side the vertex normals point to.
    pub fn emitted(&self, s: &SurfacePoint, wo: Vec3, l: Vec4) -> Vec4 {
        let m = &self.scene.materials[s.material];
        if m.emissive == Vec3::ZERO || s.n_vertex.dot(wo) <= 0.0 {
            return Vec4::ZERO;
        }
        let rgb = material::emissive_rgb(m, &self.scene.textures, s.uv);
        match &self.emission_spectra[s.material] {
            // A measured spectrum, modulated by the emissive texture's luminance.
            Some(spec) => {
                let k =
                    if m.emissive_texture.is_some() { luminance(rgb) / luminance(m.emissive) } else { 1.0 };
                spec.eval4(l) * k
            }
            None => self.units.rgb(rgb, self.upsampler, l),
        }
    }
}

/// The water surface of `medium`, lit by the sky whose irradiance below the surface the scene's
/// sky stand-in lights carry (`scene::sky`). A sky with nowhere to be seen from, or a scene
/// asking for a sky without its stand-ins, is an error rather than a silently dark sky.
fn water_surface(
    scene: &Scene,
    medium: Option<&Medium>,
    units: &EmissionUnits,
    upsampler: &dyn RgbToSpectrum,
    range: WavelengthRange,
) -> std::result::Result<Option<Surface>, String> {
    let skies: Vec<DenseSpectrum> = scene
        .lights
        .iter()
        .filter(|l| scene::sky::is_stand_in(l))
        .map(|l| units.light(&l.emission, upsampler))
        .collect();
    if let Some(w) = &scene.water
        && w.sky > 0.0
        && skies.is_empty()
    {
        return Err(format!(
            "water.sky = {} but the scene has no sky stand-in light (scene::sky::sync makes it)",
            w.sky
        ));
    }
    let irradiance = (!skies.is_empty())
        .then(|| DenseSpectrum::from_fn(range, |l| skies.iter().map(|s| s.eval(l as f32) as f64).sum()));
    match medium.and_then(|m| Some((m.region, m.surface_ior?))) {
        Some((region, n)) => Ok(Surface::new(region, n, irradiance)),
        None if irradiance.is_some() => Err("the scene has a sky under water (water.sky) but no water \
                                             surface to see it through (a medium from truth::water)"
            .into()),
        None => Ok(None),
    }
}

/// A glTF mesh asks for tangents only when its material has a normal map.
trait NormalMapped {
    fn normal_texture_or_none(&self, materials: &[scene::Material]) -> Option<()>;
}

impl NormalMapped for scene::Mesh {
    fn normal_texture_or_none(&self, materials: &[scene::Material]) -> Option<()> {
        materials.get(self.material)?.normal_texture.map(|_| ())
    }
}

/// Offsets a ray origin off a surface along the geometric normal, on the side of `dir`,
/// by an amount relative to the coordinates' magnitude (f32 has 24 bits of mantissa).
#[inline]
pub fn offset(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let eps = 1e-4 * (1.0 + p.abs().max_element());
    if ng.dot(dir) >= 0.0 { p + ng * eps } else { p - ng * eps }
}
