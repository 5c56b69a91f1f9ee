"""Ctrl-C wherever `truth` runs (a forked child, a large first pass), getters that do not wait
for another thread's render, `diff`'s HDR-FLIP options, float64 input beyond float32, and the
ordinary Python/numpy inputs and messages of every argument (found by a sweep of the package)."""

import multiprocessing
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import spectra


def _long_truth_in_child(q):
    s = spectra.load("cornell")
    t0 = time.time()
    q.put(("started", t0))
    try:
        spectra.truth(s, spp=200000, size=(16, 12))
        q.put(("finished", time.time()))
    except KeyboardInterrupt:
        q.put(("KeyboardInterrupt", time.time()))


@pytest.mark.skipif(not hasattr(os, "fork"), reason="no fork() here")
def test_ctrl_c_interrupts_truth_in_a_forked_child():
    """In a child forked after its parent traced, the render ran on a pool of its own and the
    signal check, made on a pool thread, did nothing: SIGINT was ignored until the render's end."""
    s = spectra.load("cornell")
    spectra.truth(s, spp=1, size=(8, 6))
    ctx = multiprocessing.get_context("fork")
    q = ctx.Queue()
    p = ctx.Process(target=_long_truth_in_child, args=(q,))
    p.start()
    try:
        assert q.get(timeout=60)[0] == "started"
        time.sleep(1.0)
        sent = time.time()
        os.kill(p.pid, signal.SIGINT)
        p.join(10)
        alive = p.is_alive()
    finally:
        if p.is_alive():
            p.kill()
    assert not alive, "the forked child was still rendering 10 s after SIGINT"
    what, when = q.get(timeout=5)
    assert what == "KeyboardInterrupt" and when - sent < 2.0, (what, when - sent)


def test_ctrl_c_interrupts_a_large_first_pass_at_once(tmp_path):
    """The first pass was a whole sample over the whole frame, and signals were looked at only
    between passes: 9 s from Ctrl-C to KeyboardInterrupt at 2048². Run in a process of its own,
    so that the SIGINT cannot reach pytest."""
    script = textwrap.dedent(
        """
        import os, signal, threading, time, spectra
        s = spectra.load("cornell")
        sent = []
        def interrupt():
            time.sleep(0.5)
            sent.append(time.time())
            os.kill(os.getpid(), signal.SIGINT)
        threading.Thread(target=interrupt, daemon=True).start()
        try:
            spectra.truth(s, spp=1000, size=(2048, 2048))
            print("finished")
        except KeyboardInterrupt:
            print(f"interrupted {time.time() - sent[0]:.3f}")
        """
    )
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300, cwd=tmp_path
    ).stdout.split()
    assert out[0] == "interrupted", out
    assert float(out[1]) < 1.0, f"KeyboardInterrupt {out[1]} s after SIGINT"


def test_getters_do_not_wait_for_another_threads_render():
    """`size`, `device` and `repr` took the renderer's lock with the GIL held: while another
    thread rendered, they waited for its end and froze every Python thread meanwhile."""
    r = spectra.Renderer(spectra.load("cornell"), size=(320, 240))
    r.render()
    t0 = time.perf_counter()
    r.render(samples=64)
    one = time.perf_counter() - t0
    if one < 0.3:
        pytest.skip(f"a render takes {one:.2f} s here: too short to measure a wait")
    w = threading.Thread(target=lambda: r.render(samples=64))
    w.start()
    time.sleep(0.1)
    times = {}
    for name, get in {"size": lambda: r.size, "device": lambda: r.device, "repr": lambda: repr(r)}.items():
        t = time.perf_counter()
        get()
        times[name] = time.perf_counter() - t
    rendering = w.is_alive()
    w.join()
    assert rendering, "the render had ended before the getters ran"
    assert max(times.values()) < 0.05, times
    assert r.size == (320, 240) and repr(r) == "<spectra.Renderer builtin:cornell 320×240>"


def test_hdr_flip_options_and_exposures():
    """A black reference could not be HDR-FLIPped from Python, and the message named the CLI's
    flags; the exposures used were not returned; flip_ppd without flip was ignored."""
    z = np.zeros((8, 8, 3), np.float32)
    g = np.full((8, 8, 3), 0.5, np.float32)
    with pytest.raises(ValueError, match="flip_start_exposure") as e:
        spectra.diff(z, g, flip="hdr")
    assert "--flip" not in str(e.value)
    d = spectra.diff(z, g, flip="hdr", flip_start_exposure=-2, flip_stop_exposure=1, flip_exposures=3,
                     flip_tone_mapper="hable")
    assert d["flip_exposures"] == {"start": -2.0, "stop": 1.0, "count": 3, "tone_mapper": "hable"}
    auto = spectra.diff(g, z, flip="hdr")["flip_exposures"]
    assert auto["tone_mapper"] == "aces" and auto["count"] >= 2 and auto["start"] <= auto["stop"]
    assert spectra.diff(g, z, flip="ldr")["flip_exposures"] is None
    for kw, msg in [
        (dict(flip_ppd=30), "flip_ppd .*flip="),
        (dict(flip_start_exposure=0), "flip_start_exposure .*flip="),
        (dict(flip="ldr", flip_tone_mapper="hable"), "flip_tone_mapper .*flip='ldr'"),
        (dict(flip="hdr", flip_start_exposure=1, flip_stop_exposure=0), "flip_start_exposure 1"),
        (dict(flip="hdr", flip_start_exposure=-100), "flip_start_exposure -100"),
        (dict(flip="hdr", flip_exposures=1), "flip_exposures 1"),
        (dict(flip="hdr", flip_tone_mapper="filmic"), "flip_tone_mapper"),
    ]:
        with pytest.raises(ValueError, match=msg):
            spectra.diff(g, g, **kw)


def test_float64_beyond_float32_is_refused_by_name(tmp_path):
    """Narrowed to float32, 1e300 became inf: written silently by write_image, and reported by
    diff as a non-finite pixel of "reference" the caller never gave."""
    big = np.full((2, 2, 3), 1e300)
    with pytest.raises(ValueError, match=r"^image: pixel .*1e300.*float32"):
        spectra.write_image(tmp_path / "h.exr", big)
    assert not (tmp_path / "h.exr").exists()
    with pytest.raises(ValueError, match=r"^a: pixel .*1e300.*float32"):
        spectra.diff(big, np.zeros((2, 2, 3)))
    with pytest.raises(ValueError, match=r"^b: pixel .*-1e300.*float32"):
        spectra.diff(np.zeros((2, 2, 3)), -big)
    inf = np.zeros((2, 2, 3), np.float32)
    inf[1, 0, 2] = np.inf
    with pytest.raises(ValueError, match=r"^a: pixel \(x 0, y 1\) is not finite"):
        spectra.diff(inf, np.zeros((2, 2, 3), np.float32))
    # Within float32's range float64 is taken, as before.
    spectra.write_image(tmp_path / "ok.exr", np.full((2, 2, 3), 1e30))
    assert spectra.read_image(tmp_path / "ok.exr")[0, 0, 0] == np.float32(1e30)


def test_ordinary_inputs(tmp_path):
    """Type-checker-clean calls that failed: int arrays and nested lists for upsample, lists
    for size/range/crop, pathlib.Path wherever a file may be named; bools are not counts."""
    np.testing.assert_array_equal(spectra.upsample(np.array([1, 0, 0])), spectra.upsample([1.0, 0.0, 0.0]))
    np.testing.assert_array_equal(
        spectra.upsample([[[0.5, 0.2, 0.1]]]), spectra.upsample(np.array([[[0.5, 0.2, 0.1]]]))
    )
    s = spectra.load("cornell")
    r = spectra.Renderer(s, size=[8, 6])
    assert r.size == (8, 6)
    np.testing.assert_array_equal(r.render(range=[400, 700]), r.render(range=(400, 700)))
    np.testing.assert_array_equal(r.render(range=np.array([400.0, 700.0])), r.render(range=(400, 700)))
    kw = dict(spp=1, seed=3)
    np.testing.assert_array_equal(
        spectra.truth(s, size=[16, 12], crop=[0, 0, 5, 5], **kw),
        spectra.truth(s, size=(16, 12), crop=(0, 0, 5, 5), **kw),
    )
    # Paths: an environment map, an observer file, a medium file, outputs and inputs.
    img = np.full((4, 8, 3), 0.25, np.float32)
    spectra.write_image(tmp_path / "sky.exr", img)
    lam = np.arange(380.0, 781.0, 5.0)
    rows = "".join(f"{x},{a},{b},{c}\n" for x, (a, b, c) in zip(lam, spectra.observer("cie1931", lam)))
    (tmp_path / "obs.csv").write_text("wavelength,x,y,z\n" + rows)
    (tmp_path / "medium.json").write_text('{"absorption": [0.05, 0.1, 0.2], "scattering": [0.3, 0.3, 0.3]}')
    by_path = spectra.load("cornell", env=tmp_path / "sky.exr")
    by_str = spectra.load("cornell", env=str(tmp_path / "sky.exr"))
    np.testing.assert_array_equal(
        spectra.truth(by_path, size=(8, 6), observer=tmp_path / "obs.csv", rgb_medium=tmp_path / "medium.json", **kw),
        spectra.truth(by_str, size=(8, 6), observer=str(tmp_path / "obs.csv"),
                      rgb_medium=str(tmp_path / "medium.json"), **kw),
    )
    assert spectra.observer(tmp_path / "obs.csv", [550.0]).shape == (1, 3)
    rm = spectra.Renderer(s, size=(8, 6), rgb_medium=tmp_path / "medium.json")
    assert rm.render(observer=tmp_path / "obs.csv").shape == (6, 8, 3)
    # Bools are not counts: refused as spectra.distributed refuses them.
    for call, name in [
        (lambda: spectra.truth(s, spp=True, size=(8, 6)), "spp True"),
        (lambda: spectra.truth(s, spp=1, size=(8, 6), max_depth=False), "max_depth False"),
        (lambda: spectra.truth(s, spp=1, size=(True, 6)), "size True"),
        (lambda: r.render(wavelengths=True), "wavelengths True"),
        (lambda: r.render(samples=2.0), "samples 2.0"),
    ]:
        with pytest.raises(ValueError, match=name):
            call()


def test_messages_name_the_argument_in_their_text(tmp_path):
    """pyo3 named a badly typed argument only in a note, which Python 3.9 and 3.10 do not show
    ("'None' is not an instance of 'str'"); huge numbers were shown in hundreds of digits, or as
    inf; a missing directory was a ValueError."""
    s = spectra.load("cornell")
    r = spectra.Renderer(s, size=(8, 6))
    for call, name in [
        (lambda: r.render(mode=None), "mode"),
        (lambda: r.render(exposure="1"), "exposure"),
        (lambda: r.render(spectral=1), "spectral"),
        (lambda: r.render(observer=3), "observer"),
        (lambda: spectra.truth(s, size=None), "size"),
        (lambda: spectra.truth(s, spp=1, direct_only=1), "direct_only"),
        (lambda: spectra.truth(s, spp="4"), "spp"),
        (lambda: spectra.truth(s, spp=1, crop=(0, 0, "5", 5)), "crop"),
        (lambda: spectra.load("cornell", env_sun=0), "env_sun"),
        (lambda: spectra.load("cornell", env=1), "env"),
        (lambda: spectra.Renderer(s, size=(8, 6), water=1), "water"),
        (lambda: spectra.diff(np.zeros((2, 2, 3)), np.zeros((2, 2, 3)), maps=1), "maps"),
        (lambda: spectra.upsample([0.5, 0.5, 0.5], space=None), "space"),
        (lambda: spectra.chart("cie1931", balanced="yes"), "balanced"),
        (lambda: spectra.write_image(3, np.zeros((2, 2, 3))), "path"),
    ]:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value).startswith(f"{name}: "), str(e.value)
    with pytest.raises(ValueError, match="^wavelengths .*far too large"):
        r.render(wavelengths=2**200)
    with pytest.raises(ValueError, match=r"^range \(1e-300, 700\)") as e:
        r.render(range=(1e-300, 700))
    assert len(str(e.value)) < 120, str(e.value)
    for call, name in [
        (lambda: r.render(exposure=1e39), "exposure 1e39"),
        (lambda: spectra.load("cornell", env_intensity=1e39), "env_intensity 1e39"),
    ]:
        with pytest.raises(ValueError, match=f"^{name}: beyond float32") as e:
            call()
        assert "inf" not in str(e.value)
    with pytest.raises(FileNotFoundError, match="nodir"):
        spectra.write_image(tmp_path / "nodir" / "a.exr", np.zeros((2, 2, 3)))
    with pytest.raises(ValueError) as e:
        spectra.write_image(tmp_path / "a.jpg", np.zeros((2, 2, 3)))
    assert str(e.value).count("a.jpg") == 1, str(e.value)


def test_the_module_is_typed(tmp_path):
    """spectra.distributed had no annotations though the package ships py.typed: `mypy --strict`
    on a user's call said "Call to untyped function", and the result was `Any`."""
    mypy = pytest.importorskip("mypy.api")
    user = tmp_path / "user.py"
    user.write_text(
        "import spectra, spectra.distributed as dist\n"
        "s = spectra.load('cornell')\n"
        "x = dist.truth(s, spp=4, chunks=2)\n"
        "y = dist.truth(s, spp=4, spectral_bin=10.0)\n"
        "j = dist.submit(s, spp=4)\n"
        "reveal_type(x)\n"
        "reveal_type(y)\n"
        "reveal_type(j.done())\n"
    )
    out, err, status = mypy.run(["--strict", "--cache-dir", str(tmp_path / "cache"), str(user)])
    assert status == 0, out + err
    types = [ln.split("Revealed type is ")[1] for ln in out.splitlines() if "Revealed type" in ln]
    assert types[0].startswith('"numpy.ndarray') and types[1].startswith('"tuple[numpy.ndarray'), out
    assert types[2] == '"bool"', out
    out, err, status = mypy.run(
        ["--strict", "--cache-dir", str(tmp_path / "cache"), "-p", "spectra.distributed"]
    )
    assert status == 0, out + err
