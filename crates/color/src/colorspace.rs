//! RGB colour spaces: primaries, white points, matrices derived from them, transfer
//! functions, and Bradford chromatic adaptation.
//!
//! Matrices are derived from the published chromaticities at construction (SMPTE RP 177),
//! never pasted in, so adding a space is one line of data.

use glam::{DMat3, DVec3};

use crate::error::{ColorError, Result};
use crate::illuminant;
use crate::spectrum::Spectrum;
use crate::xyz::xy_to_xyz;

/// How a space's stored values relate to linear light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransferFunction {
    Linear,
    /// IEC 61966-2-1 piecewise sRGB curve (also Display P3's).
    Srgb,
    /// ITU-R BT.2020 / BT.709 OETF (α = 1.0993, β = 0.0181).
    Rec2020,
}

impl TransferFunction {
    /// Linear → encoded.
    pub fn encode(self, v: f64) -> f64 {
        match self {
            TransferFunction::Linear => v,
            TransferFunction::Srgb => srgb_encode(v),
            TransferFunction::Rec2020 => {
                const A: f64 = 1.099_296_826_809_44;
                const B: f64 = 0.018_053_968_510_807;
                if v < B { 4.5 * v } else { A * v.powf(0.45) - (A - 1.0) }
            }
        }
    }

    /// Encoded → linear.
    pub fn decode(self, v: f64) -> f64 {
        match self {
            TransferFunction::Linear => v,
            TransferFunction::Srgb => srgb_decode(v),
            TransferFunction::Rec2020 => {
                const A: f64 = 1.099_296_826_809_44;
                const B: f64 = 0.018_053_968_510_807;
                if v < 4.5 * B { v / 4.5 } else { ((v + (A - 1.0)) / A).powf(1.0 / 0.45) }
            }
        }
    }
}

/// sRGB encoding (linear → display). Negative input is mirrored so out-of-gamut values survive.
pub fn srgb_encode(v: f64) -> f64 {
    let a = v.abs();
    let e = if a <= 0.003_130_8 { 12.92 * a } else { 1.055 * a.powf(1.0 / 2.4) - 0.055 };
    e.copysign(v)
}

/// sRGB decoding (display → linear).
pub fn srgb_decode(v: f64) -> f64 {
    let a = v.abs();
    let d = if a <= 0.040_45 { a / 12.92 } else { ((a + 0.055) / 1.055).powf(2.4) };
    d.copysign(v)
}

/// A linear RGB colour space defined by its primaries and white.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbColorSpace {
    /// Short name used on the command line (`srgb`, `p3`, `rec2020`, `acescg`, `aces2065-1`).
    pub name: String,
    /// xy chromaticities of R, G, B.
    pub primaries: [[f64; 2]; 3],
    /// xy chromaticity of the white point.
    pub white: [f64; 2],
    /// Name of the illuminant whose spectrum has this white (for spectral work: `D65`, `D60`).
    pub illuminant_name: String,
    pub transfer: TransferFunction,
    /// Linear RGB → XYZ (Y of white = 1).
    pub to_xyz: DMat3,
    /// XYZ → linear RGB.
    pub from_xyz: DMat3,
}

impl RgbColorSpace {
    /// Builds a space from chromaticities: the columns of the RGB→XYZ matrix are the primaries'
    /// XYZ, scaled so that RGB (1, 1, 1) maps to the white with Y = 1.
    pub fn new(
        name: &str,
        primaries: [[f64; 2]; 3],
        white: [f64; 2],
        illuminant_name: &str,
        transfer: TransferFunction,
    ) -> Self {
        let p = DMat3::from_cols(
            DVec3::from(xy_to_xyz(primaries[0])),
            DVec3::from(xy_to_xyz(primaries[1])),
            DVec3::from(xy_to_xyz(primaries[2])),
        );
        let s = p.inverse() * DVec3::from(xy_to_xyz(white));
        let to_xyz = p * DMat3::from_diagonal(s);
        RgbColorSpace {
            name: name.into(),
            primaries,
            white,
            illuminant_name: illuminant_name.into(),
            transfer,
            to_xyz,
            from_xyz: to_xyz.inverse(),
        }
    }

    /// IEC 61966-2-1 sRGB (Rec. 709 primaries, D65).
    pub fn srgb() -> Self {
        Self::new("srgb", [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06]], D65_XY, "D65", TransferFunction::Srgb)
    }

    /// Display P3 (DCI-P3 primaries, D65, sRGB transfer).
    pub fn display_p3() -> Self {
        Self::new(
            "p3",
            [[0.680, 0.320], [0.265, 0.690], [0.150, 0.060]],
            D65_XY,
            "D65",
            TransferFunction::Srgb,
        )
    }

    /// ITU-R BT.2020.
    pub fn rec2020() -> Self {
        Self::new(
            "rec2020",
            [[0.708, 0.292], [0.170, 0.797], [0.131, 0.046]],
            D65_XY,
            "D65",
            TransferFunction::Rec2020,
        )
    }

    /// ACEScg (AP1 primaries, ACES white ≈ D60, linear).
    pub fn acescg() -> Self {
        Self::new(
            "acescg",
            [[0.713, 0.293], [0.165, 0.830], [0.128, 0.044]],
            ACES_WHITE_XY,
            "D60",
            TransferFunction::Linear,
        )
    }

    /// ACES2065-1 (AP0 primaries, ACES white ≈ D60, linear).
    pub fn aces2065_1() -> Self {
        Self::new(
            "aces2065-1",
            [[0.7347, 0.2653], [0.0, 1.0], [0.0001, -0.077]],
            ACES_WHITE_XY,
            "D60",
            TransferFunction::Linear,
        )
    }

    /// Names accepted by [`RgbColorSpace::by_name`].
    pub const NAMES: &'static [&'static str] = &["srgb", "p3", "rec2020", "acescg", "aces2065-1"];

    /// Looks a space up by name (case-insensitive; a few common aliases are accepted).
    pub fn by_name(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().replace('_', "-").as_str() {
            "srgb" | "rec709" | "bt709" => Ok(Self::srgb()),
            "p3" | "display-p3" | "displayp3" => Ok(Self::display_p3()),
            "rec2020" | "bt2020" => Ok(Self::rec2020()),
            "acescg" | "ap1" => Ok(Self::acescg()),
            "aces2065-1" | "aces" | "ap0" => Ok(Self::aces2065_1()),
            _ => Err(ColorError::Unknown {
                kind: "colour space",
                name: name.into(),
                known: Self::NAMES.join(", "),
            }),
        }
    }

    /// Relative luminance Y of a linear RGB colour in this space (the Y row of its RGB → XYZ
    /// matrix): the one definition both renderers and the evaluation use (issue 16).
    pub fn luminance(&self, rgb: [f64; 3]) -> f64 {
        self.to_xyz.row(1).dot(DVec3::from(rgb))
    }

    pub fn rgb_to_xyz(&self, rgb: [f64; 3]) -> [f64; 3] {
        (self.to_xyz * DVec3::from(rgb)).into()
    }

    pub fn xyz_to_rgb(&self, xyz: [f64; 3]) -> [f64; 3] {
        (self.from_xyz * DVec3::from(xyz)).into()
    }

    /// XYZ of the white point with Y = 1.
    pub fn white_xyz(&self) -> [f64; 3] {
        xy_to_xyz(self.white)
    }

    /// Spectral power distribution of the space's white illuminant.
    pub fn illuminant(&self) -> Spectrum {
        illuminant::by_name(&self.illuminant_name).expect("built-in spaces name built-in illuminants")
    }

    /// What RGB white (1, 1, 1) emits in a scene whose reference white is `scene_white`: this
    /// space's illuminant scaled to the scene white's luminance, `y` being the caller's
    /// luminance integral (its observer, quadrature and range). The scene white sets the units
    /// (XYZ is normalised by ∫ȳ·white, so a light of the white's own spectrum has Y = 1) and
    /// RGB emission follows it, so RGB lights and emissive colours keep the luminance and the
    /// colour they have under D65: there is no chromatic adaptation, the output colours are
    /// this space's. The one statement of the convention; both renderers build their white
    /// with it (`spectra.white`, `--white`).
    pub fn emission_white(&self, scene_white: &Spectrum, y: impl Fn(&Spectrum) -> f64) -> Spectrum {
        let ill = self.illuminant();
        let (k_white, k_ill) = (y(scene_white), y(&ill));
        if k_ill > 0.0 { ill.scaled(k_white / k_ill) } else { ill }
    }

    /// Linear → encoded with this space's transfer function.
    pub fn encode(&self, rgb: [f64; 3]) -> [f64; 3] {
        rgb.map(|v| self.transfer.encode(v))
    }

    /// Encoded → linear.
    pub fn decode(&self, rgb: [f64; 3]) -> [f64; 3] {
        rgb.map(|v| self.transfer.decode(v))
    }

    /// Matrix taking linear RGB in `self` to linear RGB in `other`, with Bradford adaptation
    /// between their whites when they differ.
    pub fn conversion_to(&self, other: &RgbColorSpace) -> DMat3 {
        let adapt = bradford(self.white_xyz(), other.white_xyz());
        other.from_xyz * adapt * self.to_xyz
    }
}

/// The matrix from linear RGB of the colour space with chromaticities `n` (x y of red, green,
/// blue, white: an OpenEXR `chromaticities` attribute, a Radiance `PRIMARIES` line) to linear
/// sRGB, with Bradford adaptation to D65: the identity for Rec. 709's (within 10⁻³); `None` if
/// `n` is not eight chromaticities of a colour space. Primaries may lie outside the spectrum
/// locus (ACES AP0's blue has y = −0.077), the white must be a colour. Every reader of such files
/// converts through it.
/// The least x, y and 1 − x − y of a white in [`to_srgb_from_chromaticities`]: the
/// illuminants of every standard lie far inside (D65 0.3127, 0.3290; illuminant A 0.4476, 0.4074).
pub const MIN_WHITE_XY: f64 = 0.01;

pub fn to_srgb_from_chromaticities(n: &[f64]) -> Option<DMat3> {
    let ok = n.len() == 8
        && n.iter().all(|x| x.is_finite() && (-2.0..=2.0).contains(x))
        && n[..6].chunks(2).all(|c| c[1].abs() > 1e-6)
        // The white is a colour: inside the chromaticity diagram, where no real white comes
        // near its edges (a white at y = 1e-30 passed and scaled the image by ~1e29).
        && n[6] >= MIN_WHITE_XY
        && n[7] >= MIN_WHITE_XY
        && n[6] + n[7] <= 1.0 - MIN_WHITE_XY;
    let space = ok.then(|| {
        RgbColorSpace::new(
            "PRIMARIES",
            [[n[0], n[1]], [n[2], n[3]], [n[4], n[5]]],
            [n[6], n[7]],
            "",
            TransferFunction::Linear,
        )
    })?;
    let usable = space.to_xyz.is_finite()
        && space.to_xyz.determinant().abs() > 1e-6
        && space.conversion_to(&RgbColorSpace::srgb()).is_finite();
    if !usable {
        return None;
    }
    let srgb = RgbColorSpace::srgb();
    let same = space
        .primaries
        .iter()
        .flatten()
        .chain(&space.white)
        .zip(srgb.primaries.iter().flatten().chain(&srgb.white))
        .all(|(a, b)| (a - b).abs() < 1e-3);
    Some(if same { DMat3::IDENTITY } else { space.conversion_to(&srgb) })
}

/// D65 chromaticity as used by sRGB, P3 and Rec.2020 (four decimals, as the standards write it).
pub const D65_XY: [f64; 2] = [0.3127, 0.3290];
/// The ACES white (S-2008-001).
pub const ACES_WHITE_XY: [f64; 2] = [0.32168, 0.33767];

/// Bradford chromatic adaptation matrix from white `src` to white `dst` (both XYZ).
pub fn bradford(src: [f64; 3], dst: [f64; 3]) -> DMat3 {
    // Rows of the Bradford cone-response matrix, written column by column for glam.
    let m = DMat3::from_cols(
        DVec3::new(0.8951, -0.7502, 0.0389),
        DVec3::new(0.2664, 1.7135, -0.0685),
        DVec3::new(-0.1614, 0.0367, 1.0296),
    );
    let s = m * DVec3::from(src);
    let d = m * DVec3::from(dst);
    m.inverse() * DMat3::from_diagonal(d / s) * m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close_m(a: DMat3, b: [[f64; 3]; 3], tol: f64) {
        for (r, row) in b.iter().enumerate() {
            for (c, expected) in row.iter().enumerate() {
                let v = a.col(c)[r];
                assert!((v - expected).abs() < tol, "row {r} col {c}: {v} vs {expected}");
            }
        }
    }

    // Expected: colour-science 0.4.7 `normalised_primary_matrix` on the same chromaticities
    // (an independent derivation; IEC 61966-2-1 rounds it to four decimals).
    #[test]
    fn srgb_matrix_matches_iec() {
        close_m(
            RgbColorSpace::srgb().to_xyz,
            [
                [0.4123908, 0.3575843, 0.1804808],
                [0.2126390, 0.7151687, 0.0721923],
                [0.0193308, 0.1191948, 0.9505322],
            ],
            1e-6,
        );
    }

    #[test]
    fn acescg_matrix_matches_aces() {
        // ACES TB-2014-004 publishes AP1→XYZ with these values.
        close_m(
            RgbColorSpace::acescg().to_xyz,
            [
                [0.6624542, 0.1340042, 0.1561877],
                [0.2722287, 0.6740818, 0.0536895],
                [-0.0055746, 0.0040607, 1.0103391],
            ],
            1e-6,
        );
    }

    #[test]
    fn srgb_luminance_is_the_published_y_row() {
        // IEC 61966-2-1 / ITU-R BT.709: Y = 0.2126 R + 0.7152 G + 0.0722 B (4 decimals).
        let s = RgbColorSpace::srgb();
        for (rgb, want) in [([1.0, 0.0, 0.0], 0.2126), ([0.0, 1.0, 0.0], 0.7152), ([0.0, 0.0, 1.0], 0.0722)] {
            assert!((s.luminance(rgb) - want).abs() < 1e-4, "{rgb:?}: {}", s.luminance(rgb));
        }
        assert!((s.luminance([1.0; 3]) - 1.0).abs() < 1e-12);
        // Another space's own row, not sRGB's: Rec.2020 green is 0.6780.
        assert!((RgbColorSpace::rec2020().luminance([0.0, 1.0, 0.0]) - 0.6780).abs() < 1e-4);
    }

    #[test]
    fn white_maps_to_white_in_every_space() {
        for name in RgbColorSpace::NAMES {
            let s = RgbColorSpace::by_name(name).unwrap();
            let w = s.rgb_to_xyz([1.0; 3]);
            let e = s.white_xyz();
            for k in 0..3 {
                assert!((w[k] - e[k]).abs() < 1e-12, "{name}");
            }
            let back = s.xyz_to_rgb(w);
            assert!(back.iter().all(|v| (v - 1.0).abs() < 1e-12), "{name}");
        }
    }

    #[test]
    fn transfer_functions_invert() {
        for tf in [TransferFunction::Linear, TransferFunction::Srgb, TransferFunction::Rec2020] {
            for i in 0..=100 {
                let v = i as f64 / 100.0;
                assert!((tf.decode(tf.encode(v)) - v).abs() < 1e-12, "{tf:?} {v}");
            }
        }
        assert!((srgb_encode(0.5) - 0.735_356_983_052_285).abs() < 1e-12);
    }

    #[test]
    fn bradford_d65_to_d50() {
        // Lindbloom's published Bradford D65→D50 matrix, also colour-science's
        // `matrix_chromatic_adaptation_VonKries(..., 'Bradford')`.
        let m = bradford([0.95047, 1.0, 1.08883], [0.96422, 1.0, 0.82521]);
        close_m(
            m,
            [
                [1.0478112, 0.0228866, -0.0501270],
                [0.0295424, 0.9904844, -0.0170491],
                [-0.0092345, 0.0150436, 0.7521316],
            ],
            1e-6,
        );
        let white = m * DVec3::new(0.95047, 1.0, 1.08883);
        assert!((white - DVec3::new(0.96422, 1.0, 0.82521)).abs().max_element() < 1e-12);
    }

    #[test]
    fn unknown_space_lists_known() {
        let e = RgbColorSpace::by_name("adobe").unwrap_err().to_string();
        assert!(e.contains("adobe") && e.contains("rec2020"));
    }

    /// A file's chromaticities: the white must be a colour (a Radiance PRIMARIES line with a
    /// white at y = 1e-30 was accepted and scaled the map by ~1e29); imaginary primaries stay.
    #[test]
    fn chromaticities_need_a_white_inside_the_diagram() {
        let rec709 = [0.64, 0.33, 0.3, 0.6, 0.15, 0.06, 0.3127, 0.329];
        assert_eq!(to_srgb_from_chromaticities(&rec709), Some(DMat3::IDENTITY));
        let ap0 = [0.7347, 0.2653, 0.0, 1.0, 0.0001, -0.077, 0.32168, 0.33767];
        assert!(to_srgb_from_chromaticities(&ap0).is_some());
        for white in [[0.3127, 1e-30], [1e-30, 0.329], [0.6, 0.3999], [0.3127, 0.0]] {
            let mut n = rec709;
            n[6..].copy_from_slice(&white);
            assert_eq!(to_srgb_from_chromaticities(&n), None, "{white:?}");
        }
        let mut a = rec709;
        a[6..].copy_from_slice(&[0.4476, 0.4074]);
        assert!(to_srgb_from_chromaticities(&a).is_some_and(|m| m.is_finite()));
    }
}
