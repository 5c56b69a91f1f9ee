#!/usr/bin/env python3
"""Where the `glass` eval case's error lies: each image's mean CIEDE2000 against a truth, split
into the four balls' discs and the floor (each region's share of the image mean, so the columns
add up to the first).

    tools/glass_regions.py TRUTH.exr IMAGE.exr [IMAGE.exr ...]

The images are linear sRGB EXRs of the built-in `glass` scene at one size (`spectra render
glass --out X.exr`, `spectra truth glass --direct-only --out T.exr`, or the eval's
glass_truth.exr). The discs are the spheres of crates/scene/src/builtin/glass.rs projected
through its camera, 8 % wider than the silhouette. ΔE2000 with CIELAB white Y = 1 (D65), as
`spectra eval` computes it. Needs numpy, OpenEXR and colour-science (the oracle scripts' deps).
"""
import sys
import warnings

import numpy as np
import OpenEXR

warnings.filterwarnings("ignore")
import colour  # noqa: E402

# crates/scene/src/builtin/glass.rs
EYE, TARGET, FOV_Y = np.array([0.0, 0.55, 1.45]), np.array([0.0, 0.1, 0.0]), np.radians(38.0)
RADIUS = 0.12
BALLS = ["clear", "flint", "green", "frosted"]
SRGB_TO_XYZ = np.array([[0.4124564, 0.3575761, 0.1804375],
                        [0.2126729, 0.7151522, 0.0721750],
                        [0.0193339, 0.1191920, 0.9503041]])


def load(path):
    ch = OpenEXR.File(path).channels()
    if "RGB" in ch:
        return np.asarray(ch["RGB"].pixels, dtype=np.float64)
    return np.stack([np.asarray(ch[c].pixels, dtype=np.float64) for c in "RGB"], -1)


def lab(rgb):
    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    return colour.XYZ_to_Lab(rgb @ SRGB_TO_XYZ.T, white)


def regions(w, h):
    fwd = (TARGET - EYE) / np.linalg.norm(TARGET - EYE)
    right = np.cross(fwd, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    t = np.tan(FOV_Y / 2)
    yy, xx = np.mgrid[0:h, 0:w]
    out = {}
    for i, name in enumerate(BALLS):
        d = np.array([(i - 1.5) * 0.3, RADIUS, 0.0]) - EYE
        z = d @ fwd
        px = (d @ right / z / (t * w / h) * 0.5 + 0.5) * w
        py = (0.5 - 0.5 * (d @ up) / z / t) * h
        r = RADIUS / z / t * h / 2 * 1.08
        out[name] = (xx - px) ** 2 + (yy - py) ** 2 < r * r
    out["floor"] = ~np.any(list(out.values()), axis=0)
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    truth = load(sys.argv[1])
    h, w, _ = truth.shape
    masks = regions(w, h)
    reference = lab(truth)
    print("%-28s" % "image", " ".join("%8s" % k for k in ["all"] + list(masks)))
    print("%-28s" % "pixel share", " ".join("%8.3f" % v for v in [1.0] + [m.mean() for m in masks.values()]))
    for path in sys.argv[2:]:
        img = load(path)
        if img.shape != truth.shape:
            sys.exit(f"{path}: {img.shape[1]}x{img.shape[0]}, the truth is {w}x{h}")
        de = colour.delta_E(reference, lab(img), method="CIE 2000")
        row = [de.mean()] + [de[m].sum() / de.size for m in masks.values()]
        print("%-28s" % path.split("/")[-1][-28:], " ".join("%8.4f" % v for v in row))


if __name__ == "__main__":
    main()
