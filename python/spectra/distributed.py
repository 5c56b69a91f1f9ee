"""Ground truth across machines on Ray: one `spectra.truth` render split into sample chunks and
tiles, each a Ray task, merged into the render of all their samples.

>>> import ray, spectra, spectra.distributed
>>> ray.init()                      # or ray.init(address="auto") on a cluster; or let truth() do it
>>> scene = spectra.load("cornell")
>>> img = spectra.distributed.truth(scene, spp=256, size=(320, 240), chunks=8)

Each task renders samples K … K+n−1 of every pixel of its tile (`sample_offset`, `crop`) and
returns the per-pixel float64 sums; the driver adds them in a fixed order and finishes them
exactly as `spectra.truth` finishes its own (the mean as float32, then XYZ → linear sRGB), so
the result equals the single-process render up to float64 summation order (≤ 1 float32 ulp
per pixel here). The image depends on the seed alone, never on how it was split or where the
tasks ran. A task whose worker dies is run again by Ray (`max_retries`), with the same result.

Workers need the package: on one machine and on clusters whose nodes share the Python
environment it is simply installed (`pip install ./python` on every node, or in the image).
Otherwise ship the wheel with the job: `pip wheel ./python -w dist` and
`ray.init(runtime_env={"py_modules": ["dist/spectra-….whl"]})` (or pass `runtime_env=` here
when this call starts Ray). A scene given as a file is loaded again on each worker from the same
path (absolute), so the file must be reachable there (a shared filesystem, or `working_dir`);
so are an `observer=` or `rgb_medium=` file (and `eval`'s `table`), named absolutely for the
workers whatever their working directory.
`eval` runs `spectra eval` with its ground truths rendered the same way (stored in its truth
cache, the real-time renders and the report on this machine). See docs/python.md.
"""

from __future__ import annotations

import operator
import os
import sys
import time

import numpy as np

from . import Scene, _spectra

__all__ = ["Job", "eval", "split", "submit", "truth"]


def _ray():
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            "spectra.distributed needs Ray: pip install 'ray>=2.9' (on the driver and every worker)"
        ) from e
    return ray


#: Sample chunks of a render when `chunks` is not given (fewer when it has fewer samples).
CHUNKS = 8


def _whole(name, value, least=1):
    """`value` as an int ≥ `least`, or the ValueError naming `name`. Any integral type is one
    (numpy's integers too, as the extension's own arguments take them); bool and float are not."""
    try:
        if isinstance(value, bool):
            raise TypeError
        n = operator.index(value)
    except TypeError:
        raise ValueError(f"{name} {value!r}: must be a whole number ≥ {least}") from None
    if n < least:
        raise ValueError(f"{name} {n}: must be a whole number ≥ {least}")
    return n


def _observer_file(name):
    """Whether an `observer=` value names a file rather than a built-in observer: the rule of
    the Rust side (`color::observer_file::is_file_name`)."""
    lower = name.lower()
    return lower.endswith((".csv", ".txt", ".json")) or "/" in name or "\\" in name


def _absolute(path):
    """`path` made absolute against this process's working directory, as `load` names a
    scene file (no `..` or symlink resolved: `std::path::absolute`'s result)."""
    return path if os.path.isabs(path) else os.path.join(os.getcwd(), path)


def _for_workers(options):
    """`options` with the files they name (`observer=`, `rgb_medium=`) as absolute paths: a
    Ray worker's working directory need not be this process's (another node, or this process
    changed its own after Ray started). Names and inline JSON are left as they are."""
    options = dict(options)
    observer, medium = options.get("observer"), options.get("rgb_medium")
    if isinstance(observer, str) and _observer_file(observer):
        options["observer"] = _absolute(observer)
    if isinstance(medium, str) and not medium.lstrip().startswith("{"):
        options["rgb_medium"] = _absolute(medium)
    return options


def split(spp, size, chunks=None, tiles=(1, 1), sample_offset=0, crop=None):
    """The pieces a render is split into: a list of (chunk index, sample_offset, spp, crop),
    chunks of as equal a number of samples as can be (the first ones one more), each over
    every tile of a `tiles=(nx, ny)` grid of the window (the frame, or `crop`). `chunks`
    defaults to `CHUNKS`, or `spp` when that is fewer; more chunks than `spp` given
    explicitly is an error (a chunk would have no samples)."""
    spp = _whole("spp", spp)
    chunks = min(CHUNKS, spp) if chunks is None else _whole("chunks", chunks)
    if chunks > spp:
        raise ValueError(f"chunks {chunks}: more chunks than samples per pixel ({spp})")
    sample_offset = _whole("sample_offset", sample_offset, 0)
    try:
        nx, ny = tiles
        if isinstance(nx, bool) or isinstance(ny, bool):
            raise TypeError
        nx, ny = operator.index(nx), operator.index(ny)
    except (TypeError, ValueError):
        raise ValueError(f"tiles {tiles!r}: must be (nx, ny), two whole numbers ≥ 1") from None
    w, h = size
    x0, y0, ww, wh = crop if crop is not None else (0, 0, w, h)
    if nx < 1 or ny < 1 or nx > ww or ny > wh:
        raise ValueError(f"tiles {tiles!r}: must be (nx, ny) with 1 ≤ nx ≤ {ww} and 1 ≤ ny ≤ {wh}")
    xs = [x0 + ww * i // nx for i in range(nx + 1)]
    ys = [y0 + wh * j // ny for j in range(ny + 1)]
    base, extra = divmod(spp, chunks)
    pieces, offset = [], sample_offset
    for c in range(chunks):
        n = base + (1 if c < extra else 0)
        for j in range(ny):
            for i in range(nx):
                tile = (xs[i], ys[j], xs[i + 1] - xs[i], ys[j + 1] - ys[j])
                pieces.append((c, offset, n, tile))
        offset += n
    return pieces


def _piece(scene, options, chunk, sample_offset, spp, crop, threads):
    """One Ray task: the sums of samples sample_offset … +spp−1 over `crop`."""
    # The tests' way to kill a worker mid-render: the first attempt of chunk 0 exits the
    # process, as a crashed or preempted node would; Ray runs the task again.
    marker = os.environ.get("SPECTRA_TEST_KILL_CHUNK0_ONCE")
    if marker and chunk == 0 and not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)
    return _spectra._truth_sums(
        scene, spp=spp, sample_offset=sample_offset, crop=crop, threads=threads, **options
    )


class Job:
    """A truth render running as Ray tasks (from `submit`): `result()` waits for its tasks and
    merges them; `done()` says whether they have all finished."""

    def __init__(self, ray, plan, pieces, refs, spp, progress, label):
        self._ray, self._plan, self._pieces, self._refs = ray, plan, pieces, refs
        self._spp, self._progress, self._label = spp, progress, label
        self._t0 = time.perf_counter()
        self._result = None

    def done(self):
        ready, _ = self._ray.wait(self._refs, num_returns=len(self._refs), timeout=0)
        return len(ready) == len(self._refs)

    def result(self):
        """`spectra.truth`'s result: the (h, w, 3) image, or (image, bands, edges)."""
        if self._result is None:
            self._result = self._merge()
        return self._result

    def _merge(self):
        ray = self._ray
        index = {ref: k for k, ref in enumerate(self._refs)}
        results = [None] * len(self._refs)
        pending = list(self._refs)
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            for ref in done:
                results[index[ref]] = ray.get(ref)
                if self._progress:
                    finished = len(self._refs) - len(pending)
                    print(
                        f"spectra.distributed.truth{self._label}: {finished}/{len(self._refs)} tasks "
                        f"({time.perf_counter() - self._t0:.1f} s)",
                        file=sys.stderr,
                        flush=True,
                    )
        plan = self._plan
        wx, wy, ww, wh = plan["window"]
        xyz = np.zeros((wh, ww, 3))
        nb = None if plan["edges"] is None else len(plan["edges"]) - 1
        bins = None if nb is None else np.zeros((wh, ww, nb))
        dropped = 0
        # In piece order (chunk by chunk), whatever order the tasks finished in: the same sums
        # for the same split every time.
        for (c, off, n, (tx, ty, tw, th)), r in zip(self._pieces, results):
            if tuple(r["window"]) != (tx, ty, tw, th) or r["spp"] != n:
                raise RuntimeError(f"chunk {c} came back for {r['window']}, {r['spp']} spp: not the task sent")
            xyz[ty - wy : ty - wy + th, tx - wx : tx - wx + tw] += r["xyz"]
            if bins is not None:
                bins[ty - wy : ty - wy + th, tx - wx : tx - wx + tw] += r["bins"]
            dropped += r["dropped"]
        if dropped:
            print(f"warning: truth: {dropped} non-finite samples dropped", file=sys.stderr)
        if bins is None:
            return _spectra._truth_finish(xyz, self._spp, display=plan["display"])
        img, bands = _spectra._truth_finish(xyz, self._spp, bins, display=plan["display"])
        return img, bands, plan["edges"]


def submit(
    scene,
    spp=64,
    size=(256, 256),
    direct_only=False,
    seed=0,
    *,
    sample_offset=0,
    crop=None,
    range=None,
    observer=None,
    white=None,
    max_depth=1024,
    water=None,
    depth=None,
    rgb_medium=None,
    spectral_bin=None,
    camera_to_display=False,
    chunks=None,
    tiles=(1, 1),
    threads_per_task=1,
    max_retries=3,
    address=None,
    runtime_env=None,
    progress=True,
    label="",
):
    """`truth` without waiting: the render's tasks are submitted and a `Job` is returned, so
    that many renders (an evaluation's truths, a table's rows) share the cluster at once.
    `label`: shown in the progress lines."""
    ray = _ray()
    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a spectra.Scene (from spectra.load), not {type(scene).__name__}")
    threads_per_task = _whole("threads_per_task", threads_per_task)
    max_retries = _whole("max_retries", max_retries, -1)
    options = dict(
        size=size,
        direct_only=direct_only,
        seed=seed,
        range=range,
        observer=observer,
        white=white,
        max_depth=max_depth,
        water=water,
        depth=depth,
        rgb_medium=rgb_medium,
        spectral_bin=spectral_bin,
        camera_to_display=camera_to_display,
    )
    # Every argument checked here, before any task: the errors `spectra.truth` raises.
    plan = _spectra._truth_sums(scene, spp=spp, sample_offset=sample_offset, crop=crop, dry_run=True, **options)
    pieces = split(spp, size, chunks, tiles, sample_offset, plan["window"])
    if not ray.is_initialized():
        ray.init(address=address, runtime_env=runtime_env)
    task = ray.remote(_piece).options(num_cpus=threads_per_task, max_retries=max_retries)
    scene_ref = ray.put(scene)
    options = _for_workers(options)
    refs = [task.remote(scene_ref, options, c, off, n, tile, threads_per_task) for c, off, n, tile in pieces]
    return Job(ray, plan, pieces, refs, plan["spp"], progress, f" {label}" if label else "")


def truth(
    scene,
    spp=64,
    size=(256, 256),
    direct_only=False,
    seed=0,
    *,
    chunks=None,
    tiles=(1, 1),
    threads_per_task=1,
    max_retries=3,
    address=None,
    runtime_env=None,
    progress=True,
    **options,
):
    """`spectra.truth` split into `chunks` sample chunks × a `tiles=(nx, ny)` grid of tiles,
    each a Ray task, and merged: the same arguments (`sample_offset`, `crop`, `range`,
    `observer`, `white`, `max_depth`, `water`, `depth`, `rgb_medium`, `spectral_bin`,
    `camera_to_display` as keywords) and the same result (an (h, w, 3) float32 linear sRGB array; with
    `spectral_bin`, (image, bands, edges)). An `observer` or `rgb_medium` file given by a
    relative path is found from this process's working directory, not the workers'.

    chunks: default 8, or `spp` when that is fewer (more than `spp` given explicitly is an
    error). threads_per_task: CPUs each task asks Ray for and uses (the tracer's threads); Ray
    runs as many tasks at once as the cluster has CPUs for. max_retries: how often Ray runs a
    task again whose worker died (-1: without limit). address / runtime_env: passed to
    `ray.init` when Ray is not running yet in this process (address None: a local instance, or
    the cluster of $RAY_ADDRESS). progress: a line on stderr per finished task. Counts may be
    any integral type (numpy's integers too)."""
    return submit(
        scene,
        spp,
        size,
        direct_only,
        seed,
        chunks=chunks,
        tiles=tiles,
        threads_per_task=threads_per_task,
        max_retries=max_retries,
        address=address,
        runtime_env=runtime_env,
        progress=progress,
        **options,
    ).result()


def eval(
    out,
    *,
    quick=False,
    scenes=None,
    spp=None,
    size=None,
    sweep=None,
    table=None,
    observer=None,
    truth_cache=None,
    chunks=8,
    threads_per_task=1,
    max_retries=3,
    address=None,
    runtime_env=None,
    progress=True,
):
    """`spectra eval` with its ground truths rendered as Ray tasks: every truth the evaluation
    needs (two seeds per case, the jittered-accumulation truth) is split into `chunks` sample
    chunks, all submitted at once; each finished truth is stored in the truth cache
    (`truth_cache`, a directory; a temporary one by default) exactly as `spectra eval
    --truth-cache` stores its own; then the evaluation runs here, on this machine's GPU, with
    every truth taken from the cache (it renders none). Truths the cache already holds are not
    rendered again. Same arguments as the command (`quick`, `scenes` (a case id, or a list of
    them), `spp`, `size` "WxH", `sweep` "4,8,16", `table`, `observer`); returns `results.json` as
    a dict. `chunks` is at most each truth's samples per pixel. Files given by relative paths
    (`table`, an `observer` file) are found from this process's working directory, not the
    workers'."""
    import json
    import tempfile

    ray = _ray()
    chunks = _whole("chunks", chunks)
    threads_per_task = _whole("threads_per_task", threads_per_task)
    max_retries = _whole("max_retries", max_retries, -1)
    argv = ["eval", "--out", str(out)]
    # Where argv names a file or directory (the workers get them absolute).
    paths = [2]
    if quick:
        argv.append("--quick")
    if isinstance(scenes, str):
        scenes = [scenes] if scenes else []
    if scenes:
        argv += ["--scenes", ",".join(scenes)]
    if spp is not None:
        argv += ["--spp", str(spp)]
    if size is not None:
        argv += ["--size", size if isinstance(size, str) else f"{size[0]}x{size[1]}"]
    if sweep is not None:
        argv += ["--sweep", sweep if isinstance(sweep, str) else ",".join(map(str, sweep))]
    if table is not None:
        argv += ["--table", str(table)]
        paths.append(len(argv) - 1)
    if observer is not None:
        argv += ["--observer", str(observer)]
        if _observer_file(argv[-1]):
            paths.append(len(argv) - 1)
    with tempfile.TemporaryDirectory(prefix="spectra-truth-cache-") as tmp:
        cache = str(truth_cache) if truth_cache is not None else tmp
        argv += ["--truth-cache", cache]
        paths.append(len(argv) - 1)
        # The workers' working directory need not be this process's, so their copy names every
        # file absolutely. This process keeps the paths as given: an observer file's path as
        # given is what results.json names, as it is for the command.
        remote = list(argv)
        for i in paths:
            remote[i] = _absolute(argv[i])
        # The truths the evaluation will ask for, less those the cache holds in full.
        plan = _spectra._eval_plan(argv)
        if plan and not ray.is_initialized():
            ray.init(address=address, runtime_env=runtime_env)
        task = ray.remote(_eval_piece).options(num_cpus=threads_per_task, max_retries=max_retries)
        jobs = []
        for job in plan:
            pieces = split(job["spp"], (job["width"], job["height"]), min(chunks, job["spp"]))
            refs = [task.remote(remote, job, off, n, threads_per_task) for _, off, n, _ in pieces]
            jobs.append((job, refs))
        t0 = time.perf_counter()
        total = sum(len(r) for _, r in jobs)
        finished = 0
        for job, refs in jobs:
            xyz, dropped = None, 0
            # Chunk order, whatever order they finish in.
            for r in ray.get(refs):
                xyz = r["xyz"] if xyz is None else xyz + r["xyz"]
                dropped += r["dropped"]
            _spectra._eval_truth_store(argv, job, xyz, dropped)
            finished += len(refs)
            if progress:
                print(
                    f"spectra.distributed.eval: truth {job['case']} seed {job['seed']} stored "
                    f"({finished}/{total} tasks, {time.perf_counter() - t0:.1f} s)",
                    file=sys.stderr,
                    flush=True,
                )
        _spectra._eval_run(argv)
    with open(os.path.join(str(out), "results.json")) as f:
        return json.load(f)


def _eval_piece(argv, job, sample_offset, spp, threads):
    """One Ray task of `eval`: samples sample_offset … +spp−1 of one evaluation truth."""
    return _spectra._eval_truth_sums(argv, job, sample_offset, spp, threads)
