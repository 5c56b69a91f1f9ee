//! Heat maps of a per-pixel error (ΔE2000) with a labelled colour bar.
//!
//! Layout: the error map on the left (nearest-neighbour enlarged by an integer factor when the
//! image is small, so a 32×32 test render is still inspectable), and to its right a vertical
//! colour bar from 0 (bottom) to the scale maximum (top) with tick marks and numeric labels in
//! an embedded bitmap font, under a title ("ΔE00" by default). Values above the maximum take
//! the top colour and the top label gets a "+" suffix when any pixel is clipped.

use color::error::show as short;
use std::path::Path;

use crate::atomic::write_atomic;
use crate::diff::DiffMaps;
use crate::error::{CompareError, Result};
use crate::font::{draw_text, text_height, text_width};

/// Perceptually uniform colour maps (matplotlib's, via the `colorous` crate).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColorMap {
    #[default]
    Viridis,
    Magma,
    Inferno,
}

impl ColorMap {
    /// Names accepted by [`ColorMap::by_name`].
    pub const NAMES: &'static [&'static str] = &["viridis", "magma", "inferno"];

    pub fn by_name(name: &str) -> Result<ColorMap> {
        match name.to_ascii_lowercase().as_str() {
            "viridis" => Ok(ColorMap::Viridis),
            "magma" => Ok(ColorMap::Magma),
            "inferno" => Ok(ColorMap::Inferno),
            _ => Err(CompareError::InvalidOption(format!(
                "unknown colour map {name:?} (known: {})",
                Self::NAMES.join(", ")
            ))),
        }
    }

    /// sRGB8 colour at `t` ∈ [0, 1] (clamped).
    pub fn eval(self, t: f64) -> [u8; 3] {
        let g = match self {
            ColorMap::Viridis => colorous::VIRIDIS,
            ColorMap::Magma => colorous::MAGMA,
            ColorMap::Inferno => colorous::INFERNO,
        };
        let c = g.eval_continuous(t.clamp(0.0, 1.0));
        [c.r, c.g, c.b]
    }
}

/// How to draw a heat map.
#[derive(Clone, Debug, PartialEq)]
pub struct HeatmapOptions {
    /// Value at the top of the scale. `None`: the largest value rounded up to a "nice" number
    /// (1, 2, 2.5 or 5 × 10ᵏ), or 1 if all values are 0.
    pub max: Option<f64>,
    pub colormap: ColorMap,
    /// Text above the colour bar.
    pub title: String,
}

impl Default for HeatmapOptions {
    fn default() -> Self {
        HeatmapOptions { max: None, colormap: ColorMap::default(), title: "ΔE00".into() }
    }
}

/// A rendered heat map: display-ready sRGB8 pixels plus where things were drawn (for reuse
/// and for tests).
#[derive(Clone, Debug, PartialEq)]
pub struct Heatmap {
    pub width: u32,
    pub height: u32,
    /// Row-major sRGB8.
    pub pixels: Vec<[u8; 3]>,
    /// The scale maximum used.
    pub max: f64,
    /// Tick values labelled on the bar, ascending, starting at 0.
    pub ticks: Vec<f64>,
    /// Integer enlargement of the map (map pixel (x, y) covers canvas pixels from
    /// (x·scale, y·scale)).
    pub map_scale: u32,
    /// Colour bar rectangle: left x, top y (value = max), width, bottom y (value = 0).
    pub bar: (u32, u32, u32, u32),
}

const BACKGROUND: [u8; 3] = [255, 255, 255];
const INK: [u8; 3] = [0, 0, 0];
/// Small maps are enlarged until their longer side reaches this many pixels.
const MIN_MAP_SIDE: u32 = 256;

/// The range of a heat map's scale: beyond it the labels stop being numbers a reader can use (a
/// scale of 1e300 wrote a 301-digit label on a 3864-pixel-wide image, one of 1e-300 labelled
/// every tick 0). A ΔE00 between black and white is 100.
pub const MIN_SCALE: f64 = 1e-4;
pub const MAX_SCALE: f64 = 1e4;

impl Heatmap {
    /// Heat map of the ΔE2000 map of a comparison.
    pub fn of_delta_e(maps: &DiffMaps, opts: &HeatmapOptions) -> Result<Heatmap> {
        Heatmap::render(&maps.delta_e2000, maps.width, maps.height, opts)
    }

    /// Renders `values` (row-major, `width × height`, finite and ≥ 0) as a heat map.
    pub fn render(values: &[f64], width: u32, height: u32, opts: &HeatmapOptions) -> Result<Heatmap> {
        if width == 0 || height == 0 || values.len() != width as usize * height as usize {
            return Err(CompareError::InvalidImage(format!(
                "heat map of {width}×{height} needs {} values, got {}",
                width as usize * height as usize,
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(CompareError::InvalidImage(format!(
                "heat map value {i} is not finite: {}",
                values[i]
            )));
        }
        let data_max = values.iter().copied().fold(0.0, f64::max);
        let max = match opts.max {
            Some(m) if (MIN_SCALE..=MAX_SCALE).contains(&m) => m,
            Some(m) => {
                return Err(CompareError::InvalidOption(format!(
                    "heat map maximum must be from {} to {}, got {}",
                    short(MIN_SCALE),
                    short(MAX_SCALE),
                    short(m)
                )));
            }
            None => nice_ceil(data_max).clamp(MIN_SCALE, MAX_SCALE),
        };
        let clipped = data_max > max;

        let map_scale = (MIN_MAP_SIDE / width.max(height)).clamp(1, 16);
        let (map_w, map_h) = (width * map_scale, height * map_scale);
        // Font scale follows the picture size so labels stay legible on large renders.
        let s = (map_h / 128).clamp(2, 4);
        let pad = 4 * s;
        let th = text_height(s);

        let step = tick_step(max);
        let decimals = decimals_for(step);
        let mut ticks: Vec<f64> =
            (0..).map(|k| k as f64 * step).take_while(|v| *v <= max * (1.0 + 1e-9)).collect();
        let mut labels: Vec<String> = ticks.iter().map(|v| format!("{v:.decimals$}")).collect();
        // A user-chosen maximum that is not a tick gets its own label if it has room.
        let last = *ticks.last().expect("0 is always a tick");
        if max - last > 0.35 * step {
            ticks.push(max);
            labels.push(format!("{max}"));
        }
        if clipped {
            if (max - ticks[ticks.len() - 1]).abs() <= 1e-9 * max {
                labels.last_mut().expect("non-empty").push('+');
            } else {
                ticks.push(max);
                labels.push(format!("{max}+"));
            }
        }

        let bar_w = 8 * s;
        let tick_len = 3 * s;
        let bar_x = map_w + 6 * s;
        let label_x = bar_x + bar_w + tick_len + 2 * s;
        let labels_w = labels.iter().map(|l| text_width(l, s)).max().unwrap_or(0);
        let canvas_w = (label_x + labels_w).max(bar_x + text_width(&opts.title, s)) + pad;
        let canvas_h = map_h.max(120 * s);
        // Room for the title plus half a label, so the top tick label clears the title.
        let bar_top = pad + th + pad + th / 2;
        let bar_bottom = canvas_h - pad - th / 2 - 1;

        let mut px = vec![BACKGROUND; canvas_w as usize * canvas_h as usize];
        let cw = canvas_w as usize;
        for y in 0..map_h {
            for x in 0..map_w {
                let v = values[(y / map_scale) as usize * width as usize + (x / map_scale) as usize];
                px[y as usize * cw + x as usize] = opts.colormap.eval(v / max);
            }
        }
        let span = f64::from(bar_bottom - bar_top);
        for y in bar_top..=bar_bottom {
            let c = opts.colormap.eval(f64::from(bar_bottom - y) / span);
            for x in bar_x..bar_x + bar_w {
                px[y as usize * cw + x as usize] = c;
            }
        }
        // Outline so the light end of the bar does not vanish into the background.
        for x in bar_x - 1..=bar_x + bar_w {
            px[(bar_top - 1) as usize * cw + x as usize] = INK;
            px[(bar_bottom + 1) as usize * cw + x as usize] = INK;
        }
        for y in bar_top - 1..=bar_bottom + 1 {
            px[y as usize * cw + (bar_x - 1) as usize] = INK;
            px[y as usize * cw + (bar_x + bar_w) as usize] = INK;
        }
        for (v, label) in ticks.iter().zip(&labels) {
            let y = bar_bottom - (v / max * span).round() as u32;
            for t in 0..s.div_ceil(2) {
                let row = (y + t).min(bar_bottom + 1) as usize;
                for x in bar_x + bar_w..bar_x + bar_w + tick_len {
                    px[row * cw + x as usize] = INK;
                }
            }
            draw_text(&mut px, canvas_w, i64::from(label_x), i64::from(y) - i64::from(th / 2), label, s, INK);
        }
        draw_text(&mut px, canvas_w, i64::from(bar_x), i64::from(pad), &opts.title, s, INK);

        Ok(Heatmap {
            width: canvas_w,
            height: canvas_h,
            pixels: px,
            max,
            ticks,
            map_scale,
            bar: (bar_x, bar_top, bar_w, bar_bottom),
        })
    }

    /// The canvas pixel at column `x`, row `y`.
    pub fn get(&self, x: u32, y: u32) -> [u8; 3] {
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Encodes the heat map as an 8-bit sRGB PNG.
    pub fn to_png(&self) -> Result<Vec<u8>> {
        let raw: Vec<u8> = self.pixels.iter().flatten().copied().collect();
        let img =
            image::RgbImage::from_raw(self.width, self.height, raw).expect("canvas size matches pixels");
        let mut buf = std::io::Cursor::new(Vec::new());
        img.write_to(&mut buf, image::ImageFormat::Png).map_err(|e| CompareError::Encode {
            path: "heat map".into(),
            format: "PNG",
            reason: e.to_string(),
        })?;
        Ok(buf.into_inner())
    }

    /// Writes the heat map as a PNG, atomically. The extension must be `.png`.
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<()> {
        let path = path.as_ref();
        let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase()).unwrap_or_default();
        if ext != "png" {
            return Err(CompareError::UnsupportedExtension { path: path.into(), ext });
        }
        write_atomic(path, &self.to_png()?)
    }
}

const NICE: [f64; 5] = [1.0, 2.0, 2.5, 5.0, 10.0];

/// Smallest m·10ᵏ ≥ `v` with m ∈ {1, 2, 2.5, 5}; 1 for `v` ≤ 0.
pub fn nice_ceil(v: f64) -> f64 {
    if v <= 0.0 {
        return 1.0;
    }
    let e = 10f64.powf(v.log10().floor());
    NICE.iter().map(|m| m * e).find(|n| *n >= v * (1.0 - 1e-12)).unwrap_or(10.0 * e)
}

/// Tick spacing giving about five intervals up to `max`.
fn tick_step(max: f64) -> f64 {
    nice_ceil(max / 5.0)
}

/// Decimal places that print every multiple of `step` exactly (0.25 → 2, 0.5 → 1, 20 → 0).
fn decimals_for(step: f64) -> usize {
    (0..12)
        .find(|&d| {
            let scaled = step * 10f64.powi(d);
            (scaled - scaled.round()).abs() < 1e-6 * scaled.max(1.0)
        })
        .unwrap_or(12) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_numbers() {
        assert_eq!(nice_ceil(0.0), 1.0);
        assert_eq!(nice_ceil(3.2), 5.0);
        assert_eq!(nice_ceil(5.0), 5.0);
        assert_eq!(nice_ceil(0.21), 0.25);
        assert_eq!(nice_ceil(11.0), 20.0);
        assert_eq!(decimals_for(0.25), 2);
        assert_eq!(decimals_for(0.5), 1);
        assert_eq!(decimals_for(20.0), 0);
        assert_eq!(decimals_for(0.001), 3);
    }

    fn ramp(w: u32, h: u32, top: f64) -> Vec<f64> {
        (0..w * h).map(|i| f64::from(i) / f64::from(w * h - 1) * top).collect()
    }

    #[test]
    fn ticks_cover_the_scale() {
        let h = Heatmap::render(&ramp(8, 8, 3.2), 8, 8, &HeatmapOptions::default()).unwrap();
        assert_eq!(h.max, 5.0);
        assert_eq!(h.ticks, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        let fixed = HeatmapOptions { max: Some(3.7), ..Default::default() };
        let h = Heatmap::render(&ramp(8, 8, 3.2), 8, 8, &fixed).unwrap();
        assert_eq!(h.ticks, vec![0.0, 1.0, 2.0, 3.0, 3.7]);
        let h = Heatmap::render(&[0.0; 4], 2, 2, &HeatmapOptions::default()).unwrap();
        assert_eq!(h.max, 1.0);
    }

    #[test]
    fn map_and_bar_colours_follow_the_scale() {
        let opts = HeatmapOptions { max: Some(2.0), ..Default::default() };
        // Values 0, 1, 2, 7 (the last clipped to the top colour).
        let h = Heatmap::render(&[0.0, 1.0, 2.0, 7.0], 4, 1, &opts).unwrap();
        // 256 / 4 = 64, capped at 16.
        assert_eq!(h.map_scale, 16);
        let cm = ColorMap::Viridis;
        let at = |x: u32| h.get(x * 16 + 8, 8);
        assert_eq!(at(0), cm.eval(0.0));
        assert_eq!(at(1), cm.eval(0.5));
        assert_eq!(at(2), cm.eval(1.0));
        assert_eq!(at(3), cm.eval(1.0));
        let (bx, top, bw, bottom) = h.bar;
        assert_eq!(h.get(bx + bw / 2, bottom), cm.eval(0.0));
        assert_eq!(h.get(bx + bw / 2, top), cm.eval(1.0));
        assert!(bx >= 4 * 16, "bar overlaps the map");
        // Labels: there is ink right of the bar at the height of each tick.
        let span = f64::from(bottom - top);
        for v in &h.ticks {
            let y = bottom - (v / h.max * span).round() as u32;
            let ink = (bx + bw..h.width)
                .any(|x| (y.saturating_sub(4)..=(y + 4).min(h.height - 1)).any(|yy| h.get(x, yy) == INK));
            assert!(ink, "no label near tick {v}");
        }
    }

    #[test]
    fn png_round_trips() {
        let h = Heatmap::render(&ramp(5, 3, 1.0), 5, 3, &HeatmapOptions::default()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("h.png");
        h.save_png(&p).unwrap();
        let back = image::open(&p).unwrap().to_rgb8();
        assert_eq!((back.width(), back.height()), (h.width, h.height));
        assert!(back.pixels().zip(&h.pixels).all(|(a, b)| a.0 == *b));
        assert!(h.save_png(dir.path().join("h.jpg")).is_err());
    }

    #[test]
    fn bad_input_is_rejected() {
        let o = HeatmapOptions::default();
        assert!(Heatmap::render(&[1.0; 3], 2, 2, &o).is_err());
        assert!(Heatmap::render(&[1.0, f64::NAN, 0.0, 0.0], 2, 2, &o).is_err());
        assert!(
            Heatmap::render(&[1.0; 4], 2, 2, &HeatmapOptions { max: Some(0.0), ..Default::default() })
                .is_err()
        );
        assert!(ColorMap::by_name("jet").unwrap_err().to_string().contains("viridis"));
    }
}
