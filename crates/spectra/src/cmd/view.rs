//! `spectra view`: an interactive window with live controls (mode, N, range, observer,
//! exposure, tone map, accumulation at jittered wavelengths), an orbit/fly camera, a CPU/GPU
//! frame-time readout and screenshots.

use crate::cmd::render::{LookArgs, load_table, parse_size};
use crate::view::app::{ViewOptions, run as run_window};
use crate::view::controls::MAX_VIEW_WAVELENGTHS;
use anyhow::{Context, Result, anyhow, bail};
use clap::Args as ClapArgs;
use render::{Mode, RenderSettings, Tonemap};

/// What to say when there is nowhere to open a window.
pub const NO_DISPLAY: &str = "no window system: set DISPLAY or use `spectra render`";

#[derive(ClapArgs, Debug)]
pub struct Args {
    /// Built-in scene name (cornell, colorchecker, metamerism, underwater, fog, tinted-fog) or a .gltf/.glb file.
    pub scene: String,
    #[command(flatten)]
    pub files: super::SceneFileArgs,
    /// Initial window size WIDTHxHEIGHT (the renderer follows the window).
    #[arg(long, default_value = "960x640")]
    pub size: String,
    #[command(flatten)]
    pub look: LookArgs,
}

/// The initial settings: arguments first, then the scene's spectral defaults, then the
/// renderer's. Refuses what the viewer cannot show, naming the argument.
pub fn initial_settings(args: &Args, scene: &scene::Scene) -> Result<RenderSettings> {
    let (range, wavelengths, observer) = args.look.spectral(scene)?;
    if !(1..=MAX_VIEW_WAVELENGTHS).contains(&wavelengths) {
        bail!("--wavelengths {wavelengths}: the viewer shows 1 to {MAX_VIEW_WAVELENGTHS} wavelengths");
    }
    color::Observer::by_name(&observer).with_context(|| format!("--observer '{observer}'"))?;
    let s = RenderSettings {
        mode: Mode::parse(&args.look.mode).context("--mode")?,
        wavelengths,
        range,
        observer,
        white: scene.spectral.white_name().into(),
        exposure_ev: args.look.exposure,
        tonemap: Tonemap::parse(&args.look.tonemap).context("--tonemap")?,
        shadows: true,
        timestamps: true,
        jitter: None,
        quadrature: args.look.quadrature,
        lambert: args.look.lambert,
        env_occlusion: !args.look.no_env_occlusion,
    };
    s.validate().map_err(|e| anyhow!("{e}"))?;
    Ok(s)
}

/// Whether an X11 display is named (the only window system this build of winit speaks).
fn display_named(display: Option<std::ffi::OsString>) -> bool {
    display.is_some_and(|d| !d.is_empty())
}

pub fn run(args: Args) -> Result<()> {
    let size = parse_size(&args.size)?;
    let mut scene = args.files.load(&args.scene)?;
    super::print_warnings(&scene);
    args.look.env.apply(&mut scene)?;
    let settings = initial_settings(&args, &scene)?;
    let water = super::render::water_medium(&scene, args.look.water.as_deref(), args.look.depth)?;
    let water_options = args.look.underwater()?;
    if !display_named(std::env::var_os("DISPLAY")) {
        bail!("{NO_DISPLAY}");
    }
    // The event loop connects to the X server; a named but unreachable display fails here.
    let event_loop = winit::event_loop::EventLoop::new().map_err(|e| anyhow!("{NO_DISPLAY} ({e})"))?;
    let table = load_table(args.look.table.as_deref())?;
    let medium = super::realtime_medium(
        &scene,
        args.look.rgb_medium.as_deref(),
        water.is_some(),
        &table,
        args.look.rgb_medium_options(),
    )?;
    run_window(event_loop, ViewOptions { scene, settings, size, table, water, water_options, medium })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn parse(argv: &[&str]) -> Result<RenderSettings> {
        let mut full = vec!["view"];
        full.extend_from_slice(argv);
        let args = Cli::try_parse_from(full).map_err(|e| anyhow!("{e}"))?.args;
        let scene = scene::load_any(&args.scene)?;
        initial_settings(&args, &scene)
    }

    #[test]
    fn arguments_become_settings() {
        let s = parse(&["cornell", "--mode", "rgb", "--wavelengths", "8", "--range", "400:700"]).unwrap();
        assert_eq!((s.mode, s.wavelengths, s.range.min, s.range.max), (Mode::Rgb, 8, 400.0, 700.0));
        let s =
            parse(&["cornell", "--observer", "cie1964", "--exposure", "-1.5", "--tonemap", "aces"]).unwrap();
        assert_eq!((s.observer.as_str(), s.exposure_ev, s.tonemap), ("cie1964", -1.5, Tonemap::Aces));
        assert!(s.timestamps, "the viewer always asks for GPU timings");
    }

    #[test]
    fn bad_arguments_are_named() {
        let e = |argv: &[&str]| format!("{:#}", parse(argv).unwrap_err());
        assert!(e(&["cornell", "--wavelengths", "65"]).contains("--wavelengths 65"));
        assert!(e(&["cornell", "--wavelengths", "0"]).contains("1 to 64"));
        assert!(e(&["cornell", "--mode", "hsv"]).contains("hsv"));
        assert!(e(&["cornell", "--range", "700:400"]).contains("--range"));
        assert!(e(&["cornell", "--observer", "cat"]).contains("cat"));
        assert!(e(&["cornell", "--tonemap", "filmic"]).contains("filmic"));
        assert!(e(&["no-such-scene"]).contains("no-such-scene"));
    }

    #[test]
    fn display_detection() {
        assert!(!display_named(None));
        assert!(!display_named(Some("".into())));
        assert!(display_named(Some(":99".into())));
    }
}
