#!/usr/bin/env python3
"""Fits linearly transformed cosines (Heitz, Dupuy, Hill, Neubelt 2016) to the glTF BRDF's
specular lobe, for the real-time renderer's polygon lights (crates/render/src/ltc.rs).

The lobe is the one both renderers use (crates/truth/src/bsdf.rs, shading.wgsl `light_terms`):
f(l)·cos = D(h)·V(v, l)·(n·l), GGX D with α = max(roughness², 10⁻³) and the height-correlated
Smith V, without the Fresnel term (which the table's (A, B) carry: ∫ f·cos·F = F0·A + B for
Schlick's F). For each cell (roughness r = i / 63, t = j / 63 with n·v = 1 − t², kept ≥ 10⁻³)
the fit finds the matrix M whose transformed clamped cosine D(l) = D_o(M⁻¹l / |M⁻¹l|)·|M⁻¹| /
|M⁻¹l|³ is nearest the normalised lobe f·cos / (A + B) in the L² norm (the paper uses L³),
estimated with both distributions' samples and the balance heuristic. M = R·[[m11, 0, m13],
[0, m22, 0], [0, 0, 1]], R the frame whose z is the lobe's mean direction; isotropic
(m11 = m22, m13 = 0) at normal incidence. Cells are fitted from rough to smooth and from normal
incidence outwards, each starting from its neighbour's fit (the paper's continuation).

Output: little-endian f32, 64 × 64 cells of 8 values, row t (n·v axis) major, column r:
M⁻¹'s entries (0,0), (0,2), (2,0), (2,2) divided by its (1,1) — the rest are zero, and the
transformed cosine does not change when M⁻¹ is scaled — then A, B, and two zeros (reserved).

    python3 tools/fit_ltc.py crates/render/data/ltc_ggx.bin   # about 6 minutes on 2 cores

Needs numpy and scipy.
"""

import struct
import sys

import numpy as np
from scipy.optimize import minimize

SIZE = 64
MIN_ALPHA = 1e-3
MIN_NV = 1e-3
FIT_SAMPLES = 40  # per axis, per distribution
# The error's exponent: the paper uses 3; 2 fits this lobe's polygon integrals better (worst
# error over the squares of `cargo test -p render --lib ltc`, F0 = 1: 1.0 % of the albedo up to
# 60°, 4.7 % at 75°, against 1.3 % and 6.2 % with 3).
POWER = 2.0
ALBEDO_SAMPLES = 256  # per axis


def grid(n):
    u = (np.arange(n) + 0.5) / n
    return np.meshgrid(u, u, indexing="ij")


U1, U2 = (a.ravel() for a in grid(FIT_SAMPLES))
A1, A2 = (a.ravel() for a in grid(ALBEDO_SAMPLES))


def ggx_d(nh, a2):
    dd = nh * nh * (a2 - 1.0) + 1.0
    return a2 / (np.pi * dd * dd)


def lobe(l, v, a2):
    """D·V·(n·l) at directions l (rows), zero below the horizon."""
    nv = v[2]
    nl = l[:, 2]
    h = half(l, v)
    nh = np.clip(h[:, 2], 0.0, 1.0)
    nlc = np.maximum(nl, 1e-7)
    vis = 0.5 / (nlc * np.sqrt(nv * nv * (1 - a2) + a2) + nv * np.sqrt(nlc * nlc * (1 - a2) + a2))
    return np.where(nl > 0, ggx_d(nh, a2) * vis * nl, 0.0)


def lobe_pdf(l, v, a2):
    """Density of the classic GGX sampler (h ~ D·(n·h)) at l."""
    h = half(l, v)
    nh = np.clip(h[:, 2], 0.0, 1.0)
    vh = np.maximum(np.sum(v * h, axis=1), 1e-7)
    return ggx_d(nh, a2) * nh / (4.0 * vh)


def sample_lobe(v, a2, u1, u2):
    cos_t = np.sqrt((1 - u1) / (1 + (a2 - 1) * u1))
    sin_t = np.sqrt(np.maximum(1 - cos_t * cos_t, 0))
    phi = 2 * np.pi * u2
    h = np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], axis=1)
    vh = h @ v
    return 2 * vh[:, None] * h - v, h


def half(l, v):
    h = l + v
    n = np.linalg.norm(h, axis=1, keepdims=True)
    return np.where(n > 1e-12, h / np.maximum(n, 1e-12), np.array([0.0, 0.0, 1.0]))


def albedo(v, a2):
    """(A, B, mean direction) of the lobe: ∫ f·cos·(1 − (1 − v·h)⁵), ∫ f·cos·(1 − v·h)⁵."""
    l, h = sample_lobe(v, a2, A1, A2)
    nh = h[:, 2]
    vh = h @ v
    # f·cos / pdf with pdf(l) = D·(n·h) / (4·v·h): D cancels.
    ok = (l[:, 2] > 0) & (vh > 0)
    nl = np.maximum(l[:, 2], 1e-7)
    nv = v[2]
    vis = 0.5 / (nl * np.sqrt(nv * nv * (1 - a2) + a2) + nv * np.sqrt(nl * nl * (1 - a2) + a2))
    w = np.where(ok, vis * nl * 4 * np.maximum(vh, 0) / nh, 0.0)
    fc = (1 - np.clip(h @ v, 0, 1)) ** 5
    a = np.mean(w * (1 - fc))
    b = np.mean(w * fc)
    mean_dir = np.mean(w[:, None] * l, axis=0)
    return a, b, mean_dir


def frame_of(mean_dir):
    z = np.array([mean_dir[0], 0.0, mean_dir[2]])
    z /= np.linalg.norm(z)
    y = np.array([0.0, 1.0, 0.0])
    x = np.cross(y, z)
    return np.stack([x, y, z], axis=1)  # columns


def matrix(params, frame, isotropic):
    # The cosine's distribution is symmetric in x and y: a scale's sign does not matter.
    if isotropic:
        m11 = m22 = abs(params[0])
        m13 = 0.0
    else:
        m11, m22, m13 = abs(params[0]), abs(params[1]), params[2]
    m = np.array([[m11, 0.0, m13], [0.0, m22, 0.0], [0.0, 0.0, 1.0]])
    return frame @ m


def ltc_eval(l, minv, det_inv):
    lo = l @ minv.T
    length = np.linalg.norm(lo, axis=1)
    return np.maximum(lo[:, 2] / length, 0.0) / np.pi * abs(det_inv) / length**3


def ltc_sample(m, u1, u2):
    r = np.sqrt(u1)
    phi = 2 * np.pi * u2
    o = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(1 - u1, 0))], axis=1)
    l = o @ m.T
    return l / np.linalg.norm(l, axis=1, keepdims=True)


def error(params, v, a2, norm, frame, isotropic, lobe_dirs, lobe_f, lobe_p):
    if np.min(np.abs(params[:2] if not isotropic else params)) < 1e-7:
        return 1e30
    m = matrix(params, frame, isotropic)
    det = np.linalg.det(m)
    if abs(det) < 1e-30:
        return 1e30
    minv = np.linalg.inv(m)
    det_inv = 1.0 / det
    # Samples of the LTC.
    l = ltc_sample(m, U1, U2)
    d = ltc_eval(l, minv, det_inv)
    f = lobe(l, v, a2) / norm
    p = lobe_pdf(l, v, a2)
    e1 = np.abs(f - d) ** POWER / (d + p)
    # Samples of the lobe (fixed for the cell).
    d2 = ltc_eval(lobe_dirs, minv, det_inv)
    e2 = np.abs(lobe_f - d2) ** POWER / (d2 + lobe_p)
    e = np.concatenate([e1, e2])
    return float(np.mean(e[np.isfinite(e)]))


def fit_cell(r, t, guess):
    alpha = max(r * r, MIN_ALPHA)
    a2 = alpha * alpha
    nv = max(1 - t * t, MIN_NV)
    v = np.array([np.sqrt(1 - nv * nv), 0.0, nv])
    a, b, mean_dir = albedo(v, a2)
    norm = a + b
    frame = frame_of(mean_dir)
    isotropic = t == 0.0
    ld, _ = sample_lobe(v, a2, U1, U2)
    lf = lobe(ld, v, a2) / norm
    lp = lobe_pdf(ld, v, a2)
    x0 = np.array([guess[0]]) if isotropic else np.array(guess)
    best = minimize(
        error,
        x0,
        args=(v, a2, norm, frame, isotropic, ld, lf, lp),
        method="Nelder-Mead",
        options={"xatol": 1e-6, "fatol": 1e-10, "maxiter": 1000},
    )
    p = best.x
    params = [abs(p[0]), abs(p[0]), 0.0] if isotropic else [abs(p[0]), abs(p[1]), p[2]]
    m = matrix(params, frame, isotropic=False)
    return params, m, a, b



def fit_row(args):
    """One roughness's cells, from normal incidence outwards, from its normal-incidence fit."""
    i, first = args
    r = i / (SIZE - 1)
    row = np.zeros((SIZE, 8))
    guess = first
    for j in range(SIZE):
        t = j / (SIZE - 1)
        params, m, a, b = fit_cell(r, t, guess)
        guess = params
        minv = np.linalg.inv(m)
        minv /= minv[1, 1]
        row[j] = [minv[0, 0], minv[0, 2], minv[2, 0], minv[2, 2], a, b, 0.0, 0.0]
    print(f"roughness {r:.3f} done", file=sys.stderr, flush=True)
    return i, row


def main():
    import multiprocessing
    import os

    if len(sys.argv) != 2:
        sys.exit("usage: fit_ltc.py OUT.bin")
    out = sys.argv[1]
    # Normal incidence first, rough to smooth (isotropic, one parameter each): each roughness's
    # row then starts from its own.
    firsts = {}
    guess = [1.0, 1.0, 0.0]
    for i in range(SIZE - 1, -1, -1):
        guess, _, _, _ = fit_cell(i / (SIZE - 1), 0.0, guess)
        firsts[i] = guess
    cells = np.zeros((SIZE, SIZE, 8), dtype=np.float64)
    with multiprocessing.Pool(os.cpu_count()) as pool:
        for i, row in pool.imap_unordered(fit_row, [(i, firsts[i]) for i in range(SIZE)]):
            cells[:, i] = row
    tmp = out + ".tmp"
    with open(tmp, "wb") as fh:
        fh.write(cells.astype("<f4").tobytes())
    os.replace(tmp, out)
    print(f"wrote {out}: {SIZE}×{SIZE} cells × 8 f32", file=sys.stderr)


if __name__ == "__main__":
    main()
