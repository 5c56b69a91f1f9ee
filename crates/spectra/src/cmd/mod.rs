//! Subcommands, one file each.

pub mod bench;
pub mod demo;
pub mod diff;
pub mod eval;
pub mod lut;
pub mod render;
pub mod truth;
pub mod upsample;
pub mod view;

/// Checks before the work that the output `path` given with `flag` can be written (its
/// directory exists and takes new files), so a long render never ends in "directory does not
/// exist".
pub fn check_output(flag: &str, path: &std::path::Path) -> anyhow::Result<()> {
    color::outfile::check_writable(path).map_err(|e| anyhow::anyhow!("{flag} {}: {e}", path.display()))
}

/// Prints what the loader skipped or approximated, one `warning: <scene>: <text>` line each on
/// stderr (unsupported optional glTF extensions, points and lines, …).
pub fn print_warnings(scene: &scene::Scene) {
    for w in &scene.warnings {
        eprintln!("warning: {}: {w}", scene.source);
    }
}

/// `--rgb-medium`: inline JSON (starting with `{`) or a file holding it (`render`, `view`,
/// `bench`, `truth`).
pub fn rgb_medium_arg(arg: &str) -> anyhow::Result<scene::medium::RgbMedium> {
    use anyhow::Context;
    let (text, origin) = if arg.trim_start().starts_with('{') {
        (arg.to_string(), "--rgb-medium".to_string())
    } else {
        let p = std::path::Path::new(arg);
        let t = color::input::read_regular_string(p, ::truth::medium_file::MAX_MEDIUM_FILE_BYTES)
            .with_context(|| format!("--rgb-medium {arg}: cannot read"))?;
        (t, format!("--rgb-medium {arg}"))
    };
    scene::medium::RgbMedium::from_json_str(&text).map_err(|e| anyhow::anyhow!("{origin}: {e}"))
}

/// The real-time renderer's RGB medium: `--rgb-medium`, else the scene's `extras.medium`;
/// with water (which is a medium of its own) it is an error, as for `spectra truth`. As a
/// custom shader with `opts`, upsampled through `table`.
pub fn realtime_medium(
    scene: &scene::Scene,
    arg: Option<&str>,
    water: bool,
    table: &color::upsample::CoeffTable,
    opts: ::render::passes::rgb_medium::Options,
) -> anyhow::Result<Option<::render::CustomShader>> {
    let m = match (arg, &scene.medium) {
        (Some(a), _) => rgb_medium_arg(a)?,
        (None, Some(m)) => m.clone(),
        (None, None) => return Ok(None),
    };
    if water {
        anyhow::bail!(
            "--rgb-medium / the scene's medium and water (from --water or the scene) cannot be combined: pick one medium"
        );
    }
    Ok(Some(::render::passes::rgb_medium::shader(&m, table, &opts)?))
}

/// How a scene file is loaded, shared by every command that takes a scene (`render`, `view`,
/// `truth`, `bench`).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct SceneFileArgs {
    /// Let the scene's file references (buffers, images, CSV spectra, environment maps) leave
    /// its folder: absolute paths, `..`, symlinks to elsewhere. Off by default so that a scene
    /// from elsewhere cannot read your other files (docs/scene-format.md, "File references").
    #[arg(long)]
    pub allow_outside_scene_dir: bool,
}

impl SceneFileArgs {
    /// Loads a built-in scene or a .gltf/.glb file, with these options.
    pub fn load(&self, name: &str) -> anyhow::Result<scene::Scene> {
        use anyhow::Context;
        let opts = scene::LoadOptions { allow_outside_scene_dir: self.allow_outside_scene_dir };
        scene::load_any_with(name, &opts).with_context(|| format!("loading scene '{name}'"))
    }
}

/// The environment light on the command line, shared by `render`, `view` and `truth`.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct EnvArgs {
    /// Environment light: an equirectangular .hdr or .exr of linear radiance, `default` (a
    /// uniform white D65 sky over a grey ground) or `none`. Default: the scene's own
    /// (extras.environment), else the default environment when the scene has no lights at all.
    #[arg(long, value_name = "FILE|default|none")]
    pub env: Option<String>,
    /// Multiplies the environment's radiance.
    #[arg(long, value_name = "K")]
    pub env_intensity: Option<f32>,
    /// Turns the environment about +Y, degrees.
    #[arg(long, value_name = "DEGREES", allow_negative_numbers = true)]
    pub env_rotation: Option<f32>,
}

impl EnvArgs {
    /// Sets the scene's environment as asked; prints the note (default environment chosen) or
    /// warning (nothing lights the scene) on stderr.
    pub fn apply(&self, scene: &mut scene::Scene) -> anyhow::Result<()> {
        let choice = scene::environment::EnvironmentChoice {
            env: self.env.clone(),
            intensity: self.env_intensity,
            rotation: self.env_rotation,
        };
        if let Some(note) = choice.apply(scene)? {
            eprintln!("{note}");
        }
        Ok(())
    }
}

#[cfg(test)]
mod rgb_medium_tests {
    use super::realtime_medium;
    use render::passes::rgb_medium::Options;

    /// `render`/`view`/`bench` take the medium from `--rgb-medium` or the scene, refuse it with
    /// water, and name the flag in every error.
    #[test]
    fn realtime_rgb_medium_comes_from_the_flag_or_the_scene() {
        let table = color::upsample::table("srgb").unwrap();
        let fog = scene::builtin("fog").unwrap();
        let cornell = scene::builtin("cornell").unwrap();
        assert!(realtime_medium(&cornell, None, false, &table, Default::default()).unwrap().is_none());
        let s = realtime_medium(&fog, None, false, &table, Default::default())
            .unwrap()
            .expect("the scene's medium");
        assert_eq!(s.params[0], 16.0);
        let m = r#"{"absorption": [0.5, 0.2, 0.1], "g": 0.5}"#;
        let s = realtime_medium(&cornell, Some(m), false, &table, Options { steps: 8, multiple: true })
            .unwrap()
            .expect("the flag's medium");
        assert_eq!((s.params[0], s.params[1], &s.params[8..11]), (8.0, 0.5, &[0.5f32, 0.2, 0.1][..]));
        let e = |scene: &scene::Scene, arg: Option<&str>, water: bool, steps: u32| {
            format!(
                "{:#}",
                realtime_medium(scene, arg, water, &table, Options { steps, ..Default::default() })
                    .unwrap_err()
            )
        };
        let msg = e(&fog, None, true, 16);
        assert!(msg.contains("--rgb-medium") && msg.contains("water"), "{msg}");
        let msg = e(&cornell, Some(r#"{"absorption": [0.5, 0.2, 0.1], "g": 1}"#), false, 16);
        assert!(msg.contains("--rgb-medium") && msg.contains("g:"), "{msg}");
        let msg = e(&cornell, Some("no-such-medium.json"), false, 16);
        assert!(msg.contains("--rgb-medium no-such-medium.json"), "{msg}");
        let msg = e(&cornell, Some(m), false, 33);
        assert!(msg.contains("march steps") && msg.contains("33"), "{msg}");
    }
}
