#!/usr/bin/env python3
"""Oracle for the RGB-media attenuation round trip (docs/rgb-media.md), with colour-science:
ΔE2000 between the RGB target exp(−σ_rgb·d) and the colour of the box-upsampled spectral
transmittance exp(−σ_box(λ)·d) (blue below 490 nm, red from 585 nm), both as filters under D65,
CIE 1931 2°, 1 nm bins over 360–830 nm, for the ten named media of
`color::upsample::medium::study_media` at the 21 depths 0.1–10 mean free paths of
`study_depths(21)`. The box method needs no coefficient table, so this is independent of ours.

Writes/compares crates/color/tests/data/rgb_media_box.json, which the Rust test
`box_study_matches_colour_science` reads (`cargo test --release -p color --lib -- upsample::medium`).

Run: python3 tools/check_rgb_media.py (what `cargo xtask test` does) checks that a fresh
computation reproduces the checked-in file (to 1e-9); --write regenerates it.
"""

import json
import os
import sys

import numpy as np
import colour

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "crates", "color", "tests", "data", "rgb_media_box.json")

# The named media of study_media(0), before scaling to a mean free path of 1.
MEDIA = [
    ("grey fog", [1.0, 1.0, 1.0]),
    ("blue-white fog (σ rising to blue)", [0.8, 1.0, 1.2]),
    ("clear water (red absorbed)", [2.4, 0.45, 0.15]),
    ("green coastal water", [2.0, 0.5, 0.5]),
    ("brown smoke", [0.55, 0.9, 1.55]),
    ("red wine", [0.3, 2.4, 2.2]),
    ("milk-like (mild blue scattering)", [0.9, 1.0, 1.1]),
    ("cyan dye (red only)", [3.0, 0.0, 0.0]),
    ("magenta dye (green only)", [0.0, 3.0, 0.0]),
    ("yellow dye (blue only)", [0.0, 0.0, 3.0]),
]
DEPTHS = [0.1 * 100.0 ** (i / 20) for i in range(21)]


def compute():
    # spectra integrates at the midpoints of 1 nm bins over 360–830 nm
    # (color::SpectralIntegrator::reference), reading measured tables linearly and as zero
    # outside them; the same here, with colour-science's data, Lab and CIEDE2000.
    lam = np.arange(360, 830) + 0.5
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    cmf = np.stack([np.interp(lam, cmfs.wavelengths, cmfs.values[:, i]) for i in range(3)], axis=1)
    d65_sd = colour.SDS_ILLUMINANTS["D65"]
    d65 = np.interp(lam, d65_sd.wavelengths, d65_sd.values, left=0.0, right=0.0)
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    space_white = colour.xy_to_XYZ(srgb.whitepoint)
    # The matrix from the primaries and white (as color::RgbColorSpace derives it), not the
    # 4-digit one of IEC 61966-2-1, which maps RGB white 1e-4 off the white point.
    m = colour.normalised_primary_matrix(srgb.primaries, srgb.whitepoint)

    def xyz(values):
        return (values * d65) @ cmf

    grid_white = xyz(np.ones_like(lam))
    out = []
    for name, s in MEDIA:
        s = np.array(s) * 3.0 / sum(s)
        box = np.where(lam < 490, s[2], np.where(lam < 585, s[1], s[0]))
        errors = []
        for d in DEPTHS:
            target = np.exp(-s * d)
            lab_t = colour.XYZ_to_Lab(m @ target, colour.XYZ_to_xy(space_white))
            lab_s = colour.XYZ_to_Lab(xyz(np.exp(-box * d)) / grid_white[1], colour.XYZ_to_xy(grid_white))
            errors.append(float(colour.delta_E(lab_t, lab_s, method="CIE 2000")))
        out.append({"name": name, "sigma_rgb": s.tolist(), "delta_e": errors})
    return {"depths_mfp": DEPTHS, "media": out, "colour_science": colour.__version__}


def main():
    got = compute()
    if "--write" in sys.argv:
        with open(OUT, "w") as f:
            json.dump(got, f, indent=1)
            f.write("\n")
        print(f"check_rgb_media: wrote {OUT}")
        return
    with open(OUT) as f:
        want = json.load(f)
    a = np.array([m["delta_e"] for m in got["media"]])
    b = np.array([m["delta_e"] for m in want["media"]])
    if a.shape != b.shape or np.abs(a - b).max() > 1e-9:
        sys.exit(f"check_rgb_media: {OUT} is stale (max difference {np.abs(a - b).max() if a.shape == b.shape else 'shape'}); rerun with --write")
    print(f"check_rgb_media: ok ({a.size} ΔE2000 values, max {a.max():.3f})")


if __name__ == "__main__":
    main()
