#!/usr/bin/env python3
"""Oracle check of the thin-film reflectance (scene::film, KHR_materials_iridescence, issue 30)
against an independent transfer-matrix evaluation (the characteristic matrix of one layer,
Macleod, "Thin-Film Optical Filters", ch. 2, with tilted admittances η_s = n·cos θ,
η_p = n / cos θ), not Airy's sum that the Rust code uses.

The grid the issue asks for: 380–780 nm, thickness 0–1200 nm, angles 0–89°, film IOR 1.2–2.0,
dielectric bases (above and below the film's index, so the base interface reflects with both
signs and, beyond the critical angle, totally) and conductor bases (n + ik of gold, silver,
aluminium, copper-like values, and the glTF real-index convention from F0), plus a random
sample. Passes when every |R_rust − R_tmm| ≤ 1e-4 (it is ~1e-15 in practice).

Usage: tools/check_film.py [--bin target/debug/examples/film_values]
"""
import argparse
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOL = 1e-4


def tmm(lam, cos_i, d, nf, base):
    """Unpolarised reflectance of air | film (nf, d) | base by the characteristic matrix.

    Macleod's convention is e^{i(ωt − kz)}, in which an absorbing index is N = n − ik: the
    base's n + ik (the Rust code's e^{−iωt} convention) enters conjugated, and each cosine is
    the root whose admittance has Im ≤ 0 (a wave that decays into the medium)."""
    sin2 = 1.0 - cos_i * cos_i
    n0, n1, n2 = 1.0 + 0j, complex(nf), complex(base).conjugate()

    def cos_t(n):
        c = np.sqrt(1.0 - sin2 / (n * n) + 0j)
        return -c if (n * c).imag > 0 else c

    c0, c1, c2 = complex(cos_i), cos_t(n1), cos_t(n2)
    beta = 2 * np.pi * n1 * d * c1 / lam
    total = 0.0
    for pol in ("s", "p"):
        eta = (lambda n, c: n * c) if pol == "s" else (lambda n, c: n / c)
        e0, e1, e2 = eta(n0, c0), eta(n1, c1), eta(n2, c2)
        m = np.array([[np.cos(beta), 1j * np.sin(beta) / e1], [1j * e1 * np.sin(beta), np.cos(beta)]])
        b, c = m @ np.array([1.0, e2])
        r = (e0 * b - c) / (e0 * b + c)
        total += abs(r) ** 2
    return total / 2


def cases():
    out = []
    bases = [1.0, 1.33, 1.5, 1.7, 2.4, 3.2,  # dielectric, above and below the films
             0.18 + 3.1j, 0.05 + 4.0j, 1.0 + 7.0j, 0.27 + 2.8j]  # conductor-like
    # The glTF convention: a metal base colour's F0 as a real index.
    for f0 in (0.04, 0.3, 0.7, 0.95, 0.9999):
        s = np.sqrt(f0)
        bases.append((1 + s) / (1 - s))
    for lam in (380.0, 455.0, 550.0, 633.0, 780.0):
        for deg in (0.0, 20.0, 45.0, 70.0, 85.0, 89.0):
            for d in (0.0, 1.0, 100.0, 250.0, 400.0, 777.0, 1200.0):
                for nf in (1.2, 1.3, 1.5, 2.0):
                    for b in bases:
                        out.append((lam, np.cos(np.radians(deg)), d, nf, complex(b)))
    rng = np.random.default_rng(30)
    for _ in range(20000):
        b = complex(rng.uniform(1.0, 3.0)) if rng.random() < 0.5 else complex(rng.uniform(0.05, 3.0), rng.uniform(0.5, 8.0))
        out.append((rng.uniform(380, 780), np.cos(np.radians(rng.uniform(0, 89))), rng.uniform(0, 1200),
                    rng.uniform(1.2, 2.0), b))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", help="the film_values example (built with cargo when not given)")
    a = ap.parse_args()
    if a.bin:
        cmd = [a.bin]
    else:
        cmd = ["cargo", "run", "--quiet", "-p", "scene", "--example", "film_values"]
    cs = cases()
    text = "".join(" ".join(repr(float(x)) for x in (l, c, d, nf, b.real, b.imag)) + "\n" for l, c, d, nf, b in cs)
    r = subprocess.run(cmd, input=text, capture_output=True, text=True, cwd=ROOT)
    if r.returncode != 0:
        sys.exit(f"check_film: {' '.join(cmd)} failed:\n{r.stderr}")
    got = [float(x) for x in r.stdout.split()]
    if len(got) != len(cs):
        sys.exit(f"check_film: {len(got)} values for {len(cs)} cases")
    worst = (0.0, None)
    for v, case in zip(got, cs):
        e = abs(v - tmm(*case))
        if e > worst[0] or worst[1] is None:
            worst = (e, case)
    e, (lam, c, d, nf, b) = worst
    print(f"check_film: {len(cs)} cases, max |R - R_tmm| = {e:.3e} "
          f"(λ {lam:.1f} nm, cos {c:.4f}, d {d:.1f} nm, film {nf:.3f}, base {b.real:.3f}{b.imag:+.3f}i)")
    if not e <= TOL:
        sys.exit(f"check_film: FAILED, {e:.3e} > {TOL}")


if __name__ == "__main__":
    main()
