//! The viewer's live underwater settings: Jerlov type, camera depth and the real-time model's
//! options, edited in the panel and applied to the renderer without restarting.
//!
//! Depth and the numeric options are shader parameters (`Renderer::set_custom_params`, no
//! recompilation); the water type (new coefficient spectra) and switching the march or the
//! surface on or off (compile-time constants of the hooks) rebuild the shading pipelines.

use render::passes::underwater::{self, MAX_STEPS, Options};
use scene::water::WaterMedium;

/// What the panel edits.
#[derive(Clone, Debug, PartialEq)]
pub struct WaterControls {
    /// One of [`color::water::WaterType::ORDER`].
    pub water_type: String,
    /// Camera depth, metres.
    pub depth: f32,
    pub options: Options,
}

/// Deepest camera the slider offers, metres (beyond it every type is black).
pub const MAX_DEPTH: f32 = 60.0;

impl WaterControls {
    /// The controls for the water the viewer was started with.
    pub fn new(medium: &WaterMedium, options: Options) -> Self {
        let water_type = medium.water_type.map_or_else(|| "II".to_string(), |t| t.to_string());
        WaterControls { water_type, depth: medium.depth as f32, options }
    }

    /// The medium these controls describe: `base` (sun, scale, sky, sea floor) with this type
    /// and depth. The floor keeps its distance below the camera: a depth change moves the
    /// surface, not the scene.
    pub fn medium(&self, base: &WaterMedium) -> Result<WaterMedium, scene::water::WaterError> {
        let ty = color::water::WaterType::parse(&self.water_type)?;
        let mut m = WaterMedium::new(ty, self.depth as f64, base.sun_dir, base.scale)?;
        m.sky = base.sky;
        m.floor = base.floor.clone();
        Ok(m)
    }

    /// Deepest depth of the light-field table these controls need: the floor's depth when the
    /// column is closed by one, else the rounded range.
    fn table_depth(&self, base: &WaterMedium) -> f64 {
        match &base.floor {
            Some(f) if self.options.sea_floor => self.depth as f64 + f.below_camera,
            _ => underwater::light_field_range(self.depth as f64),
        }
    }

    /// Whether going from `applied` to `self` needs new pipelines (not just new parameters).
    pub fn needs_recompile(&self, applied: &WaterControls, base: &WaterMedium) -> bool {
        self.water_type != applied.water_type
            || (self.options.steps > 0) != (applied.options.steps > 0)
            || self.options.surface != applied.options.surface
            || self.options.light_field != applied.options.light_field
            || self.options.tabulated_kd != applied.options.tabulated_kd
            || self.options.irradiance != applied.options.irradiance
            || self.options.forward_cone_deg != applied.options.forward_cone_deg
            // The light-field table depends on g, the floor and the depth range it covers.
            || (self.options.light_field
                && (self.options.phase_g != applied.options.phase_g
                    || self.options.sea_floor != applied.options.sea_floor
                    || self.table_depth(base) != applied.table_depth(base)))
    }

    /// Applies `self` to `renderer`, coming from `applied`.
    pub fn apply(
        &self,
        applied: &WaterControls,
        base: &WaterMedium,
        renderer: &mut render::Renderer,
    ) -> anyhow::Result<()> {
        let medium = self.medium(base)?;
        self.options.validate().map_err(|e| anyhow::anyhow!(e))?;
        if self.needs_recompile(applied, base) {
            renderer.set_custom_shader(underwater::shader_with(&medium, &self.options)?)?;
        } else {
            renderer.set_custom_params(underwater::params_with(&medium, &self.options));
        }
        Ok(())
    }

    /// The panel section.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        egui::ComboBox::from_label("Jerlov type").selected_text(self.water_type.clone()).show_ui(ui, |ui| {
            for t in color::water::WaterType::ORDER {
                ui.selectable_value(&mut self.water_type, t.to_string(), t);
            }
        });
        ui.add(egui::Slider::new(&mut self.depth, 0.0..=MAX_DEPTH).step_by(0.5).text("depth m"));
        let o = &mut self.options;
        ui.checkbox(&mut o.light_field, "light-field source (off: the paper's isotropic term)");
        ui.add_enabled(o.light_field, egui::Checkbox::new(&mut o.tabulated_kd, "tabulated Kd on surfaces"));
        ui.add_enabled(
            o.light_field && !o.tabulated_kd,
            egui::Checkbox::new(&mut o.irradiance, "surfaces lit by the column's irradiance"),
        );
        ui.add_enabled(
            o.light_field,
            egui::Slider::new(&mut o.forward_cone_deg, 0.0..=45.0).step_by(1.0).text("forward cone °"),
        );
        ui.add_enabled(o.light_field, egui::Checkbox::new(&mut o.sea_floor, "sea floor lights the water"));
        ui.add(egui::Slider::new(&mut o.steps, 0..=MAX_STEPS).text("march steps (0 = off)"));
        ui.add_enabled(o.steps > 0, egui::Slider::new(&mut o.phase_g, 0.0..=0.99).text("phase g"));
        ui.add_enabled(o.steps > 0, egui::Checkbox::new(&mut o.split_beams, "split sun beams out of L_ms"));
        ui.checkbox(&mut o.scalar_irradiance, "scalar irradiance (Gershun)");
        ui.checkbox(&mut o.surface, "surface from below");
        if ui.button("paper's model").clicked() {
            *o = Options::paper();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn base() -> WaterMedium {
        WaterMedium::new(color::water::WaterType::parse("IB").unwrap(), 10.0, Vec3::new(0.3, 1.0, 0.2), 0.5)
            .unwrap()
    }

    #[test]
    fn only_type_and_compiled_switches_recompile() {
        let a = WaterControls::new(&base(), Options::isotropic());
        assert_eq!((a.water_type.as_str(), a.depth), ("IB", 10.0));
        // The light-field table is compiled in: its g and depth range recompile, a depth
        // within the same range does not.
        let lf = WaterControls::new(&base(), Options::default());
        let mut e = lf.clone();
        e.depth = 3.0;
        assert!(!e.needs_recompile(&lf, &base()), "same table range");
        e.depth = 30.0;
        assert!(e.needs_recompile(&lf, &base()), "deeper table");
        let mut e = lf.clone();
        e.options.phase_g = 0.5;
        assert!(e.needs_recompile(&lf, &base()), "the table depends on g");
        assert!(a.needs_recompile(&lf, &base()), "light field on/off");
        // With a sea floor the table ends at the floor, so any depth change recompiles.
        let mut floored = base();
        floored.floor = Some(scene::water::floor::SeaFloor {
            below_camera: 1.2,
            rgb: [0.4; 3],
            albedo: color::Spectrum::Constant(0.4),
            extent: None,
        });
        let mut e = lf.clone();
        e.depth = 10.5;
        assert!(e.needs_recompile(&lf, &floored) && !e.needs_recompile(&lf, &base()));
        assert_eq!(e.medium(&floored).unwrap().floor, floored.floor, "the floor follows the camera");
        let mut b = a.clone();
        b.depth = 3.0;
        b.options.steps = 8;
        b.options.phase_g = 0.5;
        b.options.split_beams = true;
        assert!(!b.needs_recompile(&a, &base()), "parameters only");
        b.options.steps = 0;
        assert!(b.needs_recompile(&a, &base()), "march off is compiled");
        let mut c = a.clone();
        c.options.surface = true;
        assert!(c.needs_recompile(&a, &base()));
        let mut d = a.clone();
        d.water_type = "3C".into();
        assert!(d.needs_recompile(&a, &base()));
        let m = d.medium(&base()).unwrap();
        assert_eq!((m.water_type.unwrap().to_string(), m.depth, m.scale), ("3C".to_string(), 10.0, 0.5));
        assert_eq!(m.sun_dir, base().sun_dir);
    }

    /// Editing in place (parameters only, or new pipelines) must give exactly the image a fresh
    /// shader for the edited water gives. Needs an adapter (lavapipe in CI).
    #[test]
    fn applied_edits_render_like_a_fresh_shader() {
        let scene = scene::builtin("underwater").unwrap();
        let settings = render::RenderSettings { wavelengths: 8, ..Default::default() };
        let base = WaterMedium::from_settings(scene.water.as_ref().unwrap()).unwrap();
        let render = |r: &mut render::Renderer| {
            r.render(&scene.camera, &settings).unwrap();
            r.read_hdr().unwrap()
        };
        let mut r = render::Renderer::new().expect("a GPU adapter (apt-get install mesa-vulkan-drivers)");
        r.set_scene(&scene).unwrap();
        r.resize(32, 24).unwrap();
        let start = WaterControls::new(&base, Options::default());
        r.set_custom_shader(underwater::shader_with(&base, &start.options).unwrap()).unwrap();
        let before = render(&mut r);
        let mut edits = vec![];
        let mut e = start.clone();
        e.depth = 4.0;
        e.options.phase_g = 0.6;
        edits.push(e.clone());
        e.water_type = "3C".into();
        e.options.surface = true;
        edits.push(e.clone());
        let mut applied = start;
        for edit in edits {
            edit.apply(&applied, &base, &mut r).unwrap();
            let got = render(&mut r);
            assert_ne!(got, before, "{edit:?} changed nothing");
            let mut fresh = render::Renderer::new().unwrap();
            fresh.set_scene(&scene).unwrap();
            fresh.resize(32, 24).unwrap();
            fresh
                .set_custom_shader(
                    underwater::shader_with(&edit.medium(&base).unwrap(), &edit.options).unwrap(),
                )
                .unwrap();
            assert_eq!(got, render(&mut fresh), "{edit:?}");
            applied = edit;
        }
    }
}
