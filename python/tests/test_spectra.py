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


def test_render_samples_equals_the_cli(tmp_path, renderer):
    exe = spectra_bin()
    out = tmp_path / "x.exr"
    subprocess.run(
        [exe, "render", "cornell", "--size", f"{W}x{H}", "--samples", "4", "--out", str(out)],
        check=True,
        env={**os.environ, "XDG_RUNTIME_DIR": os.environ.get("XDG_RUNTIME_DIR", str(tmp_path))},
    )
    cli = read_exr(out)
    py = renderer.render(samples=4)
    np.testing.assert_allclose(py, cli, rtol=1e-3, atol=1e-6)
    one = renderer.render()
    # The edges change, the image as a whole stays (the same scene, filtered over each pixel):
    # its mean away from the lamp, whose edge pixels (radiance 40, partly covered once
    # filtered) would swing an HDR mean by 20 %; 64×48 pixels of edges move it by 2 %.
    assert not np.array_equal(py, one)
    lamp = np.pad(one.max(axis=-1) > 1.0, 1)
    near_lamp = np.lib.stride_tricks.sliding_window_view(lamp, (3, 3)).any(axis=(-1, -2))
    away = ~near_lamp
    assert away.sum() > 0.9 * away.size
    assert abs(py[away].mean() - one[away].mean()) < 0.03 * one[away].mean()
    # And a single frame afterwards is the single frame again.
    assert np.array_equal(renderer.render(), one)
    for bad in (0, 257, -1):
        with pytest.raises(ValueError, match="samples"):
            renderer.render(samples=bad)
    with pytest.raises(ValueError, match="samples"):
        renderer.render(spectral=True, samples=2)


def test_render_options_change_the_image(renderer):
    base = renderer.render()
    assert not np.array_equal(renderer.render("rgb"), base)
    # The exposure is applied before the half-float target: twice the frame exactly where f16
    # is normal; below 6.1e-5 (f16's subnormals, steps of 2^-24) the exposed value keeps the
    # bit the unexposed one lost.
    twice = renderer.render(exposure=1)
    normal = np.abs(base) >= 2.0**-14
    np.testing.assert_array_equal(twice[normal], 2 * base[normal])
    np.testing.assert_allclose(twice[~normal], 2 * base[~normal], rtol=0, atol=2.0**-24)
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
    with pytest.raises(ValueError, match="^b: pixel .*not finite"):
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
    with pytest.raises(ValueError, match=r"range \(700, 400\)"):
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
        "cornell", "colorchecker", "metamerism", "iridescence", "glass", "clearcoat", "specular", "sheen", "anisotropy", "translucent", "underwater", "fog", "tinted-fog",
    }
    for name in spectra.BUILTINS:
        s = spectra.load(name)
        assert s.source == f"builtin:{name}"


def test_media_scenes_render(tmp_path):
    # The scene's water or RGB medium is set up as `spectra render` sets it up.
    for name in ("underwater", "fog"):
        img = spectra.Renderer(spectra.load(name), size=(32, 24)).render(wavelengths=4)
        assert img.shape == (24, 32, 3) and np.isfinite(img).all()


def test_spectral_capture(renderer):
    img, nodes, lam = renderer.render(wavelengths=8, quadrature="midpoint", spectral=True)
    assert img.shape == (H, W, 3) and nodes.shape == (H, W, 8) and lam.shape == (8,)
    assert nodes.dtype == np.float32 and lam.dtype == np.float64 and nodes.flags["C_CONTIGUOUS"]
    # The node wavelengths are the centres of 8 equal bins over 380–730 nm.
    np.testing.assert_allclose(lam, 380 + (np.arange(8) + 0.5) * 350 / 8)
    # Capturing does not change the image (its pipeline is another compile of the shader: at
    # most an f16 rounding step apart).
    np.testing.assert_allclose(img, renderer.render(wavelengths=8, quadrature="midpoint"), rtol=1e-3, atol=0)
    assert np.isfinite(nodes).all() and nodes.max() > 0
    # With the midpoint rule the nodes are L(λₖ): their luminance (the CIE 1931 ȳ at the
    # nodes, midpoint rule) is the frame's, up to one constant (the units' white).
    ybar = spectra.observer("cie1931", lam)[:, 1]
    y_nodes = nodes.astype(np.float64) @ ybar
    y_img = img.astype(np.float64) @ np.array([0.2126729, 0.7151522, 0.0721750])
    lit = y_img > 0.01
    assert lit.mean() > 0.3
    ratio = y_nodes[lit] / y_img[lit]
    assert np.std(ratio) / np.mean(ratio) < 1e-3, (np.mean(ratio), np.std(ratio))
    with pytest.raises(ValueError, match="rgb mode"):
        renderer.render("rgb", spectral=True)


def test_truth_spectral_bins(cornell):
    plain = spectra.truth(cornell, spp=2, size=(16, 12), direct_only=True)
    img, bands, edges = spectra.truth(cornell, spp=2, size=(16, 12), direct_only=True, spectral_bin=10)
    assert np.array_equal(img, plain)  # the bins do not change the image
    assert edges.dtype == np.float64 and edges[0] == 380 and edges[-1] == 730
    assert bands.shape == (12, 16, len(edges) - 1) and bands.dtype == np.float32
    assert np.isfinite(bands).all() and bands.max() > 0
    with pytest.raises(ValueError, match="spectral.bin"):
        spectra.truth(cornell, spp=1, size=(8, 8), spectral_bin=-1)


def test_media_options(tmp_path):
    dry = spectra.load("cornell")
    fog = '{"absorption": [0.05, 0.1, 0.2], "scattering": [0.3, 0.3, 0.3], "g": 0.3}'
    plain = spectra.truth(dry, spp=2, size=(16, 12), direct_only=True)
    foggy = spectra.truth(dry, spp=2, size=(16, 12), direct_only=True, rgb_medium=fog)
    assert foggy.shape == plain.shape and not np.array_equal(foggy, plain)
    r = spectra.Renderer(dry, size=(16, 12), rgb_medium=fog)
    assert not np.array_equal(r.render(), spectra.Renderer(dry, size=(16, 12)).render())
    sea = spectra.load("underwater")
    a = spectra.truth(sea, spp=1, size=(8, 6), direct_only=True, water="IB", depth=5)
    b = spectra.truth(sea, spp=1, size=(8, 6), direct_only=True, water="IB", depth=20)
    assert not np.array_equal(a, b)
    shallow = spectra.Renderer(sea, size=(16, 12), water="IB", depth=5).render(wavelengths=4)
    deep = spectra.Renderer(sea, size=(16, 12), water="IB", depth=20).render(wavelengths=4)
    assert shallow.mean() > deep.mean()
    with pytest.raises(ValueError, match="depth"):
        spectra.truth(dry, spp=1, size=(8, 6), depth=5)
    with pytest.raises(ValueError, match="cannot be combined"):
        spectra.truth(sea, spp=1, size=(8, 6), rgb_medium=fog)
    with pytest.raises(ValueError, match="Jerlov|water"):
        spectra.Renderer(dry, size=(8, 6), water="muddy")


def test_scene_pickles_as_a_reload(tmp_path):
    import pickle

    s = spectra.load("cornell", env="default", env_intensity=0.5)
    t = pickle.loads(pickle.dumps(s))
    assert t.source == s.source and t.lights == s.lights
    a = spectra.truth(s, spp=1, size=(16, 12))
    assert np.array_equal(a, spectra.truth(t, spp=1, size=(16, 12)))
    assert not np.array_equal(a, spectra.truth(spectra.load("cornell"), spp=1, size=(16, 12)))


def test_material_variants_are_chosen_and_survive_pickling(tmp_path):
    """`variant=` is `--variant`: the file's KHR_materials_variants variant by name, kept by a
    pickled scene; an unknown name is a ValueError listing the file's variants."""
    import base64
    import json
    import pickle
    import struct

    pos = struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0)
    idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    buf = pos + idx
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_variants", "KHR_lights_punctual"],
        "extensions": {
            "KHR_materials_variants": {"variants": [{"name": "red"}, {"name": "green"}]},
            "KHR_lights_punctual": {"lights": [{"type": "directional", "intensity": 3}]},
        },
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "translation": [0, 0, 3]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}},
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
        "materials": [
            {"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}},
            {"name": "red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.1, 0.1, 1]}},
            {"name": "green", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.8, 0.1, 1]}},
        ],
        "meshes": [
            {
                "primitives": [
                    {
                        "attributes": {"POSITION": 0},
                        "indices": 1,
                        "material": 0,
                        "extensions": {
                            "KHR_materials_variants": {
                                "mappings": [{"material": 1, "variants": [0]}, {"material": 2, "variants": [1]}]
                            }
                        },
                    }
                ]
            }
        ],
        "buffers": [
            {"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}
        ],
        "bufferViews": [
            {"buffer": 0, "byteLength": len(pos)},
            {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx)},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    path = tmp_path / "variants.gltf"
    path.write_text(json.dumps(doc))
    mean = {}
    for v in (None, "red", "GREEN"):
        s = spectra.load(str(path), variant=v)
        img = spectra.truth(s, spp=1, size=(8, 6))
        mean[v] = img[2:4, 3:5].reshape(-1, 3).mean(axis=0)
        t = pickle.loads(pickle.dumps(s))
        assert np.array_equal(img, spectra.truth(t, spp=1, size=(8, 6)))
    assert any("'red' and 'green'" in w for w in spectra.load(str(path)).warnings)
    assert mean["red"][0] > 2 * mean["red"][1] and mean["GREEN"][1] > 2 * mean["GREEN"][0]
    assert abs(mean[None][0] - mean[None][1]) < 0.05 * mean[None][1]
    with pytest.raises(ValueError, match="'red' and 'green'"):
        spectra.load(str(path), variant="blue")
    with pytest.raises(ValueError, match="built-in"):
        spectra.load("cornell", variant="red")


def test_animations_pose_the_scene_and_survive_pickling():
    """`animation=`, `time=` are `--animation`, `--time`: the Fox (a skinned mesh with three
    animations) posed by "Run" at 0.5 s, named or by its index, is drawn the same and otherwise
    than at rest; a pickled posed scene keeps the pose; an unknown animation is a ValueError
    listing the file's, a negative time a ValueError, a float index a TypeError; at rest the
    warning says so."""
    import pickle

    fox = str(ROOT / "crates" / "scene" / "tests" / "data" / "pose" / "Fox" / "Fox.gltf")

    def draw(scene):
        return spectra.Renderer(scene, size=(48, 32)).render("rgb")

    rest = spectra.load(fox)
    assert any("drawn at rest" in w and "2 'Run'" in w for w in rest.warnings), rest.warnings
    run = spectra.load(fox, animation="Run", time=0.5)
    assert not any("drawn at rest" in w for w in run.warnings), run.warnings
    a, b, r = draw(run), draw(spectra.load(fox, animation=2, time=0.5)), draw(rest)
    assert np.isfinite(a).all() and np.isfinite(r).all()
    assert np.array_equal(a, b), "the animation by its name and by its index"
    # The fox is white over the default environment's grey ground: its pixels move.
    moved = np.abs(a - r).max(axis=2) > 0.05
    assert moved.sum() > 30, f"the posed fox differs from the one at rest in {moved.sum()} pixels"
    assert np.array_equal(draw(pickle.loads(pickle.dumps(run))), a), "a pickled scene keeps its pose"
    assert rest.animation_end is None and abs(run.animation_end - 1.1583333) < 1e-6, run.animation_end
    with pytest.raises(ValueError, match="0 'Survey' of 3.417 s, 1 'Walk' of 0.708 s and 2 'Run' of 1.158 s"):
        spectra.load(fox, animation="Jump")
    with pytest.raises(ValueError, match="time"):
        spectra.load(fox, animation="Run", time=-1)
    with pytest.raises(TypeError, match="animation"):
        spectra.load(fox, animation=1.5)
    # Python's spelling in the messages, not the CLI's.
    with pytest.raises(ValueError, match=r"^[^-]*\btime -1: must be seconds"):
        spectra.load(fox, time=-1)


def test_compressed_geometry_and_textures_load_as_the_plain_files():
    """Draco geometry (KHR_draco_mesh_compression) and KTX2 textures (KHR_texture_basisu) are
    the loader's, so Python reads them as the CLI does: the Draco RiggedSimple draws as its
    plain original does, but for a few silhouette pixels (the Draco tools quantize positions
    to 11 bits); the KTX2 fuzz seed loads and draws."""
    d = ROOT / "crates" / "scene" / "tests" / "data" / "draco" / "RiggedSimple"

    def draw(scene):
        return spectra.Renderer(scene, size=(48, 32)).render("rgb")

    plain = draw(spectra.load(str(d / "glTF" / "RiggedSimple.gltf")))
    draco = draw(spectra.load(str(d / "glTF-Draco" / "RiggedSimple.gltf")))
    differ = np.abs(plain - draco).max(axis=2) > 0.02
    assert differ.sum() <= 8, f"{differ.sum()} pixels differ"
    assert np.abs(plain - draco).mean() < 2e-3
    glb = ROOT / "crates" / "fuzz" / "corpus" / "gltf" / "ktx2-basisu.glb"
    ktx = spectra.load(str(glb))
    assert np.isfinite(draw(ktx)).all()


def test_an_int_animation_is_an_index_whatever_the_names(tmp_path):
    """`animation=2` is the file's third animation even where another is named "2"; the str
    "2" is that name (as `--animation 2` reads it), and a pickled scene keeps which."""
    import json
    import pickle
    import shutil

    src = ROOT / "crates" / "scene" / "tests" / "data" / "pose" / "Fox"
    doc = json.loads((src / "Fox.gltf").read_text())
    doc["animations"][0]["name"] = "2"
    (tmp_path / "Fox.gltf").write_text(json.dumps(doc))
    shutil.copy(src / "Fox.bin", tmp_path / "Fox.bin")
    fox = str(tmp_path / "Fox.gltf")

    def draw(scene):
        return spectra.Renderer(scene, size=(48, 32)).render("rgb")

    by_int = spectra.load(fox, animation=2, time=0.5)
    by_name = spectra.load(fox, animation="2", time=0.5)
    assert np.array_equal(draw(by_int), draw(spectra.load(fox, animation="Run", time=0.5)))
    assert np.array_equal(draw(by_name), draw(spectra.load(fox, animation=0, time=0.5)))
    assert not np.array_equal(draw(by_int), draw(by_name))
    assert np.array_equal(draw(pickle.loads(pickle.dumps(by_int))), draw(by_int))
    assert np.array_equal(draw(pickle.loads(pickle.dumps(by_name))), draw(by_name))
    with pytest.raises(ValueError, match="animation 3: the file has no such animation"):
        spectra.load(fox, animation=3)


def test_env_sun_switch_is_the_clis_and_survives_pickling():
    """`env_sun=False` is `--no-env-sun`: rooitou_park's sun is then not a shadowed light, and
    the real-time image changes; a pickled scene keeps the choice."""
    import pickle

    sky = str(ROOT / "assets" / "environments" / "rooitou_park.hdr")
    with_sun = spectra.load("colorchecker", env=sky)
    without = spectra.load("colorchecker", env=sky, env_sun=False)
    a = spectra.Renderer(with_sun, size=(24, 16)).render()
    b = spectra.Renderer(without, size=(24, 16)).render()
    assert np.isfinite(a).all() and np.isfinite(b).all()
    assert not np.array_equal(a, b)
    c = spectra.Renderer(pickle.loads(pickle.dumps(without)), size=(24, 16)).render()
    assert np.array_equal(b, c)


def test_env_sun_share_is_the_clis():
    """`env_sun_share` is `--env-sun-share`: asking more of a sun than rooitou_park's gives
    (65 % of its light) makes the map sunless, as `env_sun=False` does; out of range is the
    CLI's error, naming the value; a pickled scene keeps the share."""
    import pickle

    sky = str(ROOT / "assets" / "environments" / "rooitou_park.hdr")
    strict = spectra.load("colorchecker", env=sky, env_sun_share=0.9)
    a = spectra.Renderer(strict, size=(24, 16)).render()
    b = spectra.Renderer(spectra.load("colorchecker", env=sky, env_sun=False), size=(24, 16)).render()
    c = spectra.Renderer(spectra.load("colorchecker", env=sky, env_sun_share=0.5), size=(24, 16)).render()
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    d = spectra.Renderer(pickle.loads(pickle.dumps(strict)), size=(24, 16)).render()
    assert np.array_equal(a, d)
    for bad in (0.0, 1.5, float("nan")):
        with pytest.raises(ValueError, match="share"):
            spectra.load("colorchecker", env=sky, env_sun_share=bad)


def test_env_options():
    with pytest.raises(FileNotFoundError, match="no_such_sky.hdr"):
        spectra.load("cornell", env="no_such_sky.hdr")
    with pytest.raises(ValueError, match="intensity"):
        spectra.load("cornell", env="default", env_intensity=-1)


def test_diff_maps_and_flip(renderer):
    a, b = renderer.render("rgb"), renderer.render()
    d = spectra.diff(a, b, maps=True, flip="ldr")
    m = d["delta_e2000_map"]
    assert m.shape == (H, W) and m.dtype == np.float64
    assert m.mean() == pytest.approx(d["delta_e2000"]["mean"], rel=1e-12)
    assert d["mae_linear_map"].mean() == pytest.approx(d["mae_linear"]["mean"], rel=1e-12)
    assert d["flip_kind"] == "ldr" and 0 < d["flip"]["mean"] < 1
    assert d["flip_map"].shape == (H, W)
    assert spectra.diff(a, a, flip="hdr")["flip"]["max"] == 0.0
    with pytest.raises(ValueError, match="flip 'xyz'"):
        spectra.diff(a, b, flip="xyz")
    with pytest.raises(ValueError, match="flip_ppd"):
        spectra.diff(a, b, flip="ldr", flip_ppd=0)
    with pytest.raises(ValueError, match="white_y"):
        spectra.diff(a, b, white_y=-1)


def test_diff_equals_the_cli(tmp_path):
    import json

    exe = spectra_bin()
    env = {**os.environ, "XDG_RUNTIME_DIR": os.environ.get("XDG_RUNTIME_DIR", str(tmp_path))}
    ref, test = tmp_path / "t.exr", tmp_path / "s.exr"
    subprocess.run(
        [exe, "truth", "metamerism", "--direct-only", "--spp", "4", "--size", "40x30", "--out", str(ref)],
        check=True,
        env=env,
    )
    subprocess.run([exe, "render", "metamerism", "--size", "40x30", "--out", str(test)], check=True, env=env)
    out = subprocess.run(
        [exe, "diff", str(ref), str(test), "--json", "--metric", "flip"],
        check=True,
        env=env,
        capture_output=True,
        text=True,
    ).stdout
    cli = json.loads(out)
    py = spectra.diff(spectra.read_image(ref), spectra.read_image(test), flip="hdr")
    for key in ("delta_e2000", "mae_linear", "mae_srgb", "flip", "flip_exposures"):
        assert py[key] == cli[key], key
    # The truth EXR holds what spectra.truth returns, bit for bit.
    scene = spectra.load("metamerism")
    assert np.array_equal(
        spectra.truth(scene, spp=4, size=(40, 30), direct_only=True), read_exr(ref)
    )


def test_diff_of_two_files_lines_crops_up_as_the_cli(tmp_path):
    """`spectra diff` lines EXR crops up by where they lie in their frame; `diff` of the two
    files does too (it took arrays only, which read_image gives as the crop alone: two crops of
    one size at different places were compared pixel for pixel, and a crop with its full frame
    refused for their sizes), and `read_image(placement=True)` says where each lies. Arrays
    given directly still compare as given."""
    import json

    exe = spectra_bin()
    env = {**os.environ, "XDG_RUNTIME_DIR": os.environ.get("XDG_RUNTIME_DIR", str(tmp_path))}
    size = ["--size", "40x30", "--direct-only", "--spp", "2"]

    def truth(out, *extra):
        subprocess.run([exe, "truth", "metamerism", *size, *extra, "--out", str(out)], check=True, env=env)
        return out

    full = truth(tmp_path / "full.exr", "--seed", "1")
    c1 = truth(tmp_path / "c1.exr", "--seed", "1", "--crop", "4,2,20,16")
    c2 = truth(tmp_path / "c2.exr", "--seed", "2", "--crop", "10,6,20,16")
    far = truth(tmp_path / "far.exr", "--seed", "2", "--crop", "30,20,6,6")

    img, placed = spectra.read_image(c1, placement=True)
    assert img.shape == (16, 20, 3)
    assert placed == {"frame": (40, 30), "x": 4, "y": 2, "width": 20, "height": 16}
    whole = {"frame": (40, 30), "x": 0, "y": 0, "width": 40, "height": 30}
    assert spectra.read_image(full, placement=True)[1] == whole
    assert np.array_equal(spectra.read_image(c1), img)

    def cli(a, b):
        out = subprocess.run(
            [exe, "diff", str(a), str(b), "--json"], check=True, env=env, capture_output=True, text=True
        ).stdout
        return json.loads(out)

    keys = ("width", "height", "delta_e2000", "mae_linear", "mae_srgb", "region")
    for a, b in [(c1, c2), (full, c2), (c1, full)]:
        want = cli(a, b)
        for a_, b_ in [(a, b), (str(a), str(b))]:
            got = spectra.diff(a_, b_)
            assert {k: got[k] for k in keys} == {k: want[k] for k in keys}, (a.name, b.name)
    # The overlap of the two crops: x 10…23, y 6…17 of the frame.
    r = spectra.diff(c1, c2, maps=True)
    assert r["region"] == {"frame": [40, 30], "x": 10, "y": 6, "width": 14, "height": 12}
    assert r["delta_e2000_map"].shape == (12, 14)
    a, b = spectra.read_image(c1)[4:16, 6:20], spectra.read_image(c2)[0:12, 0:14]
    assert spectra.diff(a, b)["delta_e2000"] == r["delta_e2000"]
    # A crop against its full frame: the crop's pixels of the frame.
    r = spectra.diff(full, c2)
    assert r["region"] == {"frame": [40, 30], "x": 10, "y": 6, "width": 20, "height": 16}
    cut = spectra.read_image(full)[6:22, 10:30]
    assert spectra.diff(cut, spectra.read_image(c2))["delta_e2000"] == r["delta_e2000"]
    # Arrays as given: pixel for pixel, no region.
    arrays = spectra.diff(spectra.read_image(c1), spectra.read_image(c2))
    assert arrays["region"] is None and (arrays["width"], arrays["height"]) == (20, 16)
    assert spectra.diff(str(c1), str(c1))["region"] is None
    with pytest.raises(ValueError, match="differ in size"):
        spectra.diff(spectra.read_image(full), spectra.read_image(c2))
    # Crops that share no pixel: refused, saying where each lies.
    with pytest.raises(ValueError, match="share no pixel") as e:
        spectra.diff(c1, far)
    assert "c1.exr" in str(e.value) and "6×6 pixels at (30, 20)" in str(e.value)
    with pytest.raises(FileNotFoundError, match="nope.exr"):
        spectra.diff(tmp_path / "nope.exr", c1)


def test_demo_table_equals_spectra_demo(tmp_path):
    import importlib.util

    exe = spectra_bin()
    env = {**os.environ, "XDG_RUNTIME_DIR": os.environ.get("XDG_RUNTIME_DIR", str(tmp_path))}
    out = subprocess.run(
        [exe, "demo", "--size", "48x36", "--spp", "4", "--out", str(tmp_path / "demo")],
        check=True,
        env=env,
        capture_output=True,
        text=True,
    ).stdout
    spec = importlib.util.spec_from_file_location("demo_table", ROOT / "python/examples/demo_table.py")
    demo = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(demo)
    ours = demo.format_table("metamerism", 4, demo.table("metamerism", (48, 36), 4))
    assert ours in out, (ours, out)


def test_upsample_against_colour_science():
    colour = pytest.importorskip("colour")
    rng = np.random.default_rng(5)
    rgb = rng.uniform(0.02, 0.98, size=(200, 3))
    lam = np.arange(360.0, 781.0, 5.0)
    coeffs, spectra_ = spectra.upsample(rgb, wavelengths=lam)
    assert coeffs.shape == (200, 3) and spectra_.shape == (200, lam.size)
    assert np.array_equal(spectra.upsample(rgb), coeffs)
    shape = colour.SpectralShape(360, 780, 5)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape)
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
    d65_xy = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    de = []
    for c, s, target in zip(coeffs, spectra_, rgb):
        # colour-science evaluates the same sigmoid polynomial (Jakob & Hanika 2019) itself.
        sd = colour.recovery.sd_Jakob2019(c, shape)
        np.testing.assert_allclose(sd.values, s, rtol=1e-12, atol=1e-12)
        xyz = colour.sd_to_XYZ(sd, cmfs, d65) / 100
        lab = colour.XYZ_to_Lab(xyz, d65_xy)
        want = colour.XYZ_to_Lab(colour.RGB_to_XYZ(target, "sRGB", d65_xy), d65_xy)
        de.append(colour.delta_E(lab, want, method="CIE 2000"))
    # The round trip through colour-science's integration (5 nm, 360–780) stays within the
    # table's documented accuracy (mean 0.0034, max 0.059 at 1 nm; 5 nm adds its own error).
    assert np.mean(de) < 0.05 and np.max(de) < 0.3, (np.mean(de), np.max(de))
    # Any leading shape, float32 too.
    c4 = spectra.upsample(rgb.reshape(10, 20, 3).astype(np.float32))
    assert c4.shape == (10, 20, 3)
    with pytest.raises(ValueError, match="rgb: .*within \\[0, 1\\]"):
        spectra.upsample([[0.5, 1.5, 0.2]])
    with pytest.raises(ValueError, match="rgb: .*shape"):
        spectra.upsample(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="rgb: .*dtype"):
        spectra.upsample(np.zeros((4, 3), dtype=np.complex128))
    with pytest.raises(ValueError, match="wavelengths"):
        spectra.upsample(rgb, wavelengths=[500, np.nan])
    with pytest.raises(ValueError, match="space"):
        spectra.upsample(rgb, space="cmyk")


def test_diff_against_colour_science():
    colour = pytest.importorskip("colour")
    rng = np.random.default_rng(9)
    a = rng.uniform(0, 1, size=(12, 10, 3)).astype(np.float32)
    b = np.clip(a + rng.normal(0, 0.05, size=a.shape), 0, 1).astype(np.float32)
    d = spectra.diff(a, b, maps=True)
    # sRGB's matrix derived from its primaries and D65 (0.3127, 0.3290), as spectra derives it.
    cs = colour.RGB_COLOURSPACES["sRGB"].copy()
    cs.use_derived_transformation_matrices(True)
    d65 = np.array([0.3127, 0.3290])
    lab = lambda x: colour.XYZ_to_Lab(colour.RGB_to_XYZ(x.astype(np.float64), cs, apply_cctf_decoding=False), d65)
    want = colour.delta_E(lab(a), lab(b), method="CIE 2000")
    np.testing.assert_allclose(d["delta_e2000_map"], want, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(d["mae_linear_map"], np.abs(a - b).astype(np.float64).mean(-1), rtol=1e-6, atol=1e-7)


def test_observers_and_illuminants_against_colour_science():
    colour = pytest.importorskip("colour")
    lam = np.arange(380.0, 781.0, 10.0)
    d65 = spectra.illuminant("D65", lam)
    np.testing.assert_allclose(d65, colour.SDS_ILLUMINANTS["D65"][lam], rtol=1e-6)
    xyz = spectra.observer("cie1931", lam)
    assert xyz.shape == (lam.size, 3)
    ref = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"][lam]
    np.testing.assert_allclose(xyz / xyz[:, 1].max(), ref / ref[:, 1].max(), rtol=1e-4, atol=1e-6)
    assert set(spectra.OBSERVERS) >= {"cie1931", "cie1964"} and "D65" in spectra.ILLUMINANTS
    with pytest.raises(ValueError, match="observer"):
        spectra.observer("martian", lam)
    with pytest.raises(ValueError, match="illuminant"):
        spectra.illuminant("Z99", lam)
    with pytest.raises(ValueError, match=r"wavelengths\[1\]"):
        spectra.illuminant("D65", [500, -3])


def test_cie2015_observers_against_colour_science():
    colour = pytest.importorskip("colour")
    lam = np.arange(390.0, 831.0, 1.0)
    for name, key in (("cie2015_2", "CIE 2015 2 Degree Standard Observer"),
                      ("cie2015_10", "CIE 2015 10 Degree Standard Observer")):
        ours = spectra.observer(name, lam)
        ref = colour.MSDS_CMFS[key]
        np.testing.assert_allclose(ours, ref[lam], rtol=1e-12, atol=1e-15)  # its z̄ tail has -5e-21s
        # The ColorChecker's XYZ under D65 (1 nm sums over 390–830 nm, Y of the white = 100) with
        # spectra's tables equals colour-science's own integration.
        d65 = spectra.illuminant("D65", lam)
        k = 100 / (d65 @ ours[:, 1])
        shape = colour.SpectralShape(390, 830, 1)
        d65_sd = colour.SDS_ILLUMINANTS["D65"].copy().align(shape)
        for patch, sd in colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"].items():
            r = sd.copy().align(shape)
            xyz = k * (r.values * d65) @ ours
            want = colour.sd_to_XYZ(r, ref.copy().align(shape), d65_sd, method="Integration")
            np.testing.assert_allclose(xyz, want, rtol=1e-4, err_msg=f"{name} {patch}")
    assert spectra.observer("cie2015_2", [380.0])[0].tolist() == [0.0, 0.0, 0.0]  # not tabulated there


def _camera_files():
    """Every camera spectra ships, with its data file read independently of spectra: the
    database's rawtoaces JSON files (json module), and the three older built-ins' tables from
    colour-science, where they come from (tools/gen_observer_data.py)."""
    out = {}
    for path in sorted((ROOT / "crates" / "color" / "data" / "cameras").glob("*.json")):
        import json

        doc = json.loads(path.read_text())
        idx = doc["spectral_data"]["index"]["main"]
        rows = sorted((float(k), v) for k, v in doc["spectral_data"]["data"]["main"].items())
        lam = np.array([r[0] for r in rows])
        vals = np.array([[r[1][idx.index(c)] for c in "RGB"] for r in rows], dtype=float)
        name = path.name[: -len("_380_780_5.json")].lower().replace("-", "_")
        out[name] = (lam, vals)
    return out


def test_every_camera_sees_the_colorchecker_as_numpy_integrates_its_file():
    """Issue 33's acceptance: the 24 patches under D65 and F11 in camera RGB, for every shipped
    camera, equal an independent numpy integration of the same data file (1 nm midpoints over
    360–830 nm, the file interpolated linearly and zero outside it; patches and illuminants from
    colour-science) to 1e-4 relative."""
    colour = pytest.importorskip("colour")
    files = _camera_files()
    sens = colour.MSDS_CAMERA_SENSITIVITIES
    for name, key in (("nikon_d5100", "Nikon 5100 (NPL)"), ("sigma_sd_merrill", "Sigma SDMerill (NPL)")):
        files[name] = (sens[key].wavelengths, sens[key].values)
    assert len(files) >= 50 and set(files) <= set(spectra.OBSERVERS)
    mid = np.arange(360.0, 830.0) + 0.5
    interp = lambda lam, v: np.interp(mid, lam, v, left=0.0, right=0.0)  # noqa: E731
    patches = [interp(sd.wavelengths, sd.values) for sd in colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"].values()]
    for ill, key in (("D65", "D65"), ("F11", "FL11")):
        sd = colour.SDS_ILLUMINANTS[key]
        e = interp(sd.wavelengths, sd.values)
        for name, (lam, vals) in files.items():
            s = np.stack([interp(lam, vals[:, c]) for c in range(3)], axis=1)
            want = np.array([(r * e) @ s for r in patches])
            got = spectra.chart(name, ill)
            np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-12 * want.max(), err_msg=f"{name} {ill}")
            white = e @ s
            np.testing.assert_allclose(spectra.chart(name, ill, balanced=True), want / white, rtol=1e-4)


def test_camspec_tool_writes_files_observer_reads(tmp_path):
    """tools/camspec_to_csv.py on a file in the Jiang et al. 2013 layout (name, then R, G, B rows
    at 400–720 nm): each camera's CSV is read by `--observer FILE` as those values; a malformed
    file is refused with its line number."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("camspec", ROOT / "tools" / "camspec_to_csv.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    lam = np.arange(400.0, 721.0, 10.0)
    rng = np.random.default_rng(7)
    cams = {"Canon 5D Mark II": rng.random((3, 33)), "Nikon D40": rng.random((3, 33))}
    text = "".join(f"{n}\n" + "".join("\t".join(f"{v:.6f}" for v in row) + "\n" for row in m) for n, m in cams.items())
    paths = tool.write(tool.parse(text), tmp_path)
    assert [p.name for p in paths] == ["Canon_5D_Mark_II.csv", "Nikon_D40.csv"]
    for (name, m), path in zip(cams.items(), paths):
        np.testing.assert_allclose(spectra.observer(str(path), lam), np.round(m, 6).T, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="line 3: 2 values"):
        tool.parse("Cam\n" + "\t".join(["0.1"] * 33) + "\n0.1 0.2\n")
    with pytest.raises(ValueError, match="'Cam' has 1 rows"):
        tool.parse("Cam\n" + "\t".join(["0.1"] * 33) + "\nOther\n")


def test_a_camera_balanced_and_through_its_fit_equals_the_cli(tmp_path, cornell, renderer):
    """`observer=` a database camera, with and without `camera_to_display`, in both renderers:
    the images `spectra render` / `spectra truth` write with the same flags, and the two views
    differ (the flag is not ignored)."""
    exe = spectra_bin()
    env = {**os.environ, "XDG_RUNTIME_DIR": os.environ.get("XDG_RUNTIME_DIR", str(tmp_path))}
    views = {}
    for flag in (False, True):
        extra = ["--camera-to-display"] if flag else []
        out, tout = tmp_path / f"r{flag}.exr", tmp_path / f"t{flag}.exr"
        common = ["cornell", "--size", f"{W}x{H}", "--observer", "canon_eos_r5"] + extra
        subprocess.run([exe, "render", *common, "--out", str(out)], check=True, env=env)
        subprocess.run([exe, "truth", *common, "--spp", "4", "--out", str(tout)], check=True, env=env)
        py = renderer.render(observer="canon_eos_r5", camera_to_display=flag)
        assert np.array_equal(read_exr(out).view(np.uint32), py.view(np.uint32))
        t = spectra.truth(cornell, spp=4, size=(W, H), observer="canon_eos_r5", camera_to_display=flag)
        assert np.array_equal(read_exr(tout).view(np.uint32), t.view(np.uint32))
        views[flag] = py
    assert np.abs(views[True] - views[False]).max() > 1e-3


def _unlit_quad_gltf(path):
    """A glTF with one quad facing a camera and no lights (the loader's default environment)."""
    import base64
    import json
    import struct

    pos = [-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]
    nrm = [0, 0, 1] * 4
    idx = [0, 1, 2, 0, 2, 3]
    data = struct.pack("<12f", *pos) + struct.pack("<12f", *nrm) + struct.pack("<6H", *idx)
    gltf = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1], "metallicFactor": 0}}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 12}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    path.write_text(json.dumps(gltf))
    return path


def test_a_scene_without_lights_under_water_is_lit_as_the_cli_lights_it(tmp_path):
    """`load` picks the default sky for a scene without lights; rendered with `water=` it gets
    the underwater sun instead, as `spectra render FILE --water` chooses (the choice is made
    when the water is known, not at load)."""
    import pickle

    f = str(_unlit_quad_gltf(tmp_path / "quad.gltf"))
    s = spectra.load(f)
    exe = spectra_bin()
    env = {**os.environ, "XDG_RUNTIME_DIR": os.environ.get("XDG_RUNTIME_DIR", str(tmp_path))}
    for water, out in ((None, tmp_path / "dry.exr"), ("IB", tmp_path / "wet.exr")):
        args = [exe, "render", f, "--size", "16x12", "--wavelengths", "4", "--out", str(out)]
        if water:
            args += ["--water", water, "--depth", "5"]
        subprocess.run(args, check=True, env=env)
        for scene in (s, pickle.loads(pickle.dumps(s))):
            py = spectra.Renderer(scene, size=(16, 12), water=water, depth=5 if water else None)
            img = py.render(wavelengths=4)
            cli = read_exr(out)
            assert np.array_equal(cli.view(np.uint32), img.view(np.uint32)), (water, np.abs(cli - img).max())
            assert img.mean() > 0
    # The path tracer takes the same scene: a sun, which it can refract through the surface.
    t = spectra.truth(s, spp=1, size=(8, 6), direct_only=True, water="IB", depth=5)
    assert np.isfinite(t).all() and t.mean() > 0


def test_type_stub_matches_the_extension(tmp_path):
    """python/spectra/__init__.pyi against the runtime: a stub for every exported name, and
    every function's and method's parameters (names, kinds, defaults) the extension's own
    (`#[pyo3(signature = ...)]`, read back through `inspect`). An overload may narrow a default
    away (`spectral: Literal[True]`), but one of a function's overloads takes every call the
    runtime does; a lone overload is no overload (mypy refuses it). mypy checks the stub where
    it is installed."""
    import ast
    import inspect

    stub = ROOT / "python" / "spectra" / "__init__.pyi"
    tree = ast.parse(stub.read_text())
    P = inspect.Parameter

    def params(fn):
        a = fn.args
        pos = a.posonlyargs + a.args
        pos_defaults = [P.empty] * (len(pos) - len(a.defaults)) + [ast.literal_eval(d) for d in a.defaults]
        out = [(p.arg, P.POSITIONAL_OR_KEYWORD, d) for p, d in zip(pos, pos_defaults)]
        out += [
            (p.arg, P.KEYWORD_ONLY, P.empty if d is None else ast.literal_eval(d))
            for p, d in zip(a.kwonlyargs, a.kw_defaults)
        ]
        return [p for p in out if p[0] != "self"]

    def runtime(obj):
        # A tuple default pyo3 would show as `...`; lib.rs spells those in text signatures.
        return [
            (p.name, p.kind, p.default)
            for p in inspect.signature(obj).parameters.values()
            if p.name != "self"
        ]

    def agrees(stubbed, actual, exact):
        if [(n, k) for n, k, _ in stubbed] != [(n, k) for n, k, _ in actual]:
            return False
        for (_, _, d), (_, _, want) in zip(stubbed, actual):
            if want is Ellipsis:
                want = d if d is not P.empty else want
            if d != want and (exact or d is not P.empty):
                return False
        return True

    def check(body, owner, where):
        seen = {}
        for node in body:
            if isinstance(node, ast.FunctionDef):
                overload = any(getattr(d, "id", None) == "overload" for d in node.decorator_list)
                seen.setdefault(node.name, []).append((params(node), overload))
        for name, defs in seen.items():
            if type(inspect.getattr_static(owner, name)).__name__ == "getset_descriptor":
                continue  # a property
            actual = runtime(owner if name == "__init__" else getattr(owner, name))
            overloads = [p for p, o in defs if o]
            assert len(overloads) != 1, f"{where}{name}: a lone @overload"
            if overloads:
                assert all(agrees(p, actual, exact=False) for p in overloads), f"{where}{name}: {actual}"
                assert any(agrees(p, actual, exact=True) for p in overloads), f"{where}{name}: {actual}"
            else:
                assert len(defs) == 1 and agrees(defs[0][0], actual, exact=True), f"{where}{name}: {actual}"

    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            names.add(node.target.id)
    assert set(spectra.__all__) <= names, set(spectra.__all__) - names
    check(tree.body, spectra, "")
    for node in tree.body:
        if isinstance(node, ast.ClassDef) and node.name in spectra.__all__:
            cls = getattr(spectra, node.name)
            check(node.body, cls, f"{node.name}.")
            getters = {n for n, v in vars(cls).items() if type(v).__name__ == "getset_descriptor"}
            stubbed = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
            assert getters <= stubbed, f"{node.name}: {getters - stubbed} not in the stub"

    try:
        from mypy import api as mypy
    except ImportError:
        return
    out, err, status = mypy.run(["--cache-dir", str(tmp_path / "mypy"), str(stub)])
    assert status == 0, out + err
