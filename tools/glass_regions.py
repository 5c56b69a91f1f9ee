#!/usr/bin/env python3
"""Where the `glass` eval case's error lies: each image's mean CIEDE2000 against a truth, split
into the four balls' discs and the floor (each region's share of the image mean, so the columns
add up to the first).

    tools/glass_regions.py [--spectra BIN] TRUTH.exr IMAGE.exr [IMAGE.exr ...]

The images are linear sRGB EXRs of the built-in `glass` scene at one size (`spectra render
glass --out X.exr`, `spectra truth glass --direct-only --out T.exr`, or the eval's
glass_truth.exr). The per-pixel ΔE2000 is `spectra diff --per-pixel-out`'s (the metric `spectra
eval` reports); this script only adds the regions: the spheres of
crates/scene/src/builtin/glass.rs projected through its camera, discs 8 % wider than the
silhouette. Python 3 standard library only.
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# crates/scene/src/builtin/glass.rs
EYE, TARGET, FOV_Y = (0.0, 0.55, 1.45), (0.0, 0.1, 0.0), math.radians(38.0)
RADIUS = 0.12
BALLS = ["clear", "flint", "green", "frosted"]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    n = math.sqrt(dot(a, a))
    return [x / n for x in a]


def discs(w, h):
    """(name, centre x, centre y, radius) in pixels of each ball."""
    fwd = unit(sub(TARGET, EYE))
    right = unit(cross(fwd, [0.0, 1.0, 0.0]))
    up = cross(right, fwd)
    t = math.tan(FOV_Y / 2)
    out = []
    for i, name in enumerate(BALLS):
        d = sub([(i - 1.5) * 0.3, RADIUS, 0.0], EYE)
        z = dot(d, fwd)
        px = (dot(d, right) / z / (t * w / h) * 0.5 + 0.5) * w
        py = (0.5 - 0.5 * dot(d, up) / z / t) * h
        out.append((name, px, py, RADIUS / z / t * h / 2 * 1.08))
    return out


def per_pixel(spectra, truth, image, tmp):
    out = os.path.join(tmp, "pp.csv")
    r = subprocess.run([spectra, "diff", truth, image, "--per-pixel-out", out], capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"spectra diff {truth} {image}: {r.stderr.strip()}")
    with open(out, newline="") as f:
        return [(int(row["x"]), int(row["y"]), float(row["delta_e2000"])) for row in csv.DictReader(f)]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--spectra", default=os.path.join(REPO_ROOT, "target", "release", "spectra"),
                    help="the spectra binary (default: target/release/spectra of this repository)")
    ap.add_argument("truth")
    ap.add_argument("images", nargs="+")
    a = ap.parse_args()
    if not os.path.isfile(a.spectra):
        ap.error(f"{a.spectra}: no spectra binary there (cargo build --release -p spectra, or --spectra PATH)")
    names = ["all"] + BALLS + ["floor"]
    print("%-28s" % "image", " ".join("%8s" % k for k in names))
    with tempfile.TemporaryDirectory() as tmp:
        for path in a.images:
            px = per_pixel(a.spectra, a.truth, path, tmp)
            w, h = max(p[0] for p in px) + 1, max(p[1] for p in px) + 1
            ds = discs(w, h)
            sums = dict.fromkeys(names, 0.0)
            counts = dict.fromkeys(names, 0)
            for x, y, de in px:
                region = next((n for n, cx, cy, r in ds if (x - cx) ** 2 + (y - cy) ** 2 < r * r), "floor")
                for k in ("all", region):
                    sums[k] += de
                    counts[k] += 1
            if path == a.images[0]:
                print("%-28s" % "pixel share", " ".join("%8.3f" % (counts[k] / len(px)) for k in names))
            print("%-28s" % path.split("/")[-1][-28:], " ".join("%8.4f" % (sums[k] / len(px)) for k in names))


if __name__ == "__main__":
    main()
