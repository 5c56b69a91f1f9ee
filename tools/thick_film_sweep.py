#!/usr/bin/env python3
"""The thin-film sweep of docs/realtime-gltf.md ("Thin films"): a black dielectric sphere with
a film (KHR_materials_iridescence) of index 2 and thickness d under a uniform white sky, drawn
by `spectra render` (spectral and rgb) and `spectra truth` (direct light), and each render's
ΔE2000 against the truth from `spectra diff`.

    python3 tools/thick_film_sweep.py [--spectra target/release/spectra] [--out DIR]
        [--thickness 300,1000,3000,10000] [--wavelengths 16]
"""
import argparse, base64, json, math, os, struct, subprocess, sys


def sphere(n=32, m=64):
    pos, idx = [], []
    for i in range(n + 1):
        th = math.pi * i / n
        for j in range(m + 1):
            ph = 2 * math.pi * j / m
            pos.append((math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph)))
    for i in range(n):
        for j in range(m):
            a = i * (m + 1) + j
            b = a + m + 1
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return pos, idx


def write_gltf(path, film_ior, thickness):
    pos, idx = sphere()
    p = b"".join(struct.pack("<3f", *v) for v in pos)
    i = b"".join(struct.pack("<I", k) for k in idx)
    blob = p + p + i  # positions, normals (the unit sphere's are its positions), indices
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_iridescence"],
        "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(p)},
                        {"buffer": 0, "byteOffset": len(p), "byteLength": len(p)},
                        {"buffer": 0, "byteOffset": 2 * len(p), "byteLength": len(i)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
                      {"bufferView": 1, "componentType": 5126, "count": len(pos), "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0, "roughnessFactor": 0},
                       "extensions": {"KHR_materials_iridescence": {"iridescenceFactor": 1, "iridescenceIor": film_ior,
                                                                    "iridescenceThicknessMinimum": thickness,
                                                                    "iridescenceThicknessMaximum": thickness}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.6, "znear": 0.1}}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 4]}],
        "scenes": [{"nodes": [0, 1]}],
        "scene": 0,
    }
    with open(path, "w") as f:
        json.dump(doc, f)


def write_white_hdr(path, w=64, h=32):
    # RGBE of 1.0: mantissa 128, exponent 129, flat (not run-length encoded) scanlines.
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
        f.write(bytes([128, 128, 128, 129]) * (w * h))


def mean_de(spectra, ref, test):
    out = subprocess.run([spectra, "diff", ref, test, "--json"], check=True, capture_output=True, text=True).stdout
    e = json.loads(out)["delta_e2000"]
    return e["mean"], e["p95"]


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    a.add_argument("--spectra", default="target/release/spectra")
    a.add_argument("--out", default="/tmp/thick-film-sweep")
    a.add_argument("--thickness", default="300,1000,3000,10000")
    a.add_argument("--wavelengths", default="16")
    args = a.parse_args()
    os.makedirs(args.out, exist_ok=True)
    sky = os.path.join(args.out, "white.hdr")
    write_white_hdr(sky)
    s = args.spectra
    print("thickness nm | spectral mean / p95 | rgb mean / p95 (ΔE2000 against the truth)")
    for d in [float(x) for x in args.thickness.split(",")]:
        g = os.path.join(args.out, f"film-{d:g}.gltf")
        write_gltf(g, 2.0, d)
        o = lambda n: os.path.join(args.out, f"{n}-{d:g}.exr")
        common = ["--env", sky, "--size", "96x72"]
        subprocess.run([s, "truth", g, *common, "--spp", "256", "--direct-only", "--out", o("truth")], check=True, capture_output=True)
        subprocess.run([s, "render", g, *common, "--wavelengths", args.wavelengths, "--out", o("spectral")], check=True, capture_output=True)
        subprocess.run([s, "render", g, *common, "--mode", "rgb", "--out", o("rgb")], check=True, capture_output=True)
        sp, rg = mean_de(s, o("truth"), o("spectral")), mean_de(s, o("truth"), o("rgb"))
        print(f"{d:12g} | {sp[0]:.2f} / {sp[1]:.2f} | {rg[0]:.2f} / {rg[1]:.2f}")


if __name__ == "__main__":
    sys.exit(main())
