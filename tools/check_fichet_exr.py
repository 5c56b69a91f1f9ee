#!/usr/bin/env python3
"""Writes spectral EXRs in the layout of Fichet, Pacanowski & Wilkie 2021 ("An OpenEXR Layout for
Spectral Images", JCGT 10(3)) with the OpenEXR Python package, independently of spectra's own
writer, and integrates them with colour-science: the interoperability test data of
crates/compare/tests/fichet_independent.rs.

  crates/compare/tests/data/fichet_emissive.exr    channels S0.<λ>nm, 400–700 nm every 10 nm
  crates/compare/tests/data/fichet_reflective.exr  channels T.<λ>nm, same wavelengths
  crates/compare/tests/data/fichet_expected.json   XYZ per pixel from colour-science

The wavelengths are spelled with two decimals and a comma ("S0.400,00nm"), as the paper allows,
where spectra and pbrt-v4 write three. No band-edge attribute is written: a reader has to take
the bands from the wavelengths, as for pbrt-v4's files.

colour-science's integration (method "Integration", ASTM E308-style sum on the data's own
10 nm grid, observers aligned to it) gives, per pixel:
  emissive:   X = Σ x̄·L·Δλ / Σ ȳ·W·Δλ  (W = D65: a radiance equal to D65 has Y = 1), from two
              colour.sd_to_XYZ calls, L's and W's, both against a flat illuminant;
  reflective: colour.sd_to_XYZ(R, observer, D65) / 100.
for the CIE 1931 2° and CIE 1964 10° observers; and each observer's XYZ of the white on the
same grid (D65 normalised as above: the value a renderer's white has, which spectra's display
balances onto sRGB's white, colour.RGB_COLOURSPACES["sRGB"].whitepoint), under "white".

Run: python3 tools/check_fichet_exr.py (what `cargo xtask test` does) writes to a temporary
folder and fails if the files in the repository differ from what it would write (values to
1e-12, EXR samples exactly); with --write it regenerates the files in the repository.
"""

import json
import os
import sys
import tempfile

import numpy as np
import OpenEXR
import colour

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "crates", "compare", "tests", "data")
SHAPE = colour.SpectralShape(400, 700, 10)
W, H = 4, 3
OBSERVERS = {"cie1931": "CIE 1931 2 Degree Standard Observer", "cie1964": "CIE 1964 10 Degree Standard Observer"}


def spectra(kind):
    """Smooth, varied spectra per pixel, from a fixed seed."""
    rng = np.random.default_rng(17 if kind == "emissive" else 71)
    wl = SHAPE.wavelengths
    out = np.zeros((H, W, len(wl)), np.float32)
    for y in range(H):
        for x in range(W):
            a, b, c = rng.uniform(0.05, 0.9, 3)
            centre, width = rng.uniform(420, 680), rng.uniform(30, 120)
            s = a + b * np.exp(-(((wl - centre) / width) ** 2)) + 0.1 * c * np.sin(wl / 25.0)
            out[y, x] = (s * (3.0 if kind == "emissive" else 0.8)).clip(0.0, None)
    return out


def name(prefix, l):
    return f"{prefix}.{l:.2f}nm".replace(".", ",", 2).replace(",", ".", 1)


def write(path, prefix, data, emissive):
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage, "spectralLayoutVersion": "1.0"}
    if emissive:
        header["emissiveUnits"] = "W.m^-2.sr^-1"
    channels = {name(prefix, l): np.ascontiguousarray(data[:, :, i]) for i, l in enumerate(SHAPE.wavelengths)}
    with OpenEXR.File(header, channels) as f:
        f.write(path)


def integrate(data, emissive):
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(SHAPE)
    flat = colour.sd_ones(SHAPE)
    result = {}
    for key, cmfs_name in OBSERVERS.items():
        cmfs = colour.MSDS_CMFS[cmfs_name].copy().align(SHAPE)
        rows = []
        for y in range(H):
            for x in range(W):
                sd = colour.SpectralDistribution(dict(zip(SHAPE.wavelengths, data[y, x].astype(np.float64))))
                if emissive:
                    xyz = colour.sd_to_XYZ(sd, cmfs, flat, method="Integration")
                    yw = colour.sd_to_XYZ(d65, cmfs, flat, method="Integration")[1]
                    rows.append((xyz / yw).tolist())
                else:
                    rows.append((colour.sd_to_XYZ(sd, cmfs, d65, method="Integration") / 100.0).tolist())
        result[key] = rows
        white = colour.sd_to_XYZ(d65, cmfs, flat, method="Integration")
        result.setdefault("white", {})[key] = (white / white[1]).tolist()
    return result


def generate(folder):
    xy = colour.RGB_COLOURSPACES["sRGB"].whitepoint
    expected = {"width": W, "height": H, "white": "D65", "srgb_white": colour.xy_to_XYZ(xy).tolist()}
    for kind, prefix in (("emissive", "S0"), ("reflective", "T")):
        data = spectra(kind)
        write(os.path.join(folder, f"fichet_{kind}.exr"), prefix, data, kind == "emissive")
        expected[kind] = integrate(data, kind == "emissive")
    with open(os.path.join(folder, "fichet_expected.json"), "w") as f:
        json.dump(expected, f, indent=1)
        f.write("\n")


def read_channels(path):
    with OpenEXR.File(path) as f:
        return {k: np.array(v.pixels) for k, v in f.channels().items()}


def main():
    if "--write" in sys.argv:
        os.makedirs(DATA, exist_ok=True)
        generate(DATA)
        print(f"wrote {DATA}/fichet_{{emissive,reflective}}.exr and fichet_expected.json")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        generate(tmp)
        bad = []
        for kind in ("emissive", "reflective"):
            a, b = read_channels(os.path.join(tmp, f"fichet_{kind}.exr")), read_channels(os.path.join(DATA, f"fichet_{kind}.exr"))
            if a.keys() != b.keys() or any(not np.array_equal(a[k], b[k]) for k in a):
                bad.append(f"fichet_{kind}.exr")
        ea = json.load(open(os.path.join(tmp, "fichet_expected.json")))
        eb = json.load(open(os.path.join(DATA, "fichet_expected.json")))
        for kind in ("emissive", "reflective"):
            for obs in OBSERVERS:
                for got, want in ((ea[kind][obs], eb[kind][obs]), (ea[kind]["white"][obs], eb[kind]["white"][obs])):
                    if not np.allclose(got, want, rtol=0, atol=1e-12):
                        bad.append(f"fichet_expected.json {kind} {obs}")
        if not np.allclose(ea["srgb_white"], eb["srgb_white"], rtol=0, atol=1e-12):
            bad.append("fichet_expected.json srgb_white")
        if bad:
            print("fichet_independent: the checked-in data differ from a fresh run:", ", ".join(bad))
            return 1
        print("fichet_independent: checked-in data reproduce")
        return 0


if __name__ == "__main__":
    sys.exit(main())
