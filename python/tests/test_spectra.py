"""Tests of the `spectra` Python package (python/): run with `pytest python/tests` after
`pip install ./python pytest numpy` (`cargo xtask test` does both in target/py-venv).

The comparison with the command line needs the `spectra` binary: $SPECTRA_BIN, else the
workspace's debug build (`cargo build -p spectra`, run here when cargo is on PATH)."""

import os
import pathlib
import shutil
import subprocess
import time

import numpy as np
import pytest

import spectra

ROOT = pathlib.Path(__file__).resolve().parents[2]
W, H = 64, 48


@pytest.fixture(scope="module")
def cornell():
    return spectra.load("cornell")


@pytest.fixture(scope="module")
def renderer(cornell):
    return spectra.Renderer(cornell, size=(W, H))


def spectra_bin():
    """The CLI binary: $SPECTRA_BIN, else the workspace's debug build, brought up to date."""
    if os.environ.get("SPECTRA_BIN"):
        return os.environ["SPECTRA_BIN"]
    cargo = shutil.which("cargo")
    if cargo is None or not (ROOT / "Cargo.toml").exists():
        pytest.skip("no spectra binary: set SPECTRA_BIN or run from the repository with cargo")
    subprocess.run([cargo, "build", "--quiet", "-p", "spectra"], cwd=ROOT, check=True)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    return str(target / "debug" / "spectra")


def read_exr(path):
    """The EXR's R, G, B through OpenEXR when it is installed (a reader independent of
    spectra's), else through spectra.read_image."""
    try:
        import OpenEXR
    except ImportError:
        return spectra.read_image(path)
    with OpenEXR.File(str(path)) as f:
        ch = f.channels()
        if "RGB" in ch:
            rgb = np.array(ch["RGB"].pixels)
        else:
            rgb = np.stack([np.array(ch[c].pixels) for c in "RGB"], axis=-1)
    return rgb.astype(np.float32)


def test_render_shape_dtype_contiguity(renderer):
    img = renderer.render()
    assert isinstance(img, np.ndarray)
    assert img.shape == (H, W, 3)
    assert img.dtype == np.float32
    assert img.flags["C_CONTIGUOUS"]
    assert np.isfinite(img).all() and img.max() > 0.0
    assert renderer.size == (W, H)
    for mode in ("rgb", "naive", "spectral"):
        assert renderer.render(mode, wavelengths=8).shape == (H, W, 3)


def test_second_render_reuses_the_device(cornell):
    t0 = time.perf_counter()
    r = spectra.Renderer(cornell, size=(W, H))
    first = r.render()
    t1 = time.perf_counter()
    second = r.render()
    t2 = time.perf_counter()
    ratio = (t1 - t0) / max(t2 - t1, 1e-9)
    print(
        f"\nRenderer + first render(): {t1 - t0:.3f} s, second render(): {t2 - t1:.4f} s "
        f"(first/second {ratio:.0f}×) on {r.device}"
    )
    np.testing.assert_array_equal(first, second)


def test_render_equals_the_cli(tmp_path, renderer):
    exe = spectra_bin()
    out = tmp_path / "x.exr"
    subprocess.run(
        [exe, "render", "cornell", "--size", f"{W}x{H}", "--out", str(out)],
        check=True,
        env={**os.environ, "XDG_RUNTIME_DIR": os.environ.get("XDG_RUNTIME_DIR", str(tmp_path))},
    )
    cli = read_exr(out)
    py = renderer.render()
    assert cli.shape == py.shape == (H, W, 3)
    # Bit for bit: both are the f16 HDR target read back.
    assert np.array_equal(cli.view(np.uint32), py.view(np.uint32)), np.abs(cli - py).max()
    # And spectra's own reader reads the file the same way.
    assert np.array_equal(spectra.read_image(out), cli)


def test_render_options_change_the_image(renderer):
    base = renderer.render()
    assert not np.array_equal(renderer.render("rgb"), base)
    np.testing.assert_allclose(renderer.render(exposure=1), 2 * base, rtol=0, atol=0)
    assert not np.array_equal(renderer.render(quadrature="midpoint", wavelengths=4), base)
    assert renderer.render(range=(400, 700), observer="cie1964", white="D50").shape == base.shape


def test_truth_shape_and_determinism(cornell):
    a = spectra.truth(cornell, spp=4, size=(32, 24), direct_only=True, seed=7)
    assert a.shape == (24, 32, 3) and a.dtype == np.float32 and a.flags["C_CONTIGUOUS"]
    assert np.isfinite(a).all() and a.max() > 0.0
    b = spectra.truth(cornell, spp=4, size=(32, 24), direct_only=True, seed=7)
    assert np.array_equal(a, b)
    c = spectra.truth(cornell, spp=4, size=(32, 24), direct_only=True, seed=8)
    assert not np.array_equal(a, c)


def test_truth_crop_and_sample_offset(cornell):
    full = spectra.truth(cornell, spp=4, size=(32, 24), seed=3)
    crop = spectra.truth(cornell, spp=4, size=(32, 24), seed=3, crop=(8, 4, 10, 6))
    assert crop.shape == (6, 10, 3)
    assert np.array_equal(crop, full[4:10, 8:18])
    # Two chunks of 2 samples average into the 4-sample render (up to f32 rounding).
    c0 = spectra.truth(cornell, spp=2, size=(32, 24), seed=3)
    c1 = spectra.truth(cornell, spp=2, size=(32, 24), seed=3, sample_offset=2)
    np.testing.assert_allclose((c0 + c1) / 2, full, rtol=1e-5, atol=1e-6)


def test_diff_of_an_image_with_itself_is_zero(renderer):
    img = renderer.render()
    d = spectra.diff(img, img)
    assert (d["width"], d["height"]) == (W, H)
    for metric in ("delta_e2000", "mae_linear", "mae_srgb"):
        assert set(d[metric]) == {"mean", "median", "p95", "p99", "max"}
        assert all(v == 0.0 for v in d[metric].values()), d[metric]
    other = spectra.diff(img, renderer.render("rgb"))
    assert other["delta_e2000"]["mean"] > 0.0
    assert spectra.diff(img.astype(np.float64), img)["delta_e2000"]["max"] == 0.0


def test_bad_input_raises_the_right_exception(cornell, renderer):
    img = renderer.render()
    with pytest.raises(ValueError, match="^a: .*float32"):
        spectra.diff(img.astype(np.int32), img)
    with pytest.raises(ValueError, match=r"^b: .*shape"):
        spectra.diff(img, img[:, :, :2])
    with pytest.raises(ValueError, match="^a: "):
        spectra.diff([[1.0, 2.0, 3.0]], img)
    with pytest.raises(ValueError, match="differ in size"):
        spectra.diff(img, img[:10])
    bad = img.copy()
    bad[1, 2, 0] = np.nan
    with pytest.raises(ValueError, match="test"):
        spectra.diff(img, bad)
    with pytest.raises(TypeError):
        renderer.render(no_such_option=1)
    with pytest.raises(TypeError):
        spectra.truth(cornell, no_such_option=1)
    with pytest.raises(ValueError, match="unknown mode 'hsv'"):
        renderer.render("hsv")
    with pytest.raises(ValueError, match="--wavelengths 0"):
        renderer.render(wavelengths=0)
    with pytest.raises(ValueError, match="--wavelengths 999"):
        renderer.render(wavelengths=999)
    with pytest.raises(ValueError, match="--quadrature 'simpson'"):
        renderer.render(quadrature="simpson")
    with pytest.raises(ValueError, match="--range"):
        renderer.render(range=(700, 400))
    with pytest.raises(ValueError, match="--observer 'martian'"):
        renderer.render(observer="martian")
    with pytest.raises(ValueError, match="exposure"):
        renderer.render(exposure=1000)
    with pytest.raises(ValueError, match="unknown|built-in"):
        spectra.load("no-such-scene")
    with pytest.raises(FileNotFoundError, match="missing.gltf"):
        spectra.load("missing.gltf")
    with pytest.raises(TypeError, match="spectra.Scene"):
        spectra.Renderer("cornell")
    with pytest.raises(ValueError, match="size"):
        spectra.Renderer(cornell, size=(0, 10))
    with pytest.raises(ValueError, match="spp 0"):
        spectra.truth(cornell, spp=0)
    with pytest.raises(ValueError, match="crop"):
        spectra.truth(cornell, spp=1, size=(32, 24), crop=(30, 0, 10, 10))
    with pytest.raises(ValueError, match="seed"):
        spectra.truth(cornell, seed=-1)


def test_every_builtin_loads():
    assert set(spectra.BUILTINS) >= {
        "cornell", "colorchecker", "metamerism", "iridescence", "glass", "underwater", "fog", "tinted-fog",
    }
    for name in spectra.BUILTINS:
        s = spectra.load(name)
        assert s.source == f"builtin:{name}"


def test_media_scenes_render(tmp_path):
    # The scene's water or RGB medium is set up as `spectra render` sets it up.
    for name in ("underwater", "fog"):
        img = spectra.Renderer(spectra.load(name), size=(32, 24)).render(wavelengths=4)
        assert img.shape == (24, 32, 3) and np.isfinite(img).all()
