//! RGB participating-medium coefficients → spectra, and how well each way reproduces the colour
//! of attenuation.
//!
//! An RGB renderer attenuates by `exp(−σ_rgb·d)` per channel. A spectral renderer needs σ(λ),
//! and the colour it then sees through distance `d` is the RGB of the spectrum
//! `exp(−σ(λ)·d)`, which is not in general `exp(−σ_rgb·d)`: a coefficient is unbounded and is
//! exponentiated, so the round trip of σ itself (what the reflectance tables guarantee) says
//! little about the round trip of the transmittance at several optical depths.
//!
//! Three ways to upsample an extinction (or absorption) coefficient, all over the Jakob–Hanika
//! table of the colour space (no second copy of a convention):
//! - [`Attenuation::Unbounded`]: `σ(λ) = s·ρ(σ_rgb/s)(λ)`, `s = 2·max σ_rgb`, pbrt-v4's
//!   `RGBUnboundedSpectrum` ([`UnboundedSpectrum`]), what pbrt-v4 does for RGB media;
//! - [`Attenuation::Transmittance`]: the transmittance colour `exp(−σ_rgb·d₀)` at a reference
//!   distance `d₀` (a multiple of the medium's mean free path) is a colour in (0, 1], so the
//!   table upsamples it as a reflectance `ρ(λ)`; then `σ(λ) = −ln ρ(λ) / d₀`. Exact (to the
//!   table's round trip) at `d = d₀`, and `exp(−σ(λ)·d) = ρ(λ)^{d/d₀}` stays a smooth, bounded
//!   transmittance at every other depth;
//! - [`Attenuation::Box`]: one box per channel ([`BoxSpectrum`], the real-time `naive` mode's
//!   basis and band edges). The exponential maps a box spectrum to a box spectrum, so
//!   `exp(−σ(λ)·d)` is the box spectrum of the per-channel `exp(−σ_c·d)` at every depth and its
//!   error is the box basis' reflectance round trip of the RGB target, whatever the optical depth;
//!   a smooth σ(λ) instead narrows under the exponential (the wavelengths of least σ dominate deep
//!   in the medium), which per-channel RGB attenuation does not do.
//!
//! The single-scattering albedo `σ_s/σ_t` is in [0, 1] per channel and is upsampled as a
//! reflectance ([`albedo`]), so σ_s(λ) = α(λ)·σ_t(λ) and σ_a(λ) = (1 − α(λ))·σ_t(λ) are never
//! negative and the extinction is exactly the upsampled one. docs/rgb-media.md has the
//! measurement ([`study`], `cargo run --release -p color --example rgb_media`) behind the
//! default, [`Attenuation::DEFAULT`].

use crate::delta_e::ciede2000;
use crate::error::{ColorError, Result};
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN, Spectrum};
use crate::upsample::boxes::BoxSpectrum;
use crate::upsample::fit::LabModel;
use crate::upsample::table::{CoeffTable, check_rgb};
use crate::upsample::variants::UnboundedSpectrum;

/// How an RGB attenuation coefficient becomes a spectrum (module docs).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Attenuation {
    /// `σ(λ) = s·ρ(σ_rgb/s)(λ)` (pbrt-v4's unbounded RGB spectrum).
    Unbounded,
    /// `σ(λ) = −ln ρ(exp(−σ_rgb·d₀))(λ) / d₀`, `d₀ = mfp_ref` mean free paths
    /// ([`mean_free_path`]).
    Transmittance { mfp_ref: f64 },
    /// One box per channel.
    Box,
}

impl Attenuation {
    /// The default, chosen by the measurement in docs/rgb-media.md: boxes (mean ΔE2000 1.7,
    /// max 10.4 over 1010 media × 0.1–10 mean free paths, against 2.5 / 33 for the transmittance
    /// colour and 3.5 / 52 for pbrt-v4's unbounded spectrum).
    pub const DEFAULT: Attenuation = Attenuation::Box;

    /// The transmittance method at its best-measured reference distance, one mean free path.
    pub const TRANSMITTANCE: Attenuation = Attenuation::Transmittance { mfp_ref: 1.0 };

    /// Names accepted by [`Attenuation::parse`] (and the scene format's `upsampling` key).
    pub const NAMES: [&'static str; 3] = ["box", "transmittance", "unbounded"];

    pub fn parse(s: &str) -> Result<Self> {
        match s.trim().to_ascii_lowercase().as_str() {
            "transmittance" => Ok(Self::TRANSMITTANCE),
            "unbounded" => Ok(Attenuation::Unbounded),
            "box" => Ok(Attenuation::Box),
            _ => Err(ColorError::Unknown {
                kind: "medium upsampling",
                name: s.into(),
                known: Self::NAMES.join(", "),
            }),
        }
    }

    /// The name [`Attenuation::parse`] reads back (the transmittance method's reference distance
    /// is always [`Attenuation::TRANSMITTANCE`]'s there).
    pub fn name(&self) -> &'static str {
        match self {
            Attenuation::Unbounded => "unbounded",
            Attenuation::Transmittance { .. } => "transmittance",
            Attenuation::Box => "box",
        }
    }

    pub fn label(&self) -> String {
        match self {
            Attenuation::Unbounded => "unbounded (pbrt-v4)".into(),
            Attenuation::Transmittance { mfp_ref } => format!("transmittance at {mfp_ref} mfp"),
            Attenuation::Box => "box".into(),
        }
    }
}

/// The medium's mean free path for the purpose of choosing depths: one over the mean of the
/// three channels' coefficients (infinite for a clear medium).
pub fn mean_free_path(sigma_rgb: [f64; 3]) -> f64 {
    3.0 / (sigma_rgb[0] + sigma_rgb[1] + sigma_rgb[2])
}

/// Wavelengths of the sampled spectra this module returns: 1 nm over the observer data.
fn grid() -> Vec<f64> {
    let n = (LAMBDA_MAX - LAMBDA_MIN) as usize;
    (0..=n).map(|i| LAMBDA_MIN + i as f64).collect()
}

fn sampled(f: impl Fn(f64) -> f64) -> Spectrum {
    let l = grid();
    let v = l.iter().map(|&x| f(x)).collect();
    Spectrum::Piecewise { lambda: l, values: v }
}

/// [`BoxSpectrum`] as a [`Spectrum`], with its steps 10⁻⁶ nm wide at the band edges (a 1 nm
/// sampling would put a ramp across each edge, which a midpoint integration reads as half a
/// box) and zero outside 360–830 nm like the other methods' spectra.
fn box_spectrum(rgb: [f64; 3]) -> Spectrum {
    use crate::upsample::boxes::{BOX_BLUE_GREEN_NM as BG, BOX_GREEN_RED_NM as GR};
    let b = BoxSpectrum { rgb };
    let e = 1e-6;
    let lambda = vec![LAMBDA_MIN, BG - e, BG, GR - e, GR, LAMBDA_MAX];
    let values = lambda.iter().map(|&l| b.eval(l)).collect();
    Spectrum::Piecewise { lambda, values }
}

/// σ(λ) for a non-negative RGB coefficient (any unit of inverse length; the spectrum has the
/// same unit), sampled at 1 nm over 360–830 nm. Black is exactly zero.
pub fn coefficient(table: &CoeffTable, sigma_rgb: [f64; 3], method: Attenuation) -> Result<Spectrum> {
    check_rgb(sigma_rgb)?;
    if sigma_rgb == [0.0; 3] {
        return Ok(Spectrum::Constant(0.0));
    }
    Ok(match method {
        Attenuation::Unbounded => {
            let u = UnboundedSpectrum::new(table, sigma_rgb)?;
            sampled(|l| u.eval(l))
        }
        Attenuation::Transmittance { mfp_ref } => {
            if !(mfp_ref.is_finite() && mfp_ref > 0.0) {
                return Err(ColorError::Table(format!(
                    "transmittance upsampling needs a positive reference distance, got {mfp_ref} mean free paths"
                )));
            }
            let d0 = mfp_ref * mean_free_path(sigma_rgb);
            let poly = table.fetch(sigma_rgb.map(|s| (-s * d0).exp()));
            // The sigmoid never reaches 0 or 1, so the logarithm is finite and positive.
            sampled(|l| -poly.eval(l).ln() / d0)
        }
        Attenuation::Box => box_spectrum(sigma_rgb),
    })
}

/// The single-scattering albedo α(λ) of an RGB albedo in [0, 1], as a reflectance through the
/// table. 0 and 1 are exact constants (a pure absorber must not scatter at all, and a
/// conservative medium must not absorb).
pub fn albedo(table: &CoeffTable, albedo_rgb: [f64; 3]) -> Result<Spectrum> {
    check_rgb(albedo_rgb)?;
    if albedo_rgb.iter().any(|&a| a > 1.0) {
        return Err(ColorError::Table(format!("albedo {albedo_rgb:?} has a component above 1")));
    }
    if albedo_rgb == [0.0; 3] {
        return Ok(Spectrum::Constant(0.0));
    }
    if albedo_rgb == [1.0; 3] {
        return Ok(Spectrum::Constant(1.0));
    }
    let poly = table.fetch(albedo_rgb);
    Ok(sampled(|l| poly.eval(l)))
}

/// (σ_a(λ), σ_s(λ)) of an RGB medium: the extinction σ_a + σ_s upsampled by `method`, split by
/// the albedo σ_s/σ_t upsampled as a reflectance (module docs).
pub fn medium(
    table: &CoeffTable,
    sigma_a_rgb: [f64; 3],
    sigma_s_rgb: [f64; 3],
    method: Attenuation,
) -> Result<(Spectrum, Spectrum)> {
    check_rgb(sigma_a_rgb)?;
    check_rgb(sigma_s_rgb)?;
    let t: [f64; 3] = std::array::from_fn(|i| sigma_a_rgb[i] + sigma_s_rgb[i]);
    let alb: [f64; 3] =
        std::array::from_fn(|i| if t[i] > 0.0 { (sigma_s_rgb[i] / t[i]).min(1.0) } else { 0.0 });
    let sigma_t = coefficient(table, t, method)?;
    let a = albedo(table, alb)?;
    match (&sigma_t, &a) {
        // Exact zeros for a pure absorber and a conservative medium (only 0 and 1 are constant).
        (_, Spectrum::Constant(k)) if *k == 0.0 => Ok((sigma_t, Spectrum::Constant(0.0))),
        (_, Spectrum::Constant(_)) => Ok((Spectrum::Constant(0.0), sigma_t)),
        (Spectrum::Constant(_), _) => Ok((sigma_t.clone(), sigma_t)),
        _ => {
            let st = |l: f64| sigma_t.eval(l);
            Ok((sampled(|l| (1.0 - a.eval(l)) * st(l)), sampled(|l| a.eval(l) * st(l))))
        }
    }
}

/// ΔE2000 between the RGB target `exp(−σ_rgb·d)` and the colour of the spectral transmittance
/// `exp(−σ(λ)·d)`, both as filters under the space's white (CIE 1931, 1 nm, [`LabModel`]).
pub fn transmittance_error(model: &LabModel, sigma_rgb: [f64; 3], sigma: &Spectrum, d: f64) -> f64 {
    let target = sigma_rgb.map(|s| (-s * d).exp());
    ciede2000(model.target_lab(target), model.lab_of_xyz(model.xyz_of(|l| (-sigma.eval(l) * d).exp())))
}

/// The RGB projection of a coefficient spectrum: its colour as if it were a reflectance under
/// the space's white (linear in σ; what a renderer that only keeps RGB would store for a
/// measured coefficient). The grid's white is mapped onto the space's per XYZ component, as
/// the Lab comparisons do.
pub fn project(model: &LabModel, sigma: &Spectrum) -> [f64; 3] {
    let xyz = model.xyz_of(|l| sigma.eval(l));
    let w = model.space.white_xyz();
    model.space.xyz_to_rgb(std::array::from_fn(|c| xyz[c] * w[c] / model.white[c]))
}

/// A named RGB extinction for the study.
#[derive(Clone, Debug)]
pub struct NamedMedium {
    pub name: String,
    pub sigma_rgb: [f64; 3],
}

/// The media of the study: hand-picked coloured media plus `random` random directions in the
/// RGB cube (fixed seed), every one scaled to a mean free path of 1, so depth is in mean free
/// paths.
pub fn study_media(random: usize) -> Vec<NamedMedium> {
    let fixed: [(&str, [f64; 3]); 10] = [
        ("grey fog", [1.0, 1.0, 1.0]),
        ("blue-white fog (σ rising to blue)", [0.8, 1.0, 1.2]),
        ("clear water (red absorbed)", [2.4, 0.45, 0.15]),
        ("green coastal water", [2.0, 0.5, 0.5]),
        ("brown smoke", [0.55, 0.9, 1.55]),
        ("red wine", [0.3, 2.4, 2.2]),
        ("milk-like (mild blue scattering)", [0.9, 1.0, 1.1]),
        ("cyan dye (red only)", [3.0, 0.0, 0.0]),
        ("magenta dye (green only)", [0.0, 3.0, 0.0]),
        ("yellow dye (blue only)", [0.0, 0.0, 3.0]),
    ];
    let mut out: Vec<NamedMedium> =
        fixed.iter().map(|(n, s)| NamedMedium { name: n.to_string(), sigma_rgb: normalise(*s) }).collect();
    let cols = crate::upsample::roundtrip::random_colours(random, 18);
    for (i, c) in cols.into_iter().enumerate() {
        if c.iter().sum::<f64>() > 1e-6 {
            out.push(NamedMedium { name: format!("random {i}"), sigma_rgb: normalise(c) });
        }
    }
    out
}

fn normalise(s: [f64; 3]) -> [f64; 3] {
    let m = (s[0] + s[1] + s[2]) / 3.0;
    s.map(|v| v / m)
}

/// Depths of the study: `n` log-spaced from 0.1 to 10 mean free paths.
pub fn study_depths(n: usize) -> Vec<f64> {
    (0..n).map(|i| 0.1 * 100f64.powf(i as f64 / (n - 1).max(1) as f64)).collect()
}

/// ΔE2000 per (medium, depth) for one method, row-major by medium.
pub fn study(
    table: &CoeffTable,
    model: &LabModel,
    media: &[NamedMedium],
    depths_mfp: &[f64],
    method: Attenuation,
) -> Result<Vec<Vec<f64>>> {
    study_with(model, media, depths_mfp, |rgb| coefficient(table, rgb, method))
}

/// [`study`] for any RGB → σ(λ) map (the example also tries box edges other than the
/// renderer's).
pub fn study_with(
    model: &LabModel,
    media: &[NamedMedium],
    depths_mfp: &[f64],
    upsample: impl Fn([f64; 3]) -> Result<Spectrum>,
) -> Result<Vec<Vec<f64>>> {
    media
        .iter()
        .map(|m| {
            let s = upsample(m.sigma_rgb)?;
            let mfp = mean_free_path(m.sigma_rgb);
            Ok(depths_mfp.iter().map(|&d| transmittance_error(model, m.sigma_rgb, &s, d * mfp)).collect())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat table: every colour is the flat grey of its mean (exact for greys, which is all
    /// these tests need without fitting a 64³ table).
    fn grey_table() -> CoeffTable {
        let res = 64;
        let scale = crate::upsample::fit::spectra_scale(res).iter().map(|&s| s as f32).collect();
        let mut t = CoeffTable {
            res,
            scale,
            chroma: crate::upsample::table::uniform_chroma(res),
            data: vec![0.0; CoeffTable::data_len(res)],
        };
        crate::upsample::fit::pin_grey_nodes(&mut t);
        t
    }

    #[test]
    fn greys_are_flat_and_exact_in_every_method() {
        let t = grey_table();
        for m in [Attenuation::Unbounded, Attenuation::TRANSMITTANCE, Attenuation::Box] {
            let s = coefficient(&t, [0.7; 3], m).unwrap();
            for l in [380.0, 500.0, 700.0] {
                assert!((s.eval(l) - 0.7).abs() < 1e-4, "{m:?} at {l}: {}", s.eval(l));
            }
            assert_eq!(coefficient(&t, [0.0; 3], m).unwrap(), Spectrum::Constant(0.0));
        }
    }

    #[test]
    fn albedo_splits_extinction_without_changing_it() {
        let t = grey_table();
        let (a, s) = medium(&t, [0.2; 3], [0.6; 3], Attenuation::DEFAULT).unwrap();
        for l in [400.0, 550.0, 700.0] {
            assert!((a.eval(l) - 0.2).abs() < 1e-3 && (s.eval(l) - 0.6).abs() < 1e-3, "{l}");
        }
        let (a, s) = medium(&t, [0.5, 0.1, 0.3], [0.0; 3], Attenuation::DEFAULT).unwrap();
        assert_eq!(s.max_value(360.0, 830.0), 0.0);
        assert!(a.max_value(360.0, 830.0) > 0.0);
        let (a, _) = medium(&t, [0.0; 3], [0.3, 0.4, 0.5], Attenuation::DEFAULT).unwrap();
        assert_eq!(a.max_value(360.0, 830.0), 0.0, "a conservative medium absorbs nothing");
    }

    /// A flat spectrum projects to the grey of its value.
    #[test]
    fn projection_of_a_constant_is_grey() {
        let model = LabModel::new(&crate::RgbColorSpace::srgb()).unwrap();
        let p = project(&model, &Spectrum::Constant(0.3));
        assert!(p.iter().all(|&v| (v - 0.3).abs() < 1e-3), "{p:?}");
    }

    #[test]
    fn refuses_bad_input() {
        let t = grey_table();
        assert!(coefficient(&t, [f64::NAN, 0.0, 0.0], Attenuation::DEFAULT).is_err());
        assert!(coefficient(&t, [-1.0, 0.0, 0.0], Attenuation::Unbounded).is_err());
        assert!(coefficient(&t, [1.0; 3], Attenuation::Transmittance { mfp_ref: 0.0 }).is_err());
        assert!(albedo(&t, [1.2, 0.0, 0.0]).is_err());
        assert!(
            Attenuation::parse("spline").unwrap_err().to_string().contains("box, transmittance, unbounded")
        );
        assert_eq!(Attenuation::parse("Unbounded").unwrap(), Attenuation::Unbounded);
    }

    /// On the real sRGB table the transmittance method is exact at its reference depth (to
    /// the table's reflectance round trip), which the unbounded one is not for coloured media.
    #[test]
    fn transmittance_is_exact_at_the_reference_depth() {
        let t = crate::upsample::table("srgb").expect("the sRGB table");
        let model = LabModel::new(&crate::RgbColorSpace::srgb()).unwrap();
        for m in study_media(0) {
            let s = coefficient(&t, m.sigma_rgb, Attenuation::TRANSMITTANCE).unwrap();
            let e = transmittance_error(&model, m.sigma_rgb, &s, mean_free_path(m.sigma_rgb));
            assert!(e < 0.5, "{}: ΔE2000 {e} at 1 mfp", m.name);
        }
    }

    /// The box study against colour-science (tools/check_rgb_media.py, which needs no
    /// coefficient table): same media, depths, data, integration grid; ours must agree per
    /// (medium, depth) to 0.01 ΔE2000.
    #[test]
    fn box_study_matches_colour_science() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/rgb_media_box.json");
        let want: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
        let media = study_media(0);
        let depths = study_depths(21);
        let model = LabModel::new(&crate::RgbColorSpace::srgb()).unwrap();
        let got = study_with(&model, &media, &depths, |rgb| Ok(box_spectrum(rgb))).unwrap();
        let want_media = want["media"].as_array().unwrap();
        assert_eq!(want_media.len(), media.len());
        for (i, w) in want_media.iter().enumerate() {
            assert_eq!(w["name"].as_str().unwrap(), media[i].name);
            for (j, e) in w["delta_e"].as_array().unwrap().iter().enumerate() {
                let e = e.as_f64().unwrap();
                assert!(
                    (got[i][j] - e).abs() < 0.01,
                    "{} at {} mfp: ours {}, colour-science {e}",
                    media[i].name,
                    depths[j],
                    got[i][j]
                );
            }
        }
    }

    /// The default's error does not grow with depth (it is the box basis' reflectance error of
    /// the target), while pbrt-v4's unbounded spectrum drifts far from the RGB deep in a dye.
    /// Figures measured by `cargo run --release -p color --example rgb_media` (named media,
    /// 21 depths 0.1–10 mfp): box max 7.01, unbounded 37.2 (cyan dye).
    #[test]
    fn box_default_stays_close_at_every_depth() {
        let t = crate::upsample::table("srgb").expect("the sRGB table");
        let model = LabModel::new(&crate::RgbColorSpace::srgb()).unwrap();
        let media = study_media(0);
        let depths = study_depths(21);
        let worst =
            |m| study(&t, &model, &media, &depths, m).unwrap().into_iter().flatten().fold(0.0, f64::max);
        let (b, u) = (worst(Attenuation::DEFAULT), worst(Attenuation::Unbounded));
        assert!(b < 7.1, "box: max ΔE2000 {b}");
        assert!(u > 3.0 * b, "unbounded {u} vs box {b}");
    }
}
