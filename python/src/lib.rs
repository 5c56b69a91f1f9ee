//! `spectra._spectra`: the Python extension module behind the `spectra` package (PyO3).
//!
//! Scenes, settings and media are resolved by the command line's own code
//! (`crates/spectra/src/cmd/setup.rs`, compiled in here as the module `setup`), so a render or a
//! truth from Python is the CLI's with the same options. Long work (loading, rendering,
//! path tracing, statistics) runs with the GIL released. Errors carry the Rust error's message
//! (its whole chain on one line, as the CLI prints it): bad values raise `ValueError`, a missing
//! file `FileNotFoundError`, failures of the work itself `RuntimeError`.

use anyhow::Context;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyFileNotFoundError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The CLI's scene, spectrum, water, medium and table options (not all of them are used here).
#[allow(dead_code)]
#[path = "../../crates/spectra/src/cmd/setup.rs"]
mod setup;

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
                let missing = e.chain().any(|c| {
                    c.downcast_ref::<std::io::Error>()
                        .is_some_and(|io| io.kind() == std::io::ErrorKind::NotFound)
                });
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
fn whole(what: &str, v: i64, min: i64) -> PyResult<u32> {
    if v < min || v > i64::from(u32::MAX) {
        return Err(PyValueError::new_err(format!(
            "{what} {v}: must be a whole number from {min} to {}",
            u32::MAX
        )));
    }
    Ok(v as u32)
}

/// `size=(W, H)`: both positive.
fn size_arg(size: (i64, i64)) -> PyResult<(u32, u32)> {
    let (w, h) = size;
    if w <= 0 || h <= 0 || w > i64::from(u32::MAX) || h > i64::from(u32::MAX) {
        return Err(PyValueError::new_err(format!(
            "size ({w}, {h}): width and height must be positive integers"
        )));
    }
    Ok((w as u32, h as u32))
}

/// `range=(MIN, MAX)` as the CLI's `--range MIN:MAX`.
fn range_arg(range: Option<(f64, f64)>) -> Option<String> {
    range.map(|(a, b)| format!("{a}:{b}"))
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

    fn __repr__(&self) -> String {
        format!(
            "<spectra.Scene {} ({} meshes, {} lights)>",
            self.inner.source,
            self.inner.meshes.len(),
            self.inner.lights.len()
        )
    }
}

/// The scene `obj` (a `Scene`), or a `TypeError`.
fn scene_of(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Arc<scene::Scene>> {
    match obj.extract::<PyRef<'_, Scene>>() {
        Ok(s) => Ok(s.inner.clone()),
        Err(_) => Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "{what} must be a spectra.Scene (from spectra.load), not {}",
            obj.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "that".into())
        ))),
    }
}

/// Loads a built-in scene by name (cornell, colorchecker, metamerism, iridescence, glass,
/// underwater, fog, tinted-fog) or a .gltf/.glb file, as `spectra render SCENE` does.
///
/// `allow_outside_scene_dir`: let the file's references (buffers, images, spectra,
/// environment maps) leave its folder (off by default, as on the command line).
#[pyfunction]
#[pyo3(signature = (path_or_builtin, allow_outside_scene_dir = false))]
fn load(py: Python<'_>, path_or_builtin: PathBuf, allow_outside_scene_dir: bool) -> PyResult<Scene> {
    let name = path_or_builtin
        .to_str()
        .ok_or_else(|| PyValueError::new_err(format!("{}: not a UTF-8 path", path_or_builtin.display())))?
        .to_string();
    let scene = py.detach(move || -> Result<scene::Scene, PyErr> {
        let lower = name.to_ascii_lowercase();
        let is_file = lower.ends_with(".gltf") || lower.ends_with(".glb");
        let args = setup::SceneArgs {
            scene: name.clone(),
            files: setup::SceneFileArgs { allow_outside_scene_dir },
            env: setup::EnvArgs::default(),
        };
        args.load().map_err(|e| {
            // The loader's message names the missing file; its type says so too.
            if is_file && std::fs::symlink_metadata(&name).is_err() {
                PyFileNotFoundError::new_err(format!("{e:#}"))
            } else {
                value(e).into()
            }
        })
    })?;
    Ok(Scene { inner: Arc::new(scene) })
}

/// The CLI's `LookArgs` with every default (`spectra render SCENE` without options).
fn default_look() -> setup::LookArgs {
    use clap::Parser;
    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        look: setup::LookArgs,
    }
    Cli::try_parse_from(["render"]).expect("the render options have defaults").look
}

struct Inner {
    renderer: render::Renderer,
    scene: Arc<scene::Scene>,
    size: (u32, u32),
}

/// The real-time renderer (wgpu) for one scene at one size. It keeps its GPU device, pipelines
/// and scene buffers between `render()` calls, so only the first call pays for them.
#[pyclass(frozen, module = "spectra")]
struct Renderer {
    inner: Mutex<Inner>,
    scene: Py<Scene>,
}

#[pymethods]
impl Renderer {
    /// Creates the GPU device (lavapipe without a GPU), uploads `scene` and sizes the targets to
    /// `size=(width, height)`. The water or RGB medium of the scene is set up as
    /// `spectra render` sets it up.
    #[new]
    #[pyo3(signature = (scene, size = (640, 480)))]
    fn new(py: Python<'_>, scene: &Bound<'_, PyAny>, size: (i64, i64)) -> PyResult<Self> {
        let sc = scene_of(scene, "scene")?;
        let scene_obj: Py<Scene> = scene.extract()?;
        let (w, h) = size_arg(size)?;
        let s = sc.clone();
        let renderer = py.detach(move || -> Result<render::Renderer, Fail> {
            let look = default_look();
            let table = look.table.load().map_err(runtime)?;
            let media = look.media(&s, &table).map_err(value)?;
            let custom = media.shader().map_err(value)?;
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
        Ok(Renderer { inner: Mutex::new(Inner { renderer, scene: sc, size: (w, h) }), scene: scene_obj })
    }

    /// One frame as a float32 array of shape (height, width, 3), C-contiguous: the linear RGB
    /// HDR image (`spectra render --out x.exr`'s pixels, the f16 HDR target read back, alpha
    /// dropped), multiplied by 2^exposure.
    ///
    /// mode: "spectral" (Jakob–Hanika), "naive" (box upsampling) or "rgb".
    /// wavelengths: N nodes, 1–256 (default: the scene's, else 16).
    /// quadrature: "prefiltered" or "midpoint".
    /// range: (min_nm, max_nm) (default: the scene's, else (380, 730)).
    /// observer: "cie1931", "cie1964", a camera name or a CSV file (default: the scene's, else
    /// cie1931).
    /// white: the scene white, an illuminant name ("D65", "F11", "5000K", …; default: the
    /// scene's, else D65).
    /// exposure: stops.
    #[pyo3(signature = (mode = "spectral", *, wavelengths = None, quadrature = "prefiltered", range = None,
                        observer = None, white = None, exposure = 0.0))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        mode: &str,
        wavelengths: Option<i64>,
        quadrature: &str,
        range: Option<(f64, f64)>,
        observer: Option<String>,
        white: Option<String>,
        exposure: f32,
    ) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
        let mut look = default_look();
        look.mode = render::Mode::parse(mode).map_err(|e| PyValueError::new_err(e.to_string()))?;
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
        look.quadrature = setup::parse_quadrature(quadrature)
            .map_err(|e| PyValueError::new_err(format!("--quadrature '{quadrature}': {e}")))?;
        look.spectrum = setup::SpectrumArgs { range: range_arg(range), observer, white };
        look.exposure = exposure;
        let (data, (w, h)) = py.detach(|| -> Result<(Vec<f32>, (u32, u32)), Fail> {
            let mut g = self.inner.lock().unwrap_or_else(|p| p.into_inner());
            let inner = &mut *g;
            let settings = look.settings(&inner.scene, true, false).map_err(value)?;
            inner.renderer.render(&inner.scene.camera, &settings).map_err(runtime)?;
            let hdr = inner.renderer.read_hdr().map_err(runtime)?;
            // As `spectra render --out x.exr` writes them.
            let k = settings.exposure_ev.exp2();
            let data = hdr.iter().flat_map(|p| [p[0] * k, p[1] * k, p[2] * k]).collect();
            Ok((data, inner.size))
        })?;
        rgb_array(py, w, h, data)
    }

    /// The scene this renderer draws.
    #[getter]
    fn scene(&self, py: Python<'_>) -> Py<Scene> {
        self.scene.clone_ref(py)
    }

    /// (width, height).
    #[getter]
    fn size(&self) -> (u32, u32) {
        self.inner.lock().unwrap_or_else(|p| p.into_inner()).size
    }

    /// The GPU adapter and backend, e.g. "llvmpipe (LLVM …) (Vulkan, Cpu)".
    #[getter]
    fn device(&self) -> String {
        self.inner.lock().unwrap_or_else(|p| p.into_inner()).renderer.gpu().describe()
    }

    fn __repr__(&self) -> String {
        let g = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        format!("<spectra.Renderer {} {}×{}>", g.scene.source, g.size.0, g.size.1)
    }
}

/// The truth settings `spectra truth` builds from these options (its `settings()`), the
/// scene's RGB medium or water included.
#[allow(clippy::too_many_arguments)]
fn truth_settings(
    scene: &scene::Scene,
    table: &color::upsample::CoeffTable,
    (width, height): (u32, u32),
    spp: u32,
    seed: u64,
    sample_offset: u64,
    crop: Option<truth::Crop>,
    direct_only: bool,
    max_depth: u32,
    spectrum: &setup::SpectrumArgs,
) -> anyhow::Result<truth::Settings> {
    let mut s = truth::Settings::new(width, height, spp)?;
    s.seed = seed;
    s.sample_offset = sample_offset;
    s.crop = crop;
    s.direct_only = direct_only;
    s.max_depth = max_depth;
    let sp = spectrum.resolve(scene)?;
    s.range = sp.range;
    s.observer = color::Observer::by_name(&sp.observer)?;
    s.white = color::illuminant::by_name(&sp.white)?;
    let rgb = scene.medium.is_some();
    if let Some(m) = &scene.medium {
        let origin = format!("{}: extras.medium", scene.source);
        let m = truth::Medium::from_rgb(m, table).with_context(|| origin.clone())?;
        m.validate(s.range).with_context(|| origin.clone())?;
        s.medium = Some(m);
    }
    if let Some(w) = setup::water_medium(scene, None, None)? {
        if rgb {
            anyhow::bail!(
                "--medium / --rgb-medium / the scene's medium and water (from --water or the scene) cannot be combined: pick one medium"
            );
        }
        s.medium = Some(truth::water::medium(&w, scene.camera.position()));
    }
    s.validate()?;
    Ok(s)
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
/// longest path in scattering events.
///
/// Ctrl-C interrupts it (KeyboardInterrupt) within about a second.
#[pyfunction(name = "truth")]
#[pyo3(signature = (scene, spp = 64, size = (256, 256), direct_only = false, seed = 0, *, sample_offset = 0,
                    crop = None, range = None, observer = None, white = None, max_depth = 1024))]
#[allow(clippy::too_many_arguments)]
fn truth_image<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyAny>,
    spp: i64,
    size: (i64, i64),
    direct_only: bool,
    seed: i64,
    sample_offset: i64,
    crop: Option<(i64, i64, i64, i64)>,
    range: Option<(f64, f64)>,
    observer: Option<String>,
    white: Option<String>,
    max_depth: i64,
) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
    let sc = scene_of(scene, "scene")?;
    let spp = whole("spp", spp, 1)?;
    let (w, h) = size_arg(size)?;
    if seed < 0 {
        return Err(PyValueError::new_err(format!("seed {seed}: must be a whole number ≥ 0")));
    }
    if sample_offset < 0 {
        return Err(PyValueError::new_err(format!(
            "sample_offset {sample_offset}: must be a whole number ≥ 0"
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
    let max_depth = whole("max_depth", max_depth, 0)?;
    let spectrum = setup::SpectrumArgs { range: range_arg(range), observer, white };
    let (data, (iw, ih)) = py.detach(move || -> Result<(Vec<f32>, (u32, u32)), Fail> {
        let table = setup::load_table(None).map_err(runtime)?;
        let st = truth_settings(
            &sc,
            &table,
            (w, h),
            spp,
            seed as u64,
            sample_offset as u64,
            crop,
            direct_only,
            max_depth,
            &spectrum,
        )
        .map_err(value)?;
        let mut world =
            truth::World::new(&sc, table.as_ref(), &st.white, st.range, st.medium.as_ref()).map_err(value)?;
        if let Some(env) = &st.environment {
            world = world.with_environment(env);
        }
        let mut acc = truth::Accumulator::new(&st).map_err(value)?;
        let cancel = AtomicBool::new(false);
        // Passes of about a quarter second (the first, of one sample, measures them), with a
        // look at Python's signals between them; the sums do not depend on the passes.
        let mut per_sample: Option<f64> = None;
        while acc.done < st.spp {
            let left = st.spp - acc.done;
            let n = match per_sample {
                None => 1,
                Some(t) => ((0.25 / t.max(1e-9)).floor().clamp(1.0, f64::from(left))) as u32,
            };
            let t = Instant::now();
            truth::render_pass(&world, &st, &cancel, &mut acc, n, &|_| {}).map_err(runtime)?;
            per_sample = Some(t.elapsed().as_secs_f64() / f64::from(n));
            Python::attach(|py| py.check_signals()).map_err(Fail::Py)?;
        }
        let img = acc.finish(&st);
        if img.dropped > 0 {
            eprintln!("warning: truth: {} non-finite samples dropped", img.dropped);
        }
        let rgb = img.to_rgb(&color::RgbColorSpace::srgb());
        Ok((rgb.into_iter().flatten().collect(), (img.width, img.height)))
    })?;
    rgb_array(py, iw, ih, data)
}

/// An (H, W, 3) float32 or float64 array as an image, or a `ValueError` naming `what`.
fn image_arg(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<compare::Image> {
    let bad = |got: String| {
        PyValueError::new_err(format!(
            "{what}: expected a numpy float32 or float64 array of shape (H, W, 3), got {got}"
        ))
    };
    let (shape, data): (Vec<usize>, Vec<f32>) = if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f32>>() {
        (a.shape().to_vec(), a.as_array().iter().copied().collect())
    } else if let Ok(a) = obj.extract::<PyReadonlyArrayDyn<'_, f64>>() {
        (a.shape().to_vec(), a.as_array().iter().map(|&v| v as f32).collect())
    } else if let Ok(a) = obj.extract::<Bound<'_, numpy::PyUntypedArray>>() {
        return Err(bad(format!("dtype {} with shape {:?}", a.dtype(), a.shape())));
    } else {
        let t = obj.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "another type".into());
        return Err(bad(format!("a {t}")));
    };
    match shape[..] {
        [h, w, 3] if h > 0 && w > 0 && h <= u32::MAX as usize && w <= u32::MAX as usize => {
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

/// How far image `b` is from the reference `a` (both linear sRGB arrays of shape (H, W, 3)):
/// the statistics `spectra diff --json` prints, as a dict: `width`, `height`,
/// `white_luminance`, and per-pixel `delta_e2000`, `mae_linear`, `mae_srgb`, each a dict of
/// `mean`, `median`, `p95`, `p99`, `max`.
///
/// white_y: the luminance of the CIELAB reference white (D65 chromaticity), 1 by default.
#[pyfunction]
#[pyo3(signature = (a, b, *, white_y = 1.0))]
fn diff<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    white_y: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let reference = image_arg("a", a)?;
    let test = image_arg("b", b)?;
    if reference.size() != test.size() {
        let (ra, rb) = (reference.size(), test.size());
        return Err(PyValueError::new_err(format!(
            "a and b differ in size: a is {}×{} (W×H), b is {}×{}",
            ra.0, ra.1, rb.0, rb.1
        )));
    }
    let json = py.detach(move || -> Result<String, Fail> {
        let maps =
            compare::DiffMaps::compute(&reference, &test, compare::DiffOptions { white_luminance: white_y })
                .map_err(value)?;
        serde_json::to_string(&maps.summary()).map_err(runtime)
    })?;
    py.import("json")?.call_method1("loads", (json,))
}

/// Reads an EXR (linear) or PNG (sRGB-decoded) file as `spectra diff` reads it: a float32
/// array of shape (height, width, 3).
#[pyfunction]
fn read_image(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, numpy::PyArray3<f32>>> {
    let img = py.detach(|| compare::read_image(&path).map_err(value))?;
    let (w, h) = img.size();
    rgb_array(py, w, h, img.data.into_iter().flatten().collect())
}

/// The extension module: `spectra/__init__.py` re-exports it.
#[pymodule]
fn _spectra(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Scene>()?;
    m.add_class::<Renderer>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(truth_image, m)?)?;
    m.add_function(wrap_pyfunction!(diff, m)?)?;
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add("BUILTINS", scene::BUILTIN_NAMES.to_vec())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
