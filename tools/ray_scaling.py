#!/usr/bin/env python3
"""Wall time of `spectra.distributed.truth` with 1, 2, … Ray workers (local Ray instances of
that many CPUs, one tracer thread per task) beside `spectra.truth` in one process, and the
largest per-pixel relative difference between them.

Usage: python tools/ray_scaling.py [--scene cornell] [--size 160x120] [--spp 256]
       [--chunks 8] [--workers 1,2]
Needs the package and Ray: pip install './python[distributed]'.
"""
import argparse
import os
import time

# Local instances on the loopback address (Ray's "no cluster" mode), read when ray is imported.
os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")

import numpy as np  # noqa: E402
import ray  # noqa: E402

import spectra  # noqa: E402
import spectra.distributed as dist  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="cornell")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--chunks", type=int, default=8)
    ap.add_argument("--workers", default="1,2")
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.lower().split("x"))
    scene = spectra.load(a.scene)
    t0 = time.perf_counter()
    one = spectra.truth(scene, spp=a.spp, size=(w, h), seed=a.seed)
    t_one = time.perf_counter() - t0
    print(f"{a.scene} {w}x{h}, {a.spp} spp, {a.chunks} chunks, {os.cpu_count()} cores")
    print(f"spectra.truth, one process, all cores: {t_one:.1f} s")
    for n in (int(v) for v in a.workers.split(",")):
        ray.init(num_cpus=n, include_dashboard=False, log_to_driver=False)
        try:
            t0 = time.perf_counter()
            img = dist.truth(scene, spp=a.spp, size=(w, h), seed=a.seed, chunks=a.chunks, progress=False)
            t = time.perf_counter() - t0
        finally:
            ray.shutdown()
        rel = np.abs(img.astype(np.float64) - one) / np.maximum(np.abs(one.astype(np.float64)), 1e-30)
        same = np.count_nonzero(img == one) / img.size
        print(f"Ray, {n} worker(s): {t:.1f} s  (max relative difference {rel.max():.2e}, "
              f"{100 * same:.1f} % of values bit-identical)")


if __name__ == "__main__":
    main()
