//! Observers: the three sensitivity curves that turn a spectrum into tristimulus values.

use crate::data::{SampledTable, cmf};
use crate::error::{ColorError, Result};
use crate::spectrum::Spectrum;

/// Three spectral sensitivities. For the CIE observers these are x̄, ȳ, z̄ and the tristimulus
/// values are CIE XYZ.
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

    /// Names accepted by [`Observer::by_name`].
    pub const NAMES: &'static [&'static str] = &["cie1931", "cie1964"];

    /// Looks an observer up by name (`cie1931`, `cie1964`; case-insensitive).
    pub fn by_name(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().as_str() {
            "cie1931" | "cie1931_2" | "1931" => Ok(Self::cie1931()),
            "cie1964" | "cie1964_10" | "1964" => Ok(Self::cie1964()),
            _ => Err(ColorError::Unknown {
                kind: "observer",
                name: name.into(),
                known: Self::NAMES.join(", "),
            }),
        }
    }

    /// The three sensitivities at `lambda`.
    #[inline]
    pub fn eval(&self, lambda: f64) -> [f64; 3] {
        [self.bar[0].eval(lambda), self.bar[1].eval(lambda), self.bar[2].eval(lambda)]
    }
}
