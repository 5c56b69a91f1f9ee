#!/usr/bin/env python3
"""Where a render is too bright or too dark against a truth: the ratio render/truth of the mean
green (linear) over BLOCK×BLOCK pixel blocks, in percent, one row of blocks per line, and the
truth's own block means ×1000 below it — e.g. which object carries an underwater row's error
(docs/underwater.md, "Session 10"). Several truth files (seeds) are averaged.

Usage: tools/exr_ratio.py --truth T1.exr [--truth T2.exr ...] [--block 2] RENDER.exr
(needs numpy and the OpenEXR Python package, as the oracles)
"""
import argparse
import sys

import numpy as np

from exr_rows import read  # the same reader (tools/ is the script's directory)


def blocks(img, b):
    h, w = img.shape[0] // b * b, img.shape[1] // b * b
    g = img[:h, :w, 1]
    return g.reshape(h // b, b, w // b, b).mean((1, 3))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--truth", action="append", required=True, help="truth EXR (repeat to average seeds)")
    ap.add_argument("--block", type=int, default=2)
    ap.add_argument("render")
    a = ap.parse_args()
    if a.block < 1:
        sys.exit("--block must be at least 1")
    try:
        truths = [read(p) for p in a.truth]
        render = read(a.render)
    except Exception as e:  # a missing or broken file: say which
        sys.exit(f"cannot read: {e}")
    if any(t.shape != render.shape for t in truths):
        sys.exit(f"sizes differ: truth {[t.shape[:2] for t in truths]}, render {render.shape[:2]}")
    t = blocks(sum(truths) / len(truths), a.block)
    r = blocks(render, a.block)
    print(f"render/truth, green, {a.block}×{a.block} blocks, %:")
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(t > 0, r / t, np.nan)
    for row in ratio:
        print(" ".join("  - " if np.isnan(x) else f"{round(100 * x):4d}" for x in row))
    print("truth, green ×1000:")
    for row in t:
        print(" ".join(f"{round(1000 * x):4d}" for x in row))


if __name__ == "__main__":
    main()
