//! See-through dielectrics: `KHR_materials_transmission` (how much of the light that the
//! dielectric's Fresnel term lets through goes on as a refracted specular lobe instead of
//! being scattered diffusely), `KHR_materials_volume` (the closed mesh's interior: a thickness
//! for renderers that cannot trace it, and an absorbing medium from an attenuation colour
//! reached at a distance) and `KHR_materials_dispersion` (the index varying with wavelength
//! by Cauchy's two-term formula from an Abbe number).
//!
//! The glTF model (KHR_materials_transmission, "BTDF"): the dielectric part of the material is
//! `fresnel_mix(ior, base = mix(diffuse, base_colour · specular_btdf, transmission), layer =
//! specular_brdf)`; metals are opaque whatever the factor. Without the volume extension (or
//! with thickness 0) the surface is *thin-walled*: light crosses it without changing direction
//! (the two interfaces of an infinitely thin sheet cancel), roughness only spreading it.
//!
//! One home for both renderers: the exact Fresnel term of an interface ([`fresnel_dielectric`])
//! and the Abbe index ([`Transmission::ior_at`]) are called by the path tracer per wavelength
//! and ported once to WGSL for the real-time renderer (`render/src/wgsl/transmission.wgsl`).

use crate::TextureRef;

/// Largest `KHR_materials_dispersion.dispersion` accepted: 20 is an Abbe number of 1, twenty
/// times the most dispersive natural material (rutile, 2.04); beyond it the Cauchy index of the
/// extension falls below 1 across most of the visible range.
pub const MAX_DISPERSION: f32 = 20.0;

/// Largest volume thickness, scene units (the real-time renderer's refraction offset).
pub const MAX_THICKNESS: f32 = 1.0e6;

/// A transmissive material's parameters (validated by the loader).
#[derive(Clone, Debug, PartialEq)]
pub struct Transmission {
    /// `transmissionFactor` in [0, 1] (× the texture's R channel): 0 is the opaque glTF material.
    pub factor: f32,
    pub texture: Option<TextureRef>,
    /// `KHR_materials_volume` with a thickness > 0; `None` = thin-walled.
    pub volume: Option<Volume>,
    /// `KHR_materials_dispersion.dispersion` = 20 / Abbe number, in [0, [`MAX_DISPERSION`]];
    /// 0 = one index for every wavelength. Only meaningful with a volume (the extension builds
    /// on it): a thin wall does not bend light, so nothing disperses.
    pub dispersion: f32,
}

/// `KHR_materials_volume`: the medium inside a closed mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// `thicknessFactor` (× the texture's G channel), scene units, > 0: how far a refracted ray
    /// travels inside, for renderers that do not trace the interior (the real-time one).
    pub thickness: f32,
    pub thickness_texture: Option<TextureRef>,
    /// `attenuationColor`, linear RGB in (0, 1]: the transmittance after `attenuation_distance`.
    pub attenuation_color: [f32; 3],
    /// `attenuationDistance`, scene units, > 0; infinite (the default) = a clear interior.
    pub attenuation_distance: f32,
}

impl Volume {
    /// Whether the interior absorbs at all.
    pub fn absorbs(&self) -> bool {
        self.attenuation_distance.is_finite() && self.attenuation_color != [1.0; 3]
    }

    /// The interior as an RGB medium (absorbing only; one scene unit per unit): the spectral
    /// renderers upsample it as they upsample every RGB medium (`color::upsample::medium`),
    /// so a glass and a fog of the same colour attenuate alike. `None` when it is clear.
    pub fn medium(&self) -> Option<crate::medium::RgbMedium> {
        if !self.absorbs() {
            return None;
        }
        // A channel of colour 0 (all light absorbed at any distance) is the strongest
        // attenuation the media accept instead: e⁻¹⁴ of the light after the distance.
        let color = self.attenuation_color.map(|c| f64::from(c).max(1e-6));
        // A distance so short that a coefficient passes the media's bound is that bound: as
        // opaque as a medium gets (the medium was refused, and the glass drawn clear, from
        // 10⁻⁶ units down, while 2·10⁻⁶ was black).
        let strongest = color.iter().map(|c| -c.ln()).fold(0.0, f64::max);
        let distance = f64::from(self.attenuation_distance)
            .max(strongest / crate::medium::MAX_COEFFICIENT * (1.0 + 1e-9));
        crate::medium::RgbMedium::from_attenuation(
            color,
            distance,
            [0.0; 3],
            0.0,
            1.0,
            color::upsample::medium::Attenuation::DEFAULT,
        )
        .ok()
    }
}

/// Fraunhofer d, F and C lines (nm), as the dispersion extension defines them.
pub const LAMBDA_D: f64 = 587.56;
pub const LAMBDA_F: f64 = 486.13;
pub const LAMBDA_C: f64 = 656.27;

impl Transmission {
    /// The index of refraction at `lambda_nm` for a material of index `ior` at the d line
    /// (`KHR_materials_ior`): Cauchy's n(λ) = A + B/λ² with B = (n_d − 1)/(V_d (λ_F⁻² − λ_C⁻²)),
    /// A = n_d − B/λ_d², V_d = 20 / dispersion; clamped at 1 as the extension says.
    pub fn ior_at(&self, ior: f32, lambda_nm: f64) -> f64 {
        abbe_ior(f64::from(ior), f64::from(self.dispersion), lambda_nm)
    }

    /// Whether the index varies with wavelength (the path tracer then follows one wavelength
    /// per path through the refraction).
    pub fn disperses(&self) -> bool {
        self.dispersion > 0.0 && self.volume.is_some()
    }
}

/// [`Transmission::ior_at`] for an index `n_d` and a `dispersion` (20 / Abbe number).
pub fn abbe_ior(n_d: f64, dispersion: f64, lambda_nm: f64) -> f64 {
    if dispersion <= 0.0 {
        return n_d;
    }
    let v_d = 20.0 / dispersion;
    let b = (n_d - 1.0) / (v_d * (LAMBDA_F.powi(-2) - LAMBDA_C.powi(-2)));
    let a = n_d - b / (LAMBDA_D * LAMBDA_D);
    (a + b / (lambda_nm * lambda_nm)).max(1.0)
}

/// The unpolarised Fresnel reflectance of a smooth interface for light arriving at cosine
/// `cos_i` (> 0, measured on the side it comes from) with relative index `eta` = n_transmitted /
/// n_incident: 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> f64 {
    let c = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - c * c) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (c - eta * cos_t) / (c + eta * cos_t);
    let rp = (eta * c - cos_t) / (eta * c + cos_t);
    0.5 * (rs * rs + rp * rp)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by a sweep: an attenuation distance of 10⁻⁶ units made a coefficient past the
    /// media's bound, the medium was dropped and the glass drawn clear (2·10⁻⁶: black). Now the
    /// shortest distances absorb as the bound does.
    #[test]
    fn a_very_short_attenuation_distance_absorbs_as_much_as_a_medium_can() {
        let volume = |d: f32| Volume {
            thickness: 1.0,
            thickness_texture: None,
            attenuation_color: [0.5, 0.25, 1.0],
            attenuation_distance: d,
        };
        let m = volume(1.0).medium().unwrap();
        assert!((m.absorption[0] - 2f64.ln()).abs() < 1e-9 && m.absorption[2] == 0.0, "{:?}", m.absorption);
        for d in [2e-6f32, 1e-6, 1e-12, f32::MIN_POSITIVE] {
            let m = volume(d).medium().unwrap_or_else(|| panic!("distance {d}: no medium"));
            let top = m.absorption.iter().copied().fold(0.0, f64::max);
            assert!(
                top > 0.3 * crate::medium::MAX_COEFFICIENT && top <= crate::medium::MAX_COEFFICIENT,
                "{d}: {top}"
            );
            // The colour's proportions kept: ln 4 / ln 2.
            assert!((m.absorption[1] / m.absorption[0] - 2.0).abs() < 1e-6, "{:?}", m.absorption);
        }
    }

    /// The extension's closed form: n(λ) = max(n_d + (n_d − 1)/V_d · (523655/λ² − 1.5168), 1).
    #[test]
    fn abbe_index_is_the_extensions_closed_form() {
        for (n_d, disp) in [(1.5f64, 0.33f64), (2.42, 0.36), (1.33, 1.0), (1.7, 2.04)] {
            let v = 20.0 / disp;
            for l in [380.0f64, 450.0, 486.13, 587.56, 656.27, 780.0] {
                let closed = (n_d + (n_d - 1.0) / v * (523655.0 / (l * l) - 1.5168)).max(1.0);
                let ours = abbe_ior(n_d, disp, l);
                assert!((ours - closed).abs() < 2e-4, "n_d {n_d} D {disp} λ {l}: {ours} vs {closed}");
            }
            // The definition it comes from: V_d = (n_d − 1)/(n_F − n_C), n(λ_d) = n_d.
            let (nf, nc) = (abbe_ior(n_d, disp, LAMBDA_F), abbe_ior(n_d, disp, LAMBDA_C));
            assert!(((n_d - 1.0) / (nf - nc) - v).abs() < 1e-9 * v);
            assert!((abbe_ior(n_d, disp, LAMBDA_D) - n_d).abs() < 1e-12);
        }
        assert_eq!(abbe_ior(1.5, 0.0, 400.0), 1.5);
    }

    /// Published values: 4 % at normal incidence for glass (n = 1.5), Brewster's angle
    /// (tan θ_B = η) reflects no p-polarised light, total internal reflection past the
    /// critical angle, and the reflectance is the same from both sides at refraction-related
    /// angles (Stokes).
    #[test]
    fn fresnel_matches_the_analytic_cases() {
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-12);
        let brewster = 1.5f64.atan();
        let c = brewster.cos();
        let s = brewster.sin() / 1.5;
        let ct = (1.0 - s * s).sqrt();
        let rs = ((c - 1.5 * ct) / (c + 1.5 * ct)).powi(2);
        assert!((fresnel_dielectric(c, 1.5) - 0.5 * rs).abs() < 1e-12);
        let critical = (1.0f64 / 1.5).asin();
        assert_eq!(fresnel_dielectric((critical + 0.01).cos(), 1.0 / 1.5), 1.0);
        assert!(fresnel_dielectric((critical - 0.01).cos(), 1.0 / 1.5) < 1.0);
        for theta in [0.1f64, 0.5, 0.9, 1.3] {
            let ct = (1.0 - (theta.sin() / 1.5).powi(2)).sqrt();
            let out = fresnel_dielectric(theta.cos(), 1.5);
            let back = fresnel_dielectric(ct, 1.0 / 1.5);
            assert!((out - back).abs() < 1e-12, "θ {theta}: {out} vs {back}");
        }
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-12);
    }
}
