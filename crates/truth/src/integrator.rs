//! The light transport estimator: unidirectional path tracing with next-event estimation,
//! multiple importance sampling (power heuristic) between BRDF/phase sampling and each of the
//! emissive triangles and the environment map, delta lights by NEE only, Russian roulette, and
//! free-flight sampling in a homogeneous medium with spectral MIS over the four hero wavelengths.

use crate::accel::Hit;
use crate::bsdf::{Brdf, DiffuseTransmissionLanes, FilmLanes, SheenLanes, SpecularLanes};
use crate::camera::CameraRay;
use crate::coat::Coat;
use crate::dielectric::Dielectric;
use crate::material;
use crate::medium::{Phase, phase_eval, phase_sample};
use crate::rng::Sampler;
use crate::sampling::{Frame, power_heuristic, triangle_barycentrics};
use crate::spectral::Wavelengths;
use crate::world::{World, offset, offset_distance};
use glam::{Vec3, Vec4};

/// Where a path scatters: a surface (BRDF in a shading frame; a see-through material mixes in
/// the rough dielectric with weight T·(1 − metallic); a clear coat mixes itself over all of
/// that, [`Coat`]) or a point in the medium.
// One lives on the stack per bounce; boxing the large variant would allocate per bounce.
#[allow(clippy::large_enum_variant)]
enum Vertex {
    Surface { brdf: Brdf, frame: Frame, ng: Vec3, glass: Option<(Dielectric, f32)>, coat: Option<Coat> },
    Medium { phase: Phase },
}

/// A direction sampled at a coated surface, with the estimator's weight f·|cos|/pdf and the
/// pdf for MIS (0 for a delta, which nothing else can find).
struct Scattered {
    wi: Vec3,
    crossed: bool,
    /// Crossed by the diffuse BTDF (`KHR_materials_diffuse_transmission`): a scattering event,
    /// unlike a refraction.
    diffuse: bool,
    weight: Vec4,
    pdf: f32,
}

/// (f·|cos|, pdf) of the material under any coat (see [`Vertex::eval`]).
fn eval_base(
    brdf: &Brdf,
    frame: &Frame,
    ng: Vec3,
    glass: &Option<(Dielectric, f32)>,
    wo: Vec3,
    wi: Vec3,
) -> (Vec4, f32) {
    let (lo, li) = (frame.to_local(wo), frame.to_local(wi));
    // The BRDF reflects only: both directions on the side of the (flipped) geometric normal.
    let above = ng.dot(wi) > 0.0;
    // With a diffuse transmission it transmits too, where `wi` is on the far side of both the
    // shading and the geometric plane (as the dielectric's transmission below).
    let bsdf = || {
        if above == (li.z > 0.0) {
            (brdf.eval(lo, li) * li.z.abs(), brdf.pdf(lo, li))
        } else {
            (Vec4::ZERO, 0.0)
        }
    };
    let Some((d, w)) = glass else {
        if brdf.diffuse_transmission.is_some() {
            return bsdf();
        }
        if !above {
            return (Vec4::ZERO, 0.0);
        }
        return (brdf.eval(lo, li) * li.z.max(0.0), brdf.pdf(lo, li));
    };
    let (f_o, p_o) = if brdf.diffuse_transmission.is_some() {
        bsdf()
    } else if above {
        (brdf.eval(lo, li) * li.z.max(0.0), brdf.pdf(lo, li))
    } else {
        (Vec4::ZERO, 0.0)
    };
    // A transmission must really cross the surface (shading and geometric normal agree).
    let (f_d, p_d) =
        if above == (li.z > 0.0) { (d.eval(lo, li) * li.z.abs(), d.pdf(lo, li)) } else { (Vec4::ZERO, 0.0) };
    (f_o * (1.0 - w) + f_d * *w, p_o * (1.0 - w) + p_d * w)
}

impl Vertex {
    /// (f·|cos| or phase value, pdf of sampling `wi`) for unit world directions; `wo` points
    /// back along the path (for a coated surface, the `wo` its coat was made for).
    fn eval(&self, wo: Vec3, wi: Vec3) -> (Vec4, f32) {
        match self {
            Vertex::Surface { brdf, frame, ng, glass, coat } => {
                let (fb, pb) = eval_base(brdf, frame, *ng, glass, wo, wi);
                let Some(c) = coat else { return (fb, pb) };
                let (fc, pc) = c.eval(*ng, wo, wi);
                (fb * (1.0 - c.weight) + Vec4::splat(fc * c.weight), pb * (1.0 - c.p) + pc * c.p)
            }
            Vertex::Medium { phase } => {
                let p = phase_eval(*phase, (-wo).dot(wi));
                (Vec4::splat(p), p)
            }
        }
    }

    /// Samples a coated surface's mixture: the coat lobe with probability p, else the base as
    /// an uncoated surface samples it. `None` for a lost sample or a vertex without a coat.
    fn sample_coated(&self, wo: Vec3, rng: &mut Sampler) -> Option<Scattered> {
        let Vertex::Surface { brdf, frame, ng, glass, coat: Some(c) } = self else { return None };
        let lo = frame.to_local(wo);
        let (wi, crossed, delta, diffuse) = if rng.uniform() < c.p {
            (c.sample(wo, rng.next2())?, false, None, false)
        } else if let Some((d, wt)) = glass
            && rng.uniform() < *wt
        {
            let x = d.sample(lo, rng.uniform(), rng.next2())?;
            let delta = x.specular.then(|| x.f * (x.wi.z.abs() / x.pdf));
            (frame.to_world(x.wi), x.transmitted, delta, false)
        } else {
            // Below the shading plane only by a diffuse transmission.
            let x = brdf.sample(lo, rng.uniform(), rng.next2())?;
            (frame.to_world(x.wi), x.wi.z < 0.0, None, x.wi.z < 0.0)
        };
        if (ng.dot(wi) <= 0.0) != crossed {
            return None;
        }
        if let Some(weight) = delta {
            // Drawn with probability (1 − p)·wt, weighing (1 − w)·wt times its own weight.
            return Some(Scattered {
                wi,
                crossed,
                diffuse,
                weight: weight * ((1.0 - c.weight) / (1.0 - c.p)),
                pdf: 0.0,
            });
        }
        let (fv, pdf) = self.eval(wo, wi);
        (pdf > 0.0 && pdf.is_finite()).then(|| Scattered { wi, crossed, diffuse, weight: fv / pdf, pdf })
    }
}

pub struct Integrator<'w, 's> {
    pub world: &'w World<'s>,
    /// Paths of one scattering vertex only (direct lighting), to compare like for like with
    /// a rasteriser.
    pub direct_only: bool,
    /// Hard cap on scattering events (Russian roulette ends paths long before it in practice).
    pub max_depth: u32,
    /// Replace the glTF BRDF by Lambert (base/π) everywhere; for comparisons with renderers
    /// that lack the glTF BRDF.
    pub lambert: bool,
}

#[inline]
fn mean(v: Vec4) -> f32 {
    v.element_sum() * 0.25
}

/// exp(−σt·len) per lane, with 0·∞ = 0 (a transparent lane over an infinite segment).
#[inline]
fn beer(sigma_t: Vec4, len: f32) -> Vec4 {
    Vec4::from_array(sigma_t.to_array().map(|s| if s == 0.0 { 1.0 } else { (-s * len).exp() }))
}

impl Integrator<'_, '_> {
    fn transmittance(&self, o: Vec3, d: Vec3, dist: f32, l: Vec4) -> Vec4 {
        match &self.world.medium {
            Some(m) => match m.overlap(o, d, dist) {
                Some((t0, t1)) => beer(m.coefficients(l).1, t1 - t0),
                None => Vec4::ONE,
            },
            None => Vec4::ONE,
        }
    }

    /// Light arriving at `p` from every delta light, one emissive-triangle sample and one
    /// environment-map sample, times the vertex's scattering function, MIS-weighted against the
    /// vertex's own sampling.
    fn direct(
        &self,
        p: Vec3,
        ng: Option<Vec3>,
        wo: Vec3,
        v: &Vertex,
        wl: &Wavelengths,
        rng: &mut Sampler,
    ) -> Vec4 {
        let w = self.world;
        let l = wl.0;
        let origin = |dir: Vec3| ng.map_or(p, |n| offset(p, n, dir, w.offset_floor));
        let mut sum = Vec4::ZERO;
        for light in &w.delta_lights {
            let Some(s) = light.sample(p) else { continue };
            let (f, _) = v.eval(wo, s.wi);
            if f == Vec4::ZERO {
                continue;
            }
            let o = origin(s.wi);
            let tmax =
                if s.dist.is_finite() { (s.dist - (o - p).length()) * (1.0 - 1e-5) } else { f32::INFINITY };
            if w.occluded(o, s.wi, tmax, w.ray_key(rng)) {
                continue;
            }
            sum += f * light.spectrum.eval4(l) * s.scale * self.transmittance(o, s.wi, tmax, l);
        }
        let (u, u2) = (rng.uniform(), rng.next2());
        if let Some((tri, pmf)) = w.emitters.sample(u) {
            let (_, b1, b2) = triangle_barycentrics(u2);
            let q = w.point_on(tri, b1, b2);
            let to = q.p - p;
            let d2 = to.length_squared();
            let dist = d2.sqrt();
            if dist > 0.0 {
                let wi = to / dist;
                // A sampled point where the emitter is cut out or see-through emits with the
                // probability a ray would stop there (what BRDF sampling finds).
                let le = self.coated(w.emitted(&q, -wi, l), &q, -wi) * w.coverage(tri, b1, b2, wi);
                let cos_l = q.ng.dot(wi).abs();
                if le != Vec4::ZERO && cos_l > 0.0 {
                    let (f, pdf_v) = v.eval(wo, wi);
                    if f != Vec4::ZERO {
                        let pdf_l = pmf / w.areas[tri as usize] * d2 / cos_l;
                        // Offset both ends off their surfaces: a shadow ray aimed at the exact
                        // light point would hit the light itself first when it leaves at an
                        // oblique angle (the origin offset brings it nearer the light's plane).
                        let o = origin(wi);
                        let end = offset(q.p, q.ng, -wi, w.offset_floor);
                        let seg = end - o;
                        let tmax = seg.length();
                        let dir = seg / tmax;
                        if !w.occluded(o, dir, tmax, w.ray_key(rng)) {
                            let mis = power_heuristic(pdf_l, pdf_v);
                            sum += f * le * self.transmittance(o, wi, tmax, l) * (mis / pdf_l);
                        }
                    }
                }
            }
        }
        if let Some(env) = &w.env_map {
            let u: [f32; 6] = std::array::from_fn(|_| rng.uniform());
            if let Some(es) = env.sample(u) {
                let (f, pdf_v) = v.eval(wo, es.wi);
                if f != Vec4::ZERO {
                    let le = env.texel_radiance(es.texel, l);
                    let o = origin(es.wi);
                    if le != Vec4::ZERO && !w.occluded(o, es.wi, f32::INFINITY, w.ray_key(rng)) {
                        let mis = power_heuristic(es.pdf, pdf_v);
                        sum += f * le * self.transmittance(o, es.wi, f32::INFINITY, l) * (mis / es.pdf);
                    }
                }
            }
        }
        sum
    }

    /// Radiance arriving at `o` from direction `-d` at the four wavelengths `wl`.
    pub fn radiance(&self, o: Vec3, d: Vec3, wl: &Wavelengths, rng: &mut Sampler) -> Vec4 {
        self.clipped_radiance(o, d, 0.0, f32::INFINITY, wl, rng)
    }

    /// Radiance along a camera ray: the near and far planes clip the surfaces in front of and
    /// beyond them (as the rasteriser's clipping does), not the medium, which attenuates and
    /// scatters from the eye.
    pub fn camera_radiance(&self, ray: CameraRay, wl: &Wavelengths, rng: &mut Sampler) -> Vec4 {
        self.clipped_radiance(ray.o, ray.d, ray.t_near, ray.t_far, wl, rng)
    }

    /// [`Self::radiance`] with surfaces closer than `t_near` or farther than `t_far` along the
    /// first segment ignored.
    fn clipped_radiance(
        &self,
        mut o: Vec3,
        mut d: Vec3,
        mut t_near: f32,
        mut t_far: f32,
        wl: &Wavelengths,
        rng: &mut Sampler,
    ) -> Vec4 {
        let w = self.world;
        let l = wl.0;
        // Path throughput for the hero-wavelength MIS (Wilkie et al. 2014): `f` is the product
        // of each lane's own path contribution, `p` of the pdfs each lane would have sampled the
        // same decisions with (relative to the hero, which stays at 1). Lane i's estimate is
        // f_i / mean_j(p_j): the balance heuristic over whole paths, not over single events.
        let mut f = Vec4::ONE;
        let mut p = Vec4::ONE;
        let mut radiance = Vec4::ZERO;
        // Solid-angle pdf of the direction that produced the current ray; 0 for camera rays
        // (so emitters hit directly get full weight).
        let mut prev_pdf = 0.0f32;
        let mut depth = 0u32;
        // Scattering events that count as bounces for `direct_only`: refractions through
        // see-through surfaces do not (direct light seen through glass is direct light).
        let mut bounces = 0u32;
        // The see-through material whose closed volume the path is in (KHR_materials_volume).
        let mut inside: Option<usize> = None;
        loop {
            let hit = if t_near > 0.0 {
                // Traced from the near plane, with distances still counted from the eye.
                w.intersect(o + d * t_near, d, t_far - t_near, w.ray_key(rng))
                    .map(|h| Hit { t: h.t + t_near, ..h })
            } else {
                w.intersect(o, d, t_far, w.ray_key(rng))
            };
            t_near = 0.0;
            t_far = f32::INFINITY;
            let mut t_hit = hit.map_or(f32::INFINITY, |h| h.t);
            // Inside an absorbing volume: Beer's law per lane up to the next surface (the same
            // for every lane's pdf, so only `f` changes).
            if let Some(m) = inside
                && let Some(sigma) = w.absorption[m]
                && t_hit.is_finite()
            {
                f *= beer(material::absorption_at(sigma, l), t_hit);
            }
            // The water surface, from below, comes before anything above it.
            let at_surface = w.surface.as_ref().and_then(|s| s.crossing(o, d)).filter(|&t| t <= t_hit);
            if let Some(t) = at_surface {
                t_hit = t;
            }

            // Free flight through the medium, sampled at the hero wavelength, weighted by the
            // balance heuristic over all four (the one-sample spectral MIS estimator).
            if let Some(m) = &w.medium
                && let Some((t0, t1)) = m.overlap(o, d, t_hit)
            {
                let (sigma_s, sigma_t) = m.coefficients(l);
                let u = rng.uniform();
                let t = if sigma_t.x > 0.0 { t0 - (1.0 - u).ln() / sigma_t.x } else { f32::INFINITY };
                if t < t1 {
                    let tr = beer(sigma_t, t - t0);
                    let pdf = sigma_t * tr;
                    if pdf.x <= 0.0 {
                        break;
                    }
                    f *= sigma_s * tr / pdf.x;
                    p *= pdf / pdf.x;
                    let pos = o + d * t;
                    let vtx = Vertex::Medium { phase: m.phase };
                    if self.direct_only && bounces >= 1 {
                        break;
                    }
                    radiance += f / mean(p) * self.direct(pos, None, -d, &vtx, wl, rng);
                    if depth + 1 >= self.max_depth {
                        break;
                    }
                    let (wi, pdf) = phase_sample(m.phase, d, rng.next2());
                    // phase/pdf = 1 for exact sampling; beta unchanged.
                    prev_pdf = pdf;
                    o = pos;
                    d = wi;
                    depth += 1;
                    bounces += 1;
                    if !self.roulette(&mut f, p, depth, rng) {
                        break;
                    }
                    continue;
                }
                let tr = beer(sigma_t, t1 - t0);
                if tr.x <= 0.0 {
                    break;
                }
                f *= tr / tr.x;
                p *= tr / tr.x;
            }

            if let (Some(t), Some(surf)) = (at_surface, &w.surface) {
                // Snell's window: the sky refracted in, T·n²·L_air (zero T under TIR).
                let r = surf.reflectance(d.y);
                if let Some(sky) = &surf.sky
                    && r < 1.0
                {
                    radiance += f / mean(p) * sky.eval4(l) * ((1.0 - r) * surf.ior * surf.ior);
                }
                // The mirror direction with probability R: unbiased for the reflected light
                // (R/R = 1), always under TIR. A specular vertex: light sampling cannot find
                // what lies along it, so what it hits gets full MIS weight (prev_pdf = 0).
                if (self.direct_only && bounces >= 1) || depth + 1 > self.max_depth || rng.uniform() >= r {
                    break;
                }
                let pos = o + d * t;
                o = Vec3::new(pos.x, surf.height - offset_distance(pos, self.world.offset_floor), pos.z);
                d = Vec3::new(d.x, -d.y, d.z);
                prev_pdf = 0.0;
                depth += 1;
                bounces += 1;
                if !self.roulette(&mut f, p, depth, rng) {
                    break;
                }
                continue;
            }

            let Some(hit) = hit else {
                if let Some(env) = &w.environment {
                    radiance += f / mean(p) * env.eval4(l);
                }
                if let Some(env) = &w.env_map {
                    // Camera rays and specular vertices (prev_pdf = 0) cannot be found by
                    // light sampling: full weight.
                    let mis = if prev_pdf > 0.0 { power_heuristic(prev_pdf, env.pdf(d)) } else { 1.0 };
                    radiance += f / mean(p) * env.radiance(d, l) * mis;
                }
                break;
            };
            let s = w.surface(&hit);
            let wo = -d;

            let le = self.coated(w.emitted(&s, wo, l), &s, wo);
            if le != Vec4::ZERO {
                let mis = if prev_pdf > 0.0 {
                    let pdf_l = w.emitters.pmf[s.tri as usize] / w.areas[s.tri as usize] * hit.t * hit.t
                        / s.ng.dot(wo).abs().max(1e-12);
                    power_heuristic(prev_pdf, pdf_l)
                } else {
                    1.0
                };
                radiance += f / mean(p) * le * mis;
            }
            let mat = &w.scene.materials[s.material];
            // Past a direct-only path's one bounce, light still reaches it through see-through
            // surfaces: refractions are not bounces on the light's side either (as on the
            // camera's). The path goes on through transmissions only — a reflection would be a
            // second bounce — until it meets an emitter or the sky. Only where the scene has
            // light a path can meet: punctual lights cannot be hit.
            let passing = self.direct_only && bounces >= 1;
            if (passing && (self.lambert || mat.transmission.is_none() || !w.has_light_to_meet()))
                || depth + 1 > self.max_depth
            {
                break;
            }
            if mat.unlit {
                // Unlit surfaces reflect nothing: the path ends in their colour.
                break;
            }

            // Double-sided materials face their normals towards the viewer; a single-sided one
            // is hit from the front only (`World::coverage`), so the flip never applies to it.
            let front = s.ng.dot(wo) >= 0.0;
            let flip = if front { 1.0 } else { -1.0 };
            let ng = s.ng * flip;
            // Seen from behind, the tangent frame turns with the normal (`scene::facing_tangent`).
            let tangent = s.tangent.map(|t| scene::facing_tangent(t, flip));
            let mut ns = material::mapped_normal(mat, &w.scene.textures, &s.tc, s.n_vertex * flip, tangent);
            if ns.dot(wo) <= 0.0 {
                ns = ng;
            }
            let base = material::base_reflectance(
                mat,
                &w.materials[s.material],
                &w.scene.textures,
                w.upsampler,
                &s.tc,
                s.color,
                l,
            );
            let (metallic, roughness) = material::metallic_roughness(mat, &w.scene.textures, &s.tc);
            let film = material::film(mat, &w.scene.textures, &s.tc).map(|(weight, film)| FilmLanes {
                weight,
                film,
                lambda: l,
            });
            let anisotropy =
                if self.lambert { None } else { material::anisotropy(mat, &w.scene.textures, &s.tc) };
            let brdf = if self.lambert {
                Brdf::lambertian(base)
            } else {
                let specular = material::specular(mat, &w.scene.textures, &s.tc)
                    .map(|(weight, f0)| SpecularLanes::new(weight, f0, w.upsampler, l));
                let sheen = material::sheen(mat, &w.scene.textures, &s.tc)
                    .map(|(color, roughness)| SheenLanes::new(color, roughness, w.upsampler, l));
                // Past a direct-only path's bounce it goes on through refractions only: a diffuse
                // transmission there would be a second bounce.
                let dt = material::diffuse_transmission(mat, &w.scene.textures, &s.tc)
                    .filter(|_| !passing)
                    .map(|(weight, color)| DiffuseTransmissionLanes::new(weight, color, w.upsampler, l));
                Brdf::new(base, metallic, roughness)
                    .with_ior(mat.ior)
                    .with_film(film)
                    .with_specular(specular)
                    .with_sheen(sheen)
                    .with_anisotropy(anisotropy.map(|(_, strength)| strength))
                    .with_diffuse_transmission(dt)
            };
            // An anisotropic lobe's frame has x along its direction (see-through materials: the
            // BRDF's share only; the dielectric's lobes stay isotropic).
            let frame = match anisotropy {
                Some((dir, _)) if brdf.alphas.is_some() => material::anisotropy_frame(ns, tangent, dir),
                _ => Frame::from_normal(ns),
            };
            let glass =
                match (mat.transmission.as_ref(), self.lambert) {
                    (Some(t), false) => material::transmission(mat, &w.scene.textures, &s.tc).map(|weight| {
                        if t.disperses() {
                            // Each wavelength refracts its own way: the hero carries the path on
                            // alone (its pdf over the four lanes' mean, so 4× its own estimate), an
                            // unbiased single-wavelength estimate from here on.
                            f = Vec4::new(f.x, 0.0, 0.0, 0.0);
                            p = Vec4::new(p.x, 0.0, 0.0, 0.0);
                        }
                        let ior = t.ior_at(mat.ior, f64::from(l.x)) as f32;
                        let thin = t.volume.is_none();
                        let eta = if thin || front { ior } else { 1.0 / ior };
                        let alpha = (roughness * roughness).clamp(crate::bsdf::MIN_ALPHA, 1.0);
                        let film = film.filter(|f| f.weight > 0.0).map(|film| {
                            crate::dielectric::InterfaceFilm { film, ior, inside: !thin && !front }
                        });
                        (Dielectric { tint: base, alpha, eta, thin, film }, weight * (1.0 - metallic))
                    }),
                    _ => None,
                };
            let coat = if self.lambert { None } else { w.coat(&s, wo) };
            let coat = coat.map(|c| {
                let a = brdf.albedo_estimate(frame.to_local(wo).z);
                // A see-through base returns all it does not absorb, reflected or transmitted.
                c.balanced(glass.map_or(a, |(_, wt)| a * (1.0 - wt) + wt))
            });
            let vtx = Vertex::Surface { brdf, frame, ng, glass, coat };

            if !passing {
                radiance += f / mean(p) * self.direct(s.p, Some(ng), wo, &vtx, wl, rng);
            }

            let lo = frame.to_local(wo);
            // `diffuse`: crossed by the diffuse BTDF, which scatters (a bounce) rather than
            // refracts.
            let (wi, crossed, diffuse) = if coat.is_some() {
                if passing && glass.is_none() {
                    break;
                }
                let Some(x) = vtx.sample_coated(wo, rng) else { break };
                if passing && !x.crossed {
                    break;
                }
                f *= x.weight;
                // A delta (pdf 0), or passing through where this vertex sampled no light: what
                // the path meets next has full weight.
                prev_pdf = if passing { 0.0 } else { x.pdf };
                (x.wi, x.crossed, x.diffuse)
            } else if let Some((d, wt)) = glass {
                // A delta lobe's weight, when the dielectric sampled one.
                let mut delta = None;
                let (wi, crossed, diffuse) = if rng.uniform() < wt {
                    let Some(x) = d.sample(lo, rng.uniform(), rng.next2()) else { break };
                    if x.specular {
                        delta = Some(x.f * (x.wi.z.abs() / x.pdf));
                    }
                    (frame.to_world(x.wi), x.transmitted, false)
                } else {
                    let Some(x) = brdf.sample(lo, rng.uniform(), rng.next2()) else { break };
                    (frame.to_world(x.wi), x.wi.z < 0.0, x.wi.z < 0.0)
                };
                if (ng.dot(wi) <= 0.0) != crossed || (passing && !crossed) {
                    break;
                }
                if let Some(weight) = delta {
                    // Chosen with probability wt, weighing wt: its own weight. No other lobe
                    // and no light sampling can find its direction (prev_pdf = 0, full MIS
                    // weight to what it hits).
                    f *= weight;
                    prev_pdf = 0.0;
                } else {
                    // The mixture's value and pdf (a one-sample estimate of both lobes).
                    let (fv, pdf) = vtx.eval(wo, wi);
                    if pdf <= 0.0 || !pdf.is_finite() {
                        break;
                    }
                    f *= fv / pdf;
                    // Passing through, this vertex sampled no light, so what the path meets
                    // next has full weight.
                    prev_pdf = if passing { 0.0 } else { pdf };
                }
                (wi, crossed, diffuse)
            } else {
                if passing {
                    break;
                }
                let Some(bs) = brdf.sample(lo, rng.uniform(), rng.next2()) else { break };
                let wi = frame.to_world(bs.wi);
                // Below the shading plane only by a diffuse transmission, which must cross the
                // geometric plane too.
                let crossed = bs.wi.z < 0.0;
                if (ng.dot(wi) <= 0.0) != crossed {
                    break;
                }
                // The BRDF pdf is the same for every lane, so it only scales `f`.
                f *= bs.f * (bs.wi.z.abs() / bs.pdf);
                prev_pdf = bs.pdf;
                (wi, crossed, crossed)
            };
            o = offset(s.p, ng, wi, self.world.offset_floor);
            d = wi;
            depth += 1;
            // A closed volume (`KHR_materials_volume`) is entered or left by whatever crosses its
            // boundary, refraction or diffuse transmission.
            if crossed && !self.lambert && mat.transmission.as_ref().is_some_and(|t| t.volume.is_some()) {
                inside = if front { Some(s.material) } else { None };
            }
            if !crossed || diffuse {
                bounces += 1;
            }
            if !self.roulette(&mut f, p, depth, rng) {
                break;
            }
        }
        radiance
    }

    /// Emission `le` leaving `s` towards `wo` through its clear coat, if any: 1 − w of it
    /// (`KHR_materials_clearcoat`). The Lambertian comparison mode has no coat.
    fn coated(&self, le: Vec4, s: &crate::world::SurfacePoint, wo: Vec3) -> Vec4 {
        if le == Vec4::ZERO || self.lambert {
            return le;
        }
        match self.world.coat(s, wo) {
            Some(c) => le * (1.0 - c.weight),
            None => le,
        }
    }

    /// Russian roulette from the fourth vertex on, survival ∝ the largest throughput lane.
    fn roulette(&self, f: &mut Vec4, p: Vec4, depth: u32, rng: &mut Sampler) -> bool {
        if depth < 4 || self.direct_only {
            return true;
        }
        let q = (*f / mean(p)).max_element().min(0.95);
        if q.is_nan() || q <= 0.0 || rng.uniform() >= q {
            return false;
        }
        *f /= q;
        true
    }
}

#[cfg(test)]
#[path = "integrator_tests.rs"]
mod tests;

#[cfg(test)]
#[path = "coat_tests.rs"]
mod coat_tests;

#[cfg(test)]
#[path = "specular_tests.rs"]
mod specular_tests;

#[cfg(test)]
#[path = "sheen_tests.rs"]
mod sheen_tests;

#[cfg(test)]
#[path = "anisotropy_tests.rs"]
mod anisotropy_tests;

#[cfg(test)]
#[path = "diffuse_transmission_tests.rs"]
mod diffuse_transmission_tests;
