#!/usr/bin/env python3
"""Prints docs/cameras.md's table: every camera spectra ships, with its source, licence, data
range and how colorimetric it is — the RMS residual (CIE XYZ, white Y = 1) of its least-squares
3×3 fit to CIE 1931 XYZ over the 24 ColorChecker patches under D65, the matrix
`--camera-to-display` applies (color::Observer::fit_to_xyz, recomputed here with numpy from
`spectra.chart`).

    pip install ./python && python3 tools/camera_table.py > /tmp/cameras-table.md
"""
import json
import subprocess
import sys

import numpy as np

import spectra


def fit_rms(name, ill="D65"):
    rgb = spectra.chart(name, ill, balanced=True)
    xyz = spectra.chart("cie1931", ill)
    # The perfect white's Y: a patch's response over its balanced response.
    white_y = (xyz / spectra.chart("cie1931", ill, balanced=True))[0, 1]
    xyz = xyz / white_y
    m, *_ = np.linalg.lstsq(rgb, xyz, rcond=None)
    return float(np.sqrt(np.mean(np.sum((rgb @ m - xyz) ** 2, axis=1))))


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else "spectra"
    rows = json.loads(subprocess.run([binary, "observers", "--json"], check=True, capture_output=True).stdout)
    print("| name | data (nm) | ColorChecker fit RMS (D65) | source |")
    print("|---|---|---:|---|")
    for r in rows:
        if r["kind"] != "camera RGB":
            continue
        print(f"| `{r['name']}` | {r['from_nm']:.0f}–{r['to_nm']:.0f} | {fit_rms(r['name']):.4f} | {r['source']} |")


if __name__ == "__main__":
    main()
