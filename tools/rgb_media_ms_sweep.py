#!/usr/bin/env python3
"""Multiple scattering in the real-time RGB medium against the path tracer (issue 18).

A white Lambertian wall 2 m in front of the camera, a point light 0.1 m beside the camera, a
grey homogeneous medium filling the scene (docs/rgb-media.md, "Multiple scattering"). For each
optical depth τ of the view (σ_t = τ / 2 m), single-scattering albedo α and HG g, it renders
`spectra render --rgb-medium` (real time, spectral N = 16) and `spectra truth --rgb-medium`
(full multiple scattering) and prints, per case, the image means' luminance ratio real time /
truth and their ΔE2000 (colour-science, CIE 1931, D65 white, the linear-sRGB means).

Truth images are cached in --work (they do not depend on the real-time code), keyed by
medium, size, spp and seed.

    tools/rgb_media_ms_sweep.py --bin target/release/spectra --spp 4096 [--json out.json]
    tools/rgb_media_ms_sweep.py --spp 4096 --rt-args=--single-scattering   # the model without the term
"""
import argparse
import base64
import json
import os
import struct
import subprocess
import sys

import numpy as np


def wall_gltf(path):
    s, z = 5.0, -2.0
    pos = [(-s, -s, z), (s, -s, z), (s, s, z), (-s, s, z)]
    nrm = [(0.0, 0.0, 1.0)] * 4
    idx = [0, 1, 2, 0, 2, 3]
    blob = b"".join(struct.pack("<3f", *p) for p in pos) + b"".join(struct.pack("<3f", *n) for n in nrm)
    blob += struct.pack("<6H", *idx)
    g = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"name": "lamp", "type": "point", "color": [1, 1, 1], "intensity": 10.0}]}},
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 12}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [-s, -s, z], "max": [s, s, z]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "materials": [{"name": "white", "pbrMetallicRoughness": {
            "baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.15, "aspectRatio": 1.0,
                                                             "znear": 0.01, "zfar": 100.0}}],
        "nodes": [{"mesh": 0}, {"camera": 0},
                  {"translation": [0.1, 0.0, 0.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "scenes": [{"nodes": [0, 1, 2]}],
        "scene": 0,
    }
    with open(path, "w") as f:
        json.dump(g, f)


def mean_rgb(path):
    import OpenEXR
    import Imath
    f = OpenEXR.InputFile(path)
    dw = f.header()["dataWindow"]
    n = (dw.max.x - dw.min.x + 1) * (dw.max.y - dw.min.y + 1)
    pt = Imath.PixelType(Imath.PixelType.FLOAT)
    return np.array([np.frombuffer(f.channel(c, pt), dtype=np.float32)[:n].astype(np.float64).mean()
                     for c in "RGB"])


def de2000(a, b):
    import colour
    m = colour.models.RGB_COLOURSPACE_sRGB
    lab = [colour.XYZ_to_Lab(colour.RGB_to_XYZ(c, m, apply_cctf_decoding=False), m.whitepoint) for c in (a, b)]
    return float(colour.delta_E(lab[0], lab[1], method="CIE 2000"))


def luminance(c):
    return float(np.dot([0.2126, 0.7152, 0.0722], c))


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default="target/release/spectra")
    ap.add_argument("--truth-bin", default=None, help="binary for the truth (default --bin)")
    ap.add_argument("--work", default="/tmp/rgb-media-ms-sweep")
    ap.add_argument("--size", default="8x8")
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--taus", default="0.1,0.3,1,3,10")
    ap.add_argument("--albedos", default="0.3,0.7,0.95")
    ap.add_argument("--gs", default="0,0.5,0.9")
    ap.add_argument("--truth-only", action="store_true")
    ap.add_argument("--rt-args", default="", help="extra args for spectra render")
    ap.add_argument("--json", default=None)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    gltf = os.path.join(a.work, "wall.gltf")
    wall_gltf(gltf)
    tbin = a.truth_bin or a.bin
    rows = []
    print(f"{'tau':>5} {'albedo':>6} {'g':>4} | {'lum ratio':>9} {'dE2000':>7} | truth RGB")
    for g in [float(x) for x in a.gs.split(",")]:
        for alb in [float(x) for x in a.albedos.split(",")]:
            for tau in [float(x) for x in a.taus.split(",")]:
                st = tau / 2.0
                m = json.dumps({"absorption": [st * (1 - alb)] * 3, "scattering": [st * alb] * 3, "g": g,
                                "upsampling": "unbounded"})
                key = f"t{tau}-a{alb}-g{g}-{a.size}-{a.spp}"
                truth = os.path.join(a.work, f"truth-{key}.exr")
                if not os.path.exists(truth):
                    tmp = truth + ".part.exr"
                    run([tbin, "truth", gltf, "--size", a.size, "--lambert", "--spp", str(a.spp),
                         "--rgb-medium", m, "--out", tmp])
                    os.replace(tmp, truth)
                tr = mean_rgb(truth)
                if a.truth_only:
                    print(f"{tau:5g} {alb:6g} {g:4g} | truth {tr}", flush=True)
                    continue
                rt = os.path.join(a.work, "rt.exr")
                run([a.bin, "render", gltf, "--size", a.size, "--lambert", "--no-shadows", "--wavelengths", "16",
                     "--rgb-medium", m, "--out", rt] + a.rt_args.split())
                r = mean_rgb(rt)
                ratio, de = luminance(r) / luminance(tr), de2000(r, tr)
                rows.append({"tau": tau, "albedo": alb, "g": g, "rt": r.tolist(), "truth": tr.tolist(),
                             "lum_ratio": ratio, "de2000": de})
                print(f"{tau:5g} {alb:6g} {g:4g} | {ratio:9.3f} {de:7.2f} | {np.round(tr, 4)}", flush=True)
    if rows:
        de = [r["de2000"] for r in rows]
        lr = [abs(r["lum_ratio"] - 1) for r in rows]
        print(f"mean dE2000 {np.mean(de):.2f}, max {np.max(de):.2f}; mean |lum ratio - 1| {np.mean(lr):.3f}, "
              f"max {np.max(lr):.3f}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
