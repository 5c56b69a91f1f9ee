//! A scene prepared for path tracing: the BVH, per-material spectra, lights in tracer units,
//! the optional medium, and the surface queries the integrator makes at a hit.

use crate::accel::{Geometry, Hit, NOT_OPAQUE, SINGLE_SIDED};
use crate::env_map::EnvMap;
use crate::error::{Result, TruthError};
use crate::lights::{DeltaLight, EmissionUnits, EmitterDistribution, luminance};
use crate::material::{self, PreparedMaterial, TexCoords};
use crate::medium::{Medium, PreparedMedium};
use crate::rng::{Sampler, hash_uniform};
use crate::spectral::DenseSpectrum;
use crate::upsample::RgbToSpectrum;
use crate::water_surface::Surface;
use color::{Spectrum, WavelengthRange};
use glam::{Vec2, Vec3, Vec4};
use scene::{AlphaMode, Scene};
use std::borrow::Cow;

/// Everything about a surface point the integrator needs.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub p: Vec3,
    /// Geometric normal from the winding (counter-clockwise = front, as in glTF).
    pub ng: Vec3,
    /// Interpolated vertex normal (before normal mapping); defines the emitting side.
    pub n_vertex: Vec3,
    /// `TEXCOORD_0` and `TEXCOORD_1` (zero where the mesh has none).
    pub tc: TexCoords,
    /// `COLOR_0`, linear RGBA (white where the mesh has none).
    pub color: Vec4,
    pub tangent: Option<Vec4>,
    pub material: usize,
    pub tri: u32,
}

pub struct World<'s> {
    /// The scene with the vertex convention applied ([`Scene::completed`]: normals and
    /// tangents as the real-time renderer and the glTF loader have them).
    pub scene: Cow<'s, Scene>,
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
    /// Some triangle has an `AlphaMode::Blend` material: rays then draw a key from the path's
    /// sampler for their stochastic opacity decisions ([`World::ray_key`]).
    pub stochastic: bool,
    /// Per material, the absorption inside its volume (`material::volume_absorption`).
    pub absorption: Vec<Option<[f64; 3]>>,
    /// The absolute part of [`offset`]'s distance: the scene's size, at most 1 (a scene
    /// smaller than the fixed floor of 10⁻⁴ units had every ray leave it).
    pub offset_floor: f32,
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
        // The environment is borrowed from the caller's scene (completion leaves it alone), so
        // the environment map may outlive this function.
        let original = scene;
        let scene = original.completed();
        let bad = |why: String| TruthError::BadScene { scene: scene.source.clone(), why };
        let geometry = Geometry::new(&scene).map_err(|e| bad(e.to_string()))?;
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
        for (i, m) in scene.materials.iter().enumerate() {
            if let AlphaMode::Mask { cutoff } = m.alpha_mode
                && !cutoff.is_finite()
            {
                return Err(bad(format!("material {i} ('{}') has alpha cutoff {cutoff}", m.name)));
            }
        }
        let stochastic = geometry.refs.iter().any(|r| {
            let m = &scene.materials[scene.meshes[r.mesh as usize].material];
            m.alpha_mode == AlphaMode::Blend
        });
        let units = EmissionUnits::new(white, range);
        let materials = scene.materials.iter().map(|m| PreparedMaterial::new(m, range)).collect();
        // Stand-ins approximate emissive meshes for rasterisers; the meshes themselves are
        // sampled here, so counting the stand-ins too would light the scene twice.
        let delta_lights = scene
            .lights
            .iter()
            .filter(|l| l.stands_in_for.is_none())
            .map(|l| {
                let s = units
                    .light(&l.emission, upsampler)
                    .map_err(|why| bad(format!("light '{}': {why}", l.name)))?;
                Ok(DeltaLight::new(l, s))
            })
            .collect::<Result<_>>()?;
        let emission_spectra = scene
            .materials
            .iter()
            .map(|m| {
                // Only a surface that glows needs its spectrum (the real-time renderer's rule).
                let glows = !m.unlit && m.emissive.max_element() > 0.0;
                m.emission_spectrum
                    .as_ref()
                    .filter(|_| glows)
                    .map(|s| {
                        units
                            .light(
                                &scene::Emission {
                                    rgb: m.emissive,
                                    intensity: 1.0,
                                    spectrum: Some(s.clone()),
                                },
                                upsampler,
                            )
                            .map_err(|why| bad(format!("material '{}': {why}", m.name)))
                    })
                    .transpose()
            })
            .collect::<Result<_>>()?;
        let areas: Vec<f32> =
            geometry.verts.iter().map(|v| 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length()).collect();
        let emitters = EmitterDistribution::new(
            geometry.refs.iter().zip(&areas).map(|(r, a)| {
                let m = &scene.materials[scene.meshes[r.mesh as usize].material];
                a * luminance(m.emissive.max(Vec3::ZERO)).max(0.0)
            }),
            geometry.len(),
        );
        let surface = water_surface(&scene, medium, &units, upsampler, range).map_err(bad)?;
        let env_map = match &original.environment {
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
                Some(EnvMap::new(env, &units, upsampler).map_err(|e| bad(e.to_string()))?)
            }
            _ => None,
        };
        let medium = medium.map(|m| PreparedMedium::new(m, range)).transpose()?;
        let offset_floor = offset_floor(geometry.size);
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
            stochastic,
            absorption: original.materials.iter().map(crate::material::volume_absorption).collect(),
            offset_floor,
        })
    }

    /// Whether a path can meet light by itself: emitting or unlit surfaces, an environment, the
    /// sky through a water surface. Punctual lights are found by light sampling only.
    pub fn has_light_to_meet(&self) -> bool {
        self.environment.is_some()
            || self.env_map.is_some()
            || self.surface.as_ref().is_some_and(|s| s.sky.is_some())
            || !self.emitters.is_empty()
            || self.scene.materials.iter().any(|m| m.unlit)
    }

    /// Surrounds the scene with a uniform background radiance `s(λ)` in tracer units (a
    /// spectrum equal to the scene white has Y = 1). Reached by BRDF/phase sampling only.
    /// This is the classic white-furnace illumination, and a flat sky.
    pub fn with_environment(mut self, s: &Spectrum) -> Self {
        self.environment = Some(crate::spectral::DenseSpectrum::new(s, self.units.range));
        self
    }

    /// The three vertex indices of triangle `tri` and its mesh.
    fn corners(&self, tri: u32) -> (&scene::Mesh, [usize; 3]) {
        let r = self.geometry.refs[tri as usize];
        let m = &self.scene.meshes[r.mesh as usize];
        let i = r.first as usize;
        (m, [m.indices[i] as usize, m.indices[i + 1] as usize, m.indices[i + 2] as usize])
    }

    fn vertex_attrs(&self, tri: u32, b1: f32, b2: f32) -> (Vec3, TexCoords, Vec4, Option<Vec4>) {
        let (m, idx) = self.corners(tri);
        let b = [1.0 - b1 - b2, b1, b2];
        let v = &self.geometry.verts[tri as usize];
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let n = lerp(&m.normals, idx, b).and_then(|n| n.try_normalize()).unwrap_or(ng);
        let tc = TexCoords([
            lerp(&m.uvs, idx, b).unwrap_or(Vec2::ZERO),
            lerp(&m.uvs1, idx, b).unwrap_or(Vec2::ZERO),
        ]);
        let color = lerp(&m.colors, idx, b).unwrap_or(Vec4::ONE);
        let tangent = lerp(&m.tangents, idx, b);
        (n, tc, color, tangent)
    }

    pub fn surface(&self, hit: &Hit) -> SurfacePoint {
        let v = &self.geometry.verts[hit.tri as usize];
        let ng = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
        let (n_vertex, tc, color, tangent) = self.vertex_attrs(hit.tri, hit.b1, hit.b2);
        // The barycentric point is more precise than o + t·d far from the origin.
        let p = v[0] * (1.0 - hit.b1 - hit.b2) + v[1] * hit.b1 + v[2] * hit.b2;
        let r = self.geometry.refs[hit.tri as usize];
        SurfacePoint {
            p,
            ng,
            n_vertex,
            tc,
            color,
            tangent,
            material: self.scene.meshes[r.mesh as usize].material,
            tri: hit.tri,
        }
    }

    /// A point on triangle `tri` at barycentrics (b1, b2).
    pub fn point_on(&self, tri: u32, b1: f32, b2: f32) -> SurfacePoint {
        self.surface(&Hit { t: 0.0, tri, b1, b2 })
    }

    /// The probability that a ray travelling along `d` stops at (`tri`, b1, b2) rather than
    /// passing as if the triangle were not there: 0 on the back of a single-sided material
    /// (glTF `doubleSided: false`), 0 or 1 by the alpha test of `AlphaMode::Mask`, the alpha of
    /// `AlphaMode::Blend` (base colour alpha × texture alpha × `COLOR_0` alpha), else 1.
    pub fn coverage(&self, tri: u32, b1: f32, b2: f32, d: Vec3) -> f32 {
        let flags = self.geometry.filter[tri as usize];
        if flags & SINGLE_SIDED != 0 {
            let v = &self.geometry.verts[tri as usize];
            if (v[1] - v[0]).cross(v[2] - v[0]).dot(d) > 0.0 {
                return 0.0;
            }
        }
        if flags & NOT_OPAQUE == 0 {
            return 1.0;
        }
        let (m, idx) = self.corners(tri);
        let mat = &self.scene.materials[m.material];
        let alpha = || {
            let b = [1.0 - b1 - b2, b1, b2];
            let mut tc = TexCoords::default();
            if let Some(r) = &mat.base_color_texture {
                let set = if r.tex_coord == 1 { &m.uvs1 } else { &m.uvs };
                tc.0[(r.tex_coord as usize).min(1)] = lerp(set, idx, b).unwrap_or(Vec2::ZERO);
            }
            let color = lerp(&m.colors, idx, b).unwrap_or(Vec4::ONE);
            material::alpha(mat, &self.scene.textures, &tc, color)
        };
        match mat.alpha_mode {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Mask { cutoff } => (alpha() >= cutoff) as u8 as f32,
            AlphaMode::Blend => alpha().clamp(0.0, 1.0),
        }
    }

    /// Whether a ray with key `key` ([`World::ray_key`]) travelling along `d` stops at the hit:
    /// [`World::coverage`] decided by a hash of the key and the triangle.
    #[inline]
    pub fn stops(&self, tri: u32, b1: f32, b2: f32, d: Vec3, key: u64) -> bool {
        let c = self.coverage(tri, b1, b2, d);
        c >= 1.0 || (c > 0.0 && hash_uniform(key, tri as u64) < c)
    }

    /// The key of a ray's stochastic-opacity decisions: drawn from the path's sampler when the
    /// scene has `AlphaMode::Blend` geometry (0, and no draw, otherwise), so images stay a
    /// function of the seed.
    #[inline]
    pub fn ray_key(&self, rng: &mut Sampler) -> u64 {
        if self.stochastic { rng.key() } else { 0 }
    }

    /// The closest hit along `o + t·d`, t in (0, tmax), where the ray stops ([`World::stops`]).
    pub fn intersect(&self, o: Vec3, d: Vec3, tmax: f32, key: u64) -> Option<Hit> {
        self.geometry.intersect_filtered(o, d, tmax, |tri, b1, b2| self.stops(tri, b1, b2, d, key))
    }

    /// Whether a shadow ray is stopped on the open segment `o + t·d`, t in (0, tmax).
    pub fn occluded(&self, o: Vec3, d: Vec3, tmax: f32, key: u64) -> bool {
        self.geometry.occluded_filtered(o, d, tmax, |tri, b1, b2| self.stops(tri, b1, b2, d, key))
    }

    /// The clear coat at `s` seen from `wo` (`KHR_materials_clearcoat`); `None` without one.
    /// Its normal is the coat's normal map about the interpolated normal, turned to the side
    /// of `wo` as the base's shading normal is (the geometric normal where the map faces
    /// away). The integrator's surface vertex and the coat over an emitter ([`Self::emitted`]'s
    /// callers) both take it from here, so a coated lamp has one weight for both.
    pub fn coat(&self, s: &SurfacePoint, wo: Vec3) -> Option<crate::coat::Coat> {
        let m = &self.scene.materials[s.material];
        let (strength, roughness) = material::clearcoat(m, &self.scene.textures, &s.tc)?;
        let flip = if s.ng.dot(wo) >= 0.0 { 1.0 } else { -1.0 };
        let tangent = s.tangent.map(|t| scene::facing_tangent(t, flip));
        let mut n = material::coat_normal(m, &self.scene.textures, &s.tc, s.n_vertex * flip, tangent);
        if n.dot(wo) <= 0.0 {
            n = s.ng * flip;
        }
        Some(crate::coat::Coat::new(strength, roughness, n, wo))
    }

    /// Radiance leaving `s` towards `wo` (unit, away from the surface); emission is one-sided,
    /// on the side the vertex normals point to.
    pub fn emitted(&self, s: &SurfacePoint, wo: Vec3, l: Vec4) -> Vec4 {
        let m = &self.scene.materials[s.material];
        if m.unlit {
            // Seen from whichever side is visible: a single-sided back face is never hit.
            let rgb = material::unlit_rgb(m, &self.scene.textures, &s.tc, s.color);
            return self.units.rgb(rgb, self.upsampler, l);
        }
        if m.emissive == Vec3::ZERO || s.n_vertex.dot(wo) <= 0.0 {
            return Vec4::ZERO;
        }
        let rgb = material::emissive_rgb(m, &self.scene.textures, &s.tc);
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

/// A vertex attribute at barycentrics `b` of the corners `idx`; `None` when the mesh lacks it.
#[inline]
fn lerp<T>(a: &[T], idx: [usize; 3], b: [f32; 3]) -> Option<T>
where
    T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
{
    Some(*a.get(idx[0])? * b[0] + *a.get(idx[1])? * b[1] + *a.get(idx[2])? * b[2])
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
        .collect::<std::result::Result<_, _>>()?;
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

/// Offsets a ray origin off a surface along the geometric normal, on the side of `dir`,
/// by an amount relative to the coordinates' magnitude (f32 has 24 bits of mantissa) plus
/// `floor` ([`World::offset_floor`]) for points near the origin.
#[inline]
pub fn offset(p: Vec3, ng: Vec3, dir: Vec3, floor: f32) -> Vec3 {
    let eps = offset_distance(p, floor);
    if ng.dot(dir) >= 0.0 { p + ng * eps } else { p - ng * eps }
}

/// How far [`offset`] moves a point at `p`.
#[inline]
pub fn offset_distance(p: Vec3, floor: f32) -> f32 {
    1e-4 * (floor + p.abs().max_element())
}

/// [`World::offset_floor`] for a scene whose largest side is `size`: that size, at most 1, so
/// that a scene of ordinary size keeps the fixed floor (and its images their bits) and a tiny
/// one is offset in proportion to itself; 1 without triangles.
fn offset_floor(size: f32) -> f32 {
    if size.is_finite() && size > 0.0 { size.min(1.0) } else { 1.0 }
}
