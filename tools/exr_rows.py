#!/usr/bin/env python3
"""Row profile of EXR images: the mean green (linear) of every other pixel row, top to bottom,
one line per image — a quick look at where two renders of the same scene differ (sky, surface,
floor), e.g. `spectra truth` against `spectra render` under water (docs/underwater.md).

Usage: tools/exr_rows.py A.exr [B.exr ...]   (needs the OpenEXR Python package, as the oracles)
"""
import sys

import numpy as np
import OpenEXR


def read(path):
    with OpenEXR.File(path) as f:
        ch = f.channels()
        if "RGB" in ch:
            return np.array(ch["RGB"].pixels, dtype=np.float64)
        return np.stack([np.array(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for p in sys.argv[1:]:
        try:
            img = read(p)
        except Exception as e:  # a missing or broken file: say which, go on
            print(f"{p}: {e}", file=sys.stderr)
            continue
        rows = " ".join(f"{img[y].mean(axis=0)[1]:.4f}" for y in range(0, img.shape[0], 2))
        print(f"{p}: {rows}")


if __name__ == "__main__":
    main()
