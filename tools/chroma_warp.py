#!/usr/bin/env python3
"""Why the chroma weight (color::upsample::table::chroma_weight) is what it is.

Reads an *unrefined* sRGB table on rgb2spec's uniform chroma grid (node-exact, so only the
interpolation is judged; the default tables' grid is denser next to 0 and 1, which this script
does not model, and it refuses them):

    ZGRID=ss1 MAXC=10000 cargo run --release -p color --example fit -- srgb 64 /tmp/unrefined.coeff 0
    python3 tools/chroma_warp.py /tmp/unrefined.coeff

and evaluates the direct fetch (trilinear, σ⁻¹ brightness weight; no complement, so only colours
whose lowest channel is below 0.5) with three chroma weights: linear (rgb2spec), a fixed warp
A = 2 cells, and spectra's A = 2 + 0.2·(other chroma coordinate) cells. Colour sets (seed 1):
uniform in the cube; "face": one channel 0, a second within 8 % of the largest; "corner": both
smaller channels within 3/63 of the largest. Prints mean / p99 / max ΔE2000 per set.

This is an independent evaluation: the spectrum → Lab side is colour-science's (CIE 1931 2°,
D65 on 1 nm, 360–830 nm, Lab relative to the perfect reflector), the target side colour-science's
sRGB matrix; its conventions differ slightly from spectra's (absolute figures ~0.005 higher at
the nodes), so compare the rows with each other. Needs `pip install colour-science`.
"""
import struct
import sys

import numpy as np
import colour

fn = sys.argv[1]
b = open(fn, "rb").read()
if b[:4] != b"SPEC":
    sys.exit(f"{fn}: not an rgb2spec .coeff table")
res = struct.unpack("<I", b[4:8])[0]
if b[8 + 4 * res + 36 * res**3 :].startswith(b"\nspectra-chroma-nodes\n"):
    sys.exit(f"{fn}: has a non-uniform chroma grid (spectra's default); this script needs the uniform one (see its usage)")
scale = np.frombuffer(b[8 : 8 + 4 * res], dtype="<f4").astype(float)
data = np.frombuffer(b[8 + 4 * res : 8 + 4 * res + 36 * res**3], dtype="<f4").reshape(3, res, res, res, 3).astype(float)
shape = colour.SpectralShape(360, 830, 1)
lam = np.arange(360, 831, 1.0)
cmf = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape).values
ill = colour.SDS_ILLUMINANTS["D65"].copy().align(shape).values
W = cmf * ill[:, None]
white = W.sum(0)
M = colour.RGB_COLOURSPACES["sRGB"].matrix_RGB_to_XYZ
wsp = M @ np.ones(3)


def lab(xyz, wh):
    return colour.XYZ_to_Lab(xyz / wh[1], colour.XYZ_to_xy(wh / wh[1]))


def zlogit(z):
    z = np.clip(z, 1e-6, 1 - 2e-4)
    return (2 * z - 1) / (2 * np.sqrt(z * (1 - z)))


def fetch(rgb, a0, slope):
    l = 2 - np.argmax(rgb[:, ::-1], axis=1)  # largest channel, ties to the later one
    idx = np.arange(len(rgb))
    z = rgb[idx, l]
    x = rgb[idx, (l + 1) % 3] / z * (res - 1)
    y = rgb[idx, (l + 2) % 3] / z * (res - 1)
    xi = np.minimum(x.astype(int), res - 2)
    yi = np.minimum(y.astype(int), res - 2)
    zi = np.clip(np.searchsorted(scale, z, side="right"), 1, res - 1) - 1
    s0, s1 = scale[zi], scale[zi + 1]
    h0, h1 = zlogit(s0), zlogit(s1)
    zw = np.where((h1 > h0) & (s1 <= 0.5), (zlogit(z) - h0) / np.where(h1 > h0, h1 - h0, 1), (z - s0) / (s1 - s0))
    zw = zw.clip(0, 1)
    if a0 is None:
        x1, y1 = x - xi, y - yi
    else:
        ax, ay = a0 + slope * y, a0 + slope * x
        x1 = (x - xi) * (xi + 1 + ax) / (x + ax)
        y1 = (y - yi) * (yi + 1 + ay) / (y + ay)
    c = 0
    for dk, wk in ((0, 1 - zw), (1, zw)):
        for dj, wj in ((0, 1 - y1), (1, y1)):
            for di, wi in ((0, 1 - x1), (1, x1)):
                c = c + (wk * wj * wi)[:, None] * data[l, zi + dk, yi + dj, xi + di]
    return c


def delta_e(rgb, c):
    p = (c[:, 0:1] * lam + c[:, 1:2]) * lam + c[:, 2:3]
    s = 0.5 + p / (2 * np.sqrt(1 + p * p))
    return colour.delta_E(lab(rgb @ M.T, wsp), lab(s @ W, white), method="CIE 2000")


rng = np.random.default_rng(1)
uniform = rng.random((20000, 3))
uniform = uniform[uniform.min(1) < 0.5]


def family(n, small, third):
    out = np.zeros((n, 3))
    for r in out:
        p = rng.permutation(3)
        r[p[0]] = rng.uniform(0.05, 1)
        r[p[1]] = r[p[0]] * rng.uniform(0, small)
        r[p[2]] = third(r[p[0]])
    return out


face = family(20000, 0.08, lambda m: m * rng.uniform(0, 1) * (rng.random() < 0.5))
corner = family(20000, 3 / 63, lambda m: m * rng.uniform(0, 3 / 63))
print(f"{fn}: {res}^3, direct fetch, mean / p99 / max ΔE2000")
for name, a0, slope in (("linear (rgb2spec)", None, 0), ("A = 2", 2.0, 0.0), ("A = 2 + 0.2·other", 2.0, 0.2)):
    row = []
    for s in (uniform, face, corner):
        d = delta_e(s, fetch(s, a0, slope))
        row.append(f"{d.mean():.4f} / {np.percentile(d, 99):.3f} / {d.max():.3f}")
    print(f"{name:20s} uniform {row[0]}   face {row[1]}   corner {row[2]}")
