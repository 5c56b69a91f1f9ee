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
so are an `observer=`, `rgb_medium=`, `medium=` or `table=` file (and `eval`'s `table`), named
absolutely for the workers whatever their working directory.
`eval` runs `spectra eval` with its ground truths rendered the same way (stored in its truth
cache, the real-time renders and the report on this machine).

Ctrl-C in `truth` or `eval` cancels the tasks it submitted (a running task stops within a
fraction of a second, as `spectra.truth` does on Ctrl-C); a `Job` from `submit` is cancelled
with `Job.cancel()`, and `ray.cancel` on a task stops it too. See docs/python.md.
"""

from __future__ import annotations

import operator
import os
import sys
import time
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Sequence, Tuple, Union, overload

import numpy as np

from . import Scene
from . import _spectra  # type: ignore[attr-defined]  # the extension, typed by __init__.pyi's names

if TYPE_CHECKING:
    import numpy.typing as npt

    _Image = npt.NDArray[np.float32]
    _Bands = npt.NDArray[np.float32]
    _Edges = npt.NDArray[np.float64]
    _Result = Union[_Image, Tuple[_Image, _Bands, _Edges]]
    _Path = Union[str, "os.PathLike[str]"]

__all__ = ["Job", "eval", "split", "submit", "truth"]

#: A piece of a render: (chunk index, sample_offset, spp, crop (x, y, w, h)).
Piece = Tuple[int, int, int, Tuple[int, int, int, int]]


def _ray() -> Any:
    try:
        import ray
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError(
            "spectra.distributed needs Ray: pip install 'ray>=2.9' (on the driver and every worker)"
        ) from e
    return ray


#: Sample chunks of a render when `chunks` is not given (fewer when it has fewer samples).
CHUNKS = 8


def _whole(name: str, value: Any, least: int = 1) -> int:
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


def _observer_file(name: str) -> bool:
    """Whether an `observer=` value names a file rather than a built-in observer: the rule of
    the Rust side (`color::observer_file::is_file_name`)."""
    lower = name.lower()
    return lower.endswith((".csv", ".txt", ".json")) or "/" in name or "\\" in name


def _absolute(path: str) -> str:
    """`path` made absolute against this process's working directory, as `load` names a
    scene file (no `..` or symlink resolved: `std::path::absolute`'s result)."""
    return path if os.path.isabs(path) else os.path.join(os.getcwd(), path)


def _for_workers(options: Dict[str, Any]) -> Dict[str, Any]:
    """`options` with the files they name (`observer=`, `rgb_medium=`, `medium=`, `table=`) as
    absolute paths: a Ray worker's working directory need not be this process's (another node,
    or this process changed its own after Ray started). Names and inline JSON are left as they
    are; an `os.PathLike` (`pathlib.Path`) becomes its str."""
    options = dict(options)
    for key in ("observer", "rgb_medium", "medium", "table"):
        if isinstance(options.get(key), os.PathLike):
            options[key] = os.fspath(options[key])
    observer = options.get("observer")
    if isinstance(observer, str) and _observer_file(observer):
        options["observer"] = _absolute(observer)
    for key in ("rgb_medium", "medium"):
        medium = options.get(key)
        if isinstance(medium, str) and not medium.lstrip().startswith("{"):
            options[key] = _absolute(medium)
    table = options.get("table")
    if isinstance(table, str):
        options["table"] = _absolute(table)
    return options


def split(
    spp: int,
    size: Sequence[int],
    chunks: Optional[int] = None,
    tiles: Sequence[int] = (1, 1),
    sample_offset: int = 0,
    crop: Optional[Sequence[int]] = None,
) -> List[Piece]:
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
    pieces: List[Piece] = []
    offset = sample_offset
    for c in range(chunks):
        n = base + (1 if c < extra else 0)
        for j in range(ny):
            for i in range(nx):
                tile = (xs[i], ys[j], xs[i + 1] - xs[i], ys[j + 1] - ys[j])
                pieces.append((c, offset, n, tile))
        offset += n
    return pieces


def _piece(
    scene: Scene,
    options: Dict[str, Any],
    chunk: int,
    sample_offset: int,
    spp: int,
    crop: Tuple[int, int, int, int],
    threads: int,
) -> Dict[str, Any]:
    """One Ray task: the sums of samples sample_offset … +spp−1 over `crop`."""
    # The tests' way to kill a worker mid-render: the first attempt of chunk 0 exits the
    # process, as a crashed or preempted node would; Ray runs the task again.
    marker = os.environ.get("SPECTRA_TEST_KILL_CHUNK0_ONCE")
    if marker and chunk == 0 and not os.path.exists(marker):
        open(marker, "w").close()
        os._exit(1)
    sums: Dict[str, Any] = _spectra._truth_sums(
        scene, spp=spp, sample_offset=sample_offset, crop=crop, threads=threads, **options
    )
    return sums


class Job:
    """A truth render running as Ray tasks (from `submit`): `result()` waits for its tasks and
    merges them; `done()` says whether they have all finished; `cancel()` stops them."""

    def __init__(
        self,
        ray: Any,
        plan: Dict[str, Any],
        pieces: List[Piece],
        refs: List[Any],
        spp: int,
        progress: bool,
        label: str,
    ) -> None:
        self._ray, self._plan, self._pieces, self._refs = ray, plan, pieces, refs
        self._spp, self._progress, self._label = spp, progress, label
        self._t0 = time.perf_counter()
        self._result: Optional[_Result] = None

    def done(self) -> bool:
        """Whether every task has finished (without waiting); a cancelled or failed task counts
        as finished."""
        ready, _ = self._ray.wait(self._refs, num_returns=len(self._refs), timeout=0)
        return len(ready) == len(self._refs)

    def cancel(self, force: bool = False) -> None:
        """Cancels the tasks not yet finished (`ray.cancel`): one not started never runs, a
        running one stops within a fraction of a second (its render is interrupted as Ctrl-C
        interrupts `spectra.truth`; `force=True` kills its worker process instead). `result()`
        then raises Ray's `TaskCancelledError`. Finished tasks are left as they are."""
        for ref in self._refs:
            self._ray.cancel(ref, force=force)

    def result(self) -> _Result:
        """`spectra.truth`'s result: the (h, w, 3) image, or (image, bands, edges) with
        `spectral_bin`. Waits for the tasks; interrupted (Ctrl-C), it leaves them running (call
        `cancel()` to stop them)."""
        if self._result is None:
            self._result = self._merge()
        return self._result

    def _merge(self) -> _Result:
        ray = self._ray
        index = {ref: k for k, ref in enumerate(self._refs)}
        results: List[Any] = [None] * len(self._refs)
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
            image: _Image = _spectra._truth_finish(xyz, self._spp, display=plan["display"])
            return image
        img, bands = _spectra._truth_finish(xyz, self._spp, bins, display=plan["display"])
        return img, bands, plan["edges"]


def _check_cpus(ray: Any, threads_per_task: int) -> None:
    """A task asking for more CPUs than any node of the cluster has is never scheduled: Ray
    waits for such a node for ever (its autoscaler prints "No available node types can fulfill
    resource request" every half minute). Refused before any task, naming the most there is."""
    most = max(
        (float(n.get("Resources", {}).get("CPU", 0)) for n in ray.nodes() if n.get("Alive")),
        default=0.0,
    )
    if threads_per_task > most:
        raise ValueError(
            f"threads_per_task {threads_per_task}: no node of the Ray cluster has more than {most:g} CPUs, "
            "so a task asking for that many would wait for ever (give at most that many, or add a "
            "larger node before submitting)"
        )


def submit(
    scene: Scene,
    spp: int = 64,
    size: Sequence[int] = (256, 256),
    direct_only: bool = False,
    seed: int = 0,
    *,
    sample_offset: int = 0,
    crop: Optional[Sequence[int]] = None,
    range: Optional[Sequence[float]] = None,
    observer: Optional[_Path] = None,
    white: Optional[str] = None,
    max_depth: int = 1024,
    water: Optional[str] = None,
    depth: Optional[float] = None,
    rgb_medium: Optional[_Path] = None,
    spectral_bin: Optional[float] = None,
    camera_to_display: bool = False,
    medium: Optional[_Path] = None,
    lambert: bool = False,
    xyz: bool = False,
    table: Optional[_Path] = None,
    chunks: Optional[int] = None,
    tiles: Sequence[int] = (1, 1),
    threads_per_task: int = 1,
    max_retries: int = 3,
    address: Optional[str] = None,
    runtime_env: Optional[Dict[str, Any]] = None,
    progress: bool = True,
    label: str = "",
) -> Job:
    """`truth` without waiting: the render's tasks are submitted and a `Job` is returned, so
    that many renders (an evaluation's truths, a table's rows) share the cluster at once.
    `label`: shown in the progress lines. `Job.cancel()` stops the tasks."""
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
        medium=medium,
        lambert=lambert,
        xyz=xyz,
        table=table,
    )
    # Every argument checked here, before any task: the errors `spectra.truth` raises.
    plan = _spectra._truth_sums(scene, spp=spp, sample_offset=sample_offset, crop=crop, dry_run=True, **options)
    pieces = split(spp, size, chunks, tiles, sample_offset, plan["window"])
    if not ray.is_initialized():
        ray.init(address=address, runtime_env=runtime_env)
    _check_cpus(ray, threads_per_task)
    task = ray.remote(_piece).options(num_cpus=threads_per_task, max_retries=max_retries)
    scene_ref = ray.put(scene)
    options = _for_workers(options)
    refs = [task.remote(scene_ref, options, c, off, n, tile, threads_per_task) for c, off, n, tile in pieces]
    return Job(ray, plan, pieces, refs, plan["spp"], progress, f" {label}" if label else "")


@overload
def truth(
    scene: Scene,
    spp: int = 64,
    size: Sequence[int] = (256, 256),
    direct_only: bool = False,
    seed: int = 0,
    *,
    sample_offset: int = 0,
    crop: Optional[Sequence[int]] = None,
    range: Optional[Sequence[float]] = None,
    observer: Optional[_Path] = None,
    white: Optional[str] = None,
    max_depth: int = 1024,
    water: Optional[str] = None,
    depth: Optional[float] = None,
    rgb_medium: Optional[_Path] = None,
    spectral_bin: None = None,
    camera_to_display: bool = False,
    medium: Optional[_Path] = None,
    lambert: bool = False,
    xyz: bool = False,
    table: Optional[_Path] = None,
    chunks: Optional[int] = None,
    tiles: Sequence[int] = (1, 1),
    threads_per_task: int = 1,
    max_retries: int = 3,
    address: Optional[str] = None,
    runtime_env: Optional[Dict[str, Any]] = None,
    progress: bool = True,
) -> _Image: ...
@overload
def truth(
    scene: Scene,
    spp: int = 64,
    size: Sequence[int] = (256, 256),
    direct_only: bool = False,
    seed: int = 0,
    *,
    sample_offset: int = 0,
    crop: Optional[Sequence[int]] = None,
    range: Optional[Sequence[float]] = None,
    observer: Optional[_Path] = None,
    white: Optional[str] = None,
    max_depth: int = 1024,
    water: Optional[str] = None,
    depth: Optional[float] = None,
    rgb_medium: Optional[_Path] = None,
    spectral_bin: float,
    camera_to_display: bool = False,
    medium: Optional[_Path] = None,
    lambert: bool = False,
    xyz: bool = False,
    table: Optional[_Path] = None,
    chunks: Optional[int] = None,
    tiles: Sequence[int] = (1, 1),
    threads_per_task: int = 1,
    max_retries: int = 3,
    address: Optional[str] = None,
    runtime_env: Optional[Dict[str, Any]] = None,
    progress: bool = True,
) -> Tuple[_Image, _Bands, _Edges]: ...
@overload
def truth(
    scene: Scene,
    spp: int = 64,
    size: Sequence[int] = (256, 256),
    direct_only: bool = False,
    seed: int = 0,
    *,
    sample_offset: int = 0,
    crop: Optional[Sequence[int]] = None,
    range: Optional[Sequence[float]] = None,
    observer: Optional[_Path] = None,
    white: Optional[str] = None,
    max_depth: int = 1024,
    water: Optional[str] = None,
    depth: Optional[float] = None,
    rgb_medium: Optional[_Path] = None,
    spectral_bin: Optional[float] = None,
    camera_to_display: bool = False,
    medium: Optional[_Path] = None,
    lambert: bool = False,
    xyz: bool = False,
    table: Optional[_Path] = None,
    chunks: Optional[int] = None,
    tiles: Sequence[int] = (1, 1),
    threads_per_task: int = 1,
    max_retries: int = 3,
    address: Optional[str] = None,
    runtime_env: Optional[Dict[str, Any]] = None,
    progress: bool = True,
) -> _Result: ...
def truth(
    scene: Scene,
    spp: int = 64,
    size: Sequence[int] = (256, 256),
    direct_only: bool = False,
    seed: int = 0,
    *,
    sample_offset: int = 0,
    crop: Optional[Sequence[int]] = None,
    range: Optional[Sequence[float]] = None,
    observer: Optional[_Path] = None,
    white: Optional[str] = None,
    max_depth: int = 1024,
    water: Optional[str] = None,
    depth: Optional[float] = None,
    rgb_medium: Optional[_Path] = None,
    spectral_bin: Optional[float] = None,
    camera_to_display: bool = False,
    medium: Optional[_Path] = None,
    lambert: bool = False,
    xyz: bool = False,
    table: Optional[_Path] = None,
    chunks: Optional[int] = None,
    tiles: Sequence[int] = (1, 1),
    threads_per_task: int = 1,
    max_retries: int = 3,
    address: Optional[str] = None,
    runtime_env: Optional[Dict[str, Any]] = None,
    progress: bool = True,
) -> _Result:
    """`spectra.truth` split into `chunks` sample chunks × a `tiles=(nx, ny)` grid of tiles,
    each a Ray task, and merged: the same arguments (`sample_offset`, `crop`, `range`,
    `observer`, `white`, `max_depth`, `water`, `depth`, `rgb_medium`, `spectral_bin`,
    `camera_to_display`, `medium`, `lambert`, `xyz`, `table` as keywords) and the same result
    (an (h, w, 3) float32 linear sRGB array, CIE XYZ with `xyz=True`; with `spectral_bin`,
    (image, bands, edges)). An `observer`, `rgb_medium`, `medium` or `table` file given by a
    relative path is found from this process's working directory, not the workers'.

    chunks: default 8, or `spp` when that is fewer (more than `spp` given explicitly is an
    error). threads_per_task: CPUs each task asks Ray for and uses (the tracer's threads); Ray
    runs as many tasks at once as the cluster has CPUs for, and more than any node has is a
    ValueError. max_retries: how often Ray runs a
    task again whose worker died (-1: without limit). address / runtime_env: passed to
    `ray.init` when Ray is not running yet in this process (address None: a local instance, or
    the cluster of $RAY_ADDRESS). progress: a line on stderr per finished task. Counts may be
    any integral type (numpy's integers too), not bools or floats. Ctrl-C (KeyboardInterrupt),
    or any other error while waiting, cancels the tasks not yet finished."""
    job = submit(
        scene,
        spp,
        size,
        direct_only,
        seed,
        sample_offset=sample_offset,
        crop=crop,
        range=range,
        observer=observer,
        white=white,
        max_depth=max_depth,
        water=water,
        depth=depth,
        rgb_medium=rgb_medium,
        spectral_bin=spectral_bin,
        camera_to_display=camera_to_display,
        medium=medium,
        lambert=lambert,
        xyz=xyz,
        table=table,
        chunks=chunks,
        tiles=tiles,
        threads_per_task=threads_per_task,
        max_retries=max_retries,
        address=address,
        runtime_env=runtime_env,
        progress=progress,
    )
    try:
        return job.result()
    except BaseException:
        # Ctrl-C in a notebook or a script: the tasks would otherwise go on rendering, holding
        # the cluster's CPUs, with nobody to take their result.
        job.cancel()
        raise


def eval(
    out: _Path,
    *,
    quick: bool = False,
    scenes: Optional[Union[str, Sequence[str]]] = None,
    spp: Optional[int] = None,
    size: Optional[Union[str, Sequence[int]]] = None,
    sweep: Optional[Union[str, Sequence[int]]] = None,
    table: Optional[_Path] = None,
    observer: Optional[_Path] = None,
    truth_cache: Optional[_Path] = None,
    chunks: int = 8,
    threads_per_task: int = 1,
    max_retries: int = 3,
    address: Optional[str] = None,
    runtime_env: Optional[Dict[str, Any]] = None,
    progress: bool = True,
) -> Dict[str, Any]:
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
    workers'. Ctrl-C (or any other error while waiting) cancels the tasks not yet finished."""
    import json
    import tempfile

    ray = _ray()
    chunks = _whole("chunks", chunks)
    threads_per_task = _whole("threads_per_task", threads_per_task)
    max_retries = _whole("max_retries", max_retries, -1)
    argv = ["eval", "--out", os.fspath(out)]
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
        argv += ["--table", os.fspath(table)]
        paths.append(len(argv) - 1)
    if observer is not None:
        argv += ["--observer", os.fspath(observer)]
        if _observer_file(argv[-1]):
            paths.append(len(argv) - 1)
    with tempfile.TemporaryDirectory(prefix="spectra-truth-cache-") as tmp:
        cache = os.fspath(truth_cache) if truth_cache is not None else tmp
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
        if plan:
            _check_cpus(ray, threads_per_task)
        task = ray.remote(_eval_piece).options(num_cpus=threads_per_task, max_retries=max_retries)
        jobs = []
        try:
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
        except BaseException:
            # Interrupted (Ctrl-C) or failed: the tasks not yet finished are of no use.
            for _, refs in jobs:
                for ref in refs:
                    ray.cancel(ref)
            raise
        _spectra._eval_run(argv)
    with open(os.path.join(os.fspath(out), "results.json")) as f:
        result: Dict[str, Any] = json.load(f)
    return result


def _eval_piece(
    argv: List[str], job: Dict[str, Any], sample_offset: int, spp: int, threads: int
) -> Dict[str, Any]:
    """One Ray task of `eval`: samples sample_offset … +spp−1 of one evaluation truth."""
    sums: Dict[str, Any] = _spectra._eval_truth_sums(argv, job, sample_offset, spp, threads)
    return sums
