//! The Jakob–Hanika coefficient table in rgb2spec's `.coeff` file format.
//!
//! Layout (little-endian): `"SPEC"`, `u32 res`, `f32 scale[res]`, `f32 data[3][res][res][res][3]`.
//! `data` is indexed `((l·res + k)·res + j)·res + i`, times 3 coefficients, where `l` is the
//! largest RGB channel, `k` the brightness index (the largest channel's value is `scale[k]`),
//! and `i`, `j` the two other channels (`(l+1) % 3` and `(l+2) % 3`) divided by the largest and
//! located on the chroma grid ([`CoeffTable::chroma`]): rgb2spec's is uniform (ratio × (res − 1)),
//! spectra's default tables are denser next to 0 and 1 and store their grid in a block after the
//! payload ([`CHROMA_TAG`]). Uniform-grid files written here load in rgb2spec, Mitsuba and pbrt;
//! those readers skip the block of the others and would misread them. Mitsuba's shipped
//! `srgb.coeff` (which appends a trailer after the payload) loads here.
//!
//! [`CoeffTable::fetch`] is rgb2spec's `rgb2spec_fetch`: pick the table of the largest channel,
//! find `z` in `scale` and the two ratios in `chroma` by binary search, then interpolate the
//! coefficients trilinearly — with three differences: the weight along `z` is taken in σ⁻¹ space ([`z_weight`]), which makes greys
//! exact at every brightness, the weights along x and y are warped next to a zero channel
//! ([`chroma_weight`]), where the coefficients move non-uniformly, and light colours (lowest channel above 0.3) are fetched through
//! their complement 1 − rgb with negated coefficients ([`white_blend`]), which removes the
//! near-white errors of coefficient interpolation. Because `scale` is stored in the file, a table may use any
//! increasing brightness grid and stay readable by every rgb2spec-compatible renderer; such a
//! renderer (linear `z` weight) gets the node colours exactly and greys to rgb2spec's accuracy
//! (−3.9 % at 0.01) in between.

use std::path::Path;

use crate::error::{ColorError, Result};
use crate::upsample::sigmoid::SigmoidPolynomial;

/// Largest resolution accepted from a file (a 256³ table is already 600 MB).
pub const MAX_RES: usize = 256;

const MAGIC: &[u8; 4] = b"SPEC";

/// Starts the block after a `.coeff` payload that holds a non-uniform chroma grid
/// ([`CoeffTable::chroma`]): the tag, then `res` little-endian f32. rgb2spec, Mitsuba and pbrt
/// ignore bytes after the payload (Mitsuba's own table carries a trailer), but they also assume
/// a uniform grid, so they read such a table with every non-grey node in the wrong place.
pub const CHROMA_TAG: &[u8] = b"\nspectra-chroma-nodes\n";

/// rgb2spec's chroma grid: i/(res − 1).
pub fn uniform_chroma(res: usize) -> Vec<f32> {
    (0..res).map(|i| i as f32 / (res - 1) as f32).collect()
}

/// A 3 × res³ table of sigmoid-polynomial coefficients, exactly as in a `.coeff` file.
#[derive(Clone, Debug, PartialEq)]
pub struct CoeffTable {
    /// Grid points per axis.
    pub res: usize,
    /// The largest channel's value at brightness index k, strictly increasing.
    pub scale: Vec<f32>,
    /// The channel ratio (other channel ÷ largest) at chroma index i (or j): 0 to 1, strictly
    /// increasing. rgb2spec's grid is uniform, i/(res − 1) ([`uniform_chroma`]); spectra's
    /// default tables put more nodes next to 0 (`fit::spectra_chroma`). `.coeff` files have no
    /// field for it, so a non-uniform grid travels in a block after the payload ([`CHROMA_TAG`]).
    pub chroma: Vec<f32>,
    /// `3·res³·3` coefficients in rgb2spec order (see the module docs).
    pub data: Vec<f32>,
}

/// Why a table was refused, before the file name is attached.
fn table_err(origin: &str, what: impl std::fmt::Display) -> ColorError {
    ColorError::Table(format!("{origin}: {what}"))
}

impl CoeffTable {
    /// Number of `f32` coefficients for resolution `res`.
    pub fn data_len(res: usize) -> usize {
        3 * res * res * res * 3
    }

    /// Size in bytes of the `.coeff` payload (without any trailer).
    pub fn file_len(res: usize) -> usize {
        8 + 4 * res + 4 * Self::data_len(res)
    }

    /// Size in bytes of [`Self::to_bytes`]: the payload plus the chroma block if the grid is not
    /// uniform.
    pub fn encoded_len(&self) -> usize {
        Self::file_len(self.res) + if self.has_uniform_chroma() { 0 } else { CHROMA_TAG.len() + 4 * self.res }
    }

    /// Whether the chroma grid is rgb2spec's (then the file is exactly what rgb2spec reads).
    pub fn has_uniform_chroma(&self) -> bool {
        self.chroma == uniform_chroma(self.res)
    }

    /// Index of the first coefficient of node (l, k, j, i) in [`Self::data`].
    #[inline]
    pub fn index(&self, l: usize, k: usize, j: usize, i: usize) -> usize {
        (((l * self.res + k) * self.res + j) * self.res + i) * 3
    }

    /// The stored coefficients of node (l, k, j, i).
    #[inline]
    pub fn node(&self, l: usize, k: usize, j: usize, i: usize) -> [f32; 3] {
        let o = self.index(l, k, j, i);
        [self.data[o], self.data[o + 1], self.data[o + 2]]
    }

    /// Checks the invariants [`Self::fetch`] relies on; `origin` names the table in errors.
    pub fn validate(&self, origin: &str) -> Result<()> {
        if self.res < 2 || self.res > MAX_RES {
            return Err(table_err(origin, format!("resolution {} is outside 2..={MAX_RES}", self.res)));
        }
        if self.scale.len() != self.res {
            return Err(table_err(
                origin,
                format!("{} scale entries for resolution {}", self.scale.len(), self.res),
            ));
        }
        if self.data.len() != Self::data_len(self.res) {
            return Err(table_err(
                origin,
                format!("{} coefficients, expected {}", self.data.len(), Self::data_len(self.res)),
            ));
        }
        if let Some(k) = self.scale.iter().position(|s| !(s.is_finite() && (0.0..=1.0).contains(s))) {
            return Err(table_err(
                origin,
                format!("scale[{k}] = {} is not a number in [0, 1]", self.scale[k]),
            ));
        }
        if let Some(k) = self.scale.windows(2).position(|w| !(w[1] > w[0])) {
            return Err(table_err(
                origin,
                format!(
                    "scale must increase strictly, but scale[{k}] = {} and scale[{}] = {}",
                    self.scale[k],
                    k + 1,
                    self.scale[k + 1]
                ),
            ));
        }
        // The brightness axis covers the cube up to its brightest node, 1, in every table of
        // the format (rgb2spec's and ours). One that stops short is damaged, or was read with a
        // smaller resolution than it was written with.
        let last = self.scale[self.res - 1];
        if (last - 1.0).abs() > 1e-6 {
            return Err(table_err(
                origin,
                format!(
                    "scale must end at 1, but scale[{}] = {last} (is the header's resolution, {}, the \
                     one the table was written with?)",
                    self.res - 1,
                    self.res
                ),
            ));
        }
        if self.chroma.len() != self.res {
            return Err(table_err(
                origin,
                format!("{} chroma nodes for resolution {}", self.chroma.len(), self.res),
            ));
        }
        if self.chroma[0] != 0.0 || self.chroma[self.res - 1] != 1.0 {
            return Err(table_err(
                origin,
                format!(
                    "chroma nodes must run from 0 to 1, but they run from {} to {}",
                    self.chroma[0],
                    self.chroma[self.res - 1]
                ),
            ));
        }
        if let Some(i) = self.chroma.windows(2).position(|w| !(w[1] > w[0])) {
            return Err(table_err(
                origin,
                format!(
                    "chroma nodes must increase strictly, but node {i} is {} and node {} is {}",
                    self.chroma[i],
                    i + 1,
                    self.chroma[i + 1]
                ),
            ));
        }
        if let Some(n) = self.data.iter().position(|v| !v.is_finite()) {
            let node = n / 3;
            let (i, j, k, l) = (
                node % self.res,
                node / self.res % self.res,
                node / self.res / self.res % self.res,
                node / self.res.pow(3),
            );
            return Err(table_err(
                origin,
                format!(
                    "coefficient {} of node (l={l}, k={k}, j={j}, i={i}) is {} (not finite)",
                    n % 3,
                    self.data[n]
                ),
            ));
        }
        Ok(())
    }

    /// Parses a `.coeff` payload. `origin` (usually the file name) prefixes every error. Bytes
    /// after the payload are ignored: Mitsuba appends a trailer to its shipped table.
    pub fn from_bytes(bytes: &[u8], origin: &str) -> Result<Self> {
        if bytes.len() < 8 {
            return Err(table_err(
                origin,
                format!("file is truncated: {} bytes, a header needs 8", bytes.len()),
            ));
        }
        if &bytes[..4] != MAGIC {
            return Err(table_err(
                origin,
                format!(
                    "not an rgb2spec coefficient table (starts with {:?}, expected \"SPEC\")",
                    String::from_utf8_lossy(&bytes[..4])
                ),
            ));
        }
        let res = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
        if !(2..=MAX_RES).contains(&res) {
            return Err(table_err(origin, format!("resolution {res} is outside 2..={MAX_RES}")));
        }
        let need = Self::file_len(res);
        if bytes.len() < need {
            return Err(table_err(
                origin,
                format!("file is truncated: {} bytes, resolution {res} needs {need}", bytes.len()),
            ));
        }
        let floats = |b: &[u8]| -> Vec<f32> {
            b.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect()
        };
        let scale = floats(&bytes[8..8 + 4 * res]);
        let data = floats(&bytes[8 + 4 * res..need]);
        let chroma = match bytes[need..].strip_prefix(CHROMA_TAG) {
            Some(rest) if rest.len() >= 4 * res => floats(&rest[..4 * res]),
            Some(rest) => {
                return Err(table_err(
                    origin,
                    format!(
                        "chroma block is truncated: {} bytes, resolution {res} needs {}",
                        rest.len(),
                        4 * res
                    ),
                ));
            }
            None => uniform_chroma(res),
        };
        let t = CoeffTable { res, scale, chroma, data };
        t.validate(origin)?;
        Ok(t)
    }

    /// Reads a `.coeff` file; errors name the file.
    pub fn read(path: &Path) -> Result<Self> {
        let origin = path.display().to_string();
        // A table at MAX_RES plus room for a trailer (Mitsuba appends one).
        let cap = Self::file_len(MAX_RES) as u64 + crate::input::MIB;
        let bytes = crate::input::read_regular(path, cap)
            .map_err(|e| table_err(&origin, format!("cannot read: {e}")))?;
        Self::from_bytes(&bytes, &origin)
    }

    /// The `.coeff` payload, followed by the chroma block ([`CHROMA_TAG`]) unless the chroma
    /// grid is uniform.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.encoded_len());
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&(self.res as u32).to_le_bytes());
        for v in self.scale.iter().chain(&self.data) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        if !self.has_uniform_chroma() {
            out.extend_from_slice(CHROMA_TAG);
            for v in &self.chroma {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }
        out
    }

    /// Writes a `.coeff` file atomically: a temporary file in the same directory is renamed
    /// over `path` only once it is complete, so an interrupted write never leaves half a table.
    pub fn write(&self, path: &Path) -> Result<()> {
        let origin = path.display().to_string();
        self.validate(&origin)?;
        write_atomic(path, &self.to_bytes())
    }

    /// Coefficients for a linear RGB colour with components in [0, 1], as `rgb2spec_fetch`
    /// computes them ([`Self::fetch_direct`], with the σ⁻¹-space brightness weight), except for
    /// light colours, which are fetched as the negated complement `−fetch(1 − rgb)` (blended in
    /// over a band of the lowest channel, [`white_blend`]). This is the renderer's hot path: it does not validate;
    /// NaN or negative inputs are clamped to 0 and components above 1 to 1 (use
    /// [`Self::fetch_checked`] for user input, or the unbounded variant for values above 1).
    #[inline]
    pub fn fetch(&self, rgb: [f64; 3]) -> SigmoidPolynomial {
        let rgb = rgb.map(|v| if v > 0.0 { v.min(1.0) as f32 } else { 0.0 });
        let alpha = white_blend(rgb);
        if alpha <= 0.0 {
            return self.fetch_direct(rgb);
        }
        let comp = self.fetch_direct(rgb.map(|v| 1.0 - v)).c.map(|v| -v);
        if alpha >= 1.0 {
            return SigmoidPolynomial { c: comp };
        }
        let d = self.fetch_direct(rgb).c;
        let a = alpha as f64;
        SigmoidPolynomial { c: [0, 1, 2].map(|m| d[m] + a * (comp[m] - d[m])) }
    }

    /// rgb2spec's trilinear fetch (with [`z_weight`] and [`chroma_weight`]) of a colour already
    /// clamped to [0, 1].
    #[inline]
    pub fn fetch_direct(&self, rgb: [f32; 3]) -> SigmoidPolynomial {
        self.fetch_trilinear(rgb, false)
    }

    /// Exactly `rgb2spec_fetch` (linear weights on all three axes, no complement), as rgb2spec,
    /// Mitsuba and pbrt read a table: for judging a table made for them (e.g. rgb2spec_opt's
    /// output) on its own terms. Like them it assumes the uniform chroma grid, whatever
    /// [`Self::chroma`] says. Clamps like [`Self::fetch`].
    pub fn fetch_rgb2spec(&self, rgb: [f64; 3]) -> SigmoidPolynomial {
        self.fetch_trilinear(rgb.map(|v| if v > 0.0 { v.min(1.0) as f32 } else { 0.0 }), true)
    }

    #[inline]
    fn fetch_trilinear(&self, rgb: [f32; 3], linear: bool) -> SigmoidPolynomial {
        let res = self.res;
        // Largest channel; later channels win ties, as in rgb2spec.
        let mut l = 0;
        for c in 1..3 {
            if rgb[c] >= rgb[l] {
                l = c;
            }
        }
        let z = rgb[l];
        let zi = self.scale.partition_point(|&s| s <= z).clamp(1, res - 1) - 1;
        let (xi, yi, x1, y1, z1) = if linear {
            let (x, y) = if z > 0.0 {
                let s = (res - 1) as f32 / z;
                (rgb[(l + 1) % 3] * s, rgb[(l + 2) % 3] * s)
            } else {
                (0.0, 0.0)
            };
            let xi = (x as usize).min(res - 2);
            let yi = (y as usize).min(res - 2);
            let (s0, s1) = (self.scale[zi], self.scale[zi + 1]);
            (xi, yi, x - xi as f32, y - yi as f32, ((z - s0) / (s1 - s0)).clamp(0.0, 1.0))
        } else {
            let (x, y) = if z > 0.0 { (rgb[(l + 1) % 3] / z, rgb[(l + 2) % 3] / z) } else { (0.0, 0.0) };
            let cell = |r: f32| self.chroma.partition_point(|&c| c <= r).clamp(1, res - 1) - 1;
            let (xi, yi) = (cell(x), cell(y));
            let ch = &self.chroma;
            (
                xi,
                yi,
                chroma_weight(x, ch[xi], ch[xi + 1], y),
                chroma_weight(y, ch[yi], ch[yi + 1], x),
                z_weight(z, self.scale[zi], self.scale[zi + 1]),
            )
        };
        let (x0, y0, z0) = (1.0 - x1, 1.0 - y1, 1.0 - z1);
        let o = self.index(l, zi, yi, xi);
        let (dx, dy, dz) = (3, 3 * res, 3 * res * res);
        let d = &self.data;
        let mut c = [0.0f64; 3];
        for (m, cm) in c.iter_mut().enumerate() {
            let o = o + m;
            let v = ((d[o] * x0 + d[o + dx] * x1) * y0 + (d[o + dy] * x0 + d[o + dy + dx] * x1) * y1) * z0
                + ((d[o + dz] * x0 + d[o + dz + dx] * x1) * y0
                    + (d[o + dz + dy] * x0 + d[o + dz + dy + dx] * x1) * y1)
                    * z1;
            *cm = v as f64;
        }
        SigmoidPolynomial { c }
    }

    /// [`Self::fetch`] for user input: refuses NaN, infinite, negative and above-1 components.
    pub fn fetch_checked(&self, rgb: [f64; 3]) -> Result<SigmoidPolynomial> {
        check_rgb(rgb)?;
        if rgb.iter().any(|&v| v > 1.0) {
            return Err(ColorError::Table(format!(
                "RGB ({}, {}, {}) has a component above 1; a reflectance table covers [0, 1] (use the unbounded variant)",
                rgb[0], rgb[1], rgb[2]
            )));
        }
        Ok(self.fetch(rgb))
    }

    /// Bytes of memory the coefficients, scale and chroma grid occupy.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.scale.len() + self.chroma.len() + self.data.len())
    }
}

/// Lower clamp of [`z_logit`]: the black level is stored as the flat reflectance `Z_LO`
/// (L* ≈ 0.001), because a sigmoid never reaches 0.
pub const Z_LO: f32 = 1e-6;
/// Upper clamp of [`z_logit`]: white is stored as the flat reflectance `Z_HI` (ΔE2000 ≈ 0.004
/// from exact white, coefficient 35) rather than a coefficient that runs off to the clamp and
/// spoils the interpolation towards its near-white neighbours.
pub const Z_HI: f32 = 1.0 - 2e-4;

/// σ⁻¹(z), the sigmoid's inverse at the brightness `z` clamped to [`Z_LO`, `Z_HI`]: the constant
/// coefficient of the flat (grey) reflectance `z`.
#[inline]
pub fn z_logit(z: f32) -> f32 {
    let z = z.clamp(Z_LO, Z_HI);
    (2.0 * z - 1.0) / (2.0 * (z * (1.0 - z)).sqrt())
}

/// Interpolation weight of brightness `z` between the levels `s0` and `s1`, taken in σ⁻¹ space.
///
/// A grey's coefficient σ⁻¹(g) behaves like −1/(2√g) near black and +1/(2√(1−g)) near white,
/// so a weight linear in `z` (rgb2spec's) bends every grey between two levels: −3.9 % at
/// g = 0.01 on the 64-level grid, and no affordable grid fixes it (0.1 % needs levels 8 %
/// apart). With the weight linear in σ⁻¹(z) instead, the blend of two flat grey nodes is
/// exactly the flat grey σ⁻¹(z) for every z, and dark chromatic coefficients, which grow the
/// same way, follow suit. Only cells below 0.5 use it: above, a linear weight already keeps
/// greys within 0.04 % (the error is relative to 1 − g there), and on 10⁵ uniform sRGB colours
/// σ⁻¹ weights in the upper cells raised the mean ΔE2000 from 0.0045 to 0.0052 (bright saturated
/// colours do not follow σ⁻¹ of their largest channel). Any weight running from 0 to 1 across a
/// cell keeps the interpolation continuous, so the choice can be made per cell. The WGSL
/// `fetch_coeffs` computes the same weight; levels that clamp to the same σ⁻¹ (both below
/// `Z_LO`, possible in foreign tables) fall back to the linear weight.
#[inline]
pub fn z_weight(z: f32, s0: f32, s1: f32) -> f32 {
    let (h0, h1) = (z_logit(s0), z_logit(s1));
    let w = if h1 > h0 && s1 <= 0.5 { (z_logit(z) - h0) / (h1 - h0) } else { (z - s0) / (s1 - s0) };
    w.clamp(0.0, 1.0)
}

/// Chroma warp scale on a zero channel's face ([`chroma_weight`]), as a channel ratio (≈ 2 cells
/// at 64³).
pub const CHROMA_WARP: f32 = 0.032;
/// Growth of the chroma warp scale with the other chroma coordinate (both as channel ratios).
pub const CHROMA_WARP_SLOPE: f32 = 0.2;

/// Interpolation weight along a chroma axis at the channel ratio `x`, in the cell between the
/// chroma nodes `r0` and `r1`; `other` = the other chroma coordinate (also a ratio). The weight
/// is linear in the warped coordinate g(x) = x / (x + A), A = [`CHROMA_WARP`] +
/// [`CHROMA_WARP_SLOPE`] · other: w = (g(x) − g(r0)) / (g(r1) − g(r0)) = (x − r0)(r1 + A) /
/// ((r1 − r0)(x + A)).
///
/// Next to a zero channel the node coefficients move non-uniformly with the channel: between the
/// exact nodes (0.92, 0, 0) and (0.92, 0, 0.0146) the linear blend passes through the right
/// colours but at the wrong place (the midpoint colour is at weight 0.62, not 0.5), missing the
/// midpoint by ΔE2000 0.51, while the best weight misses it by < 0.02 (sRGB 64³, uniform grid,
/// unrefined). The best weight at a cell's middle is 0.6 on a face (o = 0) and drifts towards
/// 0.5 as the other chroma coordinate o grows (0.57 at o = 8, 0.53 at o = 30 cells of 1/63),
/// which A = 2 + 0.2·o cells follows (`python3 tools/chroma_warp.py TABLE`, on a uniform grid).
/// With the default tables' denser nodes near 0 (`fit::spectra_chroma`) the warp still pays:
/// on a similar grid (t − 0.5·t(1 − t)²) a linear weight gave an sRGB adversarial max of 0.138
/// instead of 0.085 (a development build with the constants as parameters).
/// Each weight runs 0 → 1 across its cell and A is continuous, so the fetch stays continuous; the
/// nodes are unchanged, so every node colour comes back exactly whatever the weight.
#[inline]
pub fn chroma_weight(x: f32, r0: f32, r1: f32, other: f32) -> f32 {
    let a = CHROMA_WARP + CHROMA_WARP_SLOPE * other;
    ((x - r0) * (r1 + a) / ((r1 - r0) * (x + a))).clamp(0.0, 1.0)
}

/// Lowest channel at which [`CoeffTable::fetch`] starts blending in the complement fetch.
pub const WHITE_BLEND_LO: f32 = 0.3;
/// Lowest channel from which on [`CoeffTable::fetch`] uses the complement fetch alone.
pub const WHITE_BLEND_HI: f32 = 0.5;

/// Weight of the complement fetch for a colour clamped to [0, 1]: smoothstep of its lowest
/// channel between [`WHITE_BLEND_LO`] and [`WHITE_BLEND_HI`].
///
/// Near white, node spectra sit within a percent of 1 and their coefficients grow like
/// 1/√(1 − channel), each node choosing its own shape (dips at 380 or 700 nm where the observer
/// is blind); blending such coefficients linearly missed (0.985, 1, 0.987) by ΔE2000 1.22. The
/// complement 1 − s of a reflectance s is a reflectance, its coefficients are −c (σ(−x) =
/// 1 − σ(x)), and its colour is exactly (1, 1, 1) − rgb (colour is linear in the reflectance and
/// reflectance 1 is RGB (1, 1, 1) by our conventions). So a light colour can be fetched as the
/// negated dark colour 1 − rgb, where the table is smooth (σ⁻¹ brightness weight) and where an
/// XYZ error weighs ~20× less in L* once mapped back next to white. The band 0.3…0.5 blends the
/// two coefficient sets, so the fetch stays continuous. It was 0.5…0.7 until the wide-gamut
/// tables showed light yellows such as (0.98, 0.99, 0.62) in the band, where the direct fetch is
/// poor: with 0.3…0.5 the sRGB colours inside Rec.2020 / ACEScg went from ΔE2000 0.49 / 1.77 to
/// 0.42 / 0.40 and the sRGB uniform mean from 0.0039 to 0.0034, the sRGB adversarial max stayed
/// 0.161 (`cargo run --release -p color --example adversarial -- SPACE`;
/// `… --example white_corner` prints the band figures). Greys stay exact: the complement of the flat σ⁻¹(1 − g) is the flat σ⁻¹(g).
#[inline]
pub fn white_blend(rgb: [f32; 3]) -> f32 {
    let u = ((rgb[0].min(rgb[1]).min(rgb[2]) - WHITE_BLEND_LO) / (WHITE_BLEND_HI - WHITE_BLEND_LO))
        .clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// Refuses NaN, infinite and negative RGB components.
pub fn check_rgb(rgb: [f64; 3]) -> Result<()> {
    if rgb.iter().any(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(ColorError::BadRgb(rgb[0], rgb[1], rgb[2]));
    }
    Ok(())
}

/// Writes `bytes` to a temporary file next to `path`, then renames it into place
/// ([`crate::outfile::write_atomic`]).
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::outfile::write_atomic(path, bytes)
        .map_err(|e| table_err(&path.display().to_string(), format!("cannot write: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small table whose coefficients encode their own node, so fetch can be checked exactly.
    fn synthetic(res: usize) -> CoeffTable {
        let scale: Vec<f32> = (0..res).map(|k| (k as f32 / (res - 1) as f32).powi(2)).collect();
        let mut t = CoeffTable {
            res,
            scale,
            chroma: uniform_chroma(res),
            data: vec![0.0; CoeffTable::data_len(res)],
        };
        for l in 0..3 {
            for k in 0..res {
                for j in 0..res {
                    for i in 0..res {
                        let o = t.index(l, k, j, i);
                        t.data[o] = i as f32 + 100.0 * l as f32;
                        t.data[o + 1] = j as f32;
                        t.data[o + 2] = k as f32;
                    }
                }
            }
        }
        t
    }

    #[cfg(unix)]
    #[test]
    fn devices_and_directories_are_not_read() {
        // The old `fs::read` read /dev/zero until memory ran out.
        let e = CoeffTable::read(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(e.contains("/dev/zero") && e.contains("a device"), "{e}");
        let e = CoeffTable::read(Path::new("/tmp")).unwrap_err().to_string();
        assert!(e.contains("a directory"), "{e}");
    }

    #[test]
    fn fetch_interpolates_like_rgb2spec() {
        let t = synthetic(5);
        // Green largest (l = 1): x = blue/green·4, y = red/green·4, z located in scale.
        // rgb2spec's own fetch: linear weights.
        let c = t.fetch_rgb2spec([0.2, 0.5, 0.3]).c;
        assert!((c[0] - (100.0 + 0.3 / 0.5 * 4.0)).abs() < 1e-5, "{c:?}");
        assert!((c[1] - 0.2 / 0.5 * 4.0).abs() < 1e-5);
        assert!((c[2] - (2.0 + (0.5 - 0.25) / (0.5625 - 0.25))).abs() < 1e-5);
        // Ours: chroma weights f·(xi + 1 + A)/(x + A), A = 0.032·(res − 1) + 0.2·(other axis).
        // x = 2.4 (cell 2, f = 0.4, other y = 1.6); y = 1.6 (cell 1, f = 0.6, other x = 2.4).
        let c = t.fetch([0.2, 0.5, 0.3]).c;
        let (ax, ay) = (0.128 + 0.2 * 1.6, 0.128 + 0.2 * 2.4);
        let wx = 0.4 * (3.0 + ax) / (2.4 + ax);
        let wy = 0.6 * (2.0 + ay) / (1.6 + ay);
        assert!((c[0] - (102.0 + wx)).abs() < 1e-5, "{c:?} vs {}", 102.0 + wx);
        assert!((c[1] - (1.0 + wy)).abs() < 1e-5, "{c:?} vs {}", 1.0 + wy);
        // scale = (k/4)²: 0.5 lies between k = 2 (0.25) and k = 3 (0.5625).
        // The cell 0.25…0.5625 reaches above 0.5: linear brightness weight.
        assert!((c[2] - (2.0 + (0.5 - 0.25) / (0.5625 - 0.25))).abs() < 1e-5);
        // Below 0.5 the weight is σ⁻¹-space: 0.2 lies between k = 1 (0.0625) and k = 2 (0.25),
        // w = (σ⁻¹(0.2) − σ⁻¹(0.0625)) / (σ⁻¹(0.25) − σ⁻¹(0.0625)), σ⁻¹(g) = (2g − 1)/(2√(g(1 − g))).
        let h = |g: f64| (2.0 * g - 1.0) / (2.0 * (g * (1.0 - g)).sqrt());
        let w = (h(0.2) - h(0.0625)) / (h(0.25) - h(0.0625));
        let c = t.fetch([0.1, 0.2, 0.05]).c;
        assert!((c[2] - (1.0 + w)).abs() < 1e-5, "{c:?} vs {}", 1.0 + w);
        // Ties go to the later channel; black does not divide by zero.
        assert!((t.fetch_direct([0.7, 0.7, 0.7]).c[0] - 204.0).abs() < 1e-5);
        assert_eq!(t.fetch([0.0, 0.0, 0.0]).c, [200.0, 0.0, 0.0]);
        // Hot path clamps instead of failing; the checked path refuses.
        assert!(t.fetch([f64::NAN, -1.0, 2.0]).c.iter().all(|v| v.is_finite()));
        assert!(t.fetch_checked([f64::NAN, 0.0, 0.0]).is_err());
        assert!(t.fetch_checked([-0.1, 0.0, 0.0]).is_err());
        assert!(t.fetch_checked([1.5, 0.0, 0.0]).is_err());
    }

    #[test]
    fn chroma_weight_runs_from_0_to_1_across_each_cell() {
        for res in [5, 64] {
            let spectra: Vec<f32> =
                crate::upsample::fit::spectra_chroma(res).iter().map(|&c| c as f32).collect();
            for nodes in [uniform_chroma(res), spectra] {
                for xi in 0..res - 1 {
                    let (r0, r1) = (nodes[xi], nodes[xi + 1]);
                    for other in [0.0, 0.02, 1.0] {
                        let w = |f: f32| chroma_weight(r0 + f * (r1 - r0), r0, r1, other);
                        assert_eq!(w(0.0), 0.0);
                        assert!((w(1.0) - 1.0).abs() < 1e-5, "res {res} cell {xi}: {}", w(1.0));
                        // Increasing, and above linear (the warp is concave).
                        let mut prev = 0.0;
                        for m in 1..=10 {
                            let f = m as f32 / 10.0;
                            assert!(w(f) > prev && w(f) >= f - 1e-5, "res {res} cell {xi} f {f}: {}", w(f));
                            prev = w(f);
                        }
                    }
                }
            }
        }
        // Far from a zero channel the weight is nearly linear: mid-cell at x = 30.5/63, 0.508.
        let r = |x: f32| x / 63.0;
        assert!((chroma_weight(r(30.5), r(30.0), r(31.0), r(30.0)) - 0.5).abs() < 0.01);
    }

    #[test]
    fn non_uniform_chroma_grid_is_stored_and_fetched() {
        let mut t = synthetic(5);
        t.chroma = vec![0.0, 0.1, 0.3, 0.6, 1.0];
        // Written after the payload, read back; a uniform grid writes no block.
        let b = t.to_bytes();
        assert_eq!(b.len(), t.encoded_len());
        assert_eq!(b.len(), CoeffTable::file_len(5) + CHROMA_TAG.len() + 20);
        assert_eq!(CoeffTable::from_bytes(&b, "x").unwrap(), t);
        assert_eq!(synthetic(5).to_bytes().len(), CoeffTable::file_len(5));
        // A node's colour fetches exactly that node: red table (l = 0), x = green/red on node 1
        // (0.1), y = blue/red on node 3 (0.6); z = 0.5625 is level 3.
        let c = t.fetch_direct([0.5625, 0.05625, 0.3375]).c;
        assert!((c[0] - 1.0).abs() < 1e-5 && (c[1] - 3.0).abs() < 1e-5 && (c[2] - 3.0).abs() < 1e-5, "{c:?}");
        // Between nodes the weight uses the node ratios: x = 0.2 is cell 1 (0.1…0.3).
        let c = t.fetch_direct([0.5625, 0.1125, 0.3375]).c;
        let w = chroma_weight(0.2, 0.1, 0.3, 0.6);
        assert!((c[0] - (1.0 + w as f64)).abs() < 1e-5, "{c:?} vs {}", 1.0 + w);
        // Bad grids are refused with the reason.
        let mut b2 = b.clone();
        b2.truncate(b.len() - 3);
        assert!(err(&b2).contains("chroma block is truncated"));
        let mut bad = t.clone();
        bad.chroma[2] = 0.05;
        assert!(err(&bad.to_bytes()).contains("chroma nodes must increase"));
        bad.chroma = vec![0.0, 0.1, 0.3, 0.6, 0.9];
        assert!(err(&bad.to_bytes()).contains("from 0 to 1"));
    }

    #[test]
    fn light_colours_are_fetched_through_their_complement() {
        let t = synthetic(5);
        let close = |a: [f64; 3], b: [f64; 3]| (0..3).all(|m| (a[m] - b[m]).abs() < 1e-4);
        let neg = |p: SigmoidPolynomial| p.c.map(|v| -v);
        // Lowest channel ≥ 0.5: the negated fetch of 1 − rgb alone.
        let rgb = [0.9f32, 0.75, 0.8];
        let want = neg(t.fetch_direct(rgb.map(|v| 1.0 - v)));
        assert!(close(t.fetch(rgb.map(f64::from)).c, want));
        // Lowest channel ≤ 0.3: rgb2spec's fetch unchanged.
        let rgb = [0.9f32, 0.3, 1.0];
        assert!(close(t.fetch(rgb.map(f64::from)).c, t.fetch_direct(rgb).c));
        // Halfway through the band: the smoothstep weight is ½.
        let rgb = [0.4f32, 0.95, 0.8];
        let (d, c) = (t.fetch_direct(rgb).c, neg(t.fetch_direct(rgb.map(|v| 1.0 - v))));
        assert!(close(t.fetch(rgb.map(f64::from)).c, [0, 1, 2].map(|m| 0.5 * (d[m] + c[m]))));
        // Continuous at both ends of the band.
        for lo in [WHITE_BLEND_LO, WHITE_BLEND_HI] {
            let a = t.fetch([f64::from(lo) - 1e-6, 0.9, 0.95]).c;
            let b = t.fetch([f64::from(lo) + 1e-6, 0.9, 0.95]).c;
            assert!(close(a, b), "jump at {lo}: {a:?} vs {b:?}");
        }
    }

    #[test]
    fn bytes_round_trip_and_trailer_is_ignored() {
        let t = synthetic(4);
        let mut b = t.to_bytes();
        assert_eq!(b.len(), CoeffTable::file_len(4));
        assert_eq!(CoeffTable::from_bytes(&b, "x").unwrap(), t);
        b.extend_from_slice(&[1, 2, 3, 4, 5]);
        assert_eq!(CoeffTable::from_bytes(&b, "x").unwrap(), t);
    }

    #[test]
    fn file_round_trip_is_atomic_and_named_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.coeff");
        let t = synthetic(3);
        t.write(&p).unwrap();
        assert_eq!(CoeffTable::read(&p).unwrap(), t);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no temporary file left behind");
        let e = CoeffTable::read(&dir.path().join("missing.coeff")).unwrap_err().to_string();
        assert!(e.contains("missing.coeff") && e.contains("cannot read"), "{e}");
    }

    fn err(bytes: &[u8]) -> String {
        let e = CoeffTable::from_bytes(bytes, "bad.coeff").unwrap_err();
        assert!(matches!(e, ColorError::Table(_)));
        let s = e.to_string();
        assert!(s.starts_with("bad.coeff: "), "{s}");
        s
    }

    #[test]
    fn malformed_files_are_refused_with_reasons() {
        let good = synthetic(3).to_bytes();
        assert!(err(&good[..5]).contains("truncated"));
        assert!(err(&good[..good.len() - 1]).contains("truncated"));
        assert!(err(b"").contains("truncated"));
        let mut b = good.clone();
        b[..4].copy_from_slice(b"PNG\0");
        assert!(err(&b).contains("SPEC"));
        let mut b = good.clone();
        b[4..8].copy_from_slice(&1u32.to_le_bytes());
        assert!(err(&b).contains("resolution 1"));
        let mut b = good.clone();
        b[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(err(&b).contains("resolution"));
        // NaN coefficient: the message names the node.
        let mut b = good.clone();
        let off = 8 + 4 * 3 + 4 * (3 * 27 + 5);
        b[off..off + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        let s = err(&b);
        assert!(s.contains("not finite") && s.contains("l=1"), "{s}");
        // Non-monotonic and out-of-range scale.
        let mut b = good.clone();
        b[12..16].copy_from_slice(&0.0f32.to_le_bytes());
        assert!(err(&b).contains("increase"));
        let mut b = good;
        b[16..20].copy_from_slice(&f32::INFINITY.to_le_bytes());
        assert!(err(&b).contains("scale[2]"));
        // A header that understates the resolution: the first nodes of the brightness axis
        // increase but stop short of 1, and what follows is read as the rest of the table
        // (the longer file's tail passes for a trailer). It loaded before.
        let mut b = synthetic(6).to_bytes();
        b[4..8].copy_from_slice(&3u32.to_le_bytes());
        let s = err(&b);
        assert!(s.contains("scale must end at 1") && s.contains("resolution, 3,"), "{s}");
    }
}
