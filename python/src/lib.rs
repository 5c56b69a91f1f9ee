//! `spectra._spectra`: the Python extension module behind the `spectra` package (PyO3).
//!
//! Scenes, settings and media are resolved by the command line's own code (the `spectra`
//! crate's library, `spectra::cmd::setup`), so a render or a truth from Python is the CLI's
//! with the same options; `spectra.distributed.eval` runs the CLI's evaluation
//! (`spectra::eval`). Long work (loading, rendering,
//! path tracing, statistics) runs with the GIL released. Errors carry the Rust error's message
//! (its whole chain on one line, as the CLI prints it): bad values raise `ValueError`, a missing
//! file `FileNotFoundError`, failures of the work itself `RuntimeError`.

use anyhow::Context;
use numpy::{PyArray1, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyFileNotFoundError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};

/// The CLI's scene, spectrum, water, medium and table options.
use spectra::cmd::setup;

mod args;

/// Why a call failed, carried out of a GIL-free section and raised as the matching exception.
enum Fail {
    /// A bad argument or scene: `ValueError` (or `FileNotFoundError` for a missing file).
    Value(anyhow::Error),
    /// The work itself failed (GPU, tracer): `RuntimeError`.
    Runtime(anyhow::Error),
    /// A Python exception (KeyboardInterrupt from a signal).
    Py(PyErr),
}

impl From<Fail> for PyErr {
    fn from(f: Fail) -> PyErr {
        match f {
            Fail::Value(e) => {
                // The crates below often keep an I/O error only as text (a message naming the
                // file and the field); ENOENT reads "(os error 2)" there on every platform.
                let missing = e.chain().any(|c| {
                    c.downcast_ref::<std::io::Error>()
                        .is_some_and(|io| io.kind() == std::io::ErrorKind::NotFound)
                }) || format!("{e:#}").contains("(os error 2)");
                if missing {
                    PyFileNotFoundError::new_err(format!("{e:#}"))
                } else {
                    PyValueError::new_err(format!("{e:#}"))
                }
            }
            Fail::Runtime(e) => PyRuntimeError::new_err(format!("{e:#}")),
            Fail::Py(e) => e,
        }
    }
}

/// `Fail::Value` for any error that converts to anyhow's.
fn value<E: Into<anyhow::Error>>(e: E) -> Fail {
    Fail::Value(e.into())
}

/// `Fail::Runtime` for any error that converts to anyhow's.
fn runtime<E: Into<anyhow::Error>>(e: E) -> Fail {
    Fail::Runtime(e.into())
}

/// A whole number ≥ `min` that fits a u32, or a `ValueError` naming `what`.
fn whole(what: &str, v: i128, min: i128) -> PyResult<u32> {
    if v < min || v > i128::from(u32::MAX) {
        return Err(PyValueError::new_err(format!(
            "{what} {v}: must be a whole number from {min} to {}",
            u32::MAX
        )));
    }
    Ok(v as u32)
}

/// `size=(W, H)`: both positive.
fn size_arg(size: (i128, i128)) -> PyResult<(u32, u32)> {
    let (w, h) = size;
    if w <= 0 || h <= 0 || w > i128::from(u32::MAX) || h > i128::from(u32::MAX) {
        return Err(PyValueError::new_err(format!(
            "size ({w}, {h}): width and height must be positive integers"
        )));
    }
    Ok((w as u32, h as u32))
}

/// `range=(MIN, MAX)` as the CLI's `--range MIN:MAX`.
/// An invalid range is refused here, naming `range` and its values in short (the CLI's message
/// spelt 1e-300 with 300 digits); a valid one is spelt so that it parses back exactly.
fn range_arg(range: Option<(f64, f64)>) -> PyResult<Option<String>> {
    let Some((a, b)) = range else { return Ok(None) };
    let (sa, sb) = (args::short(a), args::short(b));
    if let Err(color::ColorError::BadRange { why, .. }) = color::WavelengthRange::new(a, b) {
        return Err(PyValueError::new_err(format!("range ({sa}, {sb}): {why}")));
    }
    Ok(Some(format!("{sa}:{sb}")))
}

/// A linear RGB image as a C-contiguous float32 array of shape (height, width, 3).
fn rgb_array<'py>(
    py: Python<'py>,
    width: u32,
    height: u32,
    data: Vec<f32>,
) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
    PyArray1::from_vec(py, data).reshape([height as usize, width as usize, 3])
}

/// A scene: a built-in or a glTF file, loaded with the loader's checks, the CLI's default
/// environment applied (a scene without lights gets the default sky).
#[pyclass(frozen, module = "spectra")]
struct Scene {
    inner: Arc<scene::Scene>,
    /// Whether `load` chose the environment because the scene has no lights (no `env` given):
    /// rendered under water such a scene gets a sun instead, as `spectra render --water` and
    /// `spectra truth --water` choose (`EnvironmentChoice::under_water`).
    auto_env: bool,
    /// The scene as chosen for a render under water, made on first use (`auto_env` only).
    wet: std::sync::OnceLock<Arc<scene::Scene>>,
    /// `load`'s arguments, so that a pickled scene (a Ray task's argument) loads again where it
    /// is unpickled: the name or path, then the options in `load`'s order.
    how: LoadArgs,
}

/// `load`'s arguments, as given.
#[derive(Clone)]
struct LoadArgs {
    name: String,
    allow_outside_scene_dir: bool,
    variant: Option<String>,
    animation: Option<scene::AnimationRef>,
    time: Option<f64>,
    env: Option<String>,
    env_intensity: Option<f32>,
    env_rotation: Option<f32>,
    env_sun: bool,
    env_sun_share: Option<f32>,
}

impl Scene {
    /// The scene as `spectra render` / `truth` would have loaded it with or without `--water`:
    /// only a scene whose environment `load` chose (it has no lights) differs, getting the
    /// underwater sun in place of the default sky.
    fn chosen_for(&self, under_water: bool) -> PyResult<Arc<scene::Scene>> {
        if !under_water || !self.auto_env {
            return Ok(self.inner.clone());
        }
        if let Some(s) = self.wet.get() {
            return Ok(s.clone());
        }
        let mut s = (*self.inner).clone();
        s.environment = None;
        let env = setup::EnvArgs {
            env: None,
            env_intensity: self.how.env_intensity,
            env_rotation: self.how.env_rotation,
            no_env_sun: !self.how.env_sun,
            env_sun_share: self.how.env_sun_share,
        };
        env.apply(&mut s, true).map_err(|e| PyErr::from(value(e)))?;
        Ok(self.wet.get_or_init(|| Arc::new(s)).clone())
    }
}

#[pymethods]
impl Scene {
    /// Where the scene came from: a path, or `builtin:NAME`.
    #[getter]
    fn source(&self) -> String {
        self.inner.source.clone()
    }

    /// What the loader skipped or approximated (also printed on stderr when loading).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings.clone()
    }

    /// How many lights the scene has (stand-ins included).
    #[getter]
    fn lights(&self) -> usize {
        self.inner.lights.len()
    }

    /// The end of the animation the scene is posed by (its last key, in seconds); `None` at
    /// rest. A sequence is `[spectra.load(f, animation=a, time=t) for t in ...]` up to it.
    #[getter]
    fn animation_end(&self) -> Option<f64> {
        self.inner.animation_end
    }

    /// Pickled as `spectra.load` with the same arguments: unpickling loads the scene again (a
    /// file must be reachable at the same path there, e.g. on every node of a Ray cluster).
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, pyo3::types::PyTuple>)> {
        let load = py.import("spectra")?.getattr("_load_cached")?;
        let h = &self.how;
        // An index stays an int, a name a str: what `load` was given.
        let animation: Option<Bound<'py, PyAny>> = match &h.animation {
            None => None,
            Some(scene::AnimationRef::Index(i)) => Some(i.into_pyobject(py)?.into_any()),
            Some(scene::AnimationRef::NameOrIndex(a)) => Some(a.into_pyobject(py)?.into_any()),
        };
        let args = (
            h.name.clone(),
            h.allow_outside_scene_dir,
            h.env.clone(),
            h.env_intensity,
            h.env_rotation,
            h.env_sun,
            h.env_sun_share,
            h.variant.clone(),
            animation,
            h.time,
        )
            .into_pyobject(py)?;
        Ok((load, args))
    }

    fn __repr__(&self) -> String {
        format!(
            "<spectra.Scene {} ({} meshes, {} lights)>",
            self.inner.source,
            self.inner.meshes.len(),
            self.inner.lights.len()
        )
    }
}

/// The scene `obj` (a `Scene`) as chosen for a render in water when `under_water` (the
/// `water` argument was given), or a `TypeError`.
fn scene_of(obj: &Bound<'_, PyAny>, what: &str, under_water: bool) -> PyResult<Arc<scene::Scene>> {
    match obj.extract::<PyRef<'_, Scene>>() {
        Ok(s) => s.chosen_for(under_water),
        Err(_) => Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "{what} must be a spectra.Scene (from spectra.load), not {}",
            obj.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "that".into())
        ))),
    }
}

/// Loads a built-in scene by name (cornell, colorchecker, metamerism, iridescence, glass,
/// clearcoat, specular, sheen, anisotropy, translucent, underwater, fog, tinted-fog) or a .gltf/.glb file, as `spectra render SCENE` does.
///
/// `allow_outside_scene_dir`: let the file's references (buffers, images, spectra,
/// environment maps) leave its folder (off by default, as on the command line).
/// `variant`: the file's KHR_materials_variants variant to draw, by name (`--variant`).
/// `animation`, `time`: pose the file by this animation (a str: its name, else an index; an int:
/// its index) at this moment in
/// seconds (`--animation`, `--time`; a time alone poses the first animation); default: at rest.
/// `env`: the environment light, as `--env`: an equirectangular .hdr/.exr file, "default" (a
/// uniform D65 sky over a grey ground) or "none"; default: the scene's own, else the default
/// environment when the scene has no lights (rendered with `water`, by `Renderer` or `truth`, the
/// underwater sun instead, as `spectra render FILE --water` chooses). `env_intensity` multiplies it, `env_rotation`
/// turns it about +Y (degrees). `env_sun`: light the map's sun, where it has one, in real time
/// as a shadowed directional light (`False`: `--no-env-sun`, the whole map unshadowed);
/// `env_sun_share`: the share of the map's light a compact bright region must give to be that
/// sun, in (0, 1] (`--env-sun-share`; default 0.15).
#[pyfunction]
#[pyo3(signature = (path_or_builtin, allow_outside_scene_dir = false, env = None, env_intensity = None,
                    env_rotation = None, env_sun = true, env_sun_share = None, variant = None,
                    animation = None, time = None))]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments, each its own option
fn load(
    py: Python<'_>,
    #[pyo3(from_py_with = args::path_or_builtin)] path_or_builtin: PathBuf,
    #[pyo3(from_py_with = args::allow_outside_scene_dir)] allow_outside_scene_dir: bool,
    #[pyo3(from_py_with = args::env)] env: Option<String>,
    #[pyo3(from_py_with = args::env_intensity)] env_intensity: Option<f32>,
    #[pyo3(from_py_with = args::env_rotation)] env_rotation: Option<f32>,
    #[pyo3(from_py_with = args::env_sun)] env_sun: bool,
    #[pyo3(from_py_with = args::env_sun_share)] env_sun_share: Option<f32>,
    #[pyo3(from_py_with = args::variant)] variant: Option<String>,
    #[pyo3(from_py_with = args::animation)] animation: Option<scene::AnimationRef>,
    #[pyo3(from_py_with = args::time)] time: Option<f64>,
) -> PyResult<Scene> {
    let name = path_or_builtin
        .to_str()
        .ok_or_else(|| PyValueError::new_err(format!("{}: not a UTF-8 path", path_or_builtin.display())))?
        .to_string();
    // A file is reloaded by its absolute path where the scene is unpickled (another process's
    // working directory may differ).
    let lower = name.to_ascii_lowercase();
    let abs = if lower.ends_with(".gltf") || lower.ends_with(".glb") {
        std::path::absolute(&name)
            .ok()
            .and_then(|p| p.to_str().map(String::from))
            .unwrap_or_else(|| name.clone())
    } else {
        name.clone()
    };
    let env_abs = env.as_ref().map(|e| match e.to_ascii_lowercase().as_str() {
        "default" | "none" => e.clone(),
        _ => std::path::absolute(e)
            .ok()
            .and_then(|p| p.to_str().map(String::from))
            .unwrap_or_else(|| e.clone()),
    });
    let how = LoadArgs {
        name: abs,
        allow_outside_scene_dir,
        variant: variant.clone(),
        animation: animation.clone(),
        time,
        env: env_abs,
        env_intensity,
        env_rotation,
        env_sun,
        env_sun_share,
    };
    let h = LoadArgs { env, ..how.clone() };
    let scene = py.detach(move || -> Result<(scene::Scene, bool), PyErr> {
        let lower = name.to_ascii_lowercase();
        let is_file = lower.ends_with(".gltf") || lower.ends_with(".glb");
        let env_missing = h.env.as_deref().is_some_and(|e| {
            !matches!(e.to_ascii_lowercase().as_str(), "default" | "none")
                && std::fs::symlink_metadata(e).is_err()
        });
        let args = setup::SceneArgs {
            scene: name.clone(),
            files: setup::SceneFileArgs {
                allow_outside_scene_dir,
                variant,
                animation: match &animation {
                    Some(scene::AnimationRef::NameOrIndex(a)) => Some(a.clone()),
                    _ => None,
                },
                animation_index: match animation {
                    Some(scene::AnimationRef::Index(i)) => Some(i),
                    _ => None,
                },
                time,
            },
            env: setup::EnvArgs {
                env: h.env,
                env_intensity: h.env_intensity,
                env_rotation: h.env_rotation,
                no_env_sun: !h.env_sun,
                env_sun_share: h.env_sun_share,
            },
        };
        let fail = |e: anyhow::Error| -> PyErr {
            // The loader's message names the missing file; its type says so too.
            if (is_file && std::fs::symlink_metadata(&name).is_err()) || env_missing {
                PyFileNotFoundError::new_err(format!("{e:#}"))
            } else {
                // `--time -1: …` is `time -1: …` here, as the argument was given.
                value(anyhow::anyhow!(python_flags(&format!("{e:#}")))).into()
            }
        };
        // `SceneArgs::load` in two steps, to know whether the environment is `load`'s choice.
        let mut scene = args.files.load(&args.scene).map_err(fail)?;
        setup::print_warnings(&scene);
        let auto_env = args.env.env.is_none()
            && scene.water.is_none()
            && !scene::environment::LightSources::of(&scene).any();
        args.env.apply(&mut scene, false).map_err(fail)?;
        Ok((scene, auto_env))
    })?;
    let (scene, auto_env) = scene;
    Ok(Scene { inner: Arc::new(scene), auto_env, wet: std::sync::OnceLock::new(), how })
}

/// The CLI's `LookArgs` with every default (`spectra render SCENE` without options).
fn default_look() -> setup::LookArgs {
    parse_look(vec!["render".into()]).expect("the render options have defaults")
}

/// `spectra render`'s picture options parsed from a command line (`["render", "--flag", …]`)
/// by the CLI's own parser, so that its checks (the underwater model's flags that exclude one
/// another) are the command's; a `ValueError` with clap's message, its flags spelt as the
/// Python arguments, otherwise.
fn parse_look(argv: Vec<String>) -> PyResult<setup::LookArgs> {
    use clap::Parser;
    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        look: setup::LookArgs,
    }
    Cli::try_parse_from(argv).map(|c| c.look).map_err(|e| {
        let text = e.render().to_string();
        PyValueError::new_err(python_flags(text.trim_start_matches("error: ").lines().next().unwrap_or("")))
    })
}

/// `Renderer`'s arguments for `spectra render`'s picture flags, as the CLI's messages name the
/// flags: (flag, Python argument). Longer flags first, so that `--no-water-surface` is not
/// taken for `--water-surface`.
const PYTHON_FLAGS: &[(&str, &str)] = &[
    ("--no-surface-irradiance", "surface_irradiance=False"),
    ("--no-water-surface", "water_surface=False"),
    ("--no-env-occlusion", "env_occlusion=False"),
    ("--no-sea-floor", "sea_floor=False"),
    ("--light-field-photons", "light_field_photons"),
    ("--single-scattering", "single_scattering=True"),
    ("--scalar-irradiance", "scalar_irradiance=True"),
    ("--scatter-steps", "scatter_steps"),
    ("--water-surface", "water_surface=True"),
    ("--forward-cone", "forward_cone"),
    ("--tabulated-kd", "tabulated_kd=True"),
    ("--paper-model", "paper_model=True"),
    ("--split-beams", "split_beams=True"),
    ("--isotropic", "isotropic=True"),
    ("--phase-g", "phase_g"),
    ("--variant", "variant"),
    ("--animation", "animation"),
    ("--time", "time"),
];

/// A message of the CLI's about `Renderer`'s picture flags or `load`'s file choices
/// (`--variant`, `--animation`, `--time`) with each flag spelt as the Python argument that gives it (`--scatter-steps 33: …` → `scatter_steps 33: …`), clap's value names
/// (` <STEPS>`) dropped. Other flags (`--water`, `--rgb-medium`) are left as they are.
fn python_flags(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    'scan: while !rest.is_empty() {
        if rest.starts_with("--") {
            for (flag, arg) in PYTHON_FLAGS {
                let ends =
                    |r: &str| r.chars().next().is_none_or(|c| !(c.is_ascii_alphanumeric() || c == '-'));
                if let Some(after) = rest.strip_prefix(flag)
                    && ends(after)
                {
                    out.push_str(arg);
                    rest = after;
                    // clap's value name after the flag: ` <STEPS>`.
                    if let Some(v) = rest.strip_prefix(" <")
                        && let Some(end) = v.find('>')
                        && v[..end].chars().all(|c| c.is_ascii_uppercase() || c == '_')
                    {
                        rest = &v[end + 1..];
                    }
                    continue 'scan;
                }
            }
        }
        let c = rest.chars().next().expect("not empty");
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    out
}

/// `Renderer`'s medium and table options: `spectra render`'s flags of the same meaning
/// (`surface_irradiance=False` is `--no-surface-irradiance`, `water_surface` True / False
/// `--water-surface` / `--no-water-surface`, `sea_floor=False` `--no-sea-floor`).
struct MediaOptions {
    table: Option<PathBuf>,
    scatter_steps: i128,
    single_scattering: bool,
    phase_g: f32,
    paper_model: bool,
    isotropic: bool,
    tabulated_kd: bool,
    surface_irradiance: bool,
    forward_cone: f32,
    light_field_photons: i128,
    scalar_irradiance: bool,
    split_beams: bool,
    water_surface: Option<bool>,
    sea_floor: bool,
}

impl MediaOptions {
    /// The CLI's picture options with these given as its flags (a value equal to the CLI's
    /// default is not given, so that it conflicts with nothing, as an absent flag), parsed by
    /// the CLI's parser: the flags that exclude one another are refused as `spectra render`
    /// refuses them. Ranges are checked by `LookArgs::media`, as for the command.
    fn look(&self, water: setup::WaterArgs, rgb_medium: setup::RgbMediumArgs) -> PyResult<setup::LookArgs> {
        let d = default_look();
        let steps = whole("scatter_steps", self.scatter_steps, 0)?;
        let photons = whole("light_field_photons", self.light_field_photons, 0)?;
        let mut argv: Vec<String> = vec!["render".into()];
        if steps != d.scatter_steps {
            argv.push(format!("--scatter-steps={steps}"));
        }
        if self.phase_g.to_bits() != d.phase_g.to_bits() {
            argv.push(format!("--phase-g={}", self.phase_g));
        }
        if self.forward_cone.to_bits() != d.forward_cone.to_bits() {
            argv.push(format!("--forward-cone={}", self.forward_cone));
        }
        if photons as usize != d.light_field_photons {
            argv.push(format!("--light-field-photons={photons}"));
        }
        for (on, flag) in [
            (self.single_scattering, "--single-scattering"),
            (self.paper_model, "--paper-model"),
            (self.isotropic, "--isotropic"),
            (self.tabulated_kd, "--tabulated-kd"),
            (!self.surface_irradiance, "--no-surface-irradiance"),
            (self.scalar_irradiance, "--scalar-irradiance"),
            (self.split_beams, "--split-beams"),
            (self.water_surface == Some(true), "--water-surface"),
            (self.water_surface == Some(false), "--no-water-surface"),
            (!self.sea_floor, "--no-sea-floor"),
        ] {
            if on {
                argv.push(flag.into());
            }
        }
        let mut look = parse_look(argv)?;
        look.table = setup::TableArgs { table: self.table.clone() };
        look.water = water;
        look.rgb_medium = rgb_medium;
        Ok(look)
    }
}

/// The coefficient table: `table=` (a bad or missing file is the caller's: `ValueError` /
/// `FileNotFoundError`, the message naming it as `--table` does), else the cached sRGB fit
/// (which failing is a `RuntimeError`).
fn load_table(table: Option<&std::path::Path>) -> Result<Arc<color::upsample::CoeffTable>, Fail> {
    setup::load_table(table).map_err(|e| if table.is_some() { value(e) } else { runtime(e) })
}

struct Inner {
    renderer: render::Renderer,
    scene: Arc<scene::Scene>,
    size: (u32, u32),
    /// The picture options the renderer was made with: water, RGB medium, table and the media
    /// options (`render` resolves its settings with them, as `spectra render` does).
    look: setup::LookArgs,
}

/// A (H, W, 3) float32 image, and with a spectral capture its (H, W, N) node radiances and the
/// N node wavelengths.
type Frame = (Vec<f32>, Option<(Vec<f32>, Vec<f64>)>, (u32, u32));

/// The real-time renderer (wgpu) for one scene at one size. It keeps its GPU device, pipelines
/// and scene buffers between `render()` calls, so only the first call pays for them.
///
/// Renderer(scene, size=(640, 480), *, water=None, depth=None, rgb_medium=None, table=None,
/// scatter_steps=16, single_scattering=False, phase_g=0.924, paper_model=False,
/// isotropic=False, tabulated_kd=False, surface_irradiance=True, forward_cone=15.0,
/// light_field_photons=8000, scalar_irradiance=False, split_beams=False, water_surface=None,
/// sea_floor=True): the medium as `spectra render` sets it up (`water` a Jerlov type with the
/// camera `depth` in metres, or `rgb_medium`, inline JSON or a file; by default the scene's
/// own), `table` its `--table`, and the media options its flags of the same names, with its
/// defaults (`surface_irradiance=False` is `--no-surface-irradiance`, `water_surface`
/// True / False `--water-surface` / `--no-water-surface`, None the model's choice,
/// `sea_floor=False` `--no-sea-floor`); flags it refuses together are refused together.
#[pyclass(frozen, module = "spectra")]
struct Renderer {
    inner: Mutex<Inner>,
    scene: Py<Scene>,
    /// (width, height) and the GPU's description, fixed at creation: read without the lock,
    /// which a render on another thread holds for as long as it runs.
    size: (u32, u32),
    device: String,
}

#[pymethods]
impl Renderer {
    /// Creates the GPU device (lavapipe without a GPU), uploads `scene` and sizes the targets to
    /// `size=(width, height)`. The medium is set up as `spectra render` sets it up: `water` (a
    /// Jerlov type, e.g. "IB") with the camera `depth` in metres, or `rgb_medium` (the
    /// `--rgb-medium` JSON or a JSON file); by default the scene's own.
    ///
    /// table: a Jakob–Hanika coefficient table (.coeff) to upsample with (`--table`; default the
    /// cached sRGB fit). The media options are `spectra render`'s flags, with its defaults:
    /// scatter_steps (`--scatter-steps`, 0–32, default 16), single_scattering
    /// (`--single-scattering`), phase_g (`--phase-g`, default 0.924), paper_model
    /// (`--paper-model`), isotropic (`--isotropic`), tabulated_kd (`--tabulated-kd`),
    /// surface_irradiance (False: `--no-surface-irradiance`), forward_cone (`--forward-cone`,
    /// degrees 0–45, default 15), light_field_photons (`--light-field-photons`, default 8000),
    /// scalar_irradiance (`--scalar-irradiance`), split_beams (`--split-beams`), water_surface
    /// (None: the model's default; True `--water-surface`, False `--no-water-surface`), sea_floor
    /// (False: `--no-sea-floor`). Options that exclude one another on the command line (e.g.
    /// paper_model with scatter_steps other than 16) are refused as it refuses them.
    #[new]
    // The text signatures spell the tuple defaults, which pyo3 would show as `...` (so that
    // `inspect.signature` bound defaults that cannot be passed back).
    #[pyo3(signature = (scene, size = (640, 480), *, water = None, depth = None, rgb_medium = None, table = None,
                        scatter_steps = 16, single_scattering = false, phase_g = 0.924, paper_model = false,
                        isotropic = false, tabulated_kd = false, surface_irradiance = true, forward_cone = 15.0,
                        light_field_photons = 8000, scalar_irradiance = false, split_beams = false,
                        water_surface = None, sea_floor = true),
           text_signature = "(scene, size=(640, 480), *, water=None, depth=None, rgb_medium=None, table=None, \
                             scatter_steps=16, single_scattering=False, phase_g=0.924, paper_model=False, \
                             isotropic=False, tabulated_kd=False, surface_irradiance=True, forward_cone=15.0, \
                             light_field_photons=8000, scalar_irradiance=False, split_beams=False, \
                             water_surface=None, sea_floor=True)")]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments, each its own option
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = args::size)] size: (i128, i128),
        #[pyo3(from_py_with = args::water)] water: Option<String>,
        #[pyo3(from_py_with = args::depth)] depth: Option<f64>,
        #[pyo3(from_py_with = args::rgb_medium)] rgb_medium: Option<String>,
        #[pyo3(from_py_with = args::table)] table: Option<PathBuf>,
        #[pyo3(from_py_with = args::scatter_steps)] scatter_steps: i128,
        #[pyo3(from_py_with = args::single_scattering)] single_scattering: bool,
        #[pyo3(from_py_with = args::phase_g)] phase_g: f32,
        #[pyo3(from_py_with = args::paper_model)] paper_model: bool,
        #[pyo3(from_py_with = args::isotropic)] isotropic: bool,
        #[pyo3(from_py_with = args::tabulated_kd)] tabulated_kd: bool,
        #[pyo3(from_py_with = args::surface_irradiance)] surface_irradiance: bool,
        #[pyo3(from_py_with = args::forward_cone)] forward_cone: f32,
        #[pyo3(from_py_with = args::light_field_photons)] light_field_photons: i128,
        #[pyo3(from_py_with = args::scalar_irradiance)] scalar_irradiance: bool,
        #[pyo3(from_py_with = args::split_beams)] split_beams: bool,
        #[pyo3(from_py_with = args::water_surface)] water_surface: Option<bool>,
        #[pyo3(from_py_with = args::sea_floor)] sea_floor: bool,
    ) -> PyResult<Self> {
        let sc = scene_of(scene, "scene", water.is_some())?;
        let scene_obj: Py<Scene> = scene.extract()?;
        let (w, h) = size_arg(size)?;
        let options = MediaOptions {
            table,
            scatter_steps,
            single_scattering,
            phase_g,
            paper_model,
            isotropic,
            tabulated_kd,
            surface_irradiance,
            forward_cone,
            light_field_photons,
            scalar_irradiance,
            split_beams,
            water_surface,
            sea_floor,
        };
        let look = options.look(setup::WaterArgs { water, depth }, setup::RgbMediumArgs { rgb_medium })?;
        let s = sc.clone();
        let l = look.clone();
        let renderer = py.detach(move || -> Result<render::Renderer, Fail> {
            let look = l;
            let table = load_table(look.table.table.as_deref())?;
            // The media options' messages name the Python arguments (`scatter_steps 33: …`).
            let named = |e: anyhow::Error| value(anyhow::anyhow!(python_flags(&format!("{e:#}"))));
            let media = look.media(&s, &table).map_err(named)?;
            let custom = media.shader().map_err(named)?;
            let mut r = render::Renderer::with_table(table).map_err(runtime)?;
            r.set_scene(&s).map_err(runtime)?;
            for w in r.scene_warnings() {
                eprintln!("warning: {}: {w}", s.source);
            }
            if let Some(c) = custom {
                r.set_custom_shader(c).map_err(runtime)?;
            }
            r.resize(w, h).map_err(value)?;
            Ok(r)
        })?;
        let device = renderer.gpu().describe();
        Ok(Renderer {
            inner: Mutex::new(Inner { renderer, scene: sc, size: (w, h), look }),
            scene: scene_obj,
            size: (w, h),
            device,
        })
    }

    /// One frame as a float32 array of shape (height, width, 3), C-contiguous: the linear RGB
    /// HDR image (`spectra render --out x.exr`'s pixels, the f16 HDR target read back, alpha
    /// dropped), multiplied by 2^exposure before the f16 (so a scene outside its range, e.g. lit
    /// at 1e-9, is brought into it).
    ///
    /// mode: "spectral" (Jakob–Hanika), "naive" (box upsampling) or "rgb".
    /// wavelengths: N nodes, 1–256 (default: the scene's, else 16).
    /// quadrature: "prefiltered" or "midpoint".
    /// range: (min_nm, max_nm) (default: the scene's, else (380, 730)).
    /// observer: "cie1931", "cie1964", a camera name or a CSV file (default: the scene's, else
    /// cie1931).
    /// white: the scene white, an illuminant name ("D65", "F11", "5000K", …; default: the
    /// scene's, else D65).
    /// exposure: stops (the radiance × 2^exposure is what the f16 target holds).
    /// spectral: also return the radiance at each of the N nodes, as `--spectral-out` writes
    /// it: the tuple (image, radiance of shape (H, W, N) float32, wavelengths of shape (N,)
    /// float64, nm). With the midpoint rule a node's value is L(λₖ); with the prefiltered rule
    /// it is the node's share of the integral as a radiance (docs/spectral-exr.md). Not in rgb
    /// mode.
    /// samples: antialiasing, the mean of this many frames each looking at another place in
    /// every pixel (`spectra render --samples`): the image box-filtered over each pixel, as the
    /// path tracer's are; 1–256, default 1 (the pixel centres). Not with spectral=True.
    /// lambert: every surface reflects base colour / π, no specular (`--lambert`, like
    /// `truth(lambert=True)`). env_occlusion: the screen-space occlusion of ambient light (False:
    /// `--no-env-occlusion`). shadows: shadow maps (False: `--no-shadows`).
    #[pyo3(signature = (mode = "spectral".to_string(), *, wavelengths = None, quadrature = "prefiltered".to_string(),
                        range = None, observer = None, white = None, exposure = 0.0, spectral = false,
                        camera_to_display = false, samples = 1, lambert = false, env_occlusion = true,
                        shadows = true),
           text_signature = "($self, mode='spectral', *, wavelengths=None, quadrature='prefiltered', range=None, \
                             observer=None, white=None, exposure=0.0, spectral=False, camera_to_display=False, \
                             samples=1, lambert=False, env_occlusion=True, shadows=True)")]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = args::mode)] mode: String,
        #[pyo3(from_py_with = args::wavelengths)] wavelengths: Option<i128>,
        #[pyo3(from_py_with = args::quadrature)] quadrature: String,
        #[pyo3(from_py_with = args::range)] range: Option<(f64, f64)>,
        #[pyo3(from_py_with = args::observer)] observer: Option<String>,
        #[pyo3(from_py_with = args::white)] white: Option<String>,
        #[pyo3(from_py_with = args::exposure)] exposure: f32,
        #[pyo3(from_py_with = args::spectral)] spectral: bool,
        #[pyo3(from_py_with = args::camera_to_display)] camera_to_display: bool,
        #[pyo3(from_py_with = args::samples)] samples: i128,
        #[pyo3(from_py_with = args::lambert)] lambert: bool,
        #[pyo3(from_py_with = args::env_occlusion)] env_occlusion: bool,
        #[pyo3(from_py_with = args::shadows)] shadows: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let max = spectra::cmd::render::MAX_SAMPLES;
        let samples = match u32::try_from(samples) {
            Ok(k) if (1..=max).contains(&k) => k,
            _ => {
                return Err(PyValueError::new_err(format!("samples {samples}: must be between 1 and {max}")));
            }
        };
        if spectral && samples > 1 {
            return Err(PyValueError::new_err(format!(
                "spectral=True returns one frame's node radiances: it cannot be combined with samples={samples}"
            )));
        }
        let mut look = default_look();
        look.mode = render::Mode::parse(&mode).map_err(|e| PyValueError::new_err(e.to_string()))?;
        look.wavelengths = match wavelengths {
            // The CLI's message for a count out of range (a negative one never parses there).
            Some(n) if n < 0 => {
                return Err(PyValueError::new_err(format!(
                    "--wavelengths {n}: the number of wavelengths must be between 1 and {} (got {n})",
                    render::settings::MAX_WAVELENGTHS
                )));
            }
            Some(n) => Some(usize::try_from(n).unwrap_or(usize::MAX)),
            None => None,
        };
        look.quadrature = setup::parse_quadrature(&quadrature)
            .map_err(|e| PyValueError::new_err(format!("--quadrature '{quadrature}': {e}")))?;
        look.spectrum = setup::SpectrumArgs { range: range_arg(range)?, observer, white, camera_to_display };
        look.exposure = exposure;
        look.lambert = lambert;
        look.no_env_occlusion = !env_occlusion;
        let (data, capture, (w, h)) = py.detach(|| -> Result<Frame, Fail> {
            let mut g = self.inner.lock().unwrap_or_else(|p| p.into_inner());
            let inner = &mut *g;
            look.water = inner.look.water.clone();
            look.rgb_medium = inner.look.rgb_medium.clone();
            look.table = inner.look.table.clone();
            let settings = look.settings(&inner.scene, shadows, false).map_err(value)?;
            let (w, h) = inner.size;
            if spectral {
                if settings.mode == render::Mode::Rgb {
                    return Err(value(anyhow::anyhow!(
                        "spectral=True: rgb mode has no wavelength nodes (use mode='spectral' or 'naive')"
                    )));
                }
                inner.renderer.check_spectral_capture(w, h, settings.wavelengths).map_err(value)?;
            }
            inner.renderer.set_spectral_capture(spectral);
            let never = || Ok(());
            spectra::cmd::render::draw(&mut inner.renderer, &inner.scene.camera, &settings, samples, &never)
                .map_err(runtime)?;
            let hdr = spectra::cmd::render::read_linear(&inner.renderer, samples).map_err(runtime)?;
            spectra::cmd::render::warn_if_too_dim(&inner.scene, &hdr);
            // As `spectra render --out x.exr` writes them: the exposure is in the HDR values
            // already (applied before the half float); the capture's f32 radiance takes it here.
            let k = settings.exposure_ev.exp2();
            let data = hdr.iter().flat_map(|p| [p[0], p[1], p[2]]).collect();
            let capture = if spectral {
                let cap = inner.renderer.read_spectral_capture().map_err(runtime)?;
                Some((cap.data.into_iter().map(|v| v * k).collect(), cap.lambda))
            } else {
                None
            };
            Ok((data, capture, (w, h)))
        })?;
        let img = rgb_array(py, w, h, data)?;
        match capture {
            None => Ok(img.into_any()),
            Some((nodes, lambda)) => {
                let n = lambda.len();
                let nodes = PyArray1::from_vec(py, nodes).reshape([h as usize, w as usize, n])?;
                let lambda = PyArray1::from_vec(py, lambda);
                Ok((img, nodes, lambda).into_pyobject(py)?.into_any())
            }
        }
    }

    /// The scene this renderer draws.
    #[getter]
    fn scene(&self, py: Python<'_>) -> Py<Scene> {
        self.scene.clone_ref(py)
    }

    /// (width, height).
    #[getter]
    fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The GPU adapter and backend, e.g. "llvmpipe (LLVM …) (Vulkan, Cpu)".
    #[getter]
    fn device(&self) -> String {
        self.device.clone()
    }

    // None of these three takes the renderer's lock: a render on another thread holds it, and
    // waiting for it here, with the GIL held, froze every Python thread until that render ended.
    fn __repr__(&self) -> String {
        let source = &self.scene.get().inner.source;
        format!("<spectra.Renderer {source} {}×{}>", self.size.0, self.size.1)
    }
}

/// A truth render's options, as `truth()` takes them (the CLI's `spectra truth` flags).
struct TruthArgs {
    spp: u32,
    size: (u32, u32),
    direct_only: bool,
    seed: u64,
    sample_offset: u64,
    crop: Option<truth::Crop>,
    max_depth: u32,
    spectrum: setup::SpectrumArgs,
    water: setup::WaterArgs,
    rgb_medium: setup::RgbMediumArgs,
    spectral_bin: Option<f64>,
    /// `--medium`: a spectral medium, JSON inline or a file.
    medium: Option<String>,
    lambert: bool,
    /// `--xyz`: the image is CIE XYZ (the observer's tristimulus), not linear sRGB.
    xyz: bool,
    table: Option<PathBuf>,
}

impl TruthArgs {
    /// Checks and converts `truth()`'s arguments; errors name the argument.
    #[allow(clippy::too_many_arguments)]
    fn new(
        spp: i128,
        size: (i128, i128),
        direct_only: bool,
        seed: i128,
        sample_offset: i128,
        crop: Option<(i128, i128, i128, i128)>,
        range: Option<(f64, f64)>,
        observer: Option<String>,
        white: Option<String>,
        max_depth: i128,
        water: Option<String>,
        depth: Option<f64>,
        rgb_medium: Option<String>,
        spectral_bin: Option<f64>,
        camera_to_display: bool,
        medium: Option<String>,
        lambert: bool,
        xyz: bool,
        table: Option<PathBuf>,
    ) -> PyResult<Self> {
        let spp = whole("spp", spp, 1)?;
        // `--medium` conflicts with `--rgb-medium` on the command line (clap refuses the pair).
        if medium.is_some() && rgb_medium.is_some() {
            return Err(PyValueError::new_err(
                "medium cannot be used with rgb_medium: pick one medium (as --medium cannot be used with --rgb-medium)",
            ));
        }
        let size = size_arg(size)?;
        // Python's integers are unbounded: every count is taken as i128 so that one too large
        // for the machine is refused naming its argument (not an OverflowError naming none),
        // and a seed may be any u64, as `spectra truth --seed` takes.
        if !(0..=i128::from(u64::MAX)).contains(&seed) {
            return Err(PyValueError::new_err(format!(
                "seed {seed}: must be a whole number from 0 to 2⁶⁴ − 1"
            )));
        }
        if !(0..=i128::from(u64::MAX)).contains(&sample_offset) {
            return Err(PyValueError::new_err(format!(
                "sample_offset {sample_offset}: must be a whole number ≥ 0 (below 2⁵³ with spp)"
            )));
        }
        let crop = match crop {
            Some((x, y, cw, ch)) => Some(truth::Crop {
                x: whole("crop x", x, 0)?,
                y: whole("crop y", y, 0)?,
                width: whole("crop width", cw, 1)?,
                height: whole("crop height", ch, 1)?,
            }),
            None => None,
        };
        Ok(TruthArgs {
            spp,
            size,
            direct_only,
            seed: seed as u64,
            sample_offset: sample_offset as u64,
            crop,
            max_depth: whole("max_depth", max_depth, 0)?,
            spectrum: setup::SpectrumArgs { range: range_arg(range)?, observer, white, camera_to_display },
            water: setup::WaterArgs { water, depth },
            rgb_medium: setup::RgbMediumArgs { rgb_medium },
            spectral_bin,
            medium,
            lambert,
            xyz,
            table,
        })
    }

    /// The settings `spectra truth` builds from the same flags: its own `settings()` (the
    /// scene's RGB medium unless `rgb_medium` replaces it, the water of `water`/`depth` or the
    /// scene's), so the two cannot drift apart.
    fn settings(
        &self,
        scene: &scene::Scene,
        table: &color::upsample::CoeffTable,
    ) -> anyhow::Result<truth::Settings> {
        use clap::Parser;
        #[derive(Parser)]
        struct Cli {
            #[command(flatten)]
            truth: spectra::cmd::truth::Args,
        }
        let mut a =
            Cli::try_parse_from(["truth", "--", &scene.source]).expect("truth's options have defaults").truth;
        a.spp = self.spp;
        a.size = format!("{}x{}", self.size.0, self.size.1);
        a.sample_offset = Some(self.sample_offset);
        a.crop = self.crop.map(|c| format!("{},{},{},{}", c.x, c.y, c.width, c.height));
        a.direct_only = self.direct_only;
        a.seed = self.seed;
        a.max_depth = self.max_depth;
        a.spectrum = self.spectrum.clone();
        a.water = self.water.clone();
        a.rgb_medium = self.rgb_medium.clone();
        a.medium = self.medium.clone();
        a.lambert = self.lambert;
        a.xyz = self.xyz;
        a.table = setup::TableArgs { table: self.table.clone() };
        if let Some(bin) = self.spectral_bin {
            a.spectral_bands = true;
            a.spectral_bin = bin;
        }
        spectra::cmd::truth::settings(&a, scene, table)
    }

    /// Renders the samples, stopping early (`Cancelled`) once `cancel` is set: the tracer looks
    /// at it every few samples of every pixel (`interruptible` sets it on Ctrl-C).
    fn run(
        &self,
        sc: &scene::Scene,
        cancel: &AtomicBool,
    ) -> Result<(truth::Settings, truth::Accumulator), Fail> {
        let table = load_table(self.table.as_deref())?;
        let st = self.settings(sc, &table).map_err(value)?;
        let mut world =
            truth::World::new(sc, table.as_ref(), &st.white, st.range, st.medium.as_ref()).map_err(value)?;
        if let Some(env) = &st.environment {
            world = world.with_environment(env);
        }
        let mut acc = truth::Accumulator::new(&st).map_err(value)?;
        truth::render_pass(&world, &st, cancel, &mut acc, st.spp, &|_| {}).map_err(runtime)?;
        if acc.dropped > 0 {
            eprintln!("warning: truth: {} non-finite samples dropped", acc.dropped);
        }
        Ok((st, acc))
    }
}

/// How often a waiting call looks at Python's signals.
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// Runs `work` on a thread of its own while this thread, the caller's (called without the GIL),
/// looks at Python's signals every `SIGNAL_POLL`. On a pending exception (Ctrl-C's
/// KeyboardInterrupt, or `ray.cancel` interrupting a Ray task) it sets `work`'s cancel flag,
/// waits for `work` to stop (the tracer stops within a few samples) and returns the exception.
///
/// CPython runs signal handlers on the main thread only, so the check must be made from the
/// thread that called in, never from the worker or a rayon pool's thread (where
/// `check_signals` does nothing): a forked child's render, on a pool of its own, and a Ray
/// task's, on a pool of `threads`, could not be interrupted, and a pass over a large image
/// (2048² took 9 s) ran to its end before the check between passes.
fn interruptible<R: Send>(work: impl FnOnce(&AtomicBool) -> Result<R, Fail> + Send) -> Result<R, Fail> {
    let cancel = AtomicBool::new(false);
    std::thread::scope(|s| {
        let (tx, rx) = std::sync::mpsc::channel::<()>();
        let cancel = &cancel;
        let worker = s.spawn(move || {
            let r = work(cancel);
            let _ = tx.send(());
            r
        });
        let mut interrupted = None;
        loop {
            match rx.recv_timeout(SIGNAL_POLL) {
                Ok(()) | Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        cancel.store(true, std::sync::atomic::Ordering::Relaxed);
                        interrupted = Some(e);
                        break;
                    }
                }
            }
        }
        let r = worker.join().unwrap_or_else(|p| std::panic::resume_unwind(p));
        match interrupted {
            Some(e) => Err(Fail::Py(e)),
            None => r,
        }
    })
}

/// The image of per-pixel sums over `spp` samples, as `spectra truth` finishes a render
/// (`Accumulator::finish`: the mean as f32, then XYZ → linear sRGB): one place for the
/// single-process and the distributed truth.
fn finish(
    width: u32,
    height: u32,
    xyz: &[[f64; 3]],
    bins: &[f64],
    spp: u32,
    display: glam::DMat3,
) -> (Vec<f32>, Vec<f32>) {
    let n = f64::from(spp);
    let img = truth::XyzImage {
        width,
        height,
        xyz: xyz.iter().map(|p| p.map(|v| (v / n) as f32)).collect(),
        dropped: 0,
        spectral: None,
    };
    let rgb = img
        .xyz
        .iter()
        .flat_map(|p| {
            let v = display * glam::DVec3::from_array(p.map(f64::from));
            [v.x as f32, v.y as f32, v.z as f32]
        })
        .collect();
    (rgb, bins.iter().map(|v| (v / n) as f32).collect())
}

/// The CPU spectral path tracer's image of `scene` (what `spectra truth` renders with the same
/// options), as a float32 array of shape (height, width, 3) of linear sRGB; with `crop`, the
/// crop's (h, w, 3).
///
/// spp: samples per pixel (each path carries four wavelengths). size: (width, height) of the
/// frame. direct_only: one scattering vertex (like for like with the real-time image). seed:
/// the image depends on it alone (not on the number of threads). sample_offset: render samples
/// K … K+spp−1 of each pixel's sequence (the CLI's --sample-offset; chunks with disjoint ranges
/// average into the full render). crop: (x, y, w, h) of the frame, rendered with exactly the
/// full render's samples. range / observer / white: as for `Renderer.render`. max_depth: the
/// longest path in scattering events. water / depth / rgb_medium: as for `Renderer`.
/// spectral_bin: also bin the radiance by wavelength, in bins of this many nm over the range
/// (`--spectral-out` with `--spectral-bin`): returns (image, bands of shape (h, w, B) float32,
/// band edges of shape (B + 1,) float64, nm).
/// medium: a homogeneous spectral participating medium, inline JSON ('{…}') or a JSON file
/// (`--medium`: keys sigma_a, sigma_s, phase, box; docs/ground-truth.md); not with rgb_medium.
/// lambert: a Lambertian BRDF instead of glTF's (`--lambert`). xyz: the image in CIE XYZ (the
/// observer's tristimulus, Y = 1 for the white) instead of linear sRGB (`--xyz`). table: the
/// Jakob–Hanika coefficient table (.coeff) to upsample with (`--table`; default the cached
/// sRGB fit).
///
/// Ctrl-C interrupts it (KeyboardInterrupt) within a fraction of a second, wherever it runs
/// (a forked child, a Ray task: `interruptible`).
#[pyfunction(name = "truth")]
#[pyo3(signature = (scene, spp = 64, size = (256, 256), direct_only = false, seed = 0, *, sample_offset = 0,
                    crop = None, range = None, observer = None, white = None, max_depth = 1024, water = None,
                    depth = None, rgb_medium = None, spectral_bin = None, camera_to_display = false, medium = None,
                    lambert = false, xyz = false, table = None),
       text_signature = "(scene, spp=64, size=(256, 256), direct_only=False, seed=0, *, sample_offset=0, \
                         crop=None, range=None, observer=None, white=None, max_depth=1024, water=None, \
                         depth=None, rgb_medium=None, spectral_bin=None, camera_to_display=False, medium=None, \
                         lambert=False, xyz=False, table=None)")]
#[allow(clippy::too_many_arguments)]
fn truth_image<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::spp)] spp: i128,
    #[pyo3(from_py_with = args::size)] size: (i128, i128),
    #[pyo3(from_py_with = args::direct_only)] direct_only: bool,
    #[pyo3(from_py_with = args::seed)] seed: i128,
    #[pyo3(from_py_with = args::sample_offset)] sample_offset: i128,
    #[pyo3(from_py_with = args::crop)] crop: Option<(i128, i128, i128, i128)>,
    #[pyo3(from_py_with = args::range)] range: Option<(f64, f64)>,
    #[pyo3(from_py_with = args::observer)] observer: Option<String>,
    #[pyo3(from_py_with = args::white)] white: Option<String>,
    #[pyo3(from_py_with = args::max_depth)] max_depth: i128,
    #[pyo3(from_py_with = args::water)] water: Option<String>,
    #[pyo3(from_py_with = args::depth)] depth: Option<f64>,
    #[pyo3(from_py_with = args::rgb_medium)] rgb_medium: Option<String>,
    #[pyo3(from_py_with = args::spectral_bin)] spectral_bin: Option<f64>,
    #[pyo3(from_py_with = args::camera_to_display)] camera_to_display: bool,
    #[pyo3(from_py_with = args::medium)] medium: Option<String>,
    #[pyo3(from_py_with = args::lambert)] lambert: bool,
    #[pyo3(from_py_with = args::xyz)] xyz: bool,
    #[pyo3(from_py_with = args::table)] table: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let sc = scene_of(scene, "scene", water.is_some())?;
    let a = TruthArgs::new(
        spp,
        size,
        direct_only,
        seed,
        sample_offset,
        crop,
        range,
        observer,
        white,
        max_depth,
        water,
        depth,
        rgb_medium,
        spectral_bin,
        camera_to_display,
        medium,
        lambert,
        xyz,
        table,
    )?;
    let view = color::film::CameraView::from_flag(camera_to_display);
    let (rgb, bands, edges, (w, h)) = py.detach(move || -> Result<_, Fail> {
        let (st, acc) = interruptible(|cancel| fork_safe(|| a.run(&sc, cancel)))?;
        let win = st.window();
        // `--xyz` writes the tracer's XYZ as it is (`XyzImage::xyz`): the identity here.
        let display = if xyz { glam::DMat3::IDENTITY } else { st.display_matrix(view).map_err(value)? };
        let (rgb, bands) = finish(win.width, win.height, &acc.xyz, &acc.bins, st.spp, display);
        Ok((rgb, bands, st.spectral_bands, (win.width, win.height)))
    })?;
    let img = rgb_array(py, w, h, rgb)?;
    match edges {
        None => Ok(img.into_any()),
        Some(edges) => {
            let nb = edges.len() - 1;
            let bands = PyArray1::from_vec(py, bands).reshape([h as usize, w as usize, nb])?;
            Ok((img, bands, PyArray1::from_vec(py, edges)).into_pyobject(py)?.into_any())
        }
    }
}

/// `truth`'s sums before they are averaged, for renders split into chunks and tiles
/// (`spectra.distributed`): a dict of `xyz` (float64 (h, w, 3), the per-pixel sums of CIE XYZ
/// over the samples), `bins` (float64 (h, w, B) or None), `edges`, `window` (x, y, w, h of the
/// frame), `spp` and `dropped`. Sums of disjoint sample ranges add up to the sums of their
/// union; `_truth_finish` turns sums into `truth`'s image.
///
/// threads: the tracer's threads (default: every core). dry_run: check the arguments and
/// return the dict without `xyz`, `bins` and `dropped`, rendering nothing.
#[pyfunction(name = "_truth_sums")]
#[pyo3(signature = (scene, spp = 64, size = (256, 256), direct_only = false, seed = 0, *, sample_offset = 0,
                    crop = None, range = None, observer = None, white = None, max_depth = 1024, water = None,
                    depth = None, rgb_medium = None, spectral_bin = None, camera_to_display = false, medium = None,
                    lambert = false, xyz = false, table = None, threads = None, dry_run = false),
       text_signature = "(scene, spp=64, size=(256, 256), direct_only=False, seed=0, *, sample_offset=0, \
                         crop=None, range=None, observer=None, white=None, max_depth=1024, water=None, \
                         depth=None, rgb_medium=None, spectral_bin=None, camera_to_display=False, medium=None, \
                         lambert=False, xyz=False, table=None, threads=None, dry_run=False)")]
#[allow(clippy::too_many_arguments)]
fn truth_sums<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::spp)] spp: i128,
    #[pyo3(from_py_with = args::size)] size: (i128, i128),
    #[pyo3(from_py_with = args::direct_only)] direct_only: bool,
    #[pyo3(from_py_with = args::seed)] seed: i128,
    #[pyo3(from_py_with = args::sample_offset)] sample_offset: i128,
    #[pyo3(from_py_with = args::crop)] crop: Option<(i128, i128, i128, i128)>,
    #[pyo3(from_py_with = args::range)] range: Option<(f64, f64)>,
    #[pyo3(from_py_with = args::observer)] observer: Option<String>,
    #[pyo3(from_py_with = args::white)] white: Option<String>,
    #[pyo3(from_py_with = args::max_depth)] max_depth: i128,
    #[pyo3(from_py_with = args::water)] water: Option<String>,
    #[pyo3(from_py_with = args::depth)] depth: Option<f64>,
    #[pyo3(from_py_with = args::rgb_medium)] rgb_medium: Option<String>,
    #[pyo3(from_py_with = args::spectral_bin)] spectral_bin: Option<f64>,
    #[pyo3(from_py_with = args::camera_to_display)] camera_to_display: bool,
    #[pyo3(from_py_with = args::medium)] medium: Option<String>,
    #[pyo3(from_py_with = args::lambert)] lambert: bool,
    #[pyo3(from_py_with = args::xyz)] xyz: bool,
    #[pyo3(from_py_with = args::table)] table: Option<PathBuf>,
    #[pyo3(from_py_with = args::threads)] threads: Option<i128>,
    #[pyo3(from_py_with = args::dry_run)] dry_run: bool,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let sc = scene_of(scene, "scene", water.is_some())?;
    let a = TruthArgs::new(
        spp,
        size,
        direct_only,
        seed,
        sample_offset,
        crop,
        range,
        observer,
        white,
        max_depth,
        water,
        depth,
        rgb_medium,
        spectral_bin,
        camera_to_display,
        medium,
        lambert,
        xyz,
        table,
    )?;
    let threads = threads.map(|t| whole("threads", t, 1)).transpose()?;
    let d = pyo3::types::PyDict::new(py);
    let st = if dry_run {
        py.detach(|| -> Result<_, Fail> {
            let table = load_table(a.table.as_deref())?;
            let st = a.settings(&sc, &table).map_err(value)?;
            // What `run` refuses before its first sample (an environment under water, a
            // medium the scene cannot hold), refused here too: `distributed.submit` checks
            // its arguments with this call before any task.
            fork_safe(|| {
                truth::World::new(&sc, table.as_ref(), &st.white, st.range, st.medium.as_ref()).map_err(value)
            })?;
            truth::Accumulator::new(&st).map_err(value)?;
            Ok(st)
        })?
    } else {
        let (st, acc) = py.detach(move || {
            interruptible(|cancel| match threads {
                None => fork_safe(|| a.run(&sc, cancel)),
                Some(n) => rayon::ThreadPoolBuilder::new()
                    .num_threads(n as usize)
                    .build()
                    .map_err(runtime)?
                    .install(|| a.run(&sc, cancel)),
            })
        })?;
        let win = st.window();
        let (w, h) = (win.width as usize, win.height as usize);
        let xyz: Vec<f64> = acc.xyz.iter().flatten().copied().collect();
        d.set_item("xyz", PyArray1::from_vec(py, xyz).reshape([h, w, 3])?)?;
        d.set_item("dropped", acc.dropped)?;
        match &st.spectral_bands {
            Some(edges) => {
                d.set_item("bins", PyArray1::from_vec(py, acc.bins).reshape([h, w, edges.len() - 1])?)?
            }
            None => d.set_item("bins", py.None())?,
        }
        st
    };
    let win = st.window();
    match &st.spectral_bands {
        Some(edges) => d.set_item("edges", PyArray1::from_vec(py, edges.clone()))?,
        None => d.set_item("edges", py.None())?,
    }
    d.set_item("window", (win.x, win.y, win.width, win.height))?;
    d.set_item("spp", st.spp)?;
    // What `_truth_finish` turns the sums into linear sRGB with (`color::film`), row-major; with
    // `xyz`, the identity (the sums' XYZ as it is).
    let m = if xyz {
        glam::DMat3::IDENTITY
    } else {
        st.display_matrix(color::film::CameraView::from_flag(camera_to_display)).map_err(value)?.transpose()
    };
    d.set_item("display", m.to_cols_array().to_vec())?;
    Ok(d)
}

/// The image (and bands) of sums over `spp` samples, exactly as `truth` finishes its own:
/// `xyz` float64 (h, w, 3), `bins` float64 (h, w, B) or None. Returns the float32 (h, w, 3)
/// linear sRGB image, or (image, bands) with bins.
#[pyfunction(name = "_truth_finish")]
#[pyo3(signature = (xyz, spp, bins = None, display = None))]
fn truth_finish<'py>(
    py: Python<'py>,
    xyz: PyReadonlyArrayDyn<'py, f64>,
    spp: i128,
    bins: Option<PyReadonlyArrayDyn<'py, f64>>,
    display: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    let spp = whole("spp", spp, 1)?;
    let display = match display {
        None => color::RgbColorSpace::srgb().from_xyz,
        Some(m) if m.len() == 9 && m.iter().all(|v| v.is_finite()) => {
            glam::DMat3::from_cols_array(&[m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8]]).transpose()
        }
        Some(m) => {
            return Err(PyValueError::new_err(format!(
                "display: expected the 9 finite entries of a 3×3 matrix, row by row, got {m:?}"
            )));
        }
    };
    let shape = xyz.shape().to_vec();
    let [h, w, 3] = shape[..] else {
        return Err(PyValueError::new_err(format!("xyz: expected shape (h, w, 3), got {shape:?}")));
    };
    let sums: Vec<[f64; 3]> = xyz
        .as_array()
        .iter()
        .copied()
        .collect::<Vec<_>>()
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    let (bin_vals, nb) = match &bins {
        Some(b) => {
            let bs = b.shape().to_vec();
            if bs.len() != 3 || bs[0] != h || bs[1] != w {
                return Err(PyValueError::new_err(format!("bins: expected shape ({h}, {w}, B), got {bs:?}")));
            }
            (b.as_array().iter().copied().collect::<Vec<_>>(), Some(bs[2]))
        }
        None => (Vec::new(), None),
    };
    let (rgb, bands) = finish(w as u32, h as u32, &sums, &bin_vals, spp, display);
    let img = rgb_array(py, w as u32, h as u32, rgb)?;
    match nb {
        None => Ok(img.into_any()),
        Some(nb) => {
            let bands = PyArray1::from_vec(py, bands).reshape([h, w, nb])?;
            Ok((img, bands).into_pyobject(py)?.into_any())
        }
    }
}

/// An (H, W, 3) float32 or float64 array as an image, or a `ValueError` naming `what`.
fn image_arg(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<compare::Image> {
    let bad = |got: String| {
        PyValueError::new_err(format!(
            "{what}: expected a numpy float32 or float64 array of shape (H, W, 3), got {got}"
        ))
    };
    // A finite float64 beyond float32's range, which narrowing would make inf: written as such
    // by `write_image`, or reported by `diff` as a non-finite pixel the caller never gave.
    let mut too_big: Option<(usize, f64)> = None;
    let (shape, data): (Vec<usize>, Vec<f32>) = if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f32>>() {
        (a.shape().to_vec(), a.as_array().iter().copied().collect())
    } else if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f64>>() {
        let data = a
            .as_array()
            .iter()
            .enumerate()
            .map(|(i, &v)| {
                let f = v as f32;
                if too_big.is_none() && v.is_finite() && f.is_infinite() {
                    too_big = Some((i, v));
                }
                f
            })
            .collect();
        (a.shape().to_vec(), data)
    } else if let Ok(a) = obj.extract::<Bound<'_, numpy::PyUntypedArray>>() {
        return Err(bad(format!("dtype {} with shape {:?}", a.dtype(), a.shape())));
    } else {
        return Err(bad(format!("a {}", args::type_name(obj))));
    };
    match shape[..] {
        [h, w, 3] if h > 0 && w > 0 && h <= u32::MAX as usize && w <= u32::MAX as usize => {
            if let Some((i, v)) = too_big {
                let p = i / 3;
                return Err(PyValueError::new_err(format!(
                    "{what}: pixel (x {}, y {}) channel {} is {}, beyond float32's range (±{:e})",
                    p % w,
                    p / w,
                    i % 3,
                    args::short(v),
                    f32::MAX
                )));
            }
            compare::Image::new(
                w as u32,
                h as u32,
                data.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect(),
            )
            .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))
        }
        _ => Err(bad(format!("float array of shape {shape:?}"))),
    }
}

/// `Ok` when every pixel of `img` is finite, else a `ValueError` naming the argument `what`
/// (the statistics' own message names "reference" or "test").
fn finite_image(what: &str, img: &compare::Image) -> PyResult<()> {
    let w = img.size().0 as usize;
    match img.data.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
        None => Ok(()),
        Some(i) => Err(PyValueError::new_err(format!(
            "{what}: pixel (x {}, y {}) is not finite: {:?}",
            i % w,
            i / w,
            img.data[i]
        ))),
    }
}

/// How far image `b` is from the reference `a` (both linear sRGB arrays of shape (H, W, 3),
/// compared pixel for pixel, or files): the statistics `spectra diff --json` prints, as a dict:
/// `width`, `height`, `white_luminance`, and per-pixel `delta_e2000`, `mae_linear`, `mae_srgb`,
/// each a dict of `mean`, `median`, `p95`, `p99`, `max`; and `region`.
///
/// a, b: an array, or a file (str or os.PathLike) read as `spectra diff` reads it (a spectral
/// EXR integrated with CIE 1931 against its white, else D65). Files are lined up as `spectra
/// diff` lines them up, by where their pixels lie in their frame (`read_image(placement=True)`):
/// two crops of one frame, or a crop and the full frame, are compared over the pixels both
/// hold, and `region` is that part of the frame, `{"frame": [W, H], "x", "y", "width",
/// "height"}` (the maps count from its top-left); None where the images hold the same pixels,
/// and for arrays. Crops of different frames, or sharing no pixel, are a ValueError saying
/// where each lies.
///
/// white_y: the luminance of the CIELAB reference white (D65 chromaticity), 1 by default.
/// flip: also NVIDIA's FLIP (its reference C++ code, as `spectra diff --metric flip`):
/// "ldr" or "hdr" (HDR-FLIP over a range of exposures, tone mapped); adds `flip` (the same
/// statistics, `mean` as FLIP computes it), `flip_kind`, `flip_ppd` and `flip_exposures`
/// (HDR-FLIP's `start`, `stop`, `count` and `tone_mapper`; None for LDR-FLIP).
/// flip_ppd: FLIP's pixels per degree (default FLIP's, 67.0); only with `flip`.
/// flip_start_exposure / flip_stop_exposure: HDR-FLIP's exposure range in stops (default, as
/// FLIP's tool: from `a`'s brightest pixel and median luminance; give both for a black `a`);
/// flip_exposures: their number (default ⌈stop − start⌉, at least 2); flip_tone_mapper: "aces"
/// (default), "reinhard" or "hable". Only with flip="hdr" (`--flip-start-exposure` …).
/// maps: also return the per-pixel maps, float64 arrays of shape (H, W): `delta_e2000_map`,
/// `mae_linear_map` and `mae_srgb_map` (the mean absolute difference over R, G, B), and
/// `flip_map` (float32) with `flip`.
#[pyfunction]
#[pyo3(signature = (a, b, *, white_y = 1.0, flip = None, flip_ppd = None, maps = false, flip_start_exposure = None,
                    flip_stop_exposure = None, flip_exposures = None, flip_tone_mapper = None))]
#[allow(clippy::too_many_arguments)] // Python's keyword arguments, each its own option
fn diff<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::white_y)] white_y: f64,
    #[pyo3(from_py_with = args::flip)] flip: Option<String>,
    #[pyo3(from_py_with = args::flip_ppd)] flip_ppd: Option<f32>,
    #[pyo3(from_py_with = args::maps)] maps: bool,
    #[pyo3(from_py_with = args::flip_start_exposure)] flip_start_exposure: Option<f32>,
    #[pyo3(from_py_with = args::flip_stop_exposure)] flip_stop_exposure: Option<f32>,
    #[pyo3(from_py_with = args::flip_exposures)] flip_exposures: Option<i128>,
    #[pyo3(from_py_with = args::flip_tone_mapper)] flip_tone_mapper: Option<String>,
) -> PyResult<Bound<'py, PyAny>> {
    let (reference, test, region) = diff_inputs(py, a, b)?;
    if reference.size() != test.size() {
        let (ra, rb) = (reference.size(), test.size());
        return Err(PyValueError::new_err(format!(
            "a and b differ in size: a is {}×{} (W×H), b is {}×{}",
            ra.0, ra.1, rb.0, rb.1
        )));
    }
    finite_image("a", &reference)?;
    finite_image("b", &test)?;
    let hdr = match flip.as_deref().map(str::to_ascii_lowercase).as_deref() {
        None => None,
        Some("ldr") => Some(false),
        Some("hdr") => Some(true),
        Some(_) => {
            return Err(PyValueError::new_err(format!(
                "flip '{}': FLIP can be 'ldr' or 'hdr'",
                flip.unwrap_or_default()
            )));
        }
    };
    let hdr_given: Vec<&str> = [
        ("flip_start_exposure", flip_start_exposure.is_some()),
        ("flip_stop_exposure", flip_stop_exposure.is_some()),
        ("flip_exposures", flip_exposures.is_some()),
        ("flip_tone_mapper", flip_tone_mapper.is_some()),
    ]
    .into_iter()
    .filter_map(|(k, given)| given.then_some(k))
    .collect();
    if hdr.is_none() && (flip_ppd.is_some() || !hdr_given.is_empty()) {
        let k = if flip_ppd.is_some() { "flip_ppd" } else { hdr_given[0] };
        return Err(PyValueError::new_err(format!(
            "{k} is a FLIP option: it needs flip='ldr' or flip='hdr'"
        )));
    }
    if hdr == Some(false) && !hdr_given.is_empty() {
        return Err(PyValueError::new_err(format!(
            "{} set HDR-FLIP, and flip='ldr' was chosen",
            hdr_given.join(", ")
        )));
    }
    let ppd = flip_ppd.unwrap_or(compare::flip::DEFAULT_PIXELS_PER_DEGREE);
    let (lo, hi) = compare::flip::PPD_RANGE;
    if !(lo..=hi).contains(&ppd) {
        return Err(PyValueError::new_err(format!(
            "flip_ppd {}: pixels per degree must be between {lo} and {hi}",
            args::short(f64::from(ppd))
        )));
    }
    let (lo, hi) = compare::flip::EXPOSURE_RANGE;
    for (k, v) in [("flip_start_exposure", flip_start_exposure), ("flip_stop_exposure", flip_stop_exposure)] {
        if let Some(v) = v
            && !(lo..=hi).contains(&v)
        {
            return Err(PyValueError::new_err(format!(
                "{k} {}: an exposure must lie within {lo}…{hi} stops",
                args::short(f64::from(v))
            )));
        }
    }
    if let (Some(a), Some(b)) = (flip_start_exposure, flip_stop_exposure) {
        if a > b {
            return Err(PyValueError::new_err(format!(
                "flip_start_exposure {a} must not exceed flip_stop_exposure {b}"
            )));
        }
        if b - a > compare::flip::MAX_EXPOSURE_SPAN {
            return Err(PyValueError::new_err(format!(
                "flip_start_exposure {a}, flip_stop_exposure {b}: the span must be at most {} stops",
                compare::flip::MAX_EXPOSURE_SPAN
            )));
        }
    }
    let exposures = match flip_exposures {
        None => None,
        Some(n) if (2..=1000).contains(&n) => Some(n as u32),
        Some(n) => {
            return Err(PyValueError::new_err(format!(
                "flip_exposures {n}: HDR-FLIP's number of exposures must be 2 to 1000"
            )));
        }
    };
    let hdr_opts = compare::flip::HdrOptions {
        start_exposure: flip_start_exposure,
        stop_exposure: flip_stop_exposure,
        exposures,
        tone_mapper: match &flip_tone_mapper {
            None => Default::default(),
            Some(t) => compare::flip::ToneMapper::by_name(t)
                .map_err(|e| PyValueError::new_err(format!("flip_tone_mapper: {e}")))?,
        },
    };
    let (lo, hi) = (compare::diff::MIN_WHITE_LUMINANCE, compare::diff::MAX_WHITE_LUMINANCE);
    if !(lo..=hi).contains(&white_y) {
        return Err(PyValueError::new_err(format!(
            "white_y {white_y:e}: the white luminance must be between {lo:e} and {hi:e}"
        )));
    }
    let (json, dm, flip_map) = py.detach(move || {
        fork_safe(move || -> Result<_, Fail> {
            let dm = compare::DiffMaps::compute(
                &reference,
                &test,
                compare::DiffOptions { white_luminance: white_y },
            )
            .map_err(value)?;
            let mut v = serde_json::to_value(dm.summary()).map_err(runtime)?;
            v.as_object_mut()
                .expect("a struct serialises to an object")
                .insert("region".into(), spectra::cmd::diff::region_json(region.as_ref()));
            let mut flip_map = None;
            if let Some(hdr) = hdr {
                let map = if hdr {
                    compare::flip::hdr_flip(&reference, &test, ppd, &hdr_opts).map_err(|e| {
                        // The tracer's messages name the command's flags: these are Python's.
                        let m = e
                            .to_string()
                            .replace(
                                "(`spectra diff --flip-start-exposure S --flip-stop-exposure E`)",
                                "(flip_start_exposure=S, flip_stop_exposure=E)",
                            )
                            .replace("--flip-start-exposure", "flip_start_exposure=")
                            .replace("--flip-stop-exposure", "flip_stop_exposure=")
                            .replace("or use LDR-FLIP", "or use LDR-FLIP (flip='ldr')");
                        value(anyhow::anyhow!(if m.contains("HDR-FLIP") {
                            m
                        } else {
                            format!("HDR-FLIP: {m}")
                        }))
                    })?
                } else {
                    compare::flip::ldr_flip(&reference, &test, ppd).context("LDR-FLIP").map_err(value)?
                };
                let vals: Vec<f64> = map.values.iter().map(|&x| f64::from(x)).collect();
                // The mean as FLIP's own tool computes it, as `spectra diff` reports it.
                let st = color::metrics::Stats::of(&vals)
                    .map(|st| color::metrics::Stats { mean: map.mean(), ..st })
                    .ok_or_else(|| runtime(anyhow::anyhow!("FLIP returned no pixels")))?;
                let o = v.as_object_mut().expect("a struct serialises to an object");
                o.insert("flip".into(), serde_json::to_value(st).map_err(runtime)?);
                o.insert("flip_kind".into(), if hdr { "hdr" } else { "ldr" }.into());
                o.insert("flip_exposures".into(), serde_json::to_value(map.exposures).map_err(runtime)?);
                o.insert("flip_ppd".into(), ppd.into());
                flip_map = Some(map.values);
            }
            Ok((serde_json::to_string(&v).map_err(runtime)?, dm, flip_map))
        })
    })?;
    let d = py.import("json")?.call_method1("loads", (json,))?;
    if maps {
        let (w, h) = (dm.width as usize, dm.height as usize);
        d.set_item("delta_e2000_map", PyArray1::from_vec(py, dm.delta_e2000).reshape([h, w])?)?;
        d.set_item("mae_linear_map", PyArray1::from_vec(py, dm.abs_linear).reshape([h, w])?)?;
        d.set_item("mae_srgb_map", PyArray1::from_vec(py, dm.abs_srgb).reshape([h, w])?)?;
        if let Some(f) = flip_map {
            d.set_item("flip_map", PyArray1::from_vec(py, f).reshape([h, w])?)?;
        }
    }
    Ok(d)
}

/// `diff`'s reference and test: arrays as given, pixel for pixel; files (a str or an
/// os.PathLike) read as `spectra diff` reads them and lined up as it lines them up, by where
/// their pixels lie in their frame (two crops of one size at different places were compared
/// pixel for pixel; a crop with its full frame refused for their sizes), with the region
/// compared when it is not simply both images. An array holds the whole of its frame.
fn diff_inputs(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
) -> PyResult<(compare::Image, compare::Image, Option<compare::Region>)> {
    let is_file = |o: &Bound<'_, PyAny>| {
        o.is_instance_of::<pyo3::types::PyString>() || o.hasattr("__fspath__").unwrap_or(false)
    };
    if !is_file(a) && !is_file(b) {
        return Ok((image_arg("a", a)?, image_arg("b", b)?, None));
    }
    let input = |what: &str,
                 role: &str,
                 o: &Bound<'_, PyAny>|
     -> PyResult<(compare::Image, compare::Placement)> {
        if is_file(o) {
            let path = args::path(o, what)?;
            let (img, placed, _) = py.detach(|| {
                fork_safe(|| spectra::cmd::diff::read_input(&path, role, None, None, false).map_err(value))
            })?;
            Ok((img, placed))
        } else {
            let img = image_arg(what, o)?;
            let placed = compare::Placement::whole(img.size());
            Ok((img, placed))
        }
    };
    let (reference, rp) = input("a", "reference", a)?;
    let (test, tp) = input("b", "test", b)?;
    let shown = |o: &Bound<'_, PyAny>, what: &str| {
        if is_file(o) {
            args::path(o, what).map(|p| p.display().to_string()).unwrap_or_default()
        } else {
            format!("the array {what}")
        }
    };
    compare::align(reference, rp, test, tp)
        .with_context(|| format!("comparing {} with {}", shown(a, "a"), shown(b, "b")))
        .map_err(|e| value(e).into())
}

/// An array of any shape (…, 3) of float32/float64 as f64 values and its leading shape, or a
/// `ValueError` naming `what`.
fn triples(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<(Vec<usize>, Vec<f64>)> {
    let bad = |got: String| {
        PyValueError::new_err(format!("{what}: expected a float array of shape (..., 3), got {got}"))
    };
    let np = obj.py().import("numpy")?;
    // Integer arrays, and nested lists or tuples of numbers of any depth, as float64 (what
    // `npt.ArrayLike` promises); bool, complex, string and object arrays are refused.
    let converted;
    let obj = if let Ok(a) = obj.cast::<numpy::PyUntypedArray>() {
        match a.dtype().kind() {
            b'i' | b'u' => {
                converted = np.call_method1("asarray", (obj, "float64"))?;
                &converted
            }
            _ => obj,
        }
    } else if obj.is_instance_of::<pyo3::types::PyList>() || obj.is_instance_of::<pyo3::types::PyTuple>() {
        let t = args::type_name(obj);
        converted = np.call_method1("asarray", (obj, "float64")).map_err(|e| {
            bad(format!("a {t} that is not a rectangular array of numbers ({})", e.value(obj.py())))
        })?;
        &converted
    } else {
        obj
    };
    let (shape, data): (Vec<usize>, Vec<f64>) = if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f64>>() {
        (a.shape().to_vec(), a.as_array().iter().copied().collect())
    } else if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f32>>() {
        (a.shape().to_vec(), a.as_array().iter().map(|&v| f64::from(v)).collect())
    } else if let Ok(a) = obj.extract::<Bound<'_, numpy::PyUntypedArray>>() {
        return Err(bad(format!("dtype {} with shape {:?}", a.dtype(), a.shape())));
    } else {
        return Err(bad(format!("a {}", args::type_name(obj))));
    };
    if shape.last() != Some(&3) {
        return Err(bad(format!("shape {shape:?}")));
    }
    Ok((shape[..shape.len() - 1].to_vec(), data))
}

/// A 1-D array of wavelengths in nm (float), or a `ValueError` naming `what`.
fn wavelengths_arg(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let v: Vec<f64> = if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f64>>() {
        if a.ndim() != 1 {
            return Err(PyValueError::new_err(format!(
                "{what}: expected a 1-D array of wavelengths in nm, got shape {:?}",
                a.shape()
            )));
        }
        a.as_array().iter().copied().collect()
    } else if let Ok(v) = obj.extract::<Vec<f64>>() {
        v
    } else {
        return Err(PyValueError::new_err(format!(
            "{what}: expected a 1-D sequence or float array of wavelengths in nm"
        )));
    };
    if let Some((i, l)) = v.iter().enumerate().find(|(_, l)| !(l.is_finite() && **l > 0.0 && **l < 1e5)) {
        return Err(PyValueError::new_err(format!(
            "{what}[{i}] = {l}: a wavelength must be a positive, finite number of nm"
        )));
    }
    Ok(v)
}

/// Jakob–Hanika upsampling of linear RGB reflectances, vectorised: `rgb` is a float array of
/// shape (..., 3) with components in [0, 1] in colour space `space` ("srgb", "p3", "rec2020",
/// "acescg"; the space's fitted table, cached as `spectra lut` caches it). Returns the sigmoid
/// polynomial coefficients (c0, c1, c2) of shape (..., 3) float64, λ in nm —
/// s(λ) = ½ + x / (2√(1 + x²)), x = (c0·λ + c1)·λ + c2 — exactly those the renderers use; with
/// `wavelengths` (1-D, nm) the tuple (coefficients, spectra of shape (..., L)).
#[pyfunction]
#[pyo3(signature = (rgb, space = "srgb".to_string(), *, wavelengths = None),
       text_signature = "(rgb, space='srgb', *, wavelengths=None)")]
fn upsample<'py>(
    py: Python<'py>,
    rgb: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::space)] space: String,
    wavelengths: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (lead, data) = triples("rgb", rgb)?;
    if let Some((i, v)) = data.iter().enumerate().find(|(_, v)| !(v.is_finite() && (0.0..=1.0).contains(*v)))
    {
        return Err(PyValueError::new_err(format!(
            "rgb: element {} (flat index {i}) is {v}: a reflectance's components must be finite and within [0, 1]",
            i / 3
        )));
    }
    let lambda = wavelengths.map(|w| wavelengths_arg("wavelengths", w)).transpose()?;
    let n_lambda = lambda.as_ref().map(Vec::len);
    let cs =
        color::RgbColorSpace::by_name(&space).map_err(|e| PyValueError::new_err(format!("space: {e}")))?;
    let (coeffs, spectra) = py.detach(move || -> Result<_, Fail> {
        let table = color::upsample::table_for(&cs).map_err(runtime)?;
        let polys: Vec<color::upsample::SigmoidPolynomial> =
            data.chunks_exact(3).map(|p| table.fetch([p[0], p[1], p[2]])).collect();
        let coeffs: Vec<f64> = polys.iter().flat_map(|p| p.c).collect();
        let spectra = lambda
            .as_ref()
            .map(|l| polys.iter().flat_map(|p| l.iter().map(|&x| p.eval(x))).collect::<Vec<f64>>());
        Ok((coeffs, spectra))
    })?;
    let mut shape = lead.clone();
    shape.push(3);
    let c = PyArray1::from_vec(py, coeffs).reshape(shape)?;
    match (spectra, n_lambda) {
        (Some(sp), Some(n)) => {
            let mut shape = lead;
            shape.push(n);
            Ok((c, PyArray1::from_vec(py, sp).reshape(shape)?).into_pyobject(py)?.into_any())
        }
        _ => Ok(c.into_any()),
    }
}

/// An observer's three colour-matching functions (or a camera's sensitivities) at
/// `wavelengths` (1-D, nm), as spectra uses them: float64 of shape (L, 3). `name`: "cie1931",
/// "cie1964", a camera ("nikon_d5100", "canon_eos_r5", … `OBSERVERS`) or a file (CSV of
/// wavelength and three columns, or rawtoaces camera JSON).
#[pyfunction]
fn observer<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::name)] name: String,
    wavelengths: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let l = wavelengths_arg("wavelengths", wavelengths)?;
    let o = color::Observer::by_name(&name).map_err(value)?;
    let v: Vec<f64> = l.iter().flat_map(|&x| o.eval(x)).collect();
    PyArray1::from_vec(py, v).reshape([l.len(), 3])
}

/// The 24 ColorChecker Classic patches (N. Ohta's reflectances, chart order) seen by an
/// observer under an illuminant: float64 (24, 3), each channel ∫ sensitivity·R·E dλ at 1 nm
/// over 360–830 nm (`Observer::response`, what white balance and the camera fit integrate).
/// balanced=True divides by the perfect white's response (white = (1, 1, 1)).
#[pyfunction]
#[pyo3(signature = (observer, illuminant = "D65".to_string(), *, balanced = false),
       text_signature = "(observer, illuminant='D65', *, balanced=False)")]
fn chart<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::observer_name)] observer: String,
    #[pyo3(from_py_with = args::illuminant)] illuminant: String,
    #[pyo3(from_py_with = args::balanced)] balanced: bool,
) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
    let o = color::Observer::by_name(&observer).map_err(value)?;
    let e = color::illuminant::by_name(&illuminant).map_err(value)?;
    let white = if balanced { o.white_balance(&e) } else { [1.0; 3] };
    let v: Vec<f64> = color::data::colorchecker::SPECTRA
        .iter()
        .flat_map(|t| {
            let r = o.response(&color::Spectrum::from_table(t), &e);
            [r[0] / white[0], r[1] / white[1], r[2] / white[2]]
        })
        .collect();
    PyArray1::from_vec(py, v).reshape([color::data::colorchecker::SPECTRA.len(), 3])
}

/// An illuminant's relative spectral power at `wavelengths` (1-D, nm), float64 of shape (L,):
/// "D65", "A", "F1"…"F12", "LED-B1"…, "5000K" / "blackbody:5000", as tabulated (D series 100
/// at 560 nm).
#[pyfunction]
fn illuminant<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::illuminant_name)] name: String,
    wavelengths: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let l = wavelengths_arg("wavelengths", wavelengths)?;
    let s = color::illuminant::by_name(&name).map_err(value)?;
    Ok(PyArray1::from_vec(py, s.sample(&l)))
}

/// Reads an EXR (linear) or PNG (sRGB-decoded) file as `spectra diff` reads it: a float32
/// array of shape (height, width, 3) of the pixels it holds. An EXR cropped from a larger frame
/// (its data window inside its display window, as `truth --crop` writes) gives the crop alone;
/// placement=True returns `(array, placement)` as well, where `placement` says where those
/// pixels lie: `{"frame": (W, H), "x": x, "y": y, "width": w, "height": h}` (the crop's
/// top-left pixel in the frame, negative for overscan; a PNG or a whole-frame EXR is at (0, 0)
/// and its frame's size). `diff` of two files lines crops up by it, as `spectra diff` does.
#[pyfunction]
#[pyo3(signature = (path, *, placement = false))]
fn read_image<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::path_arg)] path: PathBuf,
    #[pyo3(from_py_with = args::placement)] placement: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let (img, placed) = py.detach(|| compare::read_image_placed(&path).map_err(value))?;
    let (w, h) = img.size();
    let array = rgb_array(py, w, h, img.data.into_iter().flatten().collect())?.into_any();
    if !placement {
        return Ok(array);
    }
    let d = pyo3::types::PyDict::new(py);
    d.set_item("frame", placed.frame)?;
    d.set_item("x", placed.origin.0)?;
    d.set_item("y", placed.origin.1)?;
    d.set_item("width", placed.size.0)?;
    d.set_item("height", placed.size.1)?;
    Ok((array, d).into_pyobject(py)?.into_any())
}

/// Writes an (H, W, 3) float32/float64 linear RGB array as `spectra truth` and `spectra render`
/// write images: `.exr` (float32, linear) or `.png` (sRGB-encoded, clipped, 8-bit), atomically
/// (the file is complete or absent). A `ValueError` names a bad array or extension.
#[pyfunction]
fn write_image(
    py: Python<'_>,
    #[pyo3(from_py_with = args::path_arg)] path: PathBuf,
    image: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let img = image_arg("image", image)?;
    // A missing directory is a missing file (FileNotFoundError), as `open()` raises it.
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
        && !dir.is_dir()
    {
        return Err(PyFileNotFoundError::new_err(format!(
            "writing {}: the directory {} does not exist",
            path.display(),
            dir.display()
        )));
    }
    py.detach(|| {
        compare::io::write_image(&path, &img, Default::default()).map_err(|e| {
            // The writer's messages name the file; named once.
            let (m, p) = (e.to_string(), path.display().to_string());
            value(anyhow::anyhow!(if m.starts_with(&p) {
                format!("writing {m}")
            } else {
                format!("writing {p}: {m}")
            }))
        })
    })?;
    Ok(())
}

/// `spectra eval`'s arguments from a command line (`["eval", "--out", DIR, …]`), parsed by
/// the CLI's own parser; a `ValueError` with clap's message otherwise.
fn eval_args(argv: Vec<String>) -> PyResult<spectra::cmd::eval::Args> {
    use clap::Parser;
    #[derive(Parser)]
    struct Wrap {
        #[command(flatten)]
        inner: spectra::cmd::eval::Args,
    }
    Wrap::try_parse_from(argv).map(|w| w.inner).map_err(|e| {
        let text = e.render().to_string();
        PyValueError::new_err(text.trim_start_matches("error: ").lines().next().unwrap_or("").to_string())
    })
}

/// A planned truth of `_eval_plan` as a dict, and back.
fn job_dict<'py>(
    py: Python<'py>,
    p: &spectra::eval::PlannedTruth,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let d = pyo3::types::PyDict::new(py);
    d.set_item("case", &p.case)?;
    d.set_item("seed", p.job.seed)?;
    d.set_item("width", p.job.width)?;
    d.set_item("height", p.job.height)?;
    d.set_item("spp", p.job.spp)?;
    d.set_item("range", (p.job.range.min, p.job.range.max))?;
    Ok(d)
}

fn job_of(d: &Bound<'_, pyo3::types::PyDict>) -> PyResult<spectra::eval::PlannedTruth> {
    let get = |k: &str| -> PyResult<Bound<'_, PyAny>> {
        d.get_item(k)?.ok_or_else(|| PyValueError::new_err(format!("job: no '{k}'")))
    };
    let (lo, hi): (f64, f64) = get("range")?.extract()?;
    let range =
        color::WavelengthRange::new(lo, hi).map_err(|e| PyValueError::new_err(format!("job range: {e}")))?;
    Ok(spectra::eval::PlannedTruth {
        case: get("case")?.extract()?,
        seed: get("seed")?.extract()?,
        job: spectra::eval::measure::TruthJob {
            width: get("width")?.extract()?,
            height: get("height")?.extract()?,
            spp: get("spp")?.extract()?,
            seed: get("seed")?.extract()?,
            range,
        },
    })
}

/// The ground truths `spectra eval ARGV` would render and its truth cache (`--truth-cache`,
/// required) does not hold in full: a list of dicts (`case`, `seed`, `width`, `height`, `spp`,
/// `range`), in the evaluation's order.
#[pyfunction(name = "_eval_plan")]
fn eval_plan<'py>(py: Python<'py>, argv: Vec<String>) -> PyResult<Vec<Bound<'py, pyo3::types::PyDict>>> {
    let args = eval_args(argv)?;
    let plan = py.detach(|| -> Result<Vec<spectra::eval::PlannedTruth>, Fail> {
        let cfg = spectra::cmd::eval::config(&args).map_err(value)?;
        let dir = cfg.truth_cache.clone().ok_or_else(|| value(anyhow::anyhow!("--truth-cache is needed")))?;
        let cache = spectra::cmd::truth_cache::TruthCache::open(&dir).map_err(value)?;
        let table = setup::load_table(cfg.table.as_deref()).map_err(value)?;
        let mut out = Vec::new();
        for p in spectra::eval::truth_plan(&cfg).map_err(value)? {
            let c = cfg.case(&p.case).map_err(value)?;
            let have =
                spectra::eval::measure::cached_samples(&c.scene, &table, p.job, &cache).map_err(runtime)?;
            if have < p.job.spp {
                out.push(p);
            }
        }
        Ok(out)
    })?;
    plan.iter().map(|p| job_dict(py, p)).collect()
}

/// The sums of samples `sample_offset` … +`spp`−1 of one planned truth (`_eval_plan`'s dict),
/// on `threads` threads: a dict of `xyz` (float64 (h, w, 3)) and `dropped`.
#[pyfunction(name = "_eval_truth_sums")]
fn eval_truth_sums<'py>(
    py: Python<'py>,
    argv: Vec<String>,
    job: &Bound<'py, pyo3::types::PyDict>,
    sample_offset: u32,
    spp: u32,
    threads: usize,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let args = eval_args(argv)?;
    let p = job_of(job)?;
    let acc = py.detach(|| -> Result<truth::Accumulator, Fail> {
        let cfg = spectra::cmd::eval::config(&args).map_err(value)?;
        let table = setup::load_table(cfg.table.as_deref()).map_err(value)?;
        let c = cfg.case(&p.case).map_err(value)?;
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build().map_err(runtime)?;
        // `ray.cancel` interrupts the task as Ctrl-C would.
        interruptible(|cancel| {
            pool.install(|| {
                spectra::eval::measure::truth_piece(&c.scene, &table, p.job, sample_offset, spp, cancel)
            })
            .map_err(runtime)
        })
    })?;
    let d = pyo3::types::PyDict::new(py);
    let (w, h) = (p.job.width as usize, p.job.height as usize);
    let xyz: Vec<f64> = acc.xyz.iter().flatten().copied().collect();
    d.set_item("xyz", PyArray1::from_vec(py, xyz).reshape([h, w, 3])?)?;
    d.set_item("dropped", acc.dropped)?;
    Ok(d)
}

/// Stores the sums of all samples of one planned truth in the evaluation's truth cache, as
/// `spectra eval` stores its own.
#[pyfunction(name = "_eval_truth_store")]
fn eval_truth_store<'py>(
    py: Python<'py>,
    argv: Vec<String>,
    job: &Bound<'py, pyo3::types::PyDict>,
    xyz: PyReadonlyArrayDyn<'py, f64>,
    dropped: u64,
) -> PyResult<()> {
    let args = eval_args(argv)?;
    let p = job_of(job)?;
    let (w, h) = (p.job.width as usize, p.job.height as usize);
    if xyz.shape() != [h, w, 3] {
        return Err(PyValueError::new_err(format!(
            "xyz: expected shape ({h}, {w}, 3), got {:?}",
            xyz.shape()
        )));
    }
    let sums: Vec<[f64; 3]> = xyz
        .as_array()
        .iter()
        .copied()
        .collect::<Vec<_>>()
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]])
        .collect();
    py.detach(|| -> Result<(), Fail> {
        let cfg = spectra::cmd::eval::config(&args).map_err(value)?;
        let dir = cfg.truth_cache.clone().ok_or_else(|| value(anyhow::anyhow!("--truth-cache is needed")))?;
        let cache = spectra::cmd::truth_cache::TruthCache::open(&dir).map_err(value)?;
        let table = setup::load_table(cfg.table.as_deref()).map_err(value)?;
        let c = cfg.case(&p.case).map_err(value)?;
        let acc = truth::Accumulator { done: p.job.spp, xyz: sums, bins: Vec::new(), dropped };
        spectra::eval::measure::store_truth(&c.scene, &table, p.job, &acc, &cache).map_err(runtime)
    })?;
    Ok(())
}

/// Runs `spectra eval ARGV` here (its progress and tables on stderr/stdout, as the command
/// prints them). Ctrl-C stops it (KeyboardInterrupt) as it stops the command.
#[pyfunction(name = "_eval_run")]
fn eval_run(py: Python<'_>, argv: Vec<String>) -> PyResult<()> {
    let args = eval_args(argv)?;
    let (tx, rx) = std::sync::mpsc::channel();
    let worker = std::thread::spawn(move || {
        let _ = tx.send(spectra::cmd::eval::run(args));
    });
    let result = py.detach(move || {
        loop {
            match rx.recv_timeout(SIGNAL_POLL) {
                Ok(r) => return Ok(r),
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                    if let Err(e) = Python::attach(|py| py.check_signals()) {
                        // The command's own Ctrl-C: every long loop polls this token.
                        color::cancel::cancel();
                        let _ = rx.recv();
                        color::cancel::token().store(false, std::sync::atomic::Ordering::Relaxed);
                        return Err(e);
                    }
                }
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                    return Ok(Err(anyhow::anyhow!("the evaluation ended without a result")));
                }
            }
        }
    });
    let _ = worker.join();
    match result? {
        Ok(()) => Ok(()),
        Err(e) => Err(Fail::Runtime(e).into()),
    }
}

/// The extension module: `spectra/__init__.py` re-exports it.
/// The process the module was loaded in: rayon's global thread pool lives there, and its
/// threads do not survive `fork()` (a child made by multiprocessing's default start method on
/// Linux would wait for them forever).
static LOADED_IN: std::sync::OnceLock<u32> = std::sync::OnceLock::new();

/// Runs `f`, whose rayon work goes to the global pool in the process the module was loaded in
/// and to a pool of its own in a forked child.
fn fork_safe<R: Send>(f: impl FnOnce() -> Result<R, Fail> + Send) -> Result<R, Fail> {
    if LOADED_IN.get().is_none_or(|&pid| pid == std::process::id()) {
        return f();
    }
    rayon::ThreadPoolBuilder::new().build().map_err(runtime)?.install(f)
}

#[pymodule]
fn _spectra(m: &Bound<'_, PyModule>) -> PyResult<()> {
    LOADED_IN.get_or_init(std::process::id);
    m.add_class::<Scene>()?;
    m.add_class::<Renderer>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(truth_image, m)?)?;
    m.add_function(wrap_pyfunction!(truth_sums, m)?)?;
    m.add_function(wrap_pyfunction!(truth_finish, m)?)?;
    m.add_function(wrap_pyfunction!(diff, m)?)?;
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add_function(wrap_pyfunction!(write_image, m)?)?;
    m.add_function(wrap_pyfunction!(eval_plan, m)?)?;
    m.add_function(wrap_pyfunction!(eval_truth_sums, m)?)?;
    m.add_function(wrap_pyfunction!(eval_truth_store, m)?)?;
    m.add_function(wrap_pyfunction!(eval_run, m)?)?;
    m.add_function(wrap_pyfunction!(upsample, m)?)?;
    m.add_function(wrap_pyfunction!(observer, m)?)?;
    m.add_function(wrap_pyfunction!(illuminant, m)?)?;
    m.add_function(wrap_pyfunction!(chart, m)?)?;
    m.add("OBSERVERS", color::Observer::names())?;
    m.add("ILLUMINANTS", color::illuminant::names())?;
    m.add("BUILTINS", scene::BUILTIN_NAMES.to_vec())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
