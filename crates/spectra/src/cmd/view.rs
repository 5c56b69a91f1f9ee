//! `spectra view`: an interactive window with live controls (mode, N, range, observer,
//! exposure, tone map, accumulation at jittered wavelengths), an orbit/fly camera, a CPU/GPU
//! frame-time readout and screenshots.

use super::setup::{LookArgs, SceneArgs, parse_size};
use crate::view::app::{ViewOptions, run as run_window};
use crate::view::controls::MAX_VIEW_WAVELENGTHS;
use anyhow::{Result, anyhow, bail};
use clap::Args as ClapArgs;
use render::RenderSettings;

/// What to say when there is nowhere to open a window.
pub const NO_DISPLAY: &str = "no window system: set DISPLAY or use `spectra render`";

#[derive(ClapArgs, Debug)]
pub struct Args {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Initial window size WIDTHxHEIGHT (or WIDTHXHEIGHT, WIDTH*HEIGHT; the renderer follows
    /// the window).
    #[arg(long, default_value = "960x640")]
    pub size: String,
    #[command(flatten)]
    pub look: LookArgs,
}

/// The initial settings: arguments first, then the scene's spectral defaults, then the
/// renderer's. Refuses what the viewer cannot show, naming the argument.
pub fn initial_settings(args: &Args, scene: &scene::Scene) -> Result<RenderSettings> {
    if let Some(n) = args.look.wavelengths.filter(|n| !(1..=MAX_VIEW_WAVELENGTHS).contains(n)) {
        bail!("--wavelengths {n}: the viewer shows 1 to {MAX_VIEW_WAVELENGTHS} wavelengths");
    }
    let s = args.look.settings(scene, true, true)?;
    if !(1..=MAX_VIEW_WAVELENGTHS).contains(&s.wavelengths) {
        bail!(
            "scene {}: {} wavelengths; the viewer shows 1 to {MAX_VIEW_WAVELENGTHS} (give --wavelengths)",
            scene.source,
            s.wavelengths
        );
    }
    Ok(s)
}

/// Whether an X11 display is named (the only window system this build of winit speaks).
fn display_named(display: Option<std::ffi::OsString>) -> bool {
    display.is_some_and(|d| !d.is_empty())
}

pub fn run(args: Args) -> Result<()> {
    let size = parse_size(&args.size)?;
    let scene = args.scene.load(args.look.water.water.as_deref())?;
    let settings = initial_settings(&args, &scene)?;
    // Bad water is refused before looking for a display (the media are built after it).
    args.look.water.medium(&scene)?;
    if !display_named(std::env::var_os("DISPLAY")) {
        bail!("{NO_DISPLAY}");
    }
    // The event loop connects to the X server; a named but unreachable display fails here.
    let event_loop = winit::event_loop::EventLoop::new().map_err(|e| anyhow!("{NO_DISPLAY} ({e})"))?;
    let table = args.look.table.load()?;
    let super::setup::RealtimeMedia { water, water_options, rgb: medium } =
        args.look.media(&scene, &table)?;
    run_window(event_loop, ViewOptions { scene, settings, size, table, water, water_options, medium })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use render::{Mode, Tonemap};

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    fn parse(argv: &[&str]) -> Result<RenderSettings> {
        let mut full = vec!["view"];
        full.extend_from_slice(argv);
        let args = Cli::try_parse_from(full).map_err(|e| anyhow!("{e}"))?.args;
        let scene = scene::load_any(&args.scene.scene)?;
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

    /// `--mode`/`--tonemap` take the library's names and aliases in any case (clap
    /// `ValueEnum`s over `Mode::ALL`/`Tonemap::ALL`); `--white` reaches the settings, else the
    /// scene's white does.
    #[test]
    fn enum_spellings_and_the_white() {
        let s = parse(&["cornell", "--mode", "JH", "--tonemap", "Clamp", "--white", "D50"]).unwrap();
        assert_eq!((s.mode, s.tonemap, s.white.as_str()), (Mode::Spectral, Tonemap::None, "D50"));
        let s = parse(&["cornell", "--mode", "box"]).unwrap();
        assert_eq!((s.mode, s.white.as_str()), (Mode::Naive, scene::DEFAULT_WHITE));
        for m in Mode::ALL {
            assert_eq!(parse(&["cornell", "--mode", m.name()]).unwrap().mode, m);
        }
        for t in Tonemap::ALL {
            assert_eq!(parse(&["cornell", "--tonemap", t.name()]).unwrap().tonemap, t);
        }
        let e = format!("{:#}", parse(&["cornell", "--mode", "hsv"]).unwrap_err());
        assert!(e.contains("hsv") && e.contains("rgb, naive, spectral"), "{e}");
        let e = format!("{:#}", parse(&["cornell", "--white", "1K"]).unwrap_err());
        assert!(e.contains("--white '1K'") && e.contains("500–1000000 K"), "{e}");
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
