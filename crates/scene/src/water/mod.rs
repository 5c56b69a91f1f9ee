//! CPU reference of the real-time underwater light model (Monzón, Gutierrez, Akkaynak & Muñoz
//! 2024, "Real-time underwater spectral rendering", CGF e15009), per wavelength.
//!
//! Both the GPU pass and the path tracer's tests compare against these functions, so every
//! formula lives here once. Conventions: +Y is up, depths are metres below the surface
//! (positive downwards), coefficients are per metre, scene units are converted with
//! [`WaterMedium::scale`] (metres per scene unit).
//!
//! For a view ray from the camera at depth z0 in unit direction ω that hits a surface after
//! d metres:
//!
//! - **Surface term.** `ρ·E0·e^{−Kd·z_s}·e^{−c·d}`: the downwelling irradiance E0 just below
//!   the surface reaches the hit point at depth `z_s = z0 − d·ω_y` attenuated by Kd, is
//!   reflected with ρ (which includes whatever BRDF and cosine factors the renderer applies)
//!   and travels d metres back to the camera attenuated by the beam attenuation c = a + b.
//! - **In-scattering.** Single scattering of the downwelling light along the ray with an
//!   isotropic phase function 1/(4π). A point t metres along the ray is at depth
//!   `z0 − t·ω_y`, so
//!   `L_ms = ∫₀ᵈ b·E0/(4π)·e^{−Kd·(z0 − t·ω_y)}·e^{−c·t} dt`
//!   `     = b·E0·e^{−Kd·z0}/(4π) · ∫₀ᵈ e^{−(c − Kd·ω_y)·t} dt`
//!   `     = b·E0/(4π·k) · (1 − e^{−k·d}) · e^{−Kd·z0}`, with `k = c + Kd·cosθ`, `cosθ = −ω_y`.
//!
//!   (θ is the angle between the view direction and the downward vertical.) When k → 0
//!   (looking up in water where Kd ≈ c) the factor `(1 − e^{−k·d})/k` tends to d; we evaluate
//!   it with `exp_m1` so it is accurate for every k, including k < 0, where it is still the
//!   value of the integral.
//!
//! Assumptions (as in the paper): the whole path is under water (z_s ≥ 0), E0 already includes
//! transmission through the surface, the light field at depth is the surface one attenuated by
//! Kd in every direction, the phase function is isotropic and only single scattering of that
//! diffuse light is counted (the paper calls it multiple scattering because Kd already
//! encodes the multiply-scattered downwelling field).

use color::water::{WaterProperties, WaterSource, WaterType};
use color::{ColorError, Spectrum};
use glam::{DVec3, Vec3};
use thiserror::Error;

use crate::WaterSettings;

pub mod floor;
pub mod fresnel;
pub mod light_field;
mod quadrature;
pub mod single;

/// Refractive index of sea water used to bend the sun direction (visible band, ≈ 1.34).
pub const WATER_IOR: f64 = 1.34;

/// Mean cosine of Petzold's average-particle phase function (Mobley 1994, *Light and Water*,
/// §3.8): the Henyey–Greenstein g of the path-traced water and the real-time model's default,
/// one constant so that both renderers scatter alike.
pub const PETZOLD_G: f32 = 0.924;

impl From<ColorError> for WaterError {
    fn from(e: ColorError) -> Self {
        WaterError::Color(e)
    }
}

/// What [`WaterMedium`] refuses.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum WaterError {
    /// The colour error's text is in the message, so it is not also chained as the source
    /// (a `{:#}` print of the chain would show it twice).
    #[error("water: {0}")]
    Color(ColorError),
    #[error("water depth must be a finite number of metres ≥ 0 (positive downwards), got {0}")]
    BadDepth(f64),
    #[error("water scale (metres per scene unit) must be finite and > 0, got {0}")]
    BadScale(f64),
    #[error("sun direction {0:?} must be finite, non-zero and above the horizon (y > 0)")]
    BadSun([f64; 3]),
    #[error("water query: {0}")]
    BadQuery(String),
}

/// Coefficients at one wavelength, per metre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaterCoefficients {
    pub a: f64,
    pub b: f64,
    /// c = a + b.
    pub c: f64,
    pub kd: f64,
}

/// The per-wavelength factors of one pixel, independent of E0 and ρ, so a GPU test can compare
/// each one: radiance = ρ·E0·`surface_attenuation`·`transmittance` + E0·`in_scatter`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelTerms {
    pub lambda: f64,
    /// e^{−c·d}: beam transmittance from the hit point to the camera.
    pub transmittance: f64,
    /// e^{−Kd·z_s}: downwelling light reaching the hit point's depth.
    pub surface_attenuation: f64,
    /// L_ms / E0: in-scattered radiance per unit surface irradiance (1/sr).
    pub in_scatter: f64,
}

/// `(1 − e^{−k·d})/k`, continuous through k = 0 (where it is d).
pub fn path_integral(k: f64, d: f64) -> f64 {
    let kd = k * d;
    if kd.abs() < 1e-12 { d * (1.0 - 0.5 * kd) } else { -(-kd).exp_m1() / k }
}

/// The analytic in-scattering term L_ms for one wavelength (see the module docs): coefficients
/// `b`, `c`, `kd` (1/m), irradiance `e0`, `cos_theta` = −ω_y, camera depth `z0` and ray length
/// `d` (m).
pub fn in_scatter(b: f64, c: f64, kd: f64, e0: f64, cos_theta: f64, z0: f64, d: f64) -> f64 {
    let k = c + kd * cos_theta;
    b * e0 / (4.0 * std::f64::consts::PI) * path_integral(k, d) * (-kd * z0).exp()
}

/// The surface term `ρ·E0·e^{−Kd·z_s}·e^{−c·d}` for one wavelength.
pub fn surface_radiance(rho_e0: f64, c: f64, kd: f64, surface_depth: f64, d: f64) -> f64 {
    rho_e0 * (-kd * surface_depth).exp() * (-c * d).exp()
}

/// A body of water around the camera: its optical properties, the camera depth, the sun and
/// the scene's scale. Construct with [`WaterMedium::new`] or [`WaterMedium::from_settings`].
#[derive(Clone, Debug, PartialEq)]
pub struct WaterMedium {
    /// The Jerlov type (for messages and the UI); `None` for custom properties.
    pub water_type: Option<WaterType>,
    pub properties: WaterProperties,
    /// Camera depth z0, metres below the surface.
    pub depth: f64,
    /// Unit direction towards the sun, above water (y > 0).
    pub sun_dir: Vec3,
    /// Metres per scene unit.
    pub scale: f64,
    /// Sky plane irradiance below the surface as a multiple of the sun's (`water.sky`, see
    /// `scene::sky`); 0 unless set from the scene's settings.
    pub sky: f64,
    /// The sea floor under the camera, for the real-time light-field model ([`floor`]); `None`
    /// = a bottomless column.
    pub floor: Option<floor::SeaFloor>,
}

impl WaterMedium {
    /// A Jerlov type from the default dataset (Solonenko & Mobley 2015).
    pub fn new(water_type: WaterType, depth: f64, sun_dir: Vec3, scale: f64) -> Result<Self, WaterError> {
        Self::with_source(water_type, WaterSource::default(), depth, sun_dir, scale)
    }

    /// A Jerlov type from a chosen dataset.
    pub fn with_source(
        water_type: WaterType,
        source: WaterSource,
        depth: f64,
        sun_dir: Vec3,
        scale: f64,
    ) -> Result<Self, WaterError> {
        let properties = water_type.properties(source)?;
        let mut m = Self::with_properties(properties, depth, sun_dir, scale)?;
        m.water_type = Some(water_type);
        Ok(m)
    }

    /// Custom coefficients (e.g. measured). Checks them over 360–830 nm: finite, non-negative,
    /// c = a + b > 0.
    pub fn with_properties(
        properties: WaterProperties,
        depth: f64,
        sun_dir: Vec3,
        scale: f64,
    ) -> Result<Self, WaterError> {
        if !(depth.is_finite() && depth >= 0.0) {
            return Err(WaterError::BadDepth(depth));
        }
        if !(scale.is_finite() && scale > 0.0) {
            return Err(WaterError::BadScale(scale));
        }
        let s = sun_dir.as_dvec3();
        if !(s.is_finite() && s.length() > 1e-12 && s.y > 0.0) {
            return Err(WaterError::BadSun(s.to_array()));
        }
        properties.validate()?;
        Ok(WaterMedium {
            water_type: None,
            properties,
            depth,
            sun_dir: s.normalize().as_vec3(),
            scale,
            sky: 0.0,
            floor: None,
        })
    }

    /// From a scene's `WaterSettings` (type name parsed with [`WaterType::parse`]).
    pub fn from_settings(s: &WaterSettings) -> Result<Self, WaterError> {
        let mut m =
            Self::new(WaterType::parse(&s.water_type)?, s.depth as f64, s.sun_direction, s.scale as f64)?;
        m.sky = s.sky as f64;
        Ok(m)
    }

    /// a, b, c, Kd at `lambda` nm.
    pub fn coefficients(&self, lambda: f64) -> WaterCoefficients {
        let [a, b, c, kd] = self.properties.at(lambda);
        WaterCoefficients { a, b, c, kd }
    }

    /// `[a, b, c, Kd]` at each wavelength, as f32 for a GPU buffer.
    pub fn coefficient_table(&self, lambda: &[f64]) -> Vec<[f32; 4]> {
        lambda.iter().map(|&l| self.properties.at(l).map(|v| v as f32)).collect()
    }

    /// The direction towards the sun as seen from under water: refracted at a flat surface by
    /// Snell's law with [`WATER_IOR`], so a sun at the horizon appears at the critical angle
    /// (≈ 48° from the zenith).
    pub fn sun_dir_underwater(&self) -> Vec3 {
        let s = self.sun_dir.as_dvec3();
        let h = DVec3::new(s.x, 0.0, s.z) / WATER_IOR;
        DVec3::new(h.x, (1.0 - h.length_squared()).max(0.0).sqrt(), h.z).as_vec3()
    }

    /// Depth (m) of a scene point, given the camera's position (the camera is at [`Self::depth`]).
    pub fn depth_of(&self, camera: Vec3, point: Vec3) -> f64 {
        self.depth - (point.y as f64 - camera.y as f64) * self.scale
    }

    /// Per-wavelength factors for a ray from the camera in unit direction `dir` that travels
    /// `distance` metres to a hit (`f64::INFINITY` for a ray that hits nothing: it then runs
    /// to the surface if it points up, or forever if not, and has no surface term).
    pub fn pixel_terms(
        &self,
        lambda: &[f64],
        dir: Vec3,
        distance: f64,
    ) -> Result<Vec<PixelTerms>, WaterError> {
        let w = dir.as_dvec3();
        if !(w.is_finite() && (w.length() - 1.0).abs() < 1e-4) {
            return Err(WaterError::BadQuery(format!("view direction {w:?} is not a unit vector")));
        }
        if distance.is_nan() || distance < 0.0 {
            return Err(WaterError::BadQuery(format!("distance {distance} m is negative or NaN")));
        }
        // A ray never leaves the water: an upward ray ends at the surface.
        let to_surface = if w.y > 0.0 { self.depth / w.y } else { f64::INFINITY };
        if distance.is_finite() && distance > to_surface * (1.0 + 1e-9) {
            return Err(WaterError::BadQuery(format!(
                "a hit {distance} m along {w:?} from {} m depth is above the water surface",
                self.depth
            )));
        }
        let hit = distance.is_finite();
        let d = distance.min(to_surface);
        let z_s = (self.depth - d * w.y).max(0.0);
        Ok(lambda
            .iter()
            .map(|&l| {
                let k = self.coefficients(l);
                let ms = if d.is_finite() {
                    in_scatter(k.b, k.c, k.kd, 1.0, -w.y, self.depth, d)
                } else {
                    // d → ∞ downwards or sideways: k = c − Kd·ω_y ≥ c > 0, the exponential vanishes.
                    k.b / (4.0 * std::f64::consts::PI * (k.c - k.kd * w.y)) * (-k.kd * self.depth).exp()
                };
                PixelTerms {
                    lambda: l,
                    transmittance: if hit { (-k.c * d).exp() } else { 0.0 },
                    surface_attenuation: if hit { (-k.kd * z_s).exp() } else { 0.0 },
                    in_scatter: ms,
                }
            })
            .collect())
    }

    /// Spectral radiance at the camera for a ray from `camera` to `hit` (scene units) on a
    /// surface of reflectance `rho`, under the downwelling irradiance `e0` just below the
    /// surface, at each of `lambda`.
    pub fn shade(
        &self,
        lambda: &[f64],
        e0: &Spectrum,
        rho: &Spectrum,
        camera: Vec3,
        hit: Vec3,
    ) -> Result<Vec<f64>, WaterError> {
        let v = (hit - camera).as_dvec3();
        let len = v.length();
        if !(len.is_finite() && len > 0.0) {
            return Err(WaterError::BadQuery(format!("camera {camera:?} and hit {hit:?} must differ")));
        }
        let terms = self.pixel_terms(lambda, (v / len).as_vec3(), len * self.scale)?;
        Ok(terms
            .iter()
            .map(|t| {
                let e = e0.eval(t.lambda);
                rho.eval(t.lambda) * e * t.surface_attenuation * t.transmittance + e * t.in_scatter
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::quadrature::simpson;
    use super::*;
    use std::f64::consts::PI;

    fn single_scatter_numeric(b: f64, c: f64, kd: f64, e0: f64, wy: f64, z0: f64, d: f64) -> f64 {
        let f = |t: f64| b * e0 / (4.0 * PI) * (-kd * (z0 - t * wy)).exp() * (-c * t).exp();
        let scale = f(0.0).max(f(d)).max(1e-300);
        simpson(&f, 0.0, d, 1e-12 * scale * d.max(1.0))
    }

    fn sun() -> Vec3 {
        Vec3::new(0.3, 0.9, 0.1)
    }

    #[test]
    fn analytic_in_scatter_matches_numerical_integral() {
        let dirs = [
            DVec3::new(0.0, 1.0, 0.0),  // straight up
            DVec3::new(0.0, -1.0, 0.0), // straight down
            DVec3::new(1.0, 0.0, 0.0),  // horizontal
            DVec3::new(0.6, 0.8, 0.0),
            DVec3::new(0.3, -0.9, 0.2),
            DVec3::new(-0.7, 0.2, 0.5),
            DVec3::new(0.1, -0.3, -0.9),
        ];
        let mut checked = 0;
        let mut worst: f64 = 0.0;
        for (src, types) in [
            (WaterSource::Solonenko2015, &["I", "IB", "II.5", "III", "1C", "5C", "9C"][..]),
            (WaterSource::Williamson2022, &["IB", "III", "3C.5", "5C"][..]),
        ] {
            for ty in types {
                let p = WaterType::parse(ty).unwrap().properties(src).unwrap();
                for z0 in [0.0, 2.5, 15.0, 60.0] {
                    for w in dirs {
                        let w = w.normalize();
                        for d in [0.01, 0.7, 5.0, 30.0, 120.0] {
                            if z0 - d * w.y < 0.0 {
                                continue; // the path would leave the water
                            }
                            for l in [400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 700.0] {
                                let [_, b, c, kd] = p.at(l);
                                let e0 = 1.7;
                                let exact = in_scatter(b, c, kd, e0, -w.y, z0, d);
                                let num = single_scatter_numeric(b, c, kd, e0, w.y, z0, d);
                                let rel = (exact - num).abs() / num.abs();
                                assert!(
                                    exact > 0.0 && rel < 1e-3,
                                    "{ty} z0={z0} w={w:?} d={d} λ={l}: {exact} vs {num}"
                                );
                                worst = worst.max(rel);
                                checked += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(checked > 3000, "{checked}");
        eprintln!("in-scatter: {checked} cases, worst relative error {worst:e}");
        assert!(worst < 1e-6, "worst relative error {worst}");
    }

    #[test]
    fn in_scatter_is_continuous_where_c_plus_kd_cos_theta_vanishes() {
        // Custom water with Kd = c looking straight up: k = 0, and the integral is b·E0·d/(4π)·e^{−Kd·z0}.
        let (b, c, kd, z0, d) = (0.3, 0.5, 0.5, 10.0, 4.0);
        let exact = in_scatter(b, c, kd, 1.0, -1.0, z0, d);
        let expect = b * d / (4.0 * PI) * (-kd * z0).exp();
        assert!((exact - expect).abs() < 1e-12 * expect);
        // And k < 0 (Kd > c, looking up) still equals the integral.
        let exact = in_scatter(b, 0.4, 0.6, 1.0, -1.0, z0, d);
        let num = single_scatter_numeric(b, 0.4, 0.6, 1.0, 1.0, z0, d);
        assert!((exact - num).abs() < 1e-6 * num);
        for k in [-1e-13, 0.0, 1e-13, 1e-6] {
            assert!((path_integral(k, 3.0) - 3.0).abs() < 1e-5);
        }
    }

    #[test]
    fn pixel_terms_compose_the_paper_model() {
        let m = WaterMedium::new(WaterType::parse("II").unwrap(), 8.0, sun(), 0.5).unwrap();
        let lambda = [450.0, 550.0, 650.0];
        let e0 = Spectrum::Constant(2.0);
        let rho = Spectrum::Constant(0.4);
        let cam = Vec3::new(0.0, 0.0, 0.0);
        let hit = Vec3::new(3.0, -4.0, 0.0); // 5 scene units = 2.5 m, going down
        let l = m.shade(&lambda, &e0, &rho, cam, hit).unwrap();
        for (i, &lam) in lambda.iter().enumerate() {
            let k = m.coefficients(lam);
            let d = 2.5;
            let z_s = 8.0 + 4.0 * 0.5;
            assert!((m.depth_of(cam, hit) - z_s).abs() < 1e-9);
            let expect =
                surface_radiance(0.4 * 2.0, k.c, k.kd, z_s, d) + in_scatter(k.b, k.c, k.kd, 2.0, 0.8, 8.0, d);
            // The ray direction passes through f32 (scene positions are f32): ~1e-7 relative.
            assert!((l[i] - expect).abs() < 1e-6 * expect, "{lam}: {} vs {expect}", l[i]);
        }
        // Red is absorbed far more than blue-green in clear ocean water.
        assert!(l[2] < l[1]);
        // Farther objects fade into the water colour: radiance tends to the background in-scatter.
        let far = m.pixel_terms(&[500.0], Vec3::X, 500.0).unwrap()[0];
        let bg = m.pixel_terms(&[500.0], Vec3::X, f64::INFINITY).unwrap()[0];
        assert!(far.transmittance < 1e-20 && (far.in_scatter - bg.in_scatter).abs() < 1e-9 * bg.in_scatter);
        assert_eq!((bg.transmittance, bg.surface_attenuation), (0.0, 0.0));
        // Looking up at nothing: the path ends at the surface, 8 m away.
        let up = m.pixel_terms(&[500.0], Vec3::Y, f64::INFINITY).unwrap()[0];
        let k = m.coefficients(500.0);
        assert!((up.in_scatter - in_scatter(k.b, k.c, k.kd, 1.0, -1.0, 8.0, 8.0)).abs() < 1e-15);
    }

    /// CIE 1931 chromaticity of a radiance spectrum given at `lambda` (midpoint rule, 5 nm).
    fn xy(lambda: &[f64], radiance: &[f64]) -> [f64; 2] {
        use color::{Observer, SampledWavelengths, SpectralIntegrator, WavelengthRange};
        let wl =
            SampledWavelengths::midpoint(WavelengthRange::new(380.0, 730.0).unwrap(), lambda.len()).unwrap();
        assert_eq!(wl.lambda, lambda);
        let d65 = color::illuminant::by_name("D65").unwrap();
        let xyz = SpectralIntegrator::emission(&Observer::cie1931(), &d65, &wl).integrate_samples(radiance);
        color::xyz::xyz_to_xy(xyz)
    }

    #[test]
    fn colours_are_physically_plausible() {
        let lambda: Vec<f64> = (0..70).map(|i| 382.5 + 5.0 * i as f64).collect();
        let e0 = color::illuminant::by_name("D65").unwrap();
        let white = Spectrum::Constant(1.0);
        // A white card 0.5 m in front of a diver loses red as the diver descends: x falls
        // monotonically with depth, and by 20 m in Jerlov II (Kd lowest near 450–500 nm) it is
        // clearly blue, far from D65's (0.3127, 0.3290).
        let mut last_x = f64::INFINITY;
        for z0 in [0.0, 5.0, 10.0, 20.0, 40.0] {
            let m = WaterMedium::new(WaterType::parse("II").unwrap(), z0, sun(), 1.0).unwrap();
            let l = m.shade(&lambda, &e0, &white, Vec3::ZERO, Vec3::new(0.0, 0.0, -0.5)).unwrap();
            let [x, y] = xy(&lambda, &l);
            assert!(x < last_x, "z0 {z0}: x {x} did not fall below {last_x}");
            last_x = x;
            if z0 == 20.0 {
                eprintln!("white card at 20 m in II, xy (D65): ({x:.4}, {y:.4})");
                assert!(x < 0.22 && y < 0.29, "white at 20 m: ({x}, {y})");
            }
        }
        // The colour of the water itself (a horizontal ray that hits nothing, 5 m down): blue in
        // clear oceanic water, yellow-green in turbid coastal water.
        let water_xy = |t: &str| {
            let m = WaterMedium::new(WaterType::parse(t).unwrap(), 5.0, sun(), 1.0).unwrap();
            let terms = m.pixel_terms(&lambda, Vec3::X, f64::INFINITY).unwrap();
            let l: Vec<f64> = terms.iter().map(|p| p.in_scatter * e0.eval(p.lambda)).collect();
            xy(&lambda, &l)
        };
        let (ocean, coast) = (water_xy("I"), water_xy("9C"));
        assert!(ocean[0] < 0.25 && ocean[1] < 0.3, "Jerlov I water colour {ocean:?}");
        assert!(coast[1] > ocean[1] + 0.1 && coast[1] > 0.4, "Jerlov 9C {coast:?} vs I {ocean:?}");
        eprintln!("water colour xy at 5 m (D65): I {ocean:?}, 9C {coast:?}");
    }

    #[test]
    fn rejects_bad_parameters_with_clear_errors() {
        let t = WaterType::parse("III").unwrap();
        let e = WaterMedium::new(t, -1.0, sun(), 1.0).unwrap_err();
        assert!(e.to_string().contains("depth") && e.to_string().contains("-1"), "{e}");
        assert!(matches!(WaterMedium::new(t, f64::NAN, sun(), 1.0), Err(WaterError::BadDepth(_))));
        assert!(matches!(WaterMedium::new(t, 1.0, sun(), 0.0), Err(WaterError::BadScale(_))));
        assert!(matches!(WaterMedium::new(t, 1.0, Vec3::ZERO, 1.0), Err(WaterError::BadSun(_))));
        assert!(matches!(
            WaterMedium::new(t, 1.0, Vec3::new(1.0, -0.2, 0.0), 1.0),
            Err(WaterError::BadSun(_))
        ));
        assert!(matches!(
            WaterMedium::new(t, 1.0, Vec3::new(f32::NAN, 1.0, 0.0), 1.0),
            Err(WaterError::BadSun(_))
        ));
        let p = WaterProperties::jerlov("III").unwrap();
        let clear = WaterProperties {
            a: Spectrum::Constant(0.0),
            b: Spectrum::Constant(0.0),
            c: Spectrum::Constant(0.0),
            ..p.clone()
        };
        let e = WaterMedium::with_properties(clear, 1.0, sun(), 1.0).unwrap_err().to_string();
        assert!(e.contains("a + b"), "{e}");
        let inf = WaterProperties { b: Spectrum::Constant(f64::INFINITY), ..p };
        assert!(WaterMedium::with_properties(inf, 1.0, sun(), 1.0).is_err());
        let settings = WaterSettings {
            water_type: "XIV".into(),
            depth: 3.0,
            sun_direction: sun(),
            scale: 1.0,
            sky: 0.0,
        };
        let e = WaterMedium::from_settings(&settings).unwrap_err().to_string();
        assert!(e.contains("XIV") && e.contains("II.5"), "{e}");
        let m = WaterMedium::new(t, 2.0, sun(), 1.0).unwrap();
        assert!(m.pixel_terms(&[500.0], Vec3::Y, 5.0).is_err(), "a hit above the surface");
        assert!(m.pixel_terms(&[500.0], Vec3::new(0.0, 2.0, 0.0), 1.0).is_err());
        assert!(m.pixel_terms(&[500.0], Vec3::X, -1.0).is_err());
        assert!(
            m.shade(&[500.0], &Spectrum::Constant(1.0), &Spectrum::Constant(1.0), Vec3::ZERO, Vec3::ZERO)
                .is_err()
        );
    }

    #[test]
    fn settings_and_sun_refraction() {
        let s = WaterSettings {
            water_type: "1C.5".into(),
            depth: 4.0,
            sun_direction: Vec3::new(1.0, 1e-6, 0.0),
            scale: 2.0,
            sky: 0.0,
        };
        let m = WaterMedium::from_settings(&s).unwrap();
        assert_eq!(m.water_type.unwrap().to_string(), "1C.5");
        // A grazing sun appears at the critical angle asin(1/n) from the zenith.
        let w = m.sun_dir_underwater();
        let from_zenith = (w.y as f64).acos();
        assert!((from_zenith - (1.0 / WATER_IOR).asin()).abs() < 1e-3, "{from_zenith}");
        let zenith = WaterMedium::new(WaterType::parse("I").unwrap(), 1.0, Vec3::Y, 1.0).unwrap();
        assert!((zenith.sun_dir_underwater() - Vec3::Y).length() < 1e-6);
        let table = m.coefficient_table(&[500.0, 600.0]);
        let k = m.coefficients(600.0);
        assert_eq!(table[1], [k.a as f32, k.b as f32, k.c as f32, k.kd as f32]);
    }
}
