//! The glTF 2.0 metallic-roughness BRDF (specification, appendix B), one lane per wavelength,
//! as the appendix's normative mix(dielectric_brdf, metal_brdf, m) — the real-time renderer's
//! form (`factors_of` in crates/render's shading.wgsl):
//!
//! f = (1 − m)·(1 − F_d)·base/π + F·D·V, with F_d = F0(η) + (1 − F0(η))(1 − |v·h|)⁵ the
//! dielectric's Fresnel term and F = f0 + (1 − f0)(1 − |v·h|)⁵, f0 = lerp(F0(η), base, m)
//! (= (1 − m)·F_d + m·F_m, F_m the metal's Schlick with F0 = base), α = roughness², with the
//! dielectric's F0(η) = ((η − 1)/(η + 1))², 0.04 at glTF's default η = 1.5 (`KHR_materials_ior`),
//! D the Trowbridge–Reitz (GGX) distribution and V the height-correlated Smith visibility
//! V = 0.5 / (n·l·√(n·v²(1−α²)+α²) + n·v·√(n·l²(1−α²)+α²)) the appendix's implementation uses.
//! The diffuse loses the dielectric's Fresnel term only: the appendix's non-normative shortcut
//! (1 − F)·c_diff/π, which the tracer used before, takes the metal's too and is darker for
//! 0 < m < 1 (the same at m = 0 and 1).
//!
//! With a thin film (`KHR_materials_iridescence`), F at each lane's wavelength is
//! lerp(F, (1 − metallic)·R_film(η) + metallic·R_film(η(base)), weight): the exact film
//! reflectance (`scene::film`) over the dielectric base and over the metal (its base colour
//! as F0, the extension's convention), at v·h; the diffuse loses the dielectric's part alone,
//! F_d = lerp(F_d, R_film(η), weight).
//!
//! With `KHR_materials_specular` (`scene::specular`, [`SpecularLanes`]), the dielectric's
//! Fresnel term takes the weight s and the F0 colour F0c (an RGB reflectance, upsampled per
//! lane as the base colour is): F_d(λ) = s·(F0c(λ) + (1 − F0c(λ))(1 − v·h)⁵), and what the
//! diffuse loses is the scalar F_dmax = s·(F0c_max + (1 − F0c_max)(1 − v·h)⁵), F0c_max the
//! largest RGB channel of F0c; with F_m(λ) = base + (1 − base)(1 − v·h)⁵ the metal's,
//! f = (1 − F_dmax)·c_diff/π + [(1 − m)·F_d + m·F_m]·D·V, c_diff = base·(1 − m). Without it
//! (`None`) the arithmetic is the plain glTF BRDF's above, unchanged.
//!
//! With `KHR_materials_sheen` (`scene::sheen`, [`SheenLanes`]), a layer of fibres over all of
//! the above: f = sheenColor(λ)·D_c·V_c + s·f_base, D_c·V_c the Charlie lobe
//! (`scene::sheen::brdf`, white), s = min(1 − c·E(n·v), 1 − c·E(n·l)) the albedo scaling
//! (`scene::sheen::albedo_scaling`, c the sheen colour's largest RGB channel, E the lobe's
//! directional albedo from `scene::sheen::albedo`). It scales the whole base — diffuse and
//! specular, dielectric and metal, film or specular colour included. A clear coat lies over the
//! sheened base (`crate::coat`). Without it (`None`) the arithmetic is the one above, unchanged.
//!
//! With `KHR_materials_anisotropy` (`scene::anisotropy`, [`Brdf::with_anisotropy`]), the
//! specular lobe — the dielectric's and the metal's, not a sheen's or a clear coat's — is GGX
//! with two roughnesses, (α_x, α_y) = `scene::anisotropy::alphas_f32(α, s)` along the local x
//! and y axes: the caller's shading frame has its x axis along the anisotropy direction. D, the
//! height-correlated V, Smith's G₁ and the visible-normal sampling take the anisotropic forms
//! (Heitz 2014, 2018); the Fresnel terms, the diffuse and the lobe-choice estimates are the
//! isotropic BRDF's. Without it (`None`, or strength 0) the arithmetic is the one above,
//! unchanged to the bit.
//!
//! With `KHR_materials_diffuse_transmission` (`scene::diffuse_transmission`,
//! [`DiffuseTransmissionLanes`]), the dielectric's diffuse is the extension's mix of a Lambertian
//! BRDF and BTDF under the same layers: (1 − m)·(1 − F_d)·(1 − t)·base/π for `wi` above and
//! (1 − m)·(1 − F_d')·t·colour(λ)/π for `wi` below the surface, F_d' the diffuse's Fresnel term
//! at the half vector of `wo` and `wi` mirrored through the surface (the light crosses the
//! interface it would have reflected at), times a sheen's scaling at (n·v, |n·l|). The specular
//! lobe and the metal are untouched. The diffuse choice of the sampler goes to the far side with
//! the transmitted lobe's share of the two diffuse weights ([`Brdf::p_transmit`]), the cosine
//! lobe mirrored. Without it (`None`, or t = 0) the arithmetic is the one above, unchanged to
//! the bit.
//!
//! Directions are in the local shading frame (normal = +z). Sampling mixes a cosine lobe with
//! GGX visible-normal sampling (Heitz 2018); the mixture weight is the same for all four
//! wavelengths, so one pdf serves the whole path. A sheen adds a third, cosine-weighted choice
//! (Charlie has no closed-form inversion; the lobe is broad), chosen with a probability
//! proportional to its albedo estimate ([`Brdf::p_sheen`]).

use crate::sampling::cosine_hemisphere;
use crate::upsample::RgbToSpectrum;
use glam::{Vec3, Vec4};
use std::f32::consts::{FRAC_1_PI, PI};

/// Smallest α: below it the lobe is a mirror that neither NEE nor f32 can represent.
pub const MIN_ALPHA: f32 = 1e-3;

#[derive(Clone, Copy, Debug)]
pub struct Brdf {
    pub base: Vec4,
    pub metallic: f32,
    pub alpha: f32,
    /// Pure Lambert (base/π), ignoring metallic and roughness: only for comparisons with
    /// renderers that have no glTF BRDF (Mitsuba's `diffuse`).
    pub lambert: bool,
    pub film: Option<FilmLanes>,
    /// The dielectric's index of refraction (`KHR_materials_ior`; 1.5 by default).
    pub ior: f32,
    /// `KHR_materials_specular`'s weight and F0 colour; `None`: the index's F0 at full weight.
    pub specular: Option<SpecularLanes>,
    /// `KHR_materials_sheen`'s colour and roughness; `None`: no sheen.
    pub sheen: Option<SheenLanes>,
    /// `KHR_materials_anisotropy`: the specular lobe's (α_x, α_y) along the local x axis (the
    /// anisotropy direction t) and y axis (b = n × t); `None`: isotropic, α = `alpha`.
    pub alphas: Option<(f32, f32)>,
    /// `KHR_materials_diffuse_transmission`'s share and colour; `None`: the diffuse lobe
    /// reflects only.
    pub diffuse_transmission: Option<DiffuseTransmissionLanes>,
}

/// `KHR_materials_diffuse_transmission` at a surface point, at the four wavelengths of the
/// lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DiffuseTransmissionLanes {
    /// t = diffuseTransmissionFactor × texture A, in (0, 1]: the share of the dielectric's
    /// diffuse light sent to the far side.
    pub weight: f32,
    /// diffuseTransmissionColor(λ) at each lane's wavelength, in [0, 1].
    pub color: Vec4,
}

impl DiffuseTransmissionLanes {
    /// The share `weight` and the colour `rgb` (linear, factor × texture) at wavelengths `l`:
    /// the colour upsampled exactly as the base colour is ([`crate::material::base_reflectance`]
    /// calls the same [`crate::upsample::reflectance`], no grey shortcut), so that a colour equal
    /// to the base colour gives the same lanes in every upsampling mode.
    pub fn new(weight: f32, rgb: Vec3, up: &dyn RgbToSpectrum, l: Vec4) -> Self {
        DiffuseTransmissionLanes {
            weight: weight.clamp(0.0, 1.0),
            color: crate::upsample::reflectance(up, rgb.to_array(), l),
        }
    }
}

/// `KHR_materials_sheen` at a surface point, at the four wavelengths of the lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheenLanes {
    /// sheenColor(λ): the sheen colour at each lane's wavelength, in [0, 1].
    pub color: Vec4,
    /// c = max3(sheenColor): the largest RGB channel (not the largest lane), what the albedo
    /// scaling takes from the base.
    pub max_color: f32,
    /// The perceptual sheenRoughness (factor × texture A); `scene::sheen`'s functions square it
    /// and raise α to 0.07 themselves.
    pub roughness: f32,
}

impl SheenLanes {
    /// The sheen colour `rgb` (linear, factor × texture) and roughness `roughness` at
    /// wavelengths `l`: the colour upsampled as a reflectance exactly as the base colour is
    /// ([`crate::upsample::reflectance`]), a grey colour the constant itself (no table), as
    /// [`SpecularLanes::new`] does.
    pub fn new(rgb: Vec3, roughness: f32, up: &dyn RgbToSpectrum, l: Vec4) -> Self {
        let color = if rgb.x == rgb.y && rgb.y == rgb.z {
            Vec4::splat(rgb.x.clamp(0.0, 1.0))
        } else {
            crate::upsample::reflectance(up, rgb.to_array(), l)
        };
        SheenLanes { color, max_color: rgb.max_element().clamp(0.0, 1.0), roughness }
    }

    /// E(μ), the white lobe's directional albedo at n·ω = `mu` (the table's lookup).
    fn albedo(&self, mu: f32) -> f32 {
        scene::sheen::albedo_f32(mu, self.roughness)
    }

    /// The base's share s at n·v with albedo `e_v` and n·l = `n_l`.
    fn scaling(&self, e_v: f32, n_l: f32) -> f32 {
        scene::sheen::albedo_scaling_f32(self.max_color, e_v, self.albedo(n_l))
    }
}

/// `KHR_materials_specular` at a surface point, at the four wavelengths of the lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpecularLanes {
    /// s = specularFactor × specularTexture.a, in [0, 1].
    pub weight: f32,
    /// F0c(λ): the F0 colour at each lane's wavelength, in [0, 1].
    pub f0: Vec4,
    /// F0c_max: the largest RGB channel of the F0 colour (not the largest lane), the diffuse's
    /// share in every mode.
    pub f0_max: f32,
}

impl SpecularLanes {
    /// The weight `weight` and the F0 colour `f0_rgb` (linear RGB, `scene::specular::f0_color`)
    /// at wavelengths `l`: F0c upsampled as a reflectance exactly as the base colour is
    /// ([`crate::upsample::reflectance`]), a grey F0c the constant itself (no table).
    pub fn new(weight: f32, f0_rgb: Vec3, up: &dyn RgbToSpectrum, l: Vec4) -> Self {
        let f0 = if f0_rgb.x == f0_rgb.y && f0_rgb.y == f0_rgb.z {
            Vec4::splat(f0_rgb.x.clamp(0.0, 1.0))
        } else {
            crate::upsample::reflectance(up, f0_rgb.to_array(), l)
        };
        SpecularLanes { weight: weight.clamp(0.0, 1.0), f0, f0_max: f0_rgb.max_element().clamp(0.0, 1.0) }
    }
}

/// A thin film over the BRDF, at the four wavelengths of the lanes.
#[derive(Clone, Copy, Debug)]
pub struct FilmLanes {
    /// How much of the Fresnel term is the film's (factor × texture), in (0, 1].
    pub weight: f32,
    pub film: scene::film::Film,
    /// The lanes' wavelengths, nm.
    pub lambda: Vec4,
}

/// A sampled direction with its BRDF value and pdf (solid angle).
pub struct BrdfSample {
    pub wi: Vec3,
    pub f: Vec4,
    pub pdf: f32,
}

impl Brdf {
    pub fn new(base: Vec4, metallic: f32, roughness: f32) -> Self {
        let r = roughness.clamp(0.0, 1.0);
        Brdf {
            base,
            metallic: metallic.clamp(0.0, 1.0),
            alpha: (r * r).max(MIN_ALPHA),
            lambert: false,
            film: None,
            ior: 1.5,
            specular: None,
            sheen: None,
            alphas: None,
            diffuse_transmission: None,
        }
    }

    pub fn lambertian(base: Vec4) -> Self {
        Brdf {
            base,
            metallic: 0.0,
            alpha: 1.0,
            lambert: true,
            film: None,
            ior: 1.5,
            specular: None,
            sheen: None,
            alphas: None,
            diffuse_transmission: None,
        }
    }

    /// This BRDF with the dielectric's index `ior` (≥ 1; `scene::Material::ior`).
    pub fn with_ior(mut self, ior: f32) -> Self {
        self.ior = ior.max(1.0);
        self
    }

    /// This BRDF with a thin film (weight 0: none).
    pub fn with_film(mut self, film: Option<FilmLanes>) -> Self {
        self.film = film.filter(|f| f.weight > 0.0 && !self.lambert);
        self
    }

    /// This BRDF with `KHR_materials_specular` (`None`: without). Lambert has no Fresnel term
    /// to change, and a material with a thin film takes none (the loader drops the pair).
    pub fn with_specular(mut self, specular: Option<SpecularLanes>) -> Self {
        self.specular = specular.filter(|_| !self.lambert && self.film.is_none());
        self
    }

    /// This BRDF under `KHR_materials_sheen` (`None`: without). A black sheen is none (the
    /// extension switches the layer off; its scaling would be exactly 1), and Lambert, the
    /// comparison mode, takes none.
    pub fn with_sheen(mut self, sheen: Option<SheenLanes>) -> Self {
        self.sheen = sheen.filter(|s| !self.lambert && s.max_color > 0.0 && s.color != Vec4::ZERO);
        self
    }

    /// This BRDF under `KHR_materials_anisotropy` of strength `strength` at the point (`None`:
    /// without): (α_t, α_b) = `scene::anisotropy::alphas_f32(alpha, s)` along the local x and y
    /// axes. Strength 0 is none (the isotropic lobe, to the bit), and Lambert, the comparison
    /// mode, takes none.
    pub fn with_anisotropy(mut self, strength: Option<f32>) -> Self {
        self.alphas = strength
            .filter(|&s| s > 0.0 && !self.lambert)
            .map(|s| scene::anisotropy::alphas_f32(self.alpha, s.min(1.0)));
        self
    }

    /// This BSDF with `KHR_materials_diffuse_transmission` (`None`: without). Share 0 is none
    /// (the reflecting code path, to the bit), and Lambert, the comparison mode, takes none.
    pub fn with_diffuse_transmission(mut self, dt: Option<DiffuseTransmissionLanes>) -> Self {
        self.diffuse_transmission = dt.filter(|d| d.weight > 0.0 && !self.lambert);
        self
    }

    /// The colour of the reflected diffuse lobe: the base colour, times 1 − t with a diffuse
    /// transmission.
    #[inline]
    fn reflected_color(&self) -> Vec4 {
        match &self.diffuse_transmission {
            None => self.base,
            Some(d) => self.base * (1.0 - d.weight),
        }
    }

    /// What the diffuse returns on both sides together: (1 − t)·base + t·colour (the base
    /// colour without a diffuse transmission), for the albedo estimates.
    #[inline]
    fn diffuse_color(&self) -> Vec4 {
        match &self.diffuse_transmission {
            None => self.base,
            Some(d) => self.base * (1.0 - d.weight) + d.color * d.weight,
        }
    }

    /// The probability that a diffuse sample goes to the far side: the transmitted lobe's share
    /// of the two diffuse lobes' weights (averaged over the lanes); 0 without a transmission.
    pub fn p_transmit(&self) -> f32 {
        let Some(d) = &self.diffuse_transmission else { return 0.0 };
        let t = d.color.element_sum() * d.weight;
        let r = self.base.element_sum() * (1.0 - d.weight);
        if t + r > 0.0 { t / (t + r) } else { 0.5 }
    }

    /// (what multiplies D·V, the dielectric's Fresnel term the diffuse loses) at `cos` (v·h, or
    /// n·v for the sampling's estimate): `fr`'s pair without a specular; with one,
    /// ((1 − m)·F_d + m·F_m, F_dmax).
    fn fresnel_pair(&self, cos: f32, fr: impl FnOnce() -> (Vec4, Vec4)) -> (Vec4, Vec4) {
        let Some(sp) = &self.specular else { return fr() };
        let x = (1.0 - cos).max(0.0).powi(5);
        let m = self.metallic;
        let metal = self.base + (Vec4::ONE - self.base) * x;
        let dielectric = (sp.f0 + (Vec4::ONE - sp.f0) * x) * sp.weight;
        let dielectric_max = sp.weight * (sp.f0_max + (1.0 - sp.f0_max) * x);
        (dielectric * (1.0 - m) + metal * m, Vec4::splat(dielectric_max))
    }

    /// Schlick's Fresnel term at `cos` twice: with the glTF F0 = lerp(F0(η), base, m) (the
    /// specular lobe's, (1 − m)·F_d + m·F_m) and with the dielectric's F0(η) alone (F_d, what
    /// the diffuse loses).
    fn schlick_pair(&self, cos: f32) -> (Vec4, Vec4) {
        let x = (1.0 - cos).max(0.0).powi(5);
        let (f0, f0_d) = (self.f0(), Vec4::splat(scene::dielectric_f0(self.ior)));
        (f0 + (Vec4::ONE - f0) * x, f0_d + (Vec4::ONE - f0_d) * x)
    }

    /// The Fresnel terms at v·h, as [`Self::schlick_pair`]'s, each blended with the film's:
    /// the lobe's with (1 − m)·R_film(η) + m·R_film(η(base)), the diffuse's with the
    /// dielectric's R_film(η) alone.
    fn fresnel(&self, v_h: f32) -> (Vec4, Vec4) {
        let (schlick, schlick_d) = self.schlick_pair(v_h);
        let Some(f) = &self.film else { return (schlick, schlick_d) };
        let m = f64::from(self.metallic);
        let c = f64::from(v_h);
        let dielectric_base = f64::from(self.ior);
        let mut film_d = [0.0f32; 4];
        let lanes: [f32; 4] = std::array::from_fn(|i| {
            let l = f64::from(f.lambda[i]);
            let dielectric = if m < 1.0 { f.film.over_dielectric(l, c, dielectric_base) } else { 0.0 };
            let metal = if m > 0.0 { f.film.over_f0(l, c, f64::from(self.base[i])) } else { 0.0 };
            film_d[i] = dielectric as f32;
            ((1.0 - m) * dielectric + m * metal) as f32
        });
        (
            schlick + (Vec4::from_array(lanes) - schlick) * f.weight,
            schlick_d + (Vec4::from_array(film_d) - schlick_d) * f.weight,
        )
    }

    fn f0(&self) -> Vec4 {
        Vec4::splat(scene::dielectric_f0(self.ior) * (1.0 - self.metallic)) + self.base * self.metallic
    }

    fn d(&self, n_h: f32) -> f32 {
        ggx_d(self.alpha, n_h)
    }

    fn vis(&self, n_l: f32, n_v: f32) -> f32 {
        smith_vis(self.alpha, n_l, n_v)
    }

    /// Smith G1 for the visible-normal pdf.
    fn g1(&self, n_v: f32) -> f32 {
        smith_g1(self.alpha, n_v)
    }

    /// D(h)·V(wi, wo), the specular lobe without its Fresnel term: anisotropic with
    /// [`Self::alphas`], else the isotropic `d`·`vis`.
    #[inline]
    fn lobe(&self, wo: Vec3, wi: Vec3, h: Vec3) -> f32 {
        match self.alphas {
            None => self.d(h.z) * self.vis(wi.z, wo.z),
            Some((ax, ay)) => ggx_d_aniso(ax, ay, h) * smith_vis_aniso(ax, ay, wi, wo),
        }
    }

    /// G1(wo)·D(h), the visible-normal pdf of h times 4·n·v (with the reflection's Jacobian).
    #[inline]
    fn g1_d(&self, wo: Vec3, h: Vec3) -> f32 {
        match self.alphas {
            None => self.g1(wo.z) * self.d(h.z),
            Some((ax, ay)) => smith_g1_aniso(ax, ay, wo) * ggx_d_aniso(ax, ay, h),
        }
    }

    /// The directional albedo at `n_v` as [`Self::p_spec`] estimates it (Schlick with n·v for
    /// v·h: the lobe's F, plus (1 − m)·(1 − F_d)·base with F_d the dielectric's term alone; with
    /// a specular, its weighted F0 colour and the F0c_max share), averaged over the lanes:
    /// what the clear coat weighs its sampling probability against.
    ///
    /// With a sheen: its lobe's albedo mean(sheenColor)·E(n·v) plus the base's estimate times
    /// the scaling at n·v, 1 − c·E(n·v) (the largest s can be for this view).
    pub fn albedo_estimate(&self, n_v: f32) -> f32 {
        let base = self.base_albedo_estimate(n_v);
        match &self.sheen {
            None => base,
            Some(sh) => {
                let (a_sheen, a_base) = Self::sheen_estimates(sh, n_v, base);
                a_sheen + a_base
            }
        }
    }

    /// [`Self::albedo_estimate`] without the sheen.
    fn base_albedo_estimate(&self, n_v: f32) -> f32 {
        if self.lambert {
            return self.base.element_sum() * 0.25;
        }
        let (fs, fd) = self.fresnel_pair(n_v, || self.schlick_pair(n_v));
        (fs + (Vec4::ONE - fd) * self.diffuse_color() * (1.0 - self.metallic)).element_sum() * 0.25
    }

    /// (the sheen lobe's albedo, the scaled base's) at n·v, from the base's own estimate.
    fn sheen_estimates(sh: &SheenLanes, n_v: f32, base: f32) -> (f32, f32) {
        let e_v = sh.albedo(n_v);
        (sh.color.element_sum() * 0.25 * e_v, base * sh.scaling(e_v, n_v))
    }

    /// Probability of sampling the sheen lobe (cosine-weighted) rather than the base: its share
    /// of [`Self::albedo_estimate`], kept in [0.05, 0.95] so that neither the sheen nor the
    /// base (a metal's, which has no cosine lobe of its own) goes unsampled. 0 without a sheen.
    pub fn p_sheen(&self, n_v: f32) -> f32 {
        let Some(sh) = &self.sheen else { return 0.0 };
        let (a_sheen, a_base) = Self::sheen_estimates(sh, n_v, self.base_albedo_estimate(n_v));
        let total = a_sheen + a_base;
        if total > 0.0 { (a_sheen / total).clamp(0.05, 0.95) } else { 0.5 }
    }

    /// Probability of sampling the specular lobe: its share of the Fresnel-weighted albedo
    /// estimate at normal incidence, averaged over the four wavelengths.
    fn p_spec(&self, n_v: f32) -> f32 {
        if self.lambert {
            return 0.0;
        }
        let (fs, fd) = self.fresnel_pair(n_v, || self.schlick_pair(n_v));
        let spec = fs.element_sum();
        let diff = ((Vec4::ONE - fd) * self.diffuse_color() * (1.0 - self.metallic)).element_sum();
        if spec + diff <= 0.0 { 1.0 } else { (spec / (spec + diff)).clamp(0.05, 1.0) }
    }

    /// f(wo, wi), zero unless both are above the surface — or, with a diffuse transmission,
    /// `wo` above and `wi` below ([`Self::eval_transmitted`]).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Vec4 {
        if wi.z < 0.0
            && let Some(dt) = &self.diffuse_transmission
        {
            return self.eval_transmitted(dt, wo, wi);
        }
        let Some(sh) = &self.sheen else { return self.eval_base(wo, wi) };
        let (n_v, n_l) = (wo.z, wi.z);
        if n_v <= 0.0 || n_l <= 0.0 {
            return Vec4::ZERO;
        }
        let n_h = (wo + wi).normalize().z;
        let f_sheen = sh.color * scene::sheen::brdf_f32(n_l, n_v, n_h, sh.roughness);
        f_sheen + self.eval_base(wo, wi) * sh.scaling(sh.albedo(n_v), n_l)
    }

    /// The diffuse BTDF under the same layers as the reflected diffuse: (1 − m)·(1 − F_d)·t·
    /// colour/π, F_d the dielectric's Fresnel term the reflected diffuse loses (with its film or
    /// specular), taken at the half vector of `wo` and `wi` mirrored through the surface — the
    /// light crosses the same specular interface, at the angle it would have reflected at — and
    /// times a sheen's albedo scaling at (n·v, |n·l|), the light passing the fibres at |n·l| on
    /// the far side. Reciprocal: the mirrored half vector of (wi, wo) makes the same angle.
    fn eval_transmitted(&self, dt: &DiffuseTransmissionLanes, wo: Vec3, wi: Vec3) -> Vec4 {
        let (n_v, n_l) = (wo.z, -wi.z);
        if n_v <= 0.0 || n_l <= 0.0 {
            return Vec4::ZERO;
        }
        let h = (wo + Vec3::new(wi.x, wi.y, n_l)).normalize();
        let v_h = wo.dot(h).abs();
        let (_, fd) = self.fresnel_pair(v_h, || self.fresnel(v_h));
        let f = (Vec4::ONE - fd) * dt.color * (dt.weight * (1.0 - self.metallic) * FRAC_1_PI);
        match &self.sheen {
            None => f,
            Some(sh) => f * sh.scaling(sh.albedo(n_v), n_l),
        }
    }

    /// f without the sheen: the glTF BRDF (with its film or specular).
    fn eval_base(&self, wo: Vec3, wi: Vec3) -> Vec4 {
        let (n_v, n_l) = (wo.z, wi.z);
        if n_v <= 0.0 || n_l <= 0.0 {
            return Vec4::ZERO;
        }
        if self.lambert {
            return self.base * FRAC_1_PI;
        }
        let h = (wo + wi).normalize();
        let v_h = wo.dot(h).abs();
        let (fs, fd) = self.fresnel_pair(v_h, || self.fresnel(v_h));
        let diffuse = (Vec4::ONE - fd) * self.reflected_color() * ((1.0 - self.metallic) * FRAC_1_PI);
        diffuse + fs * self.lobe(wo, wi, h)
    }

    /// The pdf [`Self::sample`] draws `wi` with: with a sheen, p·cos θ_i/π + (1 − p)·pdf_base,
    /// p = [`Self::p_sheen`].
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wi.z < 0.0 && self.diffuse_transmission.is_some() {
            return self.pdf_transmitted(wo, wi);
        }
        if self.sheen.is_none() {
            return self.pdf_base(wo, wi);
        }
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let p = self.p_sheen(wo.z);
        p * wi.z * FRAC_1_PI + (1.0 - p) * self.pdf_base(wo, wi)
    }

    /// The pdf of a far-side `wi`: the diffuse choice (1 − p_spec) times the far side's share
    /// of it ([`Self::p_transmit`]) times the mirrored cosine lobe, under a sheen's 1 − p.
    fn pdf_transmitted(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z >= 0.0 {
            return 0.0;
        }
        let base = (1.0 - self.p_spec(wo.z)) * self.p_transmit() * -wi.z * FRAC_1_PI;
        if self.sheen.is_none() { base } else { (1.0 - self.p_sheen(wo.z)) * base }
    }

    /// The pdf the base (diffuse and specular lobes) draws `wi` with.
    fn pdf_base(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (n_v, n_l) = (wo.z, wi.z);
        if n_v <= 0.0 || n_l <= 0.0 {
            return 0.0;
        }
        let ps = self.p_spec(n_v);
        let h = (wo + wi).normalize();
        let v_h = wo.dot(h).max(0.0);
        // Visible-normal pdf of h, then the reflection Jacobian 1/(4·v·h).
        let pdf_spec = if v_h > 0.0 { self.g1_d(wo, h) / (4.0 * n_v) } else { 0.0 };
        if self.diffuse_transmission.is_some() {
            return ps * pdf_spec + (1.0 - ps) * (1.0 - self.p_transmit()) * n_l * FRAC_1_PI;
        }
        ps * pdf_spec + (1.0 - ps) * n_l * FRAC_1_PI
    }

    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: [f32; 2]) -> Option<BrdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let mut u_lobe = u_lobe;
        if self.sheen.is_some() {
            // The sheen with probability p, the base with the rest of `u_lobe` rescaled.
            let p = self.p_sheen(wo.z);
            if u_lobe < p {
                let wi = cosine_hemisphere(u);
                let pdf = self.pdf(wo, wi);
                return (pdf > 0.0).then(|| BrdfSample { wi, f: self.eval(wo, wi), pdf });
            }
            u_lobe = ((u_lobe - p) / (1.0 - p)).min(1.0 - f32::EPSILON);
        }
        let ps = self.p_spec(wo.z);
        let wi = if u_lobe < ps {
            let h = self.sample_visible_normal(wo, u);
            let wi = 2.0 * wo.dot(h) * h - wo;
            if wi.z <= 0.0 {
                return None;
            }
            wi
        } else if self.diffuse_transmission.is_some() && (u_lobe - ps) / (1.0 - ps) < self.p_transmit() {
            // The far side's cosine lobe: the near side's mirrored.
            let w = cosine_hemisphere(u);
            Vec3::new(w.x, w.y, -w.z)
        } else {
            cosine_hemisphere(u)
        };
        let pdf = self.pdf(wo, wi);
        (pdf > 0.0).then(|| BrdfSample { wi, f: self.eval(wo, wi), pdf })
    }

    fn sample_visible_normal(&self, wo: Vec3, u: [f32; 2]) -> Vec3 {
        match self.alphas {
            None => visible_normal(self.alpha, wo, u),
            Some((ax, ay)) => visible_normal_aniso(ax, ay, wo, u),
        }
    }
}

/// The GGX (Trowbridge–Reitz) distribution of roughness α at n·h.
#[inline]
fn ggx_d(alpha: f32, n_h: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = n_h * n_h * (a2 - 1.0) + 1.0;
    a2 / (PI * t * t)
}

/// glTF's height-correlated Smith visibility V = G / (4·n·l·n·v).
#[inline]
fn smith_vis(alpha: f32, n_l: f32, n_v: f32) -> f32 {
    let a2 = alpha * alpha;
    let gv = n_l * (n_v * n_v * (1.0 - a2) + a2).sqrt();
    let gl = n_v * (n_l * n_l * (1.0 - a2) + a2).sqrt();
    let s = gv + gl;
    if s > 0.0 { 0.5 / s } else { 0.0 }
}

/// Smith G1, the masking of the visible-normal pdf.
#[inline]
fn smith_g1(alpha: f32, n_v: f32) -> f32 {
    let a2 = alpha * alpha;
    2.0 * n_v / (n_v + (a2 + (1.0 - a2) * n_v * n_v).sqrt())
}

/// Anisotropic GGX (`scene::anisotropy::ggx_d` in f32): roughness `ax` along local x, `ay`
/// along y, at the unit half vector `h`; 0 below the surface.
#[inline]
fn ggx_d_aniso(ax: f32, ay: f32, h: Vec3) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let (x, y) = (h.x / ax, h.y / ay);
    let k = x * x + y * y + h.z * h.z;
    1.0 / (PI * ax * ay * k * k)
}

/// The anisotropic height-correlated Smith visibility G₂/(4·n·l·n·v)
/// (`scene::anisotropy::visibility` in f32) for light `l` and view `v`.
#[inline]
fn smith_vis_aniso(ax: f32, ay: f32, l: Vec3, v: Vec3) -> f32 {
    let gv = l.z * Vec3::new(ax * v.x, ay * v.y, v.z).length();
    let gl = v.z * Vec3::new(ax * l.x, ay * l.y, l.z).length();
    let s = gv + gl;
    if s > 0.0 { 0.5 / s } else { 0.0 }
}

/// Anisotropic Smith G1 = 1/(1 + Λ(w)) = 2·w_z/(w_z + |(ax·w_x, ay·w_y, w_z)|).
#[inline]
fn smith_g1_aniso(ax: f32, ay: f32, w: Vec3) -> f32 {
    2.0 * w.z / (w.z + Vec3::new(ax * w.x, ay * w.y, w.z).length())
}

/// The clear coat's lobe (`KHR_materials_clearcoat`): glTF's specular microfacet term D·V
/// without a Fresnel factor, which the layering weight carries (`scene::clearcoat`), in the
/// coat's own frame (its normal +z). Sampled by visible normals, as the base's specular lobe.
#[derive(Clone, Copy, Debug)]
pub struct CoatLobe {
    pub alpha: f32,
}

impl CoatLobe {
    /// α = roughness², held at [`MIN_ALPHA`] as the base's lobe is: a smooth coat is a mirror
    /// f32 can still evaluate.
    pub fn new(roughness: f32) -> Self {
        let r = roughness.clamp(0.0, 1.0);
        CoatLobe { alpha: (r * r).max(MIN_ALPHA) }
    }

    /// f(wo, wi), zero unless both are above the coat.
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (n_v, n_l) = (wo.z, wi.z);
        if n_v <= 0.0 || n_l <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        ggx_d(self.alpha, h.z) * smith_vis(self.alpha, n_l, n_v)
    }

    /// The pdf [`Self::sample`] draws `wi` with.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (n_v, n_l) = (wo.z, wi.z);
        if n_v <= 0.0 || n_l <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        if wo.dot(h) <= 0.0 {
            return 0.0;
        }
        smith_g1(self.alpha, n_v) * ggx_d(self.alpha, h.z) / (4.0 * n_v)
    }

    /// A direction reflected about a visible microfacet normal; `None` below the coat.
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<Vec3> {
        if wo.z <= 0.0 {
            return None;
        }
        let h = visible_normal(self.alpha, wo, u);
        let wi = 2.0 * wo.dot(h) * h - wo;
        (wi.z > 0.0).then_some(wi)
    }
}

/// Heitz 2018, "Sampling the GGX distribution of visible normals": a microfacet normal of the
/// GGX distribution of roughness α seen from `wo` (above the surface). Shared by the BRDF and
/// the dielectric BSDF (`crate::dielectric`).
pub fn visible_normal(alpha: f32, wo: Vec3, u: [f32; 2]) -> Vec3 {
    visible_normal_aniso(alpha, alpha, wo, u)
}

/// [`visible_normal`] for anisotropic GGX, roughness `ax` along local x and `ay` along y:
/// `wo` stretched by (ax, ay) to the hemisphere configuration, a normal sampled there and
/// unstretched (Heitz 2018). With ax = ay the isotropic sampler's arithmetic exactly.
#[inline]
pub fn visible_normal_aniso(ax: f32, ay: f32, wo: Vec3, u: [f32; 2]) -> Vec3 {
    {
        let vh = Vec3::new(ax * wo.x, ay * wo.y, wo.z).normalize();
        let len2 = vh.x * vh.x + vh.y * vh.y;
        let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
        let t2 = vh.cross(t1);
        let r = u[0].sqrt();
        let phi = 2.0 * PI * u[1];
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + vh.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
        Vec3::new(ax * nh.x, ay * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Sampler;

    fn dir(theta: f32, phi: f32) -> Vec3 {
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    }

    #[test]
    fn lambert_limit() {
        // metallic 0, f0 = 0.04: at normal incidence the diffuse part is 0.96·base/π.
        let b = Brdf::new(Vec4::splat(0.5), 0.0, 1.0);
        let f = b.eval(Vec3::Z, Vec3::Z);
        let diffuse = 0.96 * 0.5 / PI;
        assert!(f.x > diffuse && f.x < diffuse + 0.1);
    }

    /// `KHR_materials_ior`: at normal incidence the dielectric's Fresnel term is
    /// ((η − 1)/(η + 1))², so a black dielectric's reflection scales with it; 1.5 is glTF's 0.04.
    #[test]
    fn the_index_sets_the_dielectric_f0() {
        let black = |ior: f32| Brdf::new(Vec4::ZERO, 0.0, 0.4).with_ior(ior).eval(Vec3::Z, Vec3::Z).x;
        assert_eq!(black(1.5), Brdf::new(Vec4::ZERO, 0.0, 0.4).eval(Vec3::Z, Vec3::Z).x);
        for ior in [1.0f32, 1.33, 2.0, 2.42] {
            let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
            let want = black(1.5) * f0 / 0.04;
            assert!((black(ior) - want).abs() <= 1e-5 * want.max(1e-3), "η {ior}: {} vs {want}", black(ior));
        }
    }

    #[test]
    fn lambertian_has_albedo_base() {
        let b = Brdf::lambertian(Vec4::splat(0.6));
        assert!((b.eval(dir(0.2, 0.0), dir(1.0, 1.0)) - Vec4::splat(0.6 / PI)).abs().max_element() < 1e-7);
        assert!((b.pdf(dir(0.2, 0.0), dir(1.0, 1.0)) - 1.0f32.cos() / PI).abs() < 1e-6);
    }

    #[test]
    fn reciprocal() {
        let b = Brdf::new(Vec4::new(0.9, 0.5, 0.2, 0.7), 0.4, 0.35);
        let (a, c) = (dir(0.3, 0.2), dir(1.1, 2.5));
        assert!((b.eval(a, c) - b.eval(c, a)).abs().max_element() < 1e-5);
    }

    /// The pdf integrates (by quadrature) to the fraction of samples the sampler returns
    /// (GGX reflections that go below the horizon are lost, so it can be below one), and the
    /// sampler's estimate of ∫ f cos equals the quadrature's.
    #[test]
    fn pdf_normalised_and_sampling_consistent() {
        for (m, r) in [(0.0, 0.5), (1.0, 0.3), (0.5, 0.8), (1.0, 0.1)] {
            let b = Brdf::new(Vec4::new(0.8, 0.6, 0.3, 0.9), m, r);
            let wo = dir(0.6, 0.0);
            let (nt, np) = (800, 400);
            let (mut ip, mut ialb) = (0.0f64, Vec4::ZERO);
            for i in 0..nt {
                // Quadrature in cos θ for a smooth integrand near the pole.
                let c0 = (i as f32 + 0.5) / nt as f32;
                for j in 0..np {
                    let phi = 2.0 * PI * (j as f32 + 0.5) / np as f32;
                    let wi = dir(c0.acos(), phi);
                    let dw = (1.0 / nt as f32) * (2.0 * PI / np as f32);
                    ip += (b.pdf(wo, wi) * dw) as f64;
                    ialb += b.eval(wo, wi) * wi.z * dw;
                }
            }
            let mut s = Sampler::new(1, 2);
            let n = 200_000;
            let mut est = Vec4::ZERO;
            let mut returned = 0;
            for _ in 0..n {
                if let Some(x) = b.sample(wo, s.uniform(), s.next2()) {
                    est += x.f * x.wi.z / x.pdf;
                    returned += 1;
                }
            }
            est /= n as f32;
            let frac = returned as f64 / n as f64;
            assert!(ip <= 1.0 + 1e-3 && (ip - frac).abs() < 0.01, "m={m} r={r}: ∫pdf = {ip}, sampled {frac}");
            assert!((est - ialb).abs().max_element() < 0.01, "m={m} r={r}: {est} vs {ialb}");
            // Energy conservation (single scattering never exceeds 1).
            assert!(ialb.max_element() <= 1.0);
        }
    }

    /// glTF 2.0 appendix B's normative material in f64, apart from the tracer's code:
    /// mix(dielectric_brdf, metal_brdf, m) with dielectric_brdf = (1 − F_dd)·base/π + F_d·D·V
    /// and metal_brdf = F_m·D·V, where `fresnel(v·h, lane)` gives (F_d, F_dd, F_m): the
    /// dielectric's Fresnel term on the specular lobe, what its diffuse loses (the same but
    /// for a specular's neutral F_dmax) and the metal's.
    fn normative(
        base: Vec4,
        m: f32,
        alpha: f32,
        wo: Vec3,
        wi: Vec3,
        fresnel: impl Fn(f64, usize) -> (f64, f64, f64),
    ) -> [f64; 4] {
        let (wo, wi) = (wo.to_array().map(f64::from), wi.to_array().map(f64::from));
        let h = [wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2]];
        let hl = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
        let h = h.map(|x| x / hl);
        let v_h = (wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2]).abs();
        let a2 = f64::from(alpha).powi(2);
        let t = h[2] * h[2] * (a2 - 1.0) + 1.0;
        let d = a2 / (std::f64::consts::PI * t * t);
        let (nv, nl) = (wo[2], wi[2]);
        let vis = 0.5 / (nl * (nv * nv * (1.0 - a2) + a2).sqrt() + nv * (nl * nl * (1.0 - a2) + a2).sqrt());
        let m = f64::from(m);
        std::array::from_fn(|i| {
            let b = f64::from(base[i]);
            let (f_d, f_dd, f_m) = fresnel(v_h, i);
            let dielectric = (1.0 - f_dd) * b / std::f64::consts::PI + f_d * d * vis;
            let metal = f_m * d * vis;
            (1.0 - m) * dielectric + m * metal
        })
    }

    fn schlick64(f0: f64, v_h: f64) -> f64 {
        f0 + (1.0 - f0) * (1.0 - v_h).max(0.0).powi(5)
    }

    const DIRS: [(f32, f32, f32, f32); 4] =
        [(0.2, 0.0, 0.5, 2.5), (0.9, 0.3, 1.2, 3.0), (1.3, 0.0, 0.4, 1.0), (0.6, 1.0, 0.6, 4.0)];

    /// Worst relative error of `b.eval` against `want` over [`DIRS`]; panics beyond `tol`.
    fn check_normative(b: &Brdf, tol: f64, what: &str, want: impl Fn(Vec3, Vec3) -> [f64; 4]) -> f64 {
        let mut worst = 0.0f64;
        for (t0, p0, t1, p1) in DIRS {
            let (wo, wi) = (dir(t0, p0), dir(t1, p1));
            let (got, want) = (b.eval(wo, wi), want(wo, wi));
            for i in 0..4 {
                let e = (f64::from(got[i]) - want[i]).abs() / want[i].max(1e-3);
                worst = worst.max(e);
                assert!(e < tol, "{what}, θ {t0}/{t1}, lane {i}: {} vs the normative {}", got[i], want[i]);
            }
        }
        worst
    }

    /// Partial metals are glTF's normative mix (appendix B): the diffuse loses the dielectric's
    /// Fresnel term only, (1 − m)·(1 − F_d)·base/π, as the real-time renderer's `factors_of`
    /// has it; the shortcut (1 − F)·c_diff/π with F from lerp(F0, base, m) takes the metal's
    /// Fresnel term from it too (m = 0.5, base 0.5: a diffuse weight of 0.73 instead of 0.96).
    #[test]
    fn partial_metals_are_the_normative_mix() {
        let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
        let mut worst = 0.0f64;
        for m in [0.0, 0.25, 0.5, 0.75, 1.0] {
            for (r, ior) in [(0.4, 1.5), (0.7, 1.8), (0.25, 1.33)] {
                let b = Brdf::new(base, m, r).with_ior(ior);
                let f0 = ((f64::from(ior) - 1.0) / (f64::from(ior) + 1.0)).powi(2);
                worst = worst.max(check_normative(&b, 5e-5, &format!("m {m} r {r} η {ior}"), |wo, wi| {
                    normative(base, m, b.alpha, wo, wi, |v_h, i| {
                        let f_d = schlick64(f0, v_h);
                        (f_d, f_d, schlick64(f64::from(base[i]), v_h))
                    })
                }));
            }
        }
        println!("partial metals vs the normative mix: worst relative error {worst:.2e}");
    }

    /// The same with a thin film: the dielectric's Fresnel term (the lobe's and the diffuse's)
    /// is lerp(Schlick(F0(η)), R_film(η), w), the metal's lerp(Schlick(base), R_film(η(base)), w).
    #[test]
    fn partial_metals_with_a_film_are_the_normative_mix() {
        let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
        for m in [0.0, 0.25, 0.5, 0.75, 1.0] {
            for (w, d) in [(1.0, 300.0), (0.6, 520.0)] {
                let fl = film(w, d);
                let b = Brdf::new(base, m, 0.4).with_film(Some(fl));
                check_normative(&b, 1e-4, &format!("m {m} film {w} × {d} nm"), |wo, wi| {
                    normative(base, m, b.alpha, wo, wi, |v_h, i| {
                        let l = f64::from(fl.lambda[i]);
                        let w = f64::from(w);
                        let glass = num_complex::Complex64::new(1.5, 0.0);
                        let r_d = scene::film::reflectance(l, v_h, d, 1.33, glass);
                        let (s_d, s_m) = (schlick64(0.04, v_h), schlick64(f64::from(base[i]), v_h));
                        let f_d = s_d + (r_d - s_d) * w;
                        let f_m = s_m + (fl.film.over_f0(l, v_h, f64::from(base[i])) - s_m) * w;
                        (f_d, f_d, f_m)
                    })
                });
            }
        }
    }

    /// The same with `KHR_materials_specular`: the lobe's dielectric term is
    /// F_d(λ) = s·Schlick(F0c(λ)), the diffuse loses the neutral F_dmax = s·Schlick(F0c_max)
    /// alone: (1 − m)·(1 − F_dmax)·base/π.
    #[test]
    fn partial_metals_with_a_specular_are_the_normative_mix() {
        let base = Vec4::new(0.8, 0.55, 0.3, 0.1);
        for m in [0.0, 0.25, 0.5, 0.75, 1.0] {
            for (s, f0, f0_max) in
                [(0.5, Vec4::new(0.9, 0.6, 0.2, 0.05), 0.95), (1.0, Vec4::splat(0.04), 0.04)]
            {
                let sp = SpecularLanes { weight: s, f0, f0_max };
                let b = Brdf::new(base, m, 0.4).with_specular(Some(sp));
                check_normative(&b, 1e-5, &format!("m {m} s {s} F0c {f0}"), |wo, wi| {
                    normative(base, m, b.alpha, wo, wi, |v_h, i| {
                        let s = f64::from(s);
                        let f_d = s * schlick64(f64::from(f0[i]), v_h);
                        let f_dmax = s * schlick64(f64::from(f0_max), v_h);
                        (f_d, f_dmax, schlick64(f64::from(base[i]), v_h))
                    })
                });
            }
        }
    }

    /// ∫ f·cos over the hemisphere of `wo` (midpoint quadrature in cos θ and φ).
    fn albedo(b: &Brdf, wo: Vec3) -> Vec4 {
        let (nt, np) = (300, 200);
        let mut alb = Vec4::ZERO;
        for i in 0..nt {
            let c = (i as f32 + 0.5) / nt as f32;
            for j in 0..np {
                alb += b.eval(wo, dir(c.acos(), 2.0 * PI * (j as f32 + 0.5) / np as f32)) * c;
            }
        }
        alb * (2.0 * PI / (nt * np) as f32)
    }

    /// Furnace: a white half metal reflects at most what arrives — and, the normative mix being
    /// linear in m, exactly the mean of the white dielectric's and the white metal's albedos
    /// (the shortcut's is darker: its diffuse loses the metal's Fresnel term, which is 1 for a
    /// white metal, and so keeps a quarter of the base instead of a half). Where glTF's
    /// dielectric itself returns more than 1 (grazing, `mix_excess`), the bound is half its excess.
    #[test]
    fn a_white_half_metal_keeps_energy() {
        for r in [0.4, 0.6, 0.9] {
            let at = |m: f32| Brdf::new(Vec4::ONE, m, r);
            for theta in [0.1f32, 0.8, 1.3] {
                let wo = dir(theta, 0.0);
                let (half, diel, metal) = (albedo(&at(0.5), wo), albedo(&at(0.0), wo), albedo(&at(1.0), wo));
                let mean = (diel + metal) * 0.5;
                let bound = 1.0 + 0.5 * mix_excess(&at(0.0), wo) + 1e-3;
                println!("r {r} θ {theta}: half metal {} (dielectric {}, metal {})", half.x, diel.x, metal.x);
                assert!(
                    (half - mean).abs().max_element() < 1e-4,
                    "r {r} θ {theta}: {half} vs the mean {mean}"
                );
                assert!(half.max_element() <= bound, "r {r} θ {theta}: albedo {half} > {bound}");
                if theta < 1.0 {
                    assert!(half.max_element() <= 1.0 + 1e-3, "r {r} θ {theta}: albedo {half}");
                }
            }
        }
    }

    fn film(weight: f32, thickness_nm: f64) -> FilmLanes {
        FilmLanes {
            weight,
            film: scene::film::Film { thickness_nm, ior: 1.33 },
            lambda: Vec4::new(420.0, 500.0, 580.0, 660.0),
        }
    }

    /// A film of weight 1 over a dielectric makes the Fresnel term the film's reflectance at
    /// each lane's wavelength (a soap-bubble colour: the lanes differ), a weight of 0 is no
    /// film, and a film of thickness 0 is the exact Fresnel of index 1.5 in place of
    /// Schlick's approximation of it.
    #[test]
    fn film_replaces_the_fresnel_term() {
        let b = Brdf::new(Vec4::splat(0.5), 0.0, 0.4);
        let (wo, wi) = (dir(0.5, 0.0), dir(0.7, 2.9));
        let h = (wo + wi).normalize();
        let v_h = wo.dot(h);
        let plain = b.eval(wo, wi);
        assert_eq!(b.with_film(Some(film(0.0, 300.0))).eval(wo, wi), plain);
        let f = b.with_film(Some(film(1.0, 300.0)));
        let fr = f.fresnel(v_h).0;
        for i in 0..4 {
            let want = scene::film::reflectance(
                f64::from(f.film.unwrap().lambda[i]),
                f64::from(v_h),
                300.0,
                1.33,
                num_complex::Complex64::new(1.5, 0.0),
            );
            assert!((f64::from(fr[i]) - want).abs() < 1e-6, "lane {i}: {} vs {want}", fr[i]);
        }
        assert!(fr.max_element() - fr.min_element() > 0.01, "no interference colour: {fr}");
        let bare = b.with_film(Some(film(1.0, 0.0))).fresnel(v_h).0;
        let schlick = b.fresnel(v_h).0;
        assert!((bare - schlick).abs().max_element() < 0.01, "{bare} vs {schlick}");
        // Half the weight is half way.
        let half = b.with_film(Some(film(0.5, 300.0))).fresnel(v_h).0;
        assert!((half - (schlick + fr) * 0.5).abs().max_element() < 1e-6);
        // Lambert has no Fresnel term to replace.
        assert!(Brdf::lambertian(Vec4::ONE).with_film(Some(film(1.0, 300.0))).film.is_none());
    }

    /// Energy: a film reflects at most what arrives (R_film ∈ [0, 1], `scene::film`), so a
    /// white metal with a film keeps ≤ 1. Over the dielectric, glTF's mix is not itself
    /// energy-conserving — it weights the diffuse by 1 − F at each direction's half vector, so
    /// the plain BRDF returns 1.054 at 75° here — and its albedo is 1 + ∫F·(D·V − 1/π)·cos,
    /// linear in F: no Fresnel term in [0, 1] can exceed 1 + ∫max(0, D·V − 1/π)·cos, and the
    /// film's must not either.
    /// ∫max(0, D·V − 1/π)·cos over the hemisphere of `wo` (the same quadrature as below).
    fn mix_excess(b: &Brdf, wo: Vec3) -> f32 {
        let (nt, np) = (300, 200);
        let mut sum = 0.0;
        for i in 0..nt {
            let c = (i as f32 + 0.5) / nt as f32;
            for j in 0..np {
                let wi = dir(c.acos(), 2.0 * PI * (j as f32 + 0.5) / np as f32);
                let h = (wo + wi).normalize();
                sum += (b.d(h.z) * b.vis(wi.z, wo.z) - FRAC_1_PI).max(0.0) * c;
            }
        }
        sum * 2.0 * PI / (nt * np) as f32
    }

    #[test]
    fn film_keeps_energy() {
        for m in [0.0, 1.0] {
            for d in [150.0, 420.0, 900.0] {
                let b = Brdf::new(Vec4::ONE, m, 0.5).with_film(Some(film(1.0, d)));
                for theta in [0.1f32, 0.8, 1.3] {
                    let wo = dir(theta, 0.0);
                    let (nt, np) = (300, 200);
                    let mut alb = Vec4::ZERO;
                    for i in 0..nt {
                        let c = (i as f32 + 0.5) / nt as f32;
                        for j in 0..np {
                            let wi = dir(c.acos(), 2.0 * PI * (j as f32 + 0.5) / np as f32);
                            alb += b.eval(wo, wi) * c;
                        }
                    }
                    alb *= 2.0 * PI / (nt * np) as f32;
                    let bound = if m == 1.0 { 1.0 + 1e-3 } else { 1.0 + mix_excess(&b, wo) + 1e-3 };
                    assert!(alb.max_element() <= bound, "metal {m} d {d} θ {theta}: albedo {alb} > {bound}");
                }
            }
        }
    }
}
