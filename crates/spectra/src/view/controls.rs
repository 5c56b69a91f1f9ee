//! The viewer's live settings and the egui panel / keyboard shortcuts that change them.
//!
//! Edits go to a candidate copy; a candidate the renderer would refuse (e.g. a range whose
//! minimum is not below its maximum) is shown as an error and the last valid settings stay
//! on screen, so a half-typed value never stops the window.

use render::{Mode, PassTimings, RenderSettings, Tonemap};
use std::path::{Path, PathBuf};

/// Most wavelengths the viewer offers (the renderer allows more; beyond 64 lavapipe crawls).
pub const MAX_VIEW_WAVELENGTHS: usize = 64;

const MODES: [Mode; 3] = Mode::ALL;
const TONEMAPS: [Tonemap; 3] = Tonemap::ALL;

/// Shortcuts, shown in the panel and printed at start.
pub const HELP: &str = "left drag: orbit · right drag: look · wheel: zoom · WASD/QE: fly (Shift ×4) · \
R: reset camera · M or 1/2/3: mode · [ ]: N −/+1 · { }: N ÷/×2 · I: quadrature · T: tone map · O: observer · \
- =: exposure · J: accumulate (jittered λ, antialiased) · F12 or P: screenshot · Esc: quit";

/// The wavelength jitter of accumulated frame `k` (0-based since the last reset): the
/// golden-ratio additive recurrence u_k = frac(½ + k/φ), whose first K values fall one in each
/// of K strata of [0, 1) up to a small discrepancy for every K, so the running mean is a
/// stratified estimate whenever the user looks at it (no K fixed in advance).
pub fn jitter_offset(k: u32) -> f32 {
    const INV_PHI: f64 = 0.618_033_988_749_894_9;
    ((0.5 + k as f64 * INV_PHI).fract() as f32).min(1.0 - f32::EPSILON)
}

/// Where accumulated frame `k` looks inside each pixel, in pixels from its centre: Roberts' R2
/// sequence (the plastic number's additive recurrence, open-ended like [`jitter_offset`]), so
/// that the running mean is the image box-filtered over the pixel — antialiased — however many
/// frames the user waits for. Frame 0 looks at the centre.
pub fn pixel_jitter(k: u32) -> [f32; 2] {
    const G: f64 = 1.324_717_957_244_746;
    let t = f64::from(k);
    [((0.5 + t / G).fract() - 0.5) as f32, ((0.5 + t / (G * G)).fract() - 0.5) as f32]
}

/// The texture LOD bias of accumulated frames: one level finer than a single frame's, since
/// the mean covers the pixel with many samples (`spectra render --samples 4` takes the same).
pub const ACCUMULATED_LOD_BIAS: f32 = -1.0;

/// What the user asked for and what is on screen.
pub struct Controls {
    /// The settings being edited (may be invalid for a moment).
    pub wanted: RenderSettings,
    /// The last valid settings: what is rendered.
    pub applied: RenderSettings,
    /// Why `wanted` was refused, if it was.
    pub error: Option<String>,
    /// Last message for the user (screenshot path, …).
    pub status: String,
    pub screenshot_requested: bool,
    pub reset_camera_requested: bool,
    /// Accumulate frames with jittered wavelengths ([`jitter_offset`]) and places in the pixel
    /// ([`pixel_jitter`]) until the view changes.
    pub accumulate: bool,
    /// Frames in the displayed mean (set by the window each frame, shown in the panel).
    pub accumulated_frames: u32,
}

/// Timing shown in the panel.
#[derive(Clone, Copy, Debug, Default)]
pub struct FrameTimes {
    /// Smoothed wall-clock time of a whole frame loop iteration (render, UI, present), ms.
    pub cpu_ms: f64,
    /// GPU time per pass of the last frame (timestamp queries), when available.
    pub gpu: Option<PassTimings>,
}

impl Controls {
    pub fn new(settings: RenderSettings) -> Self {
        Controls {
            wanted: settings.clone(),
            applied: settings,
            error: None,
            status: String::new(),
            screenshot_requested: false,
            reset_camera_requested: false,
            accumulate: false,
            accumulated_frames: 0,
        }
    }

    /// Validates the edited settings; applies them when the renderer will accept them.
    pub fn commit(&mut self) {
        if self.wanted == self.applied {
            self.error = None;
            return;
        }
        match self.wanted.validate() {
            Ok(()) => {
                self.applied = self.wanted.clone();
                self.error = None;
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    pub fn cycle_mode(&mut self) {
        let i = MODES.iter().position(|m| *m == self.wanted.mode).unwrap_or(0);
        self.wanted.mode = MODES[(i + 1) % MODES.len()];
    }

    pub fn set_mode(&mut self, mode: Mode) {
        self.wanted.mode = mode;
    }

    /// Adds `delta` wavelengths, staying within 1..=[`MAX_VIEW_WAVELENGTHS`].
    pub fn step_wavelengths(&mut self, delta: i64) {
        let n = self.wanted.wavelengths as i64 + delta;
        self.wanted.wavelengths = n.clamp(1, MAX_VIEW_WAVELENGTHS as i64) as usize;
    }

    /// Doubles (`up`) or halves N, staying within 1..=[`MAX_VIEW_WAVELENGTHS`].
    pub fn scale_wavelengths(&mut self, up: bool) {
        let n = self.wanted.wavelengths;
        self.wanted.wavelengths = if up { n * 2 } else { n / 2 }.clamp(1, MAX_VIEW_WAVELENGTHS);
    }

    /// Switches between the prefiltered and the midpoint quadrature.
    pub fn cycle_quadrature(&mut self) {
        let all = color::Quadrature::ALL;
        let i = all.iter().position(|q| *q == self.wanted.quadrature).unwrap_or(0);
        self.wanted.quadrature = all[(i + 1) % all.len()];
    }

    pub fn cycle_tonemap(&mut self) {
        let i = TONEMAPS.iter().position(|t| *t == self.wanted.tonemap).unwrap_or(0);
        self.wanted.tonemap = TONEMAPS[(i + 1) % TONEMAPS.len()];
    }

    pub fn cycle_observer(&mut self) {
        let names = color::Observer::NAMES;
        let cur = self.wanted.observer.to_ascii_lowercase();
        let i = names.iter().position(|n| *n == cur).map(|i| i + 1).unwrap_or(0);
        self.wanted.observer = names[i % names.len()].to_string();
    }

    pub fn step_exposure(&mut self, ev: f32) {
        self.wanted.exposure_ev = (self.wanted.exposure_ev + ev).clamp(-16.0, 16.0);
    }

    /// The control panel.
    pub fn ui(&mut self, ui: &mut egui::Ui, times: &FrameTimes, adapter: &str, size: (u32, u32)) {
        let w = &mut self.wanted;
        ui.horizontal(|ui| {
            ui.label("mode");
            for m in MODES {
                ui.radio_value(&mut w.mode, m, m.name());
            }
        });
        ui.add(egui::Slider::new(&mut w.wavelengths, 1..=MAX_VIEW_WAVELENGTHS).text("N wavelengths"));
        ui.horizontal(|ui| {
            ui.label("quadrature (I)");
            for q in color::Quadrature::ALL {
                ui.radio_value(&mut w.quadrature, q, q.name());
            }
        });
        let (mut lo, mut hi) = (w.range.min, w.range.max);
        ui.horizontal(|ui| {
            ui.label("range nm");
            ui.add(egui::DragValue::new(&mut lo).range(200.0..=1200.0).speed(1.0));
            ui.add(egui::DragValue::new(&mut hi).range(200.0..=1200.0).speed(1.0));
        });
        if (lo, hi) != (w.range.min, w.range.max) {
            // Field-wise so an invalid pair is kept for the error message, not dropped.
            w.range.min = lo;
            w.range.max = hi;
        }
        // Every observer and camera of the database (the O key cycles the built-in set).
        egui::ComboBox::from_label("observer").selected_text(w.observer.clone()).show_ui(ui, |ui| {
            for name in color::Observer::names() {
                ui.selectable_value(&mut w.observer, name.to_string(), name);
            }
        });
        let mut to_display = w.camera_view == color::film::CameraView::Display;
        if ui
            .checkbox(&mut to_display, "camera to display")
            .on_hover_text("a camera through its ColorChecker fit to XYZ and sRGB, not its balanced channels")
            .changed()
        {
            w.camera_view = color::film::CameraView::from_flag(to_display);
        }
        ui.add(egui::Slider::new(&mut w.exposure_ev, -8.0..=8.0).step_by(0.25).text("exposure EV"));
        ui.horizontal(|ui| {
            ui.label("tone map");
            for t in TONEMAPS {
                ui.radio_value(&mut w.tonemap, t, t.name());
            }
        });
        ui.checkbox(&mut w.shadows, "shadow maps");
        ui.horizontal(|ui| {
            ui.checkbox(&mut self.accumulate, "accumulate (jittered λ, antialiased) (J)");
            if self.accumulate {
                ui.monospace(format!("{} frames", self.accumulated_frames));
            }
        });
        if let Some(e) = &self.error {
            ui.colored_label(egui::Color32::from_rgb(255, 110, 90), e);
        }
        ui.separator();
        let fps = if times.cpu_ms > 0.0 { 1000.0 / times.cpu_ms } else { 0.0 };
        ui.monospace(format!("{}×{}  CPU frame {:.1} ms ({fps:.1} fps)", size.0, size.1, times.cpu_ms));
        match &times.gpu {
            Some(t) => {
                ui.monospace(format!("GPU {:.1} ms (timestamps)", t.total_ms()));
                let per: Vec<String> =
                    render::timing::PASSES.iter().zip(t.ms).map(|(p, ms)| format!("{p} {ms:.1}")).collect();
                ui.monospace(per.join(" · "));
            }
            None => {
                ui.monospace("GPU: no timestamp queries on this adapter");
            }
        }
        ui.small(adapter);
        ui.horizontal(|ui| {
            if ui.button("screenshot (F12)").clicked() {
                self.screenshot_requested = true;
            }
            if ui.button("reset camera (R)").clicked() {
                self.reset_camera_requested = true;
            }
        });
        if !self.status.is_empty() {
            ui.label(&self.status);
        }
        ui.collapsing("keys", |ui| ui.small(HELP));
    }
}

/// `dir/screenshot-<n>.png` with the smallest n ≥ 1 not taken yet.
pub fn next_screenshot_path(dir: &Path) -> PathBuf {
    (1u32..)
        .map(|n| dir.join(format!("screenshot-{n}.png")))
        .find(|p| !p.exists())
        .expect("fewer than 2^32 screenshots")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shortcuts_stay_in_range() {
        let mut c = Controls::new(RenderSettings { wavelengths: 16, ..Default::default() });
        c.step_wavelengths(1);
        assert_eq!(c.wanted.wavelengths, 17);
        c.step_wavelengths(-100);
        assert_eq!(c.wanted.wavelengths, 1);
        c.scale_wavelengths(false);
        assert_eq!(c.wanted.wavelengths, 1);
        for _ in 0..10 {
            c.scale_wavelengths(true);
        }
        assert_eq!(c.wanted.wavelengths, MAX_VIEW_WAVELENGTHS);
        c.step_exposure(100.0);
        assert_eq!(c.wanted.exposure_ev, 16.0);
        assert_eq!(c.wanted.quadrature, color::Quadrature::Prefiltered);
        c.cycle_quadrature();
        assert_eq!(c.wanted.quadrature, color::Quadrature::Midpoint);
        c.cycle_quadrature();
        assert_eq!(c.wanted.quadrature, color::Quadrature::Prefiltered);
    }

    #[test]
    fn cycles_visit_every_value() {
        let mut c = Controls::new(RenderSettings { mode: Mode::Rgb, ..Default::default() });
        let mut seen = vec![c.wanted.mode];
        for _ in 0..3 {
            c.cycle_mode();
            seen.push(c.wanted.mode);
        }
        assert_eq!(seen, [Mode::Rgb, Mode::Naive, Mode::Spectral, Mode::Rgb]);
        c.cycle_tonemap();
        assert_eq!(c.wanted.tonemap, Tonemap::Reinhard);
        c.wanted.observer = "CIE1931".into();
        c.cycle_observer();
        assert_eq!(c.wanted.observer, color::Observer::NAMES[1]);
        for _ in 0..color::Observer::NAMES.len() {
            c.cycle_observer();
            assert!(color::Observer::by_name(&c.wanted.observer).is_ok());
        }
    }

    #[test]
    fn invalid_edits_keep_the_last_valid_settings() {
        let mut c = Controls::new(RenderSettings::default());
        c.wanted.range.min = 700.0;
        c.wanted.range.max = 400.0;
        c.commit();
        assert!(c.error.is_some());
        assert_eq!(c.applied, RenderSettings::default());
        c.wanted.range.max = 780.0;
        c.wanted.wavelengths = 5;
        c.commit();
        assert!(c.error.is_none());
        assert_eq!((c.applied.range.min, c.applied.range.max, c.applied.wavelengths), (700.0, 780.0, 5));
    }

    #[test]
    fn jitter_offsets_are_stratified() {
        // Every prefix of K offsets puts at most 2 in any of K equal strata and leaves few empty
        // (the recurrence's three-gap property), and all lie in [0, 1).
        for k in [1usize, 2, 3, 5, 8, 13, 16, 100] {
            let mut counts = vec![0; k];
            for i in 0..k as u32 {
                let u = jitter_offset(i);
                assert!((0.0..1.0).contains(&u), "{u}");
                counts[(u * k as f32) as usize] += 1;
            }
            assert!(counts.iter().all(|&c| c <= 2), "K = {k}: {counts:?}");
            assert!(counts.iter().filter(|&&c| c == 0).count() <= k / 3, "K = {k}: {counts:?}");
        }
        assert_eq!(jitter_offset(0), 0.5);
    }

    #[test]
    fn pixel_jitter_covers_the_pixel() {
        assert_eq!(pixel_jitter(0), [0.0, 0.0]);
        // Every prefix of 16 or more frames puts between 1/8 and 3/8 of its samples in each
        // quarter of the pixel, all inside it.
        for k in [16u32, 40, 100, 1000] {
            let mut quarters = [0u32; 4];
            for i in 0..k {
                let [x, y] = pixel_jitter(i);
                assert!((-0.5..0.5).contains(&x) && (-0.5..0.5).contains(&y), "{x}, {y}");
                quarters[usize::from(x >= 0.0) + 2 * usize::from(y >= 0.0)] += 1;
            }
            assert!(quarters.iter().all(|&q| q * 8 >= k && q * 8 <= 3 * k), "{k}: {quarters:?}");
        }
    }

    #[test]
    fn screenshot_paths_do_not_overwrite() {
        let dir = std::env::temp_dir().join(format!("spectra-view-shots-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert_eq!(next_screenshot_path(&dir), dir.join("screenshot-1.png"));
        std::fs::write(dir.join("screenshot-1.png"), b"x").unwrap();
        std::fs::write(dir.join("screenshot-2.png"), b"x").unwrap();
        assert_eq!(next_screenshot_path(&dir), dir.join("screenshot-3.png"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
