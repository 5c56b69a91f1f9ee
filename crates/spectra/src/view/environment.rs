//! The viewer's environment panel: pick the environment (the scene's own, none, the default
//! sky, or an HDR shipped in `assets/environments/`), turn it about +Y and scale it. Picking
//! prefilters the new map (a fraction of a second); rotation and intensity are per frame.

use std::path::{Path, PathBuf};

/// One entry of the picker.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvSource {
    /// What the scene came with (after `--env`).
    Scene,
    None,
    Default,
    File(PathBuf),
}

impl EnvSource {
    pub fn label(&self) -> String {
        match self {
            EnvSource::Scene => "scene's".into(),
            EnvSource::None => "none".into(),
            EnvSource::Default => "default sky".into(),
            EnvSource::File(p) => {
                p.file_stem().map_or_else(|| p.display().to_string(), |s| s.to_string_lossy().into())
            }
        }
    }
}

/// The HDR environments in `assets/environments/` next to the working directory or above the
/// executable (a repository checkout), sorted by name.
pub fn shipped() -> Vec<PathBuf> {
    let mut dirs = vec![
        PathBuf::from("assets/environments"),
        PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/environments")),
    ];
    if let Ok(exe) = std::env::current_exe() {
        // target/{debug,release}/spectra → the checkout's root.
        if let Some(root) = exe.parent().and_then(Path::parent).and_then(Path::parent) {
            dirs.push(root.join("assets/environments"));
        }
    }
    for d in dirs {
        let Ok(rd) = std::fs::read_dir(&d) else { continue };
        let mut files: Vec<PathBuf> = rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| {
                p.extension()
                    .and_then(|e| e.to_str())
                    .is_some_and(|e| matches!(e.to_ascii_lowercase().as_str(), "hdr" | "exr"))
            })
            .collect();
        if !files.is_empty() {
            files.sort();
            return files;
        }
    }
    Vec::new()
}

/// Panel state.
pub struct EnvControls {
    pub options: Vec<EnvSource>,
    pub wanted: usize,
    pub applied: usize,
    /// Degrees about +Y.
    pub rotation: f32,
    pub intensity: f32,
    pub error: Option<String>,
    /// The scene's own environment, to go back to.
    scene_env: Option<scene::Environment>,
}

impl EnvControls {
    pub fn new(scene_env: Option<scene::Environment>) -> Self {
        let mut options = vec![EnvSource::Scene, EnvSource::None, EnvSource::Default];
        options.extend(shipped().into_iter().map(EnvSource::File));
        let (rotation, intensity) =
            scene_env.as_ref().map_or((0.0, 1.0), |e| (e.rotation.to_degrees(), e.intensity));
        EnvControls { options, wanted: 0, applied: 0, rotation, intensity, error: None, scene_env }
    }

    /// The environment the picker's current choice names (intensity and rotation not applied).
    pub fn load(&self, i: usize) -> anyhow::Result<Option<scene::Environment>> {
        Ok(match &self.options[i] {
            EnvSource::Scene => self.scene_env.clone(),
            EnvSource::None => None,
            EnvSource::Default => Some(scene::Environment::default_sky()),
            EnvSource::File(p) => Some(scene::Environment::load(p)?),
        })
    }

    pub fn ui(&mut self, ui: &mut egui::Ui) {
        let label = self.options[self.wanted].label();
        egui::ComboBox::from_label("environment").selected_text(label).show_ui(ui, |ui| {
            for (i, o) in self.options.iter().enumerate() {
                ui.selectable_value(&mut self.wanted, i, o.label());
            }
        });
        ui.add(egui::Slider::new(&mut self.rotation, 0.0..=360.0).text("env rotation °"));
        ui.add(egui::Slider::new(&mut self.intensity, 0.0..=16.0).logarithmic(true).text("env intensity"));
        if let Some(e) = &self.error {
            ui.colored_label(egui::Color32::from_rgb(255, 110, 90), e);
        }
    }

    /// Applies the panel to the renderer; returns whether anything changed on screen.
    pub fn apply(&mut self, renderer: &mut render::Renderer) -> bool {
        let mut changed = false;
        if self.wanted != self.applied {
            match self.load(self.wanted) {
                Ok(env) => {
                    renderer.set_environment(env.as_ref());
                    self.applied = self.wanted;
                    self.error = None;
                    changed = true;
                }
                Err(e) => {
                    self.error = Some(format!("{e:#}"));
                    self.wanted = self.applied;
                }
            }
        }
        let (k, r) = (self.intensity, self.rotation.to_radians());
        if let Some(e) = renderer.environment()
            && (e.intensity != k || e.rotation != r)
        {
            renderer.set_environment_transform(k, r);
            changed = true;
        }
        changed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_picker_lists_the_shipped_environments_and_loads_them() {
        let c = EnvControls::new(None);
        assert!(c.options.len() > 3, "no assets/environments found from {:?}", std::env::current_dir());
        for i in 0..c.options.len() {
            let env = c.load(i).unwrap_or_else(|e| panic!("{:?}: {e:#}", c.options[i]));
            assert_eq!(env.is_some(), !matches!(c.options[i], EnvSource::Scene | EnvSource::None));
        }
    }
}
