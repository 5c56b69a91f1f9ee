"""Robustness of the Python package beyond its API tests (test_spectra.py): processes forked
after the tracer ran, and the exception type of a missing file wherever one is named."""

import multiprocessing
import os

import pytest

import spectra


def _truth_and_diff(q):
    s = spectra.load("cornell")
    a = spectra.truth(s, spp=1, size=(8, 6))
    q.put(float(spectra.diff(a, a)["delta_e2000"]["mean"]))


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork() here")
def test_a_forked_child_traces_and_diffs_after_its_parent_did():
    """rayon's global pool does not survive fork(): a child made by multiprocessing's 'fork'
    start method (Linux's default before Python 3.14) waited for it forever after the parent
    had traced or diffed."""
    s = spectra.load("cornell")
    a = spectra.truth(s, spp=1, size=(8, 6))
    spectra.diff(a, a)
    ctx = multiprocessing.get_context("fork")
    q = ctx.Queue()
    p = ctx.Process(target=_truth_and_diff, args=(q,))
    p.start()
    p.join(60)
    hung = p.is_alive()
    if hung:
        p.kill()
    assert not hung, "the forked child did not finish within 60 s"
    assert p.exitcode == 0 and q.get(timeout=5) == 0.0


def test_a_missing_file_is_file_not_found_wherever_it_is_named(tmp_path):
    """docs/python.md: FileNotFoundError for a missing file, whichever argument names it."""
    s = spectra.load("cornell")
    missing = str(tmp_path / "nope.csv")
    calls = {
        "read_image": lambda: spectra.read_image(str(tmp_path / "nope.exr")),
        "observer": lambda: spectra.observer(missing, [550.0]),
        "render(observer=)": lambda: spectra.Renderer(s, size=(8, 6)).render(observer=missing),
        "truth(observer=)": lambda: spectra.truth(s, spp=1, size=(8, 6), observer=missing),
        "load": lambda: spectra.load(str(tmp_path / "nope.gltf")),
    }
    for what, call in calls.items():
        with pytest.raises(FileNotFoundError, match="nope"):
            call()
            pytest.fail(f"{what}: no error")


def test_huge_integers_are_refused_by_name_and_any_u64_seed_is_taken():
    """Python's integers are unbounded: one beyond the machine's was an OverflowError naming no
    argument, and seeds from 2⁶³ on (valid for `spectra truth --seed`) could not be given."""
    s = spectra.load("cornell")
    r = spectra.Renderer(s, size=(8, 6))
    for name, call in {
        "spp": lambda: spectra.truth(s, spp=2**70, size=(8, 6)),
        "seed": lambda: spectra.truth(s, spp=1, size=(8, 6), seed=2**64),
        "sample_offset": lambda: spectra.truth(s, spp=1, size=(8, 6), sample_offset=2**80),
        "size": lambda: spectra.truth(s, spp=1, size=(2**65, 6)),
        "wavelengths": lambda: r.render(wavelengths=2**64),
        "samples": lambda: r.render(samples=-(2**70)),
    }.items():
        with pytest.raises(ValueError, match=name):
            call()
    big = spectra.truth(s, spp=1, size=(8, 6), seed=2**64 - 1)
    assert big.shape == (6, 8, 3) and not (big == spectra.truth(s, spp=1, size=(8, 6), seed=1)).all()


def test_signatures_spell_their_tuple_defaults():
    """inspect.signature showed `size=Ellipsis` (pyo3's rendering of a tuple default), so a
    signature's defaults, bound and passed back, were a TypeError."""
    import inspect

    t = inspect.signature(spectra.truth)
    assert t.parameters["size"].default == (256, 256)
    assert inspect.signature(spectra.Renderer).parameters["size"].default == (640, 480)
    bound = t.bind(spectra.load("cornell"), spp=1)
    bound.apply_defaults()
    bound.arguments["size"] = (8, 6)
    assert spectra.truth(*bound.args, **bound.kwargs).shape == (6, 8, 3)


def _one_triangle_gltf(path):
    """A glTF with one triangle and no lights (so that `load` lights it with the default sky)."""
    import base64
    import json
    import struct

    data = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteLength": len(data)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]}],
    }
    path.write_text(json.dumps(doc))


def test_a_frame_below_the_half_float_range_is_warned_about(tmp_path, capfd):
    """The real-time renderer's HDR target is half float: a scene lit at 1e-9 of the default
    sky comes back black, which `render` and `Renderer.render` say on stderr (it was silent)."""
    g = tmp_path / "tri.gltf"
    _one_triangle_gltf(g)
    capfd.readouterr()
    for intensity, warned in ((1e-9, True), (1.0, False)):
        s = spectra.load(str(g), env="default", env_intensity=intensity)
        img = spectra.Renderer(s, size=(16, 12)).render(mode="rgb")
        err = capfd.readouterr().err
        assert ("half-float" in err) == warned, (intensity, err)
        assert (img.max() < 6.2e-5) == warned
