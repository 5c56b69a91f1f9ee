//! The rough dielectric BSDF of see-through materials (`KHR_materials_transmission`): GGX
//! microfacet reflection and refraction (Walter et al. 2007, "Microfacet models for refraction
//! through rough surfaces"), the exact unpolarised Fresnel term at the microfacet normal
//! (`scene::transmission::fresnel_dielectric`, total internal reflection included), the
//! height-correlated Smith masking-shadowing, and visible-normal sampling (Heitz 2018) followed
//! by the choice of reflection or refraction with probability F — so a smooth interface's
//! estimate carries weight one whichever it takes.
//!
//! Directions are local, normal +z, and `wo` is always above (the integrator turns the
//! shading frame towards the viewer); `eta` is the index of the far side over that of the
//! `wo` side (the material's index when entering, its inverse when leaving). Transmission
//! carries the base colour per lane (the glTF BTDF's tint) and, for radiance travelling with
//! the camera path, the 1/η² of the radiance's change of solid angle (pbrt-v4's convention:
//! non-symmetric scattering, camera paths carry radiance).
//!
//! An *index-matched* interface (η = 1, `KHR_materials_ior` 1.0) reflects nothing and sends
//! every microfacet's refraction straight on, whatever the roughness: a delta, sampled as
//! such and evaluated as zero (pbrt-v4's `eta == 1` case).
//!
//! A *thin-walled* surface (no `KHR_materials_volume`) is a sheet whose two interfaces cancel:
//! its transmission lobe is the reflection lobe mirrored through the surface, with 1 − F of
//! the light (no 1/η², no inside).

use glam::{Vec3, Vec4};
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct Dielectric {
    /// The transmission tint per lane (the base colour).
    pub tint: Vec4,
    pub alpha: f32,
    /// Index of the far side over the `wo` side (thin-walled: the material's index).
    pub eta: f32,
    pub thin: bool,
    /// A thin film on the interface (`KHR_materials_iridescence`), which replaces its Fresnel
    /// term by the film's reflectance per lane, as on the opaque BRDF; 1 − that is transmitted
    /// (a clear film absorbs nothing). Without one, the arithmetic is the plain interface's.
    pub film: Option<InterfaceFilm>,
}

/// The film on a see-through interface at the lanes' wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct InterfaceFilm {
    pub film: crate::bsdf::FilmLanes,
    /// The material's index: the film's substrate.
    pub ior: f32,
    /// The path is inside the volume, meeting the film from the substrate's side: the film's
    /// reflectance is the same from either side of a clear stack (reciprocity and energy
    /// conservation), at the outside angle Snell's law gives; beyond the critical angle every
    /// lane reflects.
    pub inside: bool,
}

/// A sampled direction: BSDF value (per lane), pdf (solid angle) and whether it crossed.
pub struct DielectricSample {
    pub wi: Vec3,
    pub f: Vec4,
    pub pdf: f32,
    pub transmitted: bool,
    /// A delta (an index-matched interface's straight pass): `f`·|cos θ|/`pdf` is its weight,
    /// and neither [`Dielectric::eval`] nor [`Dielectric::pdf`] sees it.
    pub specular: bool,
}

/// |η − 1| under which an interface counts as index-matched. Within it the rough refraction
/// lobe is under 10⁻⁴ rad wide and reflects under 10⁻⁸, and nearer 1 its half vector
/// wo + η·wi drowns in rounding (pdfs past 10¹⁹, lost samples).
const INDEX_MATCHED: f32 = 1e-4;

fn fresnel(cos_i: f32, eta: f32) -> f32 {
    scene::transmission::fresnel_dielectric(f64::from(cos_i), f64::from(eta)) as f32
}

/// Refraction of `wo` (above) about the microfacet normal `m` into the far side of relative
/// index `eta`; `None` under total internal reflection.
pub fn refract(wo: Vec3, m: Vec3, eta: f32) -> Option<Vec3> {
    let c = wo.dot(m);
    let sin2_t = (1.0 - c * c).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / eta + (c / eta - cos_t) * m).normalize())
}

impl Dielectric {
    /// The interface's reflectance at a microfacet seen at cosine `c`: per lane, and the one
    /// value the sampler chooses reflection with (their mean). Only called with a film.
    fn film_fresnel(&self, c: f32, fl: &InterfaceFilm) -> (Vec4, f32) {
        let f = fresnel(c, self.eta);
        let c = f64::from(c);
        let outside = if fl.inside {
            let sin2 = (1.0 - c * c).max(0.0) * f64::from(fl.ior) * f64::from(fl.ior);
            (sin2 < 1.0).then(|| (1.0 - sin2).sqrt())
        } else {
            Some(c)
        };
        let lanes = Vec4::from_array(std::array::from_fn(|i| {
            outside.map_or(1.0, |co| {
                fl.film.film.over_dielectric(f64::from(fl.film.lambda[i]), co, f64::from(fl.ior)) as f32
            })
        }));
        let per_lane = Vec4::splat(f) + (lanes - Vec4::splat(f)) * fl.film.weight;
        (per_lane, per_lane.element_sum() * 0.25)
    }

    /// Equal indices on both sides (not a thin sheet, whose transmission is the mirrored
    /// reflection lobe): wi = −wo, with no reflection.
    pub fn index_matched(&self) -> bool {
        !self.thin && (self.eta - 1.0).abs() < INDEX_MATCHED
    }

    fn d(&self, m: Vec3) -> f32 {
        if m.z <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let t = m.z * m.z * (a2 - 1.0) + 1.0;
        a2 / (PI * t * t)
    }

    /// Smith Λ of direction w.
    fn lambda(&self, w: Vec3) -> f32 {
        let c2 = w.z * w.z;
        if c2 <= 0.0 {
            return f32::INFINITY;
        }
        let tan2 = (1.0 - c2).max(0.0) / c2;
        0.5 * ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0)
    }

    /// Height-correlated masking-shadowing of the pair.
    fn g2(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Visible-normal density of `m` seen from `wo`.
    fn pdf_m(&self, wo: Vec3, m: Vec3) -> f32 {
        self.g1(wo) * self.d(m) * wo.dot(m).max(0.0) / wo.z
    }

    /// The microfacet normal between `wo` and `wi`, and whether `wi` is a transmission; `None`
    /// for a pair no microfacet connects (any pair, across an index-matched interface).
    fn half(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, bool)> {
        if wi.z == 0.0 || wo.z <= 0.0 || self.index_matched() {
            return None;
        }
        let transmitted = wi.z < 0.0;
        let m = if !transmitted {
            wo + wi
        } else if self.thin {
            wo + Vec3::new(wi.x, wi.y, -wi.z)
        } else {
            wo + wi * self.eta
        };
        if m.length_squared() == 0.0 {
            return None;
        }
        let m = m.normalize();
        let m = if m.z < 0.0 { -m } else { m };
        // Both directions on the microfacet's proper sides.
        let wi_side = if transmitted && !self.thin {
            -wi
        } else if transmitted {
            Vec3::new(wi.x, wi.y, -wi.z)
        } else {
            wi
        };
        (wo.dot(m) > 0.0 && wi_side.dot(m) > 0.0).then_some((m, transmitted))
    }

    /// f(wo, wi) per lane.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec4 {
        let Some((m, transmitted)) = self.half(wo, wi) else { return Vec4::ZERO };
        if let Some(fl) = &self.film {
            let (f, _) = self.film_fresnel(wo.dot(m), fl);
            let (d, g) = (self.d(m), self.g2(wo, wi));
            if !transmitted {
                return f * (d * g / (4.0 * wo.z * wi.z));
            }
            if self.thin {
                let r = Vec3::new(wi.x, wi.y, -wi.z);
                return self.tint * (Vec4::ONE - f) * (d * self.g2(wo, r) / (4.0 * wo.z * r.z));
            }
            let (om, im) = (wo.dot(m), wi.dot(m));
            let denom = im + om / self.eta;
            let k = d * g * (im * om / (wi.z * wo.z * denom * denom)).abs();
            return self.tint * (Vec4::ONE - f) * (k / (self.eta * self.eta));
        }
        let f = fresnel(wo.dot(m), self.eta);
        let (d, g) = (self.d(m), self.g2(wo, wi));
        if !transmitted {
            return Vec4::splat(f * d * g / (4.0 * wo.z * wi.z));
        }
        if self.thin {
            let r = Vec3::new(wi.x, wi.y, -wi.z);
            return self.tint * ((1.0 - f) * d * self.g2(wo, r) / (4.0 * wo.z * r.z));
        }
        let (om, im) = (wo.dot(m), wi.dot(m));
        let denom = im + om / self.eta;
        let ft = (1.0 - f) * d * g * (im * om / (wi.z * wo.z * denom * denom)).abs();
        self.tint * (ft / (self.eta * self.eta))
    }

    /// The pdf [`Self::sample`] draws `wi` with.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let Some((m, transmitted)) = self.half(wo, wi) else { return 0.0 };
        let f = match &self.film {
            Some(fl) => self.film_fresnel(wo.dot(m), fl).1,
            None => fresnel(wo.dot(m), self.eta),
        };
        let pm = self.pdf_m(wo, m);
        if !transmitted {
            return pm * f / (4.0 * wo.dot(m));
        }
        if self.thin {
            return pm * (1.0 - f) / (4.0 * wo.dot(m));
        }
        let (om, im) = (wo.dot(m), wi.dot(m));
        let denom = im + om / self.eta;
        pm * (1.0 - f) * im.abs() / (denom * denom)
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<DielectricSample> {
        if wo.z <= 0.0 {
            return None;
        }
        if self.index_matched() {
            let wi = -wo;
            return Some(DielectricSample {
                wi,
                f: self.tint / (self.eta * self.eta * wi.z.abs()),
                pdf: 1.0,
                transmitted: true,
                specular: true,
            });
        }
        let m = crate::bsdf::visible_normal(self.alpha, wo, u);
        let f = match &self.film {
            Some(fl) => self.film_fresnel(wo.dot(m), fl).1,
            None => fresnel(wo.dot(m), self.eta),
        };
        let r = 2.0 * wo.dot(m) * m - wo;
        let wi = if u_lobe < f {
            r
        } else if self.thin {
            Vec3::new(r.x, r.y, -r.z)
        } else {
            refract(wo, m, self.eta)?
        };
        let transmitted = u_lobe >= f;
        // A sample on the wrong side (a reflection below the surface, a refraction above it) is
        // lost, as the metallic-roughness BRDF's are.
        if (wi.z < 0.0) != transmitted || wi.z == 0.0 {
            return None;
        }
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0 && pdf.is_finite()).then(|| DielectricSample {
            wi,
            f: self.eval(wo, wi),
            pdf,
            transmitted,
            specular: false,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Sampler;

    fn dir(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    fn glass(alpha: f32, eta: f32, thin: bool) -> Dielectric {
        Dielectric { tint: Vec4::ONE, alpha, eta, thin, film: None }
    }

    /// ∫ f·|cos| over the sphere by quadrature, ∫ pdf, the sampler's estimate of the first,
    /// and the energy ∫ f·|cos| with transmission counted as power (× η², undoing the
    /// radiance's change of solid angle).
    fn albedo(b: &Dielectric, wo: Vec3) -> (f32, f32, f32, f32) {
        let (nt, np) = (1200, 300);
        let (mut alb, mut ip, mut energy) = (0.0f64, 0.0f64, 0.0f64);
        for i in 0..nt {
            // cos θ from −1 to 1.
            let c = -1.0 + 2.0 * (i as f32 + 0.5) / nt as f32;
            for j in 0..np {
                let phi = 2.0 * PI * (j as f32 + 0.5) / np as f32;
                let s = (1.0 - c * c).max(0.0).sqrt();
                let wi = Vec3::new(s * phi.cos(), s * phi.sin(), c);
                let dw = (2.0 / nt as f32) * (2.0 * PI / np as f32);
                let v = f64::from(b.eval(wo, wi).x * c.abs() * dw);
                alb += v;
                energy += if c < 0.0 && !b.thin { v * f64::from(b.eta * b.eta) } else { v };
                ip += f64::from(b.pdf(wo, wi) * dw);
            }
        }
        let mut s = Sampler::new(3, 4);
        let n = 200_000;
        let mut est = 0.0f64;
        for _ in 0..n {
            if let Some(x) = b.sample(wo, s.uniform(), s.next2()) {
                est += f64::from(x.f.x * x.wi.z.abs() / x.pdf);
            }
        }
        (alb as f32, ip as f32, (est / n as f64) as f32, energy as f32)
    }

    /// Rough interfaces, entering and leaving, and thin sheets: the pdf integrates to at most
    /// one, the sampler's estimate of ∫ f·|cos| equals the quadrature's, and no energy is made.
    #[test]
    fn sampling_matches_the_pdf_and_keeps_energy() {
        for (alpha, eta, thin) in
            [(0.3, 1.5, false), (0.5, 1.0 / 1.5, false), (0.2, 1.33, false), (0.4, 1.5, true)]
        {
            let b = glass(alpha, eta, thin);
            for theta in [0.2f32, 0.7, 1.2] {
                let (alb, ip, est, energy) = albedo(&b, dir(theta, 0.3));
                let what = format!("α {alpha} η {eta} thin {thin} θ {theta}");
                assert!(ip <= 1.0 + 2e-3, "{what}: ∫pdf {ip}");
                assert!((alb - est).abs() < 0.01 * alb.max(1.0), "{what}: {alb} vs {est}");
                // Single scattering loses what masking stops (a quarter leaving glass at α = 0.5);
                // it never makes energy.
                assert!(energy <= 1.0 + 2e-3 && energy > 0.5, "{what}: energy {energy}");
            }
        }
    }

    /// A smooth interface: the sampler splits exactly into the Fresnel reflectance and its
    /// complement (Snell's direction), with weight one each; a thin sheet lets light straight
    /// through; beyond the critical angle everything reflects.
    #[test]
    fn a_smooth_interface_is_fresnel_and_snell() {
        let b = glass(1e-3, 1.5, false);
        let theta = 0.6f32;
        let wo = dir(theta, 0.0);
        let mut s = Sampler::new(5, 6);
        let (mut refl, mut trans, n) = (0.0f64, 0.0f64, 100_000);
        let (mut snell, mut crossed) = (0, 0);
        for _ in 0..n {
            let Some(x) = b.sample(wo, s.uniform(), s.next2()) else { continue };
            let w = f64::from(x.f.x * x.wi.z.abs() / x.pdf);
            if x.transmitted {
                trans += w * 1.5 * 1.5;
                // Snell: sin θ_t = sin θ_i / η, in the plane of incidence (but for GGX's tail,
                // which even α = 10⁻³ has).
                let st = (x.wi.x * x.wi.x + x.wi.y * x.wi.y).sqrt();
                crossed += 1;
                if (st - theta.sin() / 1.5).abs() < 1e-2 && x.wi.x < 0.0 && x.wi.z < 0.0 {
                    snell += 1;
                }
            } else {
                refl += w;
            }
        }
        assert!(
            f64::from(snell) > 0.99 * f64::from(crossed),
            "{snell} of {crossed} refractions by Snell's law"
        );
        let r = scene::transmission::fresnel_dielectric(f64::from(theta.cos()), 1.5);
        assert!((refl / n as f64 - r).abs() < 0.004, "R {} vs {r}", refl / n as f64);
        assert!((trans / n as f64 - (1.0 - r)).abs() < 0.006, "T·η² {} vs {}", trans / n as f64, 1.0 - r);
        let thin = glass(1e-3, 1.5, true);
        let mut s = Sampler::new(7, 8);
        let (mut straight, mut through) = (0, 0);
        for _ in 0..10_000 {
            if let Some(x) = thin.sample(wo, s.uniform(), s.next2())
                && x.transmitted
            {
                through += 1;
                straight += usize::from((x.wi + wo).length() < 0.02);
            }
        }
        assert!(
            straight as f64 > 0.99 * through as f64,
            "thin sheet: {straight} of {through} straight through"
        );
        // Leaving glass past the critical angle (41.8°): no transmission sample at all.
        let inside = glass(1e-3, 1.0 / 1.5, false);
        let mut s = Sampler::new(9, 10);
        for _ in 0..1000 {
            if let Some(x) = inside.sample(dir(0.9, 0.0), s.uniform(), s.next2()) {
                assert!(!x.transmitted);
            }
        }
    }

    /// Reciprocity (Veach 1997): the physical BTDF obeys f(wo→wi)/n_i² = f(wi→wo)/n_o²; with
    /// the radiance form's 1/η² folded in, entering glass (wo outside, index 1 → 1.5) and the
    /// same pair leaving it (in the flipped frame: −wi, −wo) differ by exactly η².
    #[test]
    fn refraction_is_reciprocal_up_to_eta_squared() {
        for (p, q) in [((0.5, 0.2), (2.4, 2.9)), ((1.1, 0.0), (2.0, 3.3)), ((0.2, 1.0), (2.9, 4.0))] {
            let (a, c) = (dir(p.0, p.1), dir(q.0, q.1));
            let f1 = glass(0.4, 1.5, false).eval(a, c).x;
            let f2 = glass(0.4, 1.0 / 1.5, false).eval(-c, -a).x;
            assert!(f1 > 0.0, "no transmission for {a} → {c}");
            assert!((f1 * 1.5 * 1.5 - f2).abs() <= 1e-4 * f2, "{f1}·η² = {} vs {f2}", f1 * 2.25);
        }
    }

    /// IOR 1.0 (η = 1), the pair a render of TransmissionRoughnessTest's IOR 1.0 row met: wi is
    /// −wo but for one ulp in z. The refraction's half vector wo + η·wi was rounding noise and
    /// its pdf 4.3·10¹⁹, which MIS against the environment's pdf squared past f32's range:
    /// ∞/∞ = NaN. An index-matched interface is a delta no pair of directions evaluates.
    #[test]
    fn an_index_matched_pair_has_no_runaway_pdf() {
        let b = glass(1e-3, 1.0, false);
        let wo = Vec3::new(0.58109576, -0.6474817, 0.49304697);
        let wi = Vec3::new(-0.58109576, 0.6474817, -0.49304703);
        let pdf = b.pdf(wo, wi);
        let mis = crate::sampling::power_heuristic(pdf, 0.03183099);
        assert!(mis.is_finite(), "pdf {pdf}: MIS weight {mis}");
        assert_eq!((pdf, b.eval(wo, wi)), (0.0, Vec4::ZERO));
    }

    /// Sampled, an index-matched interface (smooth or rough, at any angle) lets all the light
    /// straight through as a delta of weight the tint; the rough model lost two thirds of it to
    /// half vectors that rounded to zero.
    #[test]
    fn an_index_matched_interface_passes_light_straight_through() {
        let tint = Vec4::new(0.5, 0.7, 0.9, 1.0);
        let mut s = Sampler::new(11, 12);
        for alpha in [1e-3, 0.3, 1.0] {
            let b = Dielectric { tint, alpha, eta: 1.0, thin: false, film: None };
            for theta in [0.0f32, 0.5, 1.0, 1.5] {
                let wo = dir(theta, 0.7);
                for _ in 0..1000 {
                    let x = b.sample(wo, s.uniform(), s.next2()).expect("no sample");
                    assert!(x.specular && x.transmitted && x.wi == -wo, "α {alpha} θ {theta}: {}", x.wi);
                    assert!((x.f * x.wi.z.abs() / x.pdf - tint).abs().max_element() < 1e-6);
                }
            }
        }
    }

    /// Found by a sweep: a film on a see-through material was dropped by the path tracer (its
    /// pixels the same with and without), while the real-time renderer drew it. The interface's
    /// Fresnel term is the film's reflectance per lane — from outside, and from inside at the
    /// outside angle Snell gives (a clear stack reflects alike from both sides), all of it
    /// past the critical angle — and what it does not reflect it transmits.
    #[test]
    fn a_film_on_glass_reflects_its_reflectance_and_transmits_the_rest() {
        let lambda = Vec4::new(420.0, 500.0, 580.0, 660.0);
        let film = scene::film::Film { thickness_nm: 350.0, ior: 1.33 };
        let lanes = crate::bsdf::FilmLanes { weight: 1.0, film, lambda };
        let ior = 1.5f32;
        let make = |inside: bool| Dielectric {
            tint: Vec4::ONE,
            alpha: 0.3,
            eta: if inside { 1.0 / ior } else { ior },
            thin: false,
            film: Some(InterfaceFilm { film: lanes, ior, inside }),
        };
        let want = |c: f64| {
            Vec4::from_array(std::array::from_fn(|i| {
                film.over_dielectric(f64::from(lambda[i]), c, 1.5) as f32
            }))
        };
        let out = make(false);
        let (f, p) = out.film_fresnel(0.8, out.film.as_ref().unwrap());
        assert!((f - want(0.8)).abs().max_element() < 1e-6, "{f} vs {}", want(0.8));
        assert!((p - f.element_sum() / 4.0).abs() < 1e-7);
        assert!(f.max_element() - f.min_element() > 0.02, "the film colours the reflection: {f}");
        let inside = make(true);
        // cos 0.9 inside ↔ sin_out = 1.5·√(1 − 0.81).
        let s_out = 1.5 * (1.0f64 - 0.81).sqrt();
        let (f, _) = inside.film_fresnel(0.9, inside.film.as_ref().unwrap());
        assert!((f - want((1.0 - s_out * s_out).sqrt())).abs().max_element() < 1e-6, "{f}");
        let (f, p) = inside.film_fresnel(0.5, inside.film.as_ref().unwrap());
        assert_eq!((f, p), (Vec4::ONE, 1.0), "past the critical angle");
        // Reflection and transmission of a smooth-ish interface share the light per lane:
        // sampled many times, the reflected weight is R and the transmitted 1 − R (normal
        // incidence, lanes weighed by f·cos/pdf).
        let g = Dielectric { alpha: crate::bsdf::MIN_ALPHA, ..out };
        let wo = Vec3::Z;
        let mut rng = crate::rng::Sampler::new(3, 0);
        let (mut refl, mut trans, n) = (Vec4::ZERO, Vec4::ZERO, 200_000);
        for _ in 0..n {
            let Some(x) = g.sample(wo, rng.uniform(), rng.next2()) else { continue };
            let w = x.f * (x.wi.z.abs() / x.pdf);
            if x.transmitted { trans += w * ior * ior } else { refl += w }
        }
        let (refl, trans) = (refl / n as f32, trans / n as f32);
        let r = want(1.0);
        assert!((refl - r).abs().max_element() < 0.01, "{refl} vs {r}");
        assert!((trans - (Vec4::ONE - r)).abs().max_element() < 0.01, "{trans} vs {}", Vec4::ONE - r);
    }
}
