#!/usr/bin/env python3
"""Agreement of spectra's Jakob–Hanika implementation with colour-science (an independent one).

Two comparisons on N random linear sRGB colours (uniform in the cube, fixed seed):

1. Table lookup: colour-science's `LUT3D_Jakob2019.read()` loads the same `.coeff` file and
   interpolates it with its own code (`RGB_to_coefficients`); spectra's `CoeffTable::fetch`
   (via `cargo run --example fetch_batch`) must give the same spectra.
2. Fit: colour-science's `find_coefficients_Jakob2019` optimises each colour directly (L-BFGS-B,
   no table, its own integration on 360–780 nm at 5 nm, stopping at ΔE76 < 1e-4); spectra's table spectrum should be
   close to it. Differences come from interpolation in the table and the two fits' different
   integration grids and Lab whites.

Usage (from the repository root): python3 tools/rgb2spec_colour_science.py TABLE.coeff [N]
(needs scipy and colour-science: `pip install scipy colour-science`).
Reports the largest absolute spectral difference (reflectance units) over 360–780 nm at 5 nm.
"""
import subprocess
import sys
import warnings

import numpy as np

warnings.filterwarnings("ignore")
import colour  # noqa: E402
from colour.recovery.jakob2019 import (  # noqa: E402
    LUT3D_Jakob2019,
    find_coefficients_Jakob2019,
)


def sigmoid_spectrum(c, lam):
    x = (c[:, 0:1] * lam + c[:, 1:2]) * lam + c[:, 2:3]
    return 0.5 + x / (2.0 * np.sqrt(1.0 + x * x))


def main():
    path = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 1000
    rng = np.random.default_rng(2024)
    rgb = rng.random((n, 3))
    lam = np.arange(360.0, 780.0 + 1e-9, 5.0)[None, :]

    # Build first (quietly), then run the binary itself: `cargo run` would wait on the shared
    # target-directory lock for every other build in progress.
    subprocess.run(["cargo", "build", "-q", "--release", "-p", "color", "--example", "fetch_batch"], check=True)
    out = subprocess.run(
        ["target/release/examples/fetch_batch", path],
        input="\n".join(f"{r:.17g} {g:.17g} {b:.17g}" for r, g, b in rgb),
        capture_output=True, text=True, check=True,
    ).stdout
    ours = np.array([[float(v) for v in line.split()] for line in out.splitlines()])
    s_ours = sigmoid_spectrum(ours, lam)

    # colour-science, like rgb2spec, assumes the uniform chroma grid; spectra's default tables
    # carry another one after the payload (color::upsample::table::CHROMA_TAG).
    with open(path, "rb") as f:
        b = f.read()
    res = int.from_bytes(b[4:8], "little")
    if b[8 + 4 * res + 36 * res**3 :].startswith(b"\nspectra-chroma-nodes\n"):
        print("1. skipped: the table has spectra's non-uniform chroma grid, which colour-science cannot read")
        compare_fit(rgb, s_ours, lam, n)
        return
    lut = LUT3D_Jakob2019()
    lut.read(path)
    theirs = np.array([lut.RGB_to_coefficients(c) for c in rgb])
    s_lut = sigmoid_spectrum(theirs, lam)
    d1 = np.abs(s_ours - s_lut).max(axis=1)
    print(f"1. same table, colour-science LUT3D_Jakob2019 interpolation vs spectra fetch, {n} colours:")
    print(f"   largest spectral difference {d1.max():.3e} (mean {d1.mean():.3e}), "
          f"worst RGB {np.array2string(rgb[d1.argmax()], precision=4)}")
    compare_fit(rgb, s_ours, lam, n)


def compare_fit(rgb, s_ours, lam, n):
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    xyz = colour.RGB_to_XYZ(rgb, srgb, apply_cctf_decoding=False)
    d2 = np.zeros(n)
    de = np.zeros(n)
    for i in range(n):
        c, err = find_coefficients_Jakob2019(xyz[i], max_error=1e-4)
        de[i] = err
        d2[i] = np.abs(sigmoid_spectrum(np.array([c]), lam) - s_ours[i : i + 1]).max()
    k = d2.argmax()
    print(f"2. colour-science find_coefficients_Jakob2019 (direct fit) vs spectra's table, {n} colours:")
    print(f"   largest spectral difference {d2.max():.3e} (mean {d2.mean():.3e}, p99 {np.quantile(d2, 0.99):.3e}), "
          f"worst RGB {np.array2string(rgb[k], precision=4)}")
    print(f"   (colour-science's own fit residual ΔE76: mean {de.mean():.2e}, max {de.max():.2e})")


if __name__ == "__main__":
    main()
