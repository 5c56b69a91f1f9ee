"""spectra.distributed on a local Ray instance: a truth split into 8 chunk tasks (and tiles)
equals the single-process render; a worker killed mid-task is replaced and the result is still
exact. Needs Ray (`cargo xtask test` installs it in its venv)."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import spectra

# A local Ray instance on the loopback address, not the machine's network address: what Ray
# does on a laptop (its "no cluster" mode), so the tests send nothing beyond this machine.
# Read when ray is imported.
os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
ray = pytest.importorskip("ray")
import spectra.distributed as dist  # noqa: E402

SIZE = (40, 30)


@pytest.fixture(scope="module")
def local_ray(tmp_path_factory):
    marker = tmp_path_factory.mktemp("kill") / "chunk0-killed"
    # Two CPUs: two tasks at a time whatever the machine. The marker makes the first attempt
    # of chunk 0 kill its worker (see distributed._piece).
    ray.init(
        num_cpus=2,
        include_dashboard=False,
        runtime_env={"env_vars": {"SPECTRA_TEST_KILL_CHUNK0_ONCE": str(marker)}},
    )
    assert ray.util.get_node_ip_address() == "127.0.0.1"
    yield marker
    ray.shutdown()


def relative(a, b):
    return np.abs(a.astype(np.float64) - b) / np.maximum(np.abs(b.astype(np.float64)), 1e-30)


def camera_csv(path):
    """A camera's sensitivities as an observer file (`--observer FILE`)."""
    lam = np.arange(380.0, 781.0, 5.0)
    rows = "".join(f"{x},{r},{g},{b}\n" for x, (r, g, b) in zip(lam, spectra.observer("canon_eos_r5", lam)))
    path.write_text("wavelength,r,g,b\n" + rows)


def test_split():
    pieces = dist.split(10, (7, 5), chunks=3, tiles=(2, 1))
    assert [(c, o, n) for c, o, n, _ in pieces] == [(0, 0, 4), (0, 0, 4), (1, 4, 3), (1, 4, 3), (2, 7, 3), (2, 7, 3)]
    assert [t for *_, t in pieces[:2]] == [(0, 0, 3, 5), (3, 0, 4, 5)]
    with pytest.raises(ValueError, match="chunks 11"):
        dist.split(10, (7, 5), chunks=11)
    with pytest.raises(ValueError, match="tiles"):
        dist.split(10, (7, 5), tiles=(8, 1))
    # Without `chunks`: 8, or one a sample when there are fewer samples.
    assert len(dist.split(10, (7, 5))) == 8
    assert [(o, n) for _, o, n, _ in dist.split(3, (7, 5))] == [(0, 1), (1, 1), (2, 1)]


def test_split_takes_numpy_integers_not_bools_or_floats():
    """Counts from numpy (an `np.arange`, a config array) are whole numbers, as the extension's
    own arguments take them; bool and float are still refused, with the same messages."""
    want = dist.split(10, (7, 5), chunks=3, tiles=(2, 1), sample_offset=4)
    got = dist.split(
        np.int64(10), (7, 5), chunks=np.int32(3), tiles=(np.int64(2), np.uint8(1)), sample_offset=np.int64(4)
    )
    assert got == want and all(type(o) is int and type(n) is int for _, o, n, _ in got)
    for kw, msg in [
        (dict(chunks=True), "chunks True"),
        (dict(chunks=2.0), "chunks 2.0"),
        (dict(chunks=np.int64(0)), "chunks 0"),
        (dict(tiles=(1.5, 1)), "tiles"),
        (dict(tiles=(True, 1)), "tiles"),
    ]:
        with pytest.raises(ValueError, match=msg):
            dist.split(10, (7, 5), **kw)
    with pytest.raises(ValueError, match="spp 4.0"):
        dist.split(4.0, (7, 5))


def test_eight_chunks_equal_one_process(local_ray):
    scene = spectra.load("cornell")
    one = spectra.truth(scene, spp=16, size=SIZE, seed=4)
    many = dist.truth(scene, spp=16, size=SIZE, seed=4, chunks=8)
    assert many.shape == one.shape and many.dtype == np.float32
    assert relative(many, one).max() <= 1e-6
    # The marker shows chunk 0's first worker was killed: Ray ran it again, still exact.
    assert local_ray.exists()


def test_chunks_and_tiles_with_crop_and_bins(local_ray):
    scene = spectra.load("metamerism")
    kw = dict(spp=6, size=SIZE, direct_only=True, seed=2, crop=(5, 4, 30, 20), spectral_bin=25)
    img, bands, edges = spectra.truth(scene, **kw)
    dimg, dbands, dedges = dist.truth(scene, chunks=3, tiles=(2, 2), **kw)
    assert np.array_equal(edges, dedges)
    assert relative(dimg, img).max() <= 1e-6
    assert np.abs(dbands - bands).max() <= 1e-6 * np.abs(bands).max()


def test_bad_input_before_any_task(local_ray):
    scene = spectra.load("cornell")
    with pytest.raises(ValueError, match="spp 0"):
        dist.truth(scene, spp=0)
    with pytest.raises(ValueError, match="chunks 0"):
        dist.truth(scene, spp=4, chunks=0)
    with pytest.raises(ValueError, match="--observer 'martian'"):
        dist.truth(scene, spp=4, observer="martian")
    with pytest.raises(TypeError, match="spectra.Scene"):
        dist.truth("cornell", spp=4)
    with pytest.raises(TypeError):
        dist.truth(scene, spp=4, no_such_option=1)
    # More chunks than samples, asked for: no chunk may be empty.
    with pytest.raises(ValueError, match="chunks 5: more chunks than samples"):
        dist.truth(scene, spp=4, chunks=5)
    for bad in (0, np.int64(0), True, 1.0):
        with pytest.raises(ValueError, match="threads_per_task"):
            dist.truth(scene, spp=4, threads_per_task=bad)
    # Refused by the tracer's set-up rather than by the settings: still before any task.
    lit = spectra.load("cornell", env="default")
    with pytest.raises(ValueError, match="cannot light a scene under a water surface"):
        dist.submit(lit, spp=4, size=(8, 6), water="IB")


def test_fewer_samples_than_the_default_chunks(local_ray):
    """`spp` below the default 8 chunks renders in one chunk a sample, as `eval` splits its
    truths, rather than failing on a default the caller never chose."""
    scene = spectra.load("cornell")
    kw = dict(spp=3, size=(12, 8), direct_only=True, seed=1)
    assert relative(dist.truth(scene, progress=False, **kw), spectra.truth(scene, **kw)).max() <= 1e-6


def test_numpy_integer_arguments(local_ray):
    scene = spectra.load("cornell")
    kw = dict(size=(12, 8), direct_only=True, seed=1)
    one = spectra.truth(scene, spp=4, **kw)
    many = dist.truth(
        scene,
        spp=np.int64(4),
        chunks=np.int64(2),
        tiles=(np.int64(2), np.int64(1)),
        threads_per_task=np.int64(1),
        max_retries=np.int64(3),
        progress=False,
        **kw,
    )
    assert relative(many, one).max() <= 1e-6


def test_relative_files_are_the_drivers(local_ray, tmp_path, monkeypatch):
    """An `observer=` or `rgb_medium=` file named relative to the driver's working directory,
    which is not the workers' (Ray started before the driver moved, as a notebook's `os.chdir`
    or a cluster node does): the workers read the driver's files. Built-in observer names and
    inline JSON stay as given."""
    camera_csv(tmp_path / "cam.csv")
    (tmp_path / "medium.json").write_text('{"absorption": [0.05, 0.1, 0.2], "scattering": [0.3, 0.3, 0.3]}')
    monkeypatch.chdir(tmp_path)
    scene = spectra.load("cornell")
    kw = dict(spp=2, size=(12, 8), seed=3, observer="cam.csv", rgb_medium="medium.json")
    one = spectra.truth(scene, **kw)
    assert relative(dist.truth(scene, chunks=2, progress=False, **kw), one).max() <= 1e-6

    names = dict(observer="nikon_d5100", rgb_medium='{"absorption": [0.1, 0.1, 0.1], "scattering": [0, 0, 0]}')
    assert dist._for_workers(names) == names
    files = dist._for_workers(dict(observer="cams/a.JSON", rgb_medium="medium.json"))
    assert files == dict(observer=str(tmp_path / "cams" / "a.JSON"), rgb_medium=str(tmp_path / "medium.json"))


def test_eval_truths_as_tasks(local_ray, tmp_path, capfd):
    """`spectra eval`'s truths as Ray tasks: stored in the truth cache, the evaluation renders
    none of them, and its results are the command's (same truths up to float64 summation
    order)."""
    import json
    import subprocess

    from test_spectra import spectra_bin

    args = dict(quick=True, scenes=["colorchecker-d65"], spp=6, size="32x24", sweep="4")
    cache = tmp_path / "cache"
    got = dist.eval(tmp_path / "ray", truth_cache=cache, chunks=3, **args)
    err = capfd.readouterr().err
    # The evaluation's own log: every truth came from the cache, none was rendered here.
    lines = [ln for ln in err.splitlines() if "ground truth:" in ln or "jitter truth:" in ln]
    assert len(lines) == 2 and all(ln.endswith("nothing rendered") for ln in lines), err
    assert len(list(cache.glob("*.truth"))) == 3  # seeds 1, 2 and the jitter truth
    # Again: nothing left to render.
    assert spectra._spectra._eval_plan(
        ["eval", "--out", str(tmp_path / "x"), "--quick", "--scenes", "colorchecker-d65", "--spp", "6",
         "--size", "32x24", "--sweep", "4", "--truth-cache", str(cache)]
    ) == []
    subprocess.run(
        [spectra_bin(), "eval", "--quick", "--scenes", "colorchecker-d65", "--spp", "6", "--size", "32x24",
         "--sweep", "4", "--out", str(tmp_path / "cli")],
        check=True,
        capture_output=True,
    )
    want = json.loads((tmp_path / "cli" / "results.json").read_text())
    a, b = got["cases"][0], want["cases"][0]
    assert a["truth_spp"] == b["truth_spp"] == 6
    for ma, mb in zip(a["modes"], b["modes"]):
        assert ma["mode"] == mb["mode"]
        for k in ("delta_e2000", "mae_linear"):
            x, y = ma["errors"][k]["mean"], mb["errors"][k]["mean"]
            assert x == pytest.approx(y, rel=1e-5, abs=1e-7), (ma["mode"], k)
    with pytest.raises(ValueError, match="--sweep"):
        dist.eval(tmp_path / "bad", quick=True, sweep="0")


def test_eval_relative_observer_and_one_scene_name(local_ray, tmp_path, monkeypatch):
    """`eval` with an observer file named relative to the driver's working directory (not the
    workers') and `scenes` one case id as a string, not a list of its letters. The driver keeps
    the name as given: it is in results.json, as the command writes it."""
    camera_csv(tmp_path / "cam.csv")
    monkeypatch.chdir(tmp_path)
    got = dist.eval(
        "out", quick=True, scenes="colorchecker-d65", spp=2, size="12x8", sweep="4", observer="cam.csv",
        truth_cache="cache", chunks=2, progress=False,
    )
    assert [c["id"] for c in got["cases"]] == ["colorchecker-d65"] and got["observer"] == "cam.csv"
    assert len(list((tmp_path / "cache").glob("*.truth"))) == 3
    with pytest.raises(ValueError, match="no-such-case"):
        dist.eval(tmp_path / "bad", quick=True, scenes="no-such-case")


def _cpus_free():
    return ray.available_resources().get("CPU", 0)


def _wait_for(cond, timeout):
    t = time.time() + timeout
    while time.time() < t:
        if cond():
            return True
        time.sleep(0.2)
    return cond()


def test_cancel_stops_running_tasks(local_ray):
    """Nothing stopped a job's tasks: `ray.cancel` raised KeyboardInterrupt in a task whose
    render never looked (it runs on a pool of `threads`), and `Job` had no `cancel()`."""
    from ray.exceptions import TaskCancelledError

    scene = spectra.load("cornell")
    job = dist.submit(scene, spp=40000, size=(32, 24), chunks=2, progress=False)
    assert _wait_for(lambda: _cpus_free() == 0, 60), "the tasks did not start"
    assert not job.done()
    job.cancel()
    assert _wait_for(lambda: _cpus_free() == 2, 10), "tasks still running 10 s after Job.cancel()"
    assert job.done()
    with pytest.raises(TaskCancelledError):
        job.result()
    assert dist.Job.done.__doc__ and dist.Job.cancel.__doc__


def test_ctrl_c_cancels_the_tasks(local_ray):
    """Ctrl-C on the driver raised at once, and the tasks went on rendering, holding every CPU."""
    scene = spectra.load("cornell")

    def interrupt():
        _wait_for(lambda: _cpus_free() == 0, 60)
        time.sleep(0.5)
        os.kill(os.getpid(), signal.SIGINT)

    threading.Thread(target=interrupt, daemon=True).start()
    with pytest.raises(KeyboardInterrupt):
        dist.truth(scene, spp=40000, size=(32, 24), chunks=2, progress=False)
    assert _wait_for(lambda: _cpus_free() == 2, 10), "tasks still running 10 s after Ctrl-C"


def test_more_threads_per_task_than_any_node_has(local_ray):
    """A task asking for 3 CPUs of a cluster whose nodes have 2 waited for ever."""
    scene = spectra.load("cornell")
    job = None
    try:
        with pytest.raises(ValueError, match="threads_per_task 3: no node .* more than 2 CPUs"):
            job = dist.submit(scene, spp=2, size=(8, 6), threads_per_task=3, progress=False)
    finally:
        if job is not None:
            job.cancel(force=True)
    assert dist.truth(scene, spp=2, size=(8, 6), threads_per_task=2, progress=False).shape == (6, 8, 3)


def test_truth_agrees_with_spectra_truth_on_arguments(local_ray):
    """Keywords unknown to distributed.truth were reported against `submit()`, and `spp=True`
    was refused by distributed.truth but taken as 1 by spectra.truth."""
    scene = spectra.load("cornell")
    with pytest.raises(TypeError, match=r"^truth\(\) got an unexpected keyword argument 'bogus'"):
        dist.truth(scene, spp=4, bogus=1)
    for f in (spectra.truth, dist.truth):
        with pytest.raises(ValueError, match="spp True"):
            f(scene, spp=True, size=(8, 6))
    # Lists and paths, as spectra.truth takes them.
    kw = dict(spp=2, seed=1, crop=[0, 0, 6, 4], range=[400, 700])
    one = spectra.truth(scene, size=(8, 6), **kw)
    assert relative(dist.truth(scene, size=[8, 6], chunks=2, progress=False, **kw), one).max() <= 1e-6



def test_medium_lambert_xyz_and_table_as_tasks(local_ray, tmp_path, monkeypatch):
    """The CLI-parity options of `spectra.truth` (`medium`, `lambert`, `xyz`, `table`) travel to
    the tasks: the merged image is the single-process one (XYZ with `xyz=True`), and relative
    `medium` / `table` files are the driver's."""
    import subprocess

    from test_spectra import spectra_bin

    subprocess.run(
        [spectra_bin(), "lut", "--res", "8", "--no-refine", "--check", "0", "--out", str(tmp_path / "t8.coeff")],
        check=True,
        capture_output=True,
    )
    (tmp_path / "fog.json").write_text('{"sigma_a": 0.05, "sigma_s": 0.2, "phase": {"hg": 0.3}}')
    monkeypatch.chdir(tmp_path)
    scene = spectra.load("cornell")
    kw = dict(spp=2, size=(12, 8), seed=3, medium="fog.json", lambert=True, xyz=True, table="t8.coeff")
    one = spectra.truth(scene, **kw)
    assert not np.array_equal(one, spectra.truth(scene, spp=2, size=(12, 8), seed=3))
    assert relative(dist.truth(scene, chunks=2, progress=False, **kw), one).max() <= 1e-6
    files = dist._for_workers(dict(medium="fog.json", table="t8.coeff"))
    assert files == dict(medium=str(tmp_path / "fog.json"), table=str(tmp_path / "t8.coeff"))
    inline = '{"sigma_a": 0.1, "sigma_s": 0}'
    assert dist._for_workers(dict(medium=inline)) == dict(medium=inline)
    with pytest.raises(ValueError, match="^medium cannot be used with rgb_medium"):
        dist.truth(scene, spp=2, medium="fog.json", rgb_medium='{"absorption": [1, 1, 1]}')
