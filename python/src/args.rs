//! Arguments converted with errors that name them in their message.
//!
//! pyo3 names a failed argument only in a note (`add_note`, "while processing 'mode'"), which
//! Python 3.9 and 3.10 neither have nor show: there `render(mode=None)` said only "'None' is not
//! an instance of 'str'". Every public argument is therefore converted here (`from_py_with`,
//! one small function an argument, made by `arg_fns!`), and the message starts with the
//! argument's name. Counts refuse bools and floats (a `ValueError`, as `spectra.distributed`
//! refuses them), sizes and ranges take lists and 1-D arrays as well as tuples, and names that
//! may be files take `os.PathLike` objects (`pathlib.Path`) as well as `str`.

use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyFloat, PyList, PyString, PyTuple};

/// The Python type name of `o`, for messages.
pub fn type_name(o: &Bound<'_, PyAny>) -> String {
    o.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "another type".into())
}

/// A float for a message: short, in exponent notation when huge or tiny (Rust's `{}` spells
/// 1e300 with 301 digits).
pub fn short(v: f64) -> String {
    if v == 0.0 || !v.is_finite() || (1e-4..1e7).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// `T` by its own conversion; a `TypeError` "WHAT: expected KIND, got TYPE" otherwise (any other
/// error keeps its type, its message prefixed with the argument's name).
pub fn named<'py, T>(o: &Bound<'py, PyAny>, what: &str, kind: &str) -> PyResult<T>
where
    T: pyo3::conversion::FromPyObjectOwned<'py>,
{
    o.extract::<T>().map_err(|e| {
        let e: PyErr = e.into();
        let py = o.py();
        if e.is_instance_of::<PyTypeError>(py) {
            PyTypeError::new_err(format!("{what}: expected {kind}, got {}", type_name(o)))
        } else {
            PyErr::from_type(e.get_type(py), format!("{what}: {}", e.value(py)))
        }
    })
}

/// A whole number, taken as i128 so that range checks further on name their argument whatever
/// its size. bool and float are refused with a `ValueError` (they are numbers, not counts), an
/// integer beyond ±2¹²⁷ with a `ValueError` naming the argument, other types with a `TypeError`.
pub fn int(o: &Bound<'_, PyAny>, what: &str) -> PyResult<i128> {
    if o.is_instance_of::<PyBool>() || o.is_instance_of::<PyFloat>() {
        let r = o.repr().map(|r| r.to_string()).unwrap_or_default();
        return Err(PyValueError::new_err(format!(
            "{what} {r}: must be a whole number (an int, not a {})",
            type_name(o)
        )));
    }
    match o.extract::<i128>() {
        Ok(v) => Ok(v),
        Err(e) if e.is_instance_of::<pyo3::exceptions::PyOverflowError>(o.py()) => {
            let s = o.str().map(|r| r.to_string()).unwrap_or_default();
            let s = if s.len() > 24 { format!("{}…({} digits)", &s[..12], s.len()) } else { s };
            Err(PyValueError::new_err(format!("{what} {s}: far too large")))
        }
        Err(_) => Err(PyTypeError::new_err(format!("{what}: expected an int, got {}", type_name(o)))),
    }
}

/// A float (an int or a numpy float too).
pub fn float(o: &Bound<'_, PyAny>, what: &str) -> PyResult<f64> {
    named::<f64>(o, what, "a float")
}

/// A float kept as f32: a finite value beyond f32's range is refused naming it (narrowed, it
/// was reported as "inf", which the caller never gave).
pub fn float32(o: &Bound<'_, PyAny>, what: &str) -> PyResult<f32> {
    let v = float(o, what)?;
    if v.is_finite() && (v as f32).is_infinite() {
        return Err(PyValueError::new_err(format!(
            "{what} {}: beyond float32's range (±{:e})",
            short(v),
            f32::MAX
        )));
    }
    Ok(v as f32)
}

/// A bool (Python's or numpy's), not any truthy object.
pub fn boolean(o: &Bound<'_, PyAny>, what: &str) -> PyResult<bool> {
    named::<bool>(o, what, "a bool")
}

/// A str.
pub fn string(o: &Bound<'_, PyAny>, what: &str) -> PyResult<String> {
    named::<String>(o, what, "a str")
}

/// A name that may be a file: a str or an `os.PathLike` (`pathlib.Path`), as a str.
pub fn name_or_path(o: &Bound<'_, PyAny>, what: &str) -> PyResult<String> {
    if let Ok(s) = o.cast::<PyString>() {
        return Ok(s.to_string());
    }
    if o.hasattr("__fspath__").unwrap_or(false) {
        let p = o.py().import("os")?.call_method1("fspath", (o,))?;
        if let Ok(s) = p.cast::<PyString>() {
            return Ok(s.to_string());
        }
    }
    Err(PyTypeError::new_err(format!("{what}: expected a str or os.PathLike, got {}", type_name(o))))
}

/// A path (str or `os.PathLike`).
pub fn path(o: &Bound<'_, PyAny>, what: &str) -> PyResult<std::path::PathBuf> {
    named::<std::path::PathBuf>(o, what, "a str or os.PathLike path")
}

/// The `n` items of a tuple, a list or a 1-D numpy array, or an error naming `what` and
/// describing the `shape` wanted (e.g. "(width, height)").
fn items<'py>(o: &Bound<'py, PyAny>, what: &str, n: usize, shape: &str) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let v: Vec<Bound<'py, PyAny>> = if let Ok(t) = o.cast::<PyTuple>() {
        t.iter().collect()
    } else if let Ok(l) = o.cast::<PyList>() {
        l.iter().collect()
    } else if o.is_instance_of::<numpy::PyUntypedArray>() && o.getattr("ndim")?.extract::<usize>()? == 1 {
        o.call_method0("tolist")?.cast_into::<PyList>()?.iter().collect()
    } else {
        return Err(PyTypeError::new_err(format!(
            "{what}: expected a tuple or list {shape}, got {}",
            type_name(o)
        )));
    };
    if v.len() != n {
        return Err(PyValueError::new_err(format!("{what}: expected {shape}, got {} values", v.len())));
    }
    Ok(v)
}

/// `n` whole numbers (see `int`).
pub fn ints<const N: usize>(o: &Bound<'_, PyAny>, what: &str, shape: &str) -> PyResult<[i128; N]> {
    let v = items(o, what, N, shape)?;
    let mut out = [0; N];
    for (slot, x) in out.iter_mut().zip(&v) {
        *slot = int(x, what)?;
    }
    Ok(out)
}

/// `n` floats.
pub fn floats<const N: usize>(o: &Bound<'_, PyAny>, what: &str, shape: &str) -> PyResult<[f64; N]> {
    let v = items(o, what, N, shape)?;
    let mut out = [0.0; N];
    for (slot, x) in out.iter_mut().zip(&v) {
        *slot = float(x, what)?;
    }
    Ok(out)
}

/// `None`, or `f(o)`.
pub fn opt<'py, T>(
    o: &Bound<'py, PyAny>,
    what: &str,
    f: impl Fn(&Bound<'py, PyAny>, &str) -> PyResult<T>,
) -> PyResult<Option<T>> {
    if o.is_none() { Ok(None) } else { f(o, what).map(Some) }
}

/// The `from_py_with` converters: `name(ARG) -> TYPE = CONVERSION;` makes `fn name(o)`
/// converting argument ARG.
macro_rules! arg_fns {
    ($($f:ident($what:literal) -> $t:ty = $conv:expr;)*) => {
        $(
            pub fn $f(o: &Bound<'_, PyAny>) -> PyResult<$t> {
                $conv(o, $what)
            }
        )*
    };
}

fn size_pair(o: &Bound<'_, PyAny>, what: &str) -> PyResult<(i128, i128)> {
    let [w, h] = ints::<2>(o, what, "(width, height)")?;
    Ok((w, h))
}

fn range_pair(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<(f64, f64)>> {
    opt(o, what, |o, what| {
        let [a, b] = floats::<2>(o, what, "(min_nm, max_nm)")?;
        Ok((a, b))
    })
}

fn crop_quad(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<(i128, i128, i128, i128)>> {
    opt(o, what, |o, what| {
        let [x, y, w, h] = ints::<4>(o, what, "(x, y, width, height)")?;
        Ok((x, y, w, h))
    })
}

fn opt_int(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<i128>> {
    opt(o, what, int)
}

fn opt_float(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<f64>> {
    opt(o, what, float)
}

fn opt_float32(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<f32>> {
    opt(o, what, float32)
}

fn opt_string(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<String>> {
    opt(o, what, string)
}

/// An animation: its name (a str, which `--animation` reads as a name, else an index) or its
/// index (an int ≥ 0, an index whatever the names).
fn opt_animation(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<scene::AnimationRef>> {
    opt(o, what, |o, what| {
        if o.is_instance_of::<PyString>() {
            return string(o, what).map(scene::AnimationRef::NameOrIndex);
        }
        let i = int(o, what).map_err(|_| {
            PyTypeError::new_err(format!(
                "{what}: expected a str (a name) or an int (an index), got {}",
                type_name(o)
            ))
        })?;
        usize::try_from(i)
            .map(scene::AnimationRef::Index)
            .map_err(|_| PyValueError::new_err(format!("{what} {i}: an index is 0 or more")))
    })
}

fn opt_path(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<std::path::PathBuf>> {
    opt(o, what, path)
}

fn opt_boolean(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<bool>> {
    opt(o, what, boolean)
}

fn opt_name_or_path(o: &Bound<'_, PyAny>, what: &str) -> PyResult<Option<String>> {
    opt(o, what, name_or_path)
}

arg_fns! {
    path_or_builtin("path_or_builtin") -> std::path::PathBuf = path;
    path_arg("path") -> std::path::PathBuf = path;
    allow_outside_scene_dir("allow_outside_scene_dir") -> bool = boolean;
    variant("variant") -> Option<String> = opt_string;
    animation("animation") -> Option<scene::AnimationRef> = opt_animation;
    time("time") -> Option<f64> = opt_float;
    env("env") -> Option<String> = opt_name_or_path;
    env_intensity("env_intensity") -> Option<f32> = opt_float32;
    env_rotation("env_rotation") -> Option<f32> = opt_float32;
    env_sun("env_sun") -> bool = boolean;
    env_sun_share("env_sun_share") -> Option<f32> = opt_float32;
    size("size") -> (i128, i128) = size_pair;
    water("water") -> Option<String> = opt_string;
    depth("depth") -> Option<f64> = opt_float;
    rgb_medium("rgb_medium") -> Option<String> = opt_name_or_path;
    mode("mode") -> String = string;
    wavelengths("wavelengths") -> Option<i128> = opt_int;
    quadrature("quadrature") -> String = string;
    range("range") -> Option<(f64, f64)> = range_pair;
    observer("observer") -> Option<String> = opt_name_or_path;
    observer_name("observer") -> String = name_or_path;
    name("name") -> String = name_or_path;
    illuminant("illuminant") -> String = string;
    illuminant_name("name") -> String = string;
    white("white") -> Option<String> = opt_string;
    exposure("exposure") -> f32 = float32;
    spectral("spectral") -> bool = boolean;
    camera_to_display("camera_to_display") -> bool = boolean;
    samples("samples") -> i128 = int;
    spp("spp") -> i128 = int;
    direct_only("direct_only") -> bool = boolean;
    seed("seed") -> i128 = int;
    sample_offset("sample_offset") -> i128 = int;
    crop("crop") -> Option<(i128, i128, i128, i128)> = crop_quad;
    max_depth("max_depth") -> i128 = int;
    spectral_bin("spectral_bin") -> Option<f64> = opt_float;
    threads("threads") -> Option<i128> = opt_int;
    dry_run("dry_run") -> bool = boolean;
    white_y("white_y") -> f64 = float;
    flip("flip") -> Option<String> = opt_string;
    flip_ppd("flip_ppd") -> Option<f32> = opt_float32;
    flip_start_exposure("flip_start_exposure") -> Option<f32> = opt_float32;
    flip_stop_exposure("flip_stop_exposure") -> Option<f32> = opt_float32;
    flip_exposures("flip_exposures") -> Option<i128> = opt_int;
    flip_tone_mapper("flip_tone_mapper") -> Option<String> = opt_string;
    maps("maps") -> bool = boolean;
    placement("placement") -> bool = boolean;
    space("space") -> String = string;
    balanced("balanced") -> bool = boolean;
    medium("medium") -> Option<String> = opt_name_or_path;
    lambert("lambert") -> bool = boolean;
    xyz("xyz") -> bool = boolean;
    table("table") -> Option<std::path::PathBuf> = opt_path;
    scatter_steps("scatter_steps") -> i128 = int;
    single_scattering("single_scattering") -> bool = boolean;
    phase_g("phase_g") -> f32 = float32;
    paper_model("paper_model") -> bool = boolean;
    isotropic("isotropic") -> bool = boolean;
    tabulated_kd("tabulated_kd") -> bool = boolean;
    surface_irradiance("surface_irradiance") -> bool = boolean;
    forward_cone("forward_cone") -> f32 = float32;
    light_field_photons("light_field_photons") -> i128 = int;
    scalar_irradiance("scalar_irradiance") -> bool = boolean;
    split_beams("split_beams") -> bool = boolean;
    water_surface("water_surface") -> Option<bool> = opt_boolean;
    sea_floor("sea_floor") -> bool = boolean;
    env_occlusion("env_occlusion") -> bool = boolean;
    shadows("shadows") -> bool = boolean;
}
