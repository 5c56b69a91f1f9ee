//! Observers: the three sensitivity curves that turn a spectrum into tristimulus values.
//!
//! Besides the CIE observers there are camera sensitivity sets, human cone fundamentals and an
//! animal observer. For those the three "tristimulus" values are not CIE XYZ; see
//! [`ObserverKind`] for what they are and how a renderer should display them.

use glam::{DMat3, DVec3};

use crate::data::{SampledTable, cmf, colorchecker, observers_extra as ox};
use crate::error::{ColorError, Result};
use crate::spectrum::{LAMBDA_MAX, LAMBDA_MIN, Spectrum};

/// What the three channels of an observer mean.
///
/// Only [`ObserverKind::CieXyz`] produces CIE XYZ. For the others spectra's convention is:
/// the channels are white balanced by dividing by the response to the perfect white under the
/// scene illuminant (von Kries; [`Observer::white_balance`]), and the balanced triple is then
/// treated as **linear display RGB** (white → (1, 1, 1)), which shows what the sensor or eye
/// distinguishes rather than a colorimetric reproduction. For a colorimetric view of a camera,
/// [`Observer::fit_to_xyz`] gives the least-squares 3×3 matrix from balanced camera RGB to
/// CIE 1931 XYZ over the 24 ColorChecker patches (the usual camera characterisation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObserverKind {
    /// x̄, ȳ, z̄ of a CIE standard observer: the output is CIE XYZ.
    CieXyz,
    /// Camera raw R, G, B sensitivities: the output is camera RGB.
    CameraRgb,
    /// Photoreceptor sensitivities, longest-wavelength receptor first (L, M, S for humans):
    /// the output is receptor excitations.
    Receptors,
}

/// Three spectral sensitivities. For the CIE observers these are x̄, ȳ, z̄ and the tristimulus
/// values are CIE XYZ; for the others see [`ObserverKind`].
#[derive(Clone, Debug, PartialEq)]
pub struct Observer {
    pub name: String,
    pub bar: [Spectrum; 3],
}

impl Observer {
    fn from_tables(name: &str, t: [&SampledTable; 3]) -> Self {
        Observer { name: name.into(), bar: t.map(Spectrum::from_table) }
    }

    /// CIE 1931 2° standard observer, the default everywhere in spectra.
    pub fn cie1931() -> Self {
        Self::from_tables("cie1931", [&cmf::CIE1931_2_X, &cmf::CIE1931_2_Y, &cmf::CIE1931_2_Z])
    }

    /// CIE 1964 10° supplementary standard observer.
    pub fn cie1964() -> Self {
        Self::from_tables("cie1964", [&cmf::CIE1964_10_X, &cmf::CIE1964_10_Y, &cmf::CIE1964_10_Z])
    }

    /// CIE 2015 2° observer (CIE 170-2:2015): x̄, ȳ, z̄ derived from the CIE 2006 LMS cone
    /// fundamentals, 390–830 nm at 1 nm (zero below 390 nm, where it is not tabulated).
    pub fn cie2015_2() -> Self {
        Self::from_tables("cie2015_2", [&cmf::CIE2015_2_X, &cmf::CIE2015_2_Y, &cmf::CIE2015_2_Z])
    }

    /// CIE 2015 10° observer (CIE 170-2:2015), 390–830 nm at 1 nm.
    pub fn cie2015_10() -> Self {
        Self::from_tables("cie2015_10", [&cmf::CIE2015_10_X, &cmf::CIE2015_10_Y, &cmf::CIE2015_10_Z])
    }

    /// Nikon D5100 camera raw RGB, measured at NPL (Darrodi et al. 2015), 380–780 nm at 5 nm.
    pub fn nikon_d5100() -> Self {
        Self::from_tables("nikon_d5100", [&ox::NIKON_D5100_R, &ox::NIKON_D5100_G, &ox::NIKON_D5100_B])
    }

    /// Sigma SD Merrill (Foveon) camera raw RGB, measured at NPL (Darrodi et al. 2015),
    /// 400–680 nm at 10 nm.
    pub fn sigma_sd_merrill() -> Self {
        Self::from_tables(
            "sigma_sd_merrill",
            [&ox::SIGMA_SD_MERRILL_R, &ox::SIGMA_SD_MERRILL_G, &ox::SIGMA_SD_MERRILL_B],
        )
    }

    /// Canon EOS 5D Mark II camera raw RGB from the Academy's rawtoaces, 380–780 nm at 5 nm.
    pub fn canon_5d_mark_ii() -> Self {
        Self::from_tables(
            "canon_5d_mark_ii",
            [&ox::CANON_5D_MARK_II_R, &ox::CANON_5D_MARK_II_G, &ox::CANON_5D_MARK_II_B],
        )
    }

    /// The Academy's idealised ACES Reference Input Capture Device (a linear transform of the
    /// CIE 1931 observer, so it satisfies the Luther condition exactly).
    pub fn aces_ricd() -> Self {
        Self::from_tables("aces_ricd", [&ox::ACES_RICD_R, &ox::ACES_RICD_G, &ox::ACES_RICD_B])
    }

    /// Human L, M, S cone fundamentals, Stockman & Sharpe 2000 2° (CIE 170-1:2006), 390–830 nm.
    pub fn lms_stockman_sharpe() -> Self {
        Self::from_tables(
            "lms2",
            [&ox::STOCKMAN_SHARPE_2_L, &ox::STOCKMAN_SHARPE_2_M, &ox::STOCKMAN_SHARPE_2_S],
        )
    }

    /// Picasso triggerfish (*Rhinecanthus aculeatus*), a trichromatic coral-reef fish: visual
    /// pigments with λmax 528 nm (LW), 480 nm (MW) and 413 nm (SW) (Cheney et al. 2013,
    /// J. Exp. Biol. 216, microspectrophotometry), each modelled with the Govardovskii et al. 2000 A1 template
    /// ([`govardovskii_a1`]). Pigment absorbance only: ocular media filtering and
    /// photoreceptor self-screening are not modelled.
    pub fn triggerfish() -> Self {
        Self::from_pigments("triggerfish", [528.0, 480.0, 413.0])
    }

    /// Dog, a dichromat: S pigment λmax 429 nm and L pigment λmax 555 nm (Neitz, Geist & Jacobs
    /// 1989, Vis. Neurosci. 3, 119), Govardovskii A1 template. Two receptors are shown as three
    /// channels (L, L, S), so under the display convention of [`ObserverKind`] every colour
    /// falls on the yellow–blue axis, which is what a dichromat can distinguish.
    pub fn dog() -> Self {
        Self::from_pigments("dog", [555.0, 555.0, 429.0])
    }

    /// A human protanope (no L cones): Stockman & Sharpe 2° cone fundamentals as (M, M, S); see
    /// [`Observer::dog`] for why a receptor is repeated.
    pub fn protanope() -> Self {
        Self::from_tables(
            "protanope",
            [&ox::STOCKMAN_SHARPE_2_M, &ox::STOCKMAN_SHARPE_2_M, &ox::STOCKMAN_SHARPE_2_S],
        )
    }

    /// A human deuteranope (no M cones): Stockman & Sharpe 2° cone fundamentals as (L, L, S).
    pub fn deuteranope() -> Self {
        Self::from_tables(
            "deuteranope",
            [&ox::STOCKMAN_SHARPE_2_L, &ox::STOCKMAN_SHARPE_2_L, &ox::STOCKMAN_SHARPE_2_S],
        )
    }

    /// An observer whose three channels are A1 visual pigments with the given λmax (nm,
    /// longest first), sampled from the Govardovskii template at 1 nm over 360–830 nm.
    pub fn from_pigments(name: &str, lambda_max: [f64; 3]) -> Self {
        let lambda: Vec<f64> = (LAMBDA_MIN as usize..=LAMBDA_MAX as usize).map(|l| l as f64).collect();
        let bar = lambda_max.map(|lm| Spectrum::Piecewise {
            lambda: lambda.clone(),
            values: lambda.iter().map(|&l| govardovskii_a1(lm, l)).collect(),
        });
        Observer { name: name.into(), bar }
    }

    /// What the channels of this observer mean (by name; unknown names count as receptors).
    pub fn kind(&self) -> ObserverKind {
        match self.name.as_str() {
            "cie1931" | "cie1964" | "cie2015_2" | "cie2015_10" => ObserverKind::CieXyz,
            "nikon_d5100" | "sigma_sd_merrill" | "canon_5d_mark_ii" | "aces_ricd" => ObserverKind::CameraRgb,
            n if Self::camera(n).is_some() => ObserverKind::CameraRgb,
            // A file (`--observer FILE.csv`): a CIE observer's colour-matching functions give
            // CIE XYZ; any other such file is taken for a camera, as most are.
            n if crate::observer_file::is_file_name(n) => match crate::observer_file::cie_twin(self) {
                Some(_) => ObserverKind::CieXyz,
                None => ObserverKind::CameraRgb,
            },
            _ => ObserverKind::Receptors,
        }
    }

    /// Response of each channel to the perfect white (reflectance 1) under `illuminant`,
    /// integrated at 1 nm over 360–830 nm. Dividing by it is the white balance described in
    /// [`ObserverKind`].
    pub fn white_balance(&self, illuminant: &Spectrum) -> [f64; 3] {
        self.response(&Spectrum::Constant(1.0), illuminant)
    }

    /// Channel responses to a reflectance under an illuminant, 1 nm midpoint rule, 360–830 nm.
    pub fn response(&self, reflectance: &Spectrum, illuminant: &Spectrum) -> [f64; 3] {
        let mut out = [0.0; 3];
        let n = (LAMBDA_MAX - LAMBDA_MIN) as usize;
        for i in 0..n {
            let l = LAMBDA_MIN + i as f64 + 0.5;
            let e = reflectance.eval(l) * illuminant.eval(l);
            for (o, s) in out.iter_mut().zip(self.eval(l)) {
                *o += s * e;
            }
        }
        out
    }

    /// Least-squares 3×3 matrix M with XYZ ≈ M · rgb for the 24 ColorChecker Classic patches
    /// under `illuminant`, where rgb is this observer's white-balanced response (white = 1) and
    /// XYZ is CIE 1931 normalised to Y = 1 for the perfect white. Also returns the RMS residual
    /// over the patches in XYZ units. Errors if the white gives a zero channel.
    pub fn fit_to_xyz(&self, illuminant: &Spectrum) -> Result<(DMat3, f64)> {
        let wb = self.white_balance(illuminant);
        if wb.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            return Err(ColorError::BadSpectrum(format!(
                "observer '{}' has a zero or invalid channel under this illuminant ({wb:?})",
                self.name
            )));
        }
        let cie = Observer::cie1931();
        let yw = cie.white_balance(illuminant)[1];
        let pairs: Vec<(DVec3, DVec3)> = colorchecker::SPECTRA
            .iter()
            .map(|t| {
                let r = Spectrum::from_table(t);
                let rgb = self.response(&r, illuminant);
                let xyz = cie.response(&r, illuminant);
                (DVec3::new(rgb[0] / wb[0], rgb[1] / wb[1], rgb[2] / wb[2]), DVec3::from_array(xyz) / yw)
            })
            .collect();
        // Normal equations: M = (Σ x rᵀ)(Σ r rᵀ)⁻¹.
        let outer = |a: DVec3, b: DVec3| DMat3::from_cols(a * b.x, a * b.y, a * b.z);
        let (xr, rr) = pairs
            .iter()
            .fold((DMat3::ZERO, DMat3::ZERO), |(xr, rr), (r, x)| (xr + outer(*x, *r), rr + outer(*r, *r)));
        if rr.determinant().abs() < 1e-300 {
            return Err(ColorError::BadSpectrum(format!(
                "observer '{}' cannot be fitted to XYZ: its channels are linearly dependent on the chart",
                self.name
            )));
        }
        let m = xr * rr.inverse();
        let rms = (pairs.iter().map(|(r, x)| (m * *r - *x).length_squared()).sum::<f64>()
            / pairs.len() as f64)
            .sqrt();
        Ok((m, rms))
    }

    /// Where each of [`Self::NAMES`] comes from, in the same order (`spectra observers`).
    pub const SOURCES: &'static [&'static str] = &[
        "CIE 1931 2° standard observer (CIE 018:2019 / ISO 11664-1 tables, via colour-science)",
        "CIE 1964 10° supplementary standard observer (CIE 018:2019 / ISO 11664-1 tables, via colour-science)",
        "CIE 2015 2° observer from the CIE 2006 cone fundamentals (CIE 170-2:2015, via colour-science)",
        "CIE 2015 10° observer from the CIE 2006 cone fundamentals (CIE 170-2:2015, via colour-science)",
        "Nikon D5100 raw RGB, measured at NPL: Darrodi et al. 2015, JOSA A 32(3) 381",
        "Sigma SD Merrill (Foveon) raw RGB, measured at NPL: Darrodi et al. 2015, JOSA A 32(3) 381",
        "Canon EOS 5D Mark II raw RGB: the Academy's rawtoaces data",
        "ACES Reference Input Capture Device (the Academy; a linear transform of CIE 1931)",
        "human L, M, S cones: Stockman & Sharpe 2000 2° (CIE 170-1:2006, CVRL)",
        "human protanope: Stockman & Sharpe 2° cones as (M, M, S)",
        "human deuteranope: Stockman & Sharpe 2° cones as (L, L, S)",
        "Picasso triggerfish: pigments λmax 528/480/413 nm (Cheney et al. 2013), Govardovskii A1 template",
        "dog: pigments λmax 555/429 nm (Neitz, Geist & Jacobs 1989), Govardovskii A1 template",
    ];

    /// The wavelengths (nm, whole) where any channel is above zero: the span the data covers.
    pub fn support(&self) -> Option<(f64, f64)> {
        let positive = |l: f64| self.eval(l).iter().any(|&v| v > 0.0);
        let lambda = (LAMBDA_MIN as u32..=LAMBDA_MAX as u32).map(f64::from);
        let first = lambda.clone().find(|&l| positive(l))?;
        let last = lambda.rev().find(|&l| positive(l))?;
        Some((first, last))
    }

    /// Names accepted by [`Observer::by_name`].
    pub const NAMES: &'static [&'static str] = &[
        "cie1931",
        "cie1964",
        "cie2015_2",
        "cie2015_10",
        "nikon_d5100",
        "sigma_sd_merrill",
        "canon_5d_mark_ii",
        "aces_ricd",
        "lms2",
        "protanope",
        "deuteranope",
        "triggerfish",
        "dog",
    ];

    /// The camera database's entry called `name` (crates/color/data/cameras, `data::cameras`).
    pub fn camera(name: &str) -> Option<&'static crate::data::cameras::Camera> {
        let n = name.trim().to_ascii_lowercase().replace('-', "_");
        crate::data::cameras::CAMERAS.iter().find(|c| c.name == n)
    }

    /// Every name [`Self::by_name`] knows: [`Self::NAMES`], then the camera database's.
    pub fn names() -> Vec<&'static str> {
        Self::NAMES.iter().copied().chain(crate::data::cameras::CAMERAS.iter().map(|c| c.name)).collect()
    }

    /// Where the observer called `name` comes from ([`Self::SOURCES`], or the database's
    /// record), or `None` for a name [`Self::names`] does not list.
    pub fn source(name: &str) -> Option<String> {
        if let Some(i) = Self::NAMES.iter().position(|n| *n == name) {
            return Some(Self::SOURCES[i].to_string());
        }
        Self::camera(name).map(|c| {
            format!("{} {} raw RGB, {}: rawtoaces-data {} (Apache-2.0)", c.make, c.model, c.measured, c.file)
        })
    }

    /// Looks an observer up by name (any of [`Self::names`] or a short alias; case-insensitive),
    /// or reads it from a file when `name` is a path (`crate::observer_file`: CSV, or the
    /// rawtoaces JSON of the camera database).
    pub fn by_name(name: &str) -> Result<Self> {
        if crate::observer_file::is_file_name(name) {
            return crate::observer_file::read(std::path::Path::new(name.trim()));
        }
        if let Some(c) = Self::camera(name) {
            let mut o = crate::observer_file::parse_json(c.json, c.name)?;
            o.name = c.name.to_string();
            return Ok(o);
        }
        match name.trim().to_ascii_lowercase().as_str() {
            "cie1931" | "cie1931_2" | "1931" => Ok(Self::cie1931()),
            "cie1964" | "cie1964_10" | "1964" => Ok(Self::cie1964()),
            "cie2015_2" | "cie2015" | "2015" => Ok(Self::cie2015_2()),
            "cie2015_10" => Ok(Self::cie2015_10()),
            "nikon_d5100" | "nikon" => Ok(Self::nikon_d5100()),
            "sigma_sd_merrill" | "sigma" => Ok(Self::sigma_sd_merrill()),
            "canon_5d_mark_ii" | "canon" => Ok(Self::canon_5d_mark_ii()),
            "aces_ricd" | "ricd" => Ok(Self::aces_ricd()),
            "lms2" | "lms" | "stockman_sharpe" => Ok(Self::lms_stockman_sharpe()),
            "triggerfish" | "fish" => Ok(Self::triggerfish()),
            "dog" => Ok(Self::dog()),
            "protanope" => Ok(Self::protanope()),
            "deuteranope" => Ok(Self::deuteranope()),
            _ => Err(ColorError::Unknown {
                kind: "observer",
                name: name.into(),
                known: format!(
                    "{}, one of the {} cameras `spectra observers` lists (e.g. {}), or a file: CSV \
                     (wavelength and three sensitivities) or rawtoaces camera JSON",
                    Self::NAMES.join(", "),
                    crate::data::cameras::CAMERAS.len(),
                    crate::data::cameras::CAMERAS
                        .iter()
                        .take(3)
                        .map(|c| c.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            }),
        }
    }

    /// The three sensitivities at `lambda`.
    #[inline]
    pub fn eval(&self, lambda: f64) -> [f64; 3] {
        [self.bar[0].eval(lambda), self.bar[1].eval(lambda), self.bar[2].eval(lambda)]
    }
}

/// Govardovskii, Fyhrquist, Reuter, Kuzmin & Donner 2000 (Vis. Neurosci. 17, 509) template for
/// the absorbance of an A1 (retinal) visual pigment with peak `lambda_max`, at `lambda` (nm):
/// the α-band
/// `1 / (exp(A(a − x)) + exp(B(b − x)) + exp(C(c − x)) + D)` with x = λmax/λ, A = 69.7,
/// a = 0.8795 + 0.0459·exp(−(λmax − 300)²/11940), B = 28, b = 0.922, C = −14.9, c = 1.104,
/// D = 0.674, plus the β-band `0.26·exp(−((λ − λβ)/w)²)` with λβ = 189 + 0.315·λmax and
/// w = −40.5 + 0.195·λmax. Normalised to ≈ 1 at λmax by construction.
pub fn govardovskii_a1(lambda_max: f64, lambda: f64) -> f64 {
    let x = lambda_max / lambda;
    let a = 0.8795 + 0.0459 * (-(lambda_max - 300.0).powi(2) / 11940.0).exp();
    let alpha =
        1.0 / ((69.7 * (a - x)).exp() + (28.0 * (0.922 - x)).exp() + (-14.9 * (1.104 - x)).exp() + 0.674);
    let beta_peak = 189.0 + 0.315 * lambda_max;
    let beta_width = -40.5 + 0.195 * lambda_max;
    alpha + 0.26 * (-((lambda - beta_peak) / beta_width).powi(2)).exp()
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_builtin_has_a_source_and_a_support() {
        assert_eq!(Observer::SOURCES.len(), Observer::NAMES.len());
        for name in Observer::names() {
            assert!(Observer::source(name).is_some_and(|s| !s.is_empty()), "{name}");
            let o = Observer::by_name(name).unwrap();
            let (a, b) = o.support().unwrap_or_else(|| panic!("{name}: no support"));
            assert!((LAMBDA_MIN..450.0).contains(&a) && b > 650.0 && b <= LAMBDA_MAX, "{name}: {a}–{b}");
        }
        assert_eq!(Observer::cie1931().support(), Some((360.0, 830.0)));
    }

    use super::*;
    use crate::illuminant;

    #[test]
    fn by_name_round_trips_every_observer() {
        for name in Observer::names() {
            let o = Observer::by_name(name).unwrap();
            assert_eq!(o.name, name);
            assert_eq!(Observer::by_name(&name.to_ascii_uppercase()).unwrap(), o);
        }
        let e = Observer::by_name("cat").unwrap_err().to_string();
        assert!(e.contains("cat") && e.contains("triggerfish") && e.contains("canon_5d_mark_ii"), "{e}");
    }

    #[test]
    fn equal_energy_white_gives_three_positive_channels() {
        let e = illuminant::by_name("E").unwrap();
        for name in Observer::names() {
            let o = Observer::by_name(name).unwrap();
            let w = o.white_balance(&e);
            assert!(w.iter().all(|c| c.is_finite() && *c > 0.0), "{name}: {w:?}");
        }
        // Cross-check with a published number: ∫ȳ dλ of the CIE 1931 observer at 1 nm is
        // 106.857 (CIE 015:2018), and the cameras peak-normalised to 1 integrate to tens of nm.
        let y = Observer::cie1931().white_balance(&e)[1];
        assert!((y - 106.857).abs() < 0.01, "{y}");
    }

    /// The database: names unique and apart from the built-ins', every file a camera that the
    /// ColorChecker can characterise (its least-squares fit to XYZ under D65 within the
    /// residuals of measured cameras), named in its source with its licence.
    #[test]
    fn the_camera_database() {
        let names = Observer::names();
        let unique: std::collections::HashSet<_> = names.iter().collect();
        assert_eq!(unique.len(), names.len());
        let cams = crate::data::cameras::CAMERAS;
        assert!(cams.len() >= 50, "{}", cams.len());
        let d65 = illuminant::by_name("D65").unwrap();
        for c in cams {
            let o = Observer::by_name(c.name).unwrap();
            assert_eq!((o.name.as_str(), o.kind()), (c.name, ObserverKind::CameraRgb));
            assert_eq!(Observer::by_name(&c.name.replace('_', "-").to_uppercase()).unwrap(), o);
            assert!(Observer::source(c.name).unwrap().contains("Apache-2.0"));
            let (_, rms) = o.fit_to_xyz(&d65).unwrap();
            assert!(rms < 0.05, "{}: fit residual {rms}", c.name);
        }
    }

    #[test]
    fn camera_tables_are_indexed_from_their_own_start() {
        // The public demo of Monzón et al. indexed a table starting at 390 nm as if it began at
        // 380 nm. Each table here carries its own start: the first sample is at its first λ.
        let sigma = Observer::sigma_sd_merrill();
        assert_eq!(sigma.bar[2].eval(400.0), ox::SIGMA_SD_MERRILL_B.values[0]);
        assert_eq!(sigma.bar[2].eval(410.0), ox::SIGMA_SD_MERRILL_B.values[1]);
        assert_eq!(sigma.bar[2].eval(399.0), 0.0);
        let lms = Observer::lms_stockman_sharpe();
        assert_eq!(lms.bar[0].eval(390.0), ox::STOCKMAN_SHARPE_2_L.values[0]);
        assert_eq!(lms.bar[0].eval(391.0), ox::STOCKMAN_SHARPE_2_L.values[1]);
        // Peaks where the literature puts them: L ≈ 570, M ≈ 543, S ≈ 442 nm (Stockman & Sharpe).
        for (ch, peak) in [(0, 570.0), (1, 543.0), (2, 442.0)] {
            let arg = (390..=830)
                .max_by(|&a, &b| lms.bar[ch].eval(a as f64).total_cmp(&lms.bar[ch].eval(b as f64)));
            assert!((arg.unwrap() as f64 - peak).abs() <= 3.0, "channel {ch}: {arg:?}");
        }
    }

    #[test]
    fn govardovskii_template_peaks_at_lambda_max() {
        for lm in [413.0, 480.0, 528.0, 560.0] {
            let (arg, max) = (3600..=8300)
                .map(|i| i as f64 / 10.0)
                .map(|l| (l, govardovskii_a1(lm, l)))
                .filter(|(l, _)| *l > lm - 80.0)
                .fold((0.0, 0.0), |best, p| if p.1 > best.1 { p } else { best });
            assert!((arg - lm).abs() < 2.0, "λmax {lm}: peak at {arg}");
            assert!((max - 1.0).abs() < 0.02, "λmax {lm}: peak value {max}");
            // Bandwidth: the α-band's half maximum spans roughly 95–110 nm at these λmax.
            let half: Vec<f64> = (3600..=8300)
                .map(|i| i as f64 / 10.0)
                .filter(|&l| l > lm - 90.0 && govardovskii_a1(lm, l) >= 0.5 * max)
                .collect();
            let width = half.last().unwrap() - half[0];
            assert!((70.0..140.0).contains(&width), "λmax {lm}: FWHM {width}");
        }
        let fish = Observer::triggerfish();
        assert_eq!(fish.kind(), ObserverKind::Receptors);
        assert!(fish.bar[0].eval(528.0) > 0.99 && fish.bar[2].eval(413.0) > 0.99);
    }

    #[test]
    fn dichromats_see_only_a_yellow_blue_axis() {
        let d65 = illuminant::by_name("D65").unwrap();
        for o in [Observer::dog(), Observer::protanope(), Observer::deuteranope()] {
            assert_eq!(o.kind(), ObserverKind::Receptors);
            assert_eq!(o.bar[0], o.bar[1], "{}", o.name);
        }
        // The dog's L pigment peaks where Neitz et al. measured it.
        let dog = Observer::dog();
        assert!(dog.bar[0].eval(555.0) > 0.99 && dog.bar[2].eval(429.0) > 0.99);
        // A protanope's long-wave channel is the M cone: it sees deep red as much darker
        // relative to white than a deuteranope does (the classic protan luminance loss).
        let red = Spectrum::from_table(&colorchecker::SPECTRA[14]);
        let rel = |o: &Observer| o.response(&red, &d65)[0] / o.white_balance(&d65)[0];
        let (p, d) = (rel(&Observer::protanope()), rel(&Observer::deuteranope()));
        eprintln!("red patch / white, long-wave channel: protanope {p:.4}, deuteranope {d:.4}");
        assert!(p < 0.8 * d);
    }

    #[test]
    fn camera_to_xyz_fit_is_exact_for_ricd_and_close_for_real_cameras() {
        let d65 = illuminant::by_name("D65").unwrap();
        let (_, rms) = Observer::aces_ricd().fit_to_xyz(&d65).unwrap();
        eprintln!("fit_to_xyz D65 rms: aces_ricd {rms:e}");
        assert!(rms < 1e-6, "ACES RICD is a linear transform of CIE 1931: rms {rms}");
        let (m, rms) = Observer::cie1931().fit_to_xyz(&d65).unwrap();
        assert!(
            rms < 1e-9
                && (m - DMat3::from_diagonal(DVec3::new(0.95047, 1.0, 1.08883)))
                    .abs()
                    .to_cols_array()
                    .iter()
                    .all(|v| *v < 2e-3),
            "{m:?} {rms}"
        );
        for name in ["nikon_d5100", "sigma_sd_merrill", "canon_5d_mark_ii"] {
            let o = Observer::by_name(name).unwrap();
            assert_eq!(o.kind(), ObserverKind::CameraRgb);
            let (m, rms) = o.fit_to_xyz(&d65).unwrap();
            eprintln!("fit_to_xyz D65 rms: {name} {rms:.4}");
            // Real sensors miss the Luther condition, but a 3×3 fit gets within a few percent of
            // white's Y on the chart; and white maps near the D65 white.
            assert!(rms < 0.03, "{name}: rms {rms}");
            let w = m * DVec3::ONE;
            assert!((w - DVec3::new(0.95047, 1.0, 1.08883)).abs().max_element() < 0.03, "{name}: {w:?}");
        }
        let dead = Observer {
            name: "dead".into(),
            bar: [Spectrum::Constant(1.0), Spectrum::Constant(0.0), Spectrum::Constant(1.0)],
        };
        assert!(dead.fit_to_xyz(&d65).is_err());
    }
}
