#!/usr/bin/env python3
"""Agreement and speed of `spectra truth` against Mitsuba 3 (`scalar_spectral`).

For each scene (see mitsuba_gltf.py): write the glTF, let `spectra truth --export-mitsuba`
export exactly what our loader produced (world-space PLY meshes, 1 nm spectra, camera, lights),
build the Mitsuba scene from that export, render both at the same size and spp, and report
  - mean / median / 99th-percentile CIEDE2000 between the two images (each the average of two
    independent runs, 2·spp samples per pixel), per pixel and on k×k block means (where Monte
    Carlo noise is k times smaller, so what remains is disagreement, not noise);
  - the noise floor: the same statistics between our two runs (different seeds), which is what
    ΔE between two unbiased renderers looks like at this sample count;
  - samples (paths) per second of each, and the noise each reaches at equal spp (relative RMS
    difference of luminance between its two runs, /√2), hence the efficiency ratio.

Both sides use a Lambertian BRDF (`spectra truth --lambert`, Mitsuba `diffuse`): Mitsuba has
no glTF metallic-roughness BRDF; ours is tested separately (furnace and quadrature tests in
crates/truth). Both integrate 360–830 nm with the CIE 1931 observer and return XYZ.

Lab uses the D65 white at Y = 1 (the scenes are exposed so that diffuse white is at most ~1).

Usage: python3 tools/mitsuba_compare.py [--spp 256] [--size 256] [--spectra target/release/spectra]
"""

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mitsuba_gltf  # noqa: E402

import mitsuba as mi  # noqa: E402

mi.set_variant("scalar_spectral")
import colour  # noqa: E402

# Mitsuba's spectral film divides ∫ȳ·L by ∫ȳ over 360–830 nm; `spectra truth` divides by
# k_white = ∫ȳ·W over its range. So a radiance L in our units is L·∫ȳ/k_white in Mitsuba's.
_CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
_W = _CMFS.wavelengths
Y_INTEGRAL = float(_CMFS.values[(_W >= 360) & (_W <= 830), 1].sum())


def spectrum(s, scale=1.0):
    return {"type": "spectrum", "value": [(float(l), float(v) * scale) for l, v in zip(s["wavelengths"], s["values"])]}


def mitsuba_scene(export_dir, spp, seed_offset=0):
    doc = json.load(open(os.path.join(export_dir, "scene.json")))
    if doc["unsupported"]:
        raise SystemExit(f"{export_dir}: export left out {doc['unsupported']}; the comparison would not be like for like")
    k = Y_INTEGRAL / doc["k_white"]
    cam = doc["camera"]
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1},
        "sensor": {
            "type": "perspective",
            "fov": cam["fov_y_deg"],
            "fov_axis": "y",
            # The glTF near plane: surfaces in front of it are clipped, as in spectra (exports
            # before issue 28 have none: Mitsuba's default, 0.01, is the glTF importer's).
            # Mitsuba refuses 0 (glTF allows it for orthographic cameras, not exported).
            "near_clip": max(cam.get("near_clip", 0.01), 1e-6),
            # And the far plane (exports before session 35 have none: Mitsuba's default).
            "far_clip": cam.get("far_clip", 1e4),
            "to_world": mi.ScalarTransform4f().look_at(origin=cam["origin"], target=cam["target"], up=cam["up"]),
            "film": {
                "type": "hdrfilm",
                "width": doc["width"],
                "height": doc["height"],
                "pixel_format": "xyz",
                "rfilter": {"type": "box"},
            },
            # Mitsuba's best general-purpose sampler (ours stratifies the hero wavelength only),
            # so the noise comparison is not against its plain independent sampler.
            "sampler": {"type": "multijitter", "sample_count": spp, "seed": seed_offset},
        },
    }
    for i, m in enumerate(doc["meshes"]):
        mat = doc["materials"][m["material"]]
        r = mat["reflectance"]
        if "spectrum" in r:
            refl = spectrum(r["spectrum"])
        elif "rgb" in r:
            refl = {"type": "rgb", "value": r["rgb"]}
        else:
            refl = {
                "type": "bitmap",
                "filename": os.path.join(export_dir, r["texture"]),
                "filter_type": "bilinear",
                "wrap_mode": "repeat",
            }
        shape = {
            "type": "ply",
            "filename": os.path.join(export_dir, m["ply"]),
            "face_normals": False,
            "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": refl}},
        }
        if mat["emission"]:
            shape["emitter"] = {"type": "area", "radiance": spectrum(mat["emission"], k)}
        scene[f"mesh_{i}"] = shape
    for i, l in enumerate(doc["lights"]):
        if l["type"] == "point":
            scene[f"light_{i}"] = {"type": "point", "position": l["position"], "intensity": spectrum(l["intensity"], k)}
        elif l["type"] == "directional":
            scene[f"light_{i}"] = {"type": "directional", "direction": l["direction"], "irradiance": spectrum(l["irradiance"], k)}
    return mi.load_dict(scene)


def run_truth(exe, gltf, out, spp, size, seed):
    cmd = [exe, "truth", gltf, "--spp", str(spp), "--size", f"{size}x{size}", "--range", "360:830",
           "--lambert", "--xyz", "--seed", str(seed), "--out", out]
    res = subprocess.run(cmd, check=True, stderr=subprocess.PIPE, text=True)
    # The render time it reports excludes loading, like the Mitsuba timing below.
    secs = float(re.search(r"; ([0-9.]+) s \(", res.stderr).group(1))
    return secs, np.array(mi.Bitmap(out), dtype=np.float64)[..., :3]


def run_mitsuba(export_dir, spp, seed):
    scene = mitsuba_scene(export_dir, spp, seed)
    t = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=seed)
    secs = time.perf_counter() - t
    return secs, np.array(img, dtype=np.float64)[..., :3]


def delta_e(xyz_a, xyz_b):
    white = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    lab_a = colour.XYZ_to_Lab(xyz_a, white)
    lab_b = colour.XYZ_to_Lab(xyz_b, white)
    return colour.delta_E(lab_a, lab_b, method="CIE 2000")


def stats(de):
    return f"mean {de.mean():.3f}, median {np.median(de):.3f}, p99 {np.percentile(de, 99):.3f}"


def blocks(img, k):
    """k×k box-averaged image: Monte Carlo noise drops by k, bias stays."""
    h, w = img.shape[0] // k * k, img.shape[1] // k * k
    return img[:h, :w].reshape(h // k, k, w // k, k, -1).mean(axis=(1, 3))


def noise(a, b):
    """Relative RMS luminance difference between two independent runs, /√2: one run's noise."""
    y_a, y_b = a[..., 1], b[..., 1]
    return math.sqrt(np.mean((y_a - y_b) ** 2)) / math.sqrt(2) / max(np.mean(0.5 * (y_a + y_b)), 1e-12)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap.add_argument("--spectra", default=os.path.join(root, "target", "release", "spectra"))
    ap.add_argument("--work", default="/tmp/spectra-mitsuba")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--scenes", default=",".join(mitsuba_gltf.SCENES))
    ap.add_argument("--block", type=int, default=16, help="block size for the bias-only ΔE")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    paths = a.size * a.size * a.spp
    for name in a.scenes.split(","):
        gltf = os.path.join(a.work, f"{name}.gltf")
        mitsuba_gltf.SCENES[name](gltf)
        export = os.path.join(a.work, f"{name}_mitsuba")
        shutil.rmtree(export, ignore_errors=True)
        subprocess.run([a.spectra, "truth", gltf, "--range", "360:830", "--size", f"{a.size}x{a.size}",
                        "--export-mitsuba", export], check=True)
        ours = [run_truth(a.spectra, gltf, os.path.join(a.work, f"{name}_truth_{s}.exr"), a.spp, a.size, s) for s in (1, 2)]
        theirs = [run_mitsuba(export, a.spp, s) for s in (1, 2)]
        o = 0.5 * (ours[0][1] + ours[1][1])
        m = 0.5 * (theirs[0][1] + theirs[1][1])
        mi.Bitmap(m.astype(np.float32)).write(os.path.join(a.work, f"{name}_mitsuba.exr"))
        de = delta_e(o, m)
        floor = delta_e(ours[0][1], ours[1][1])
        t_o = min(t for t, _ in ours)
        t_m = min(t for t, _ in theirs)
        n_o, n_m = noise(ours[0][1], ours[1][1]), noise(theirs[0][1], theirs[1][1])
        # Efficiency = 1 / (time × variance); the ratio says how much faster we reach equal noise.
        eff = (t_m * n_m**2) / (t_o * n_o**2)
        ratio_y = o[..., 1].mean() / m[..., 1].mean()
        print(f"== {name}: {a.size}×{a.size}, {a.spp} spp per run, 2 runs each")
        print(f"  ΔE2000 truth vs Mitsuba (2×{a.spp} spp each): {stats(de)}")
        print(f"  ΔE2000 noise floor, truth run 1 vs run 2 ({a.spp} spp each): {stats(floor)}")
        k = a.block
        print(f"  ΔE2000 on {k}×{k} block means, truth vs Mitsuba: {stats(delta_e(blocks(o, k), blocks(m, k)))}")
        print(f"  ΔE2000 on {k}×{k} block means, noise floor: {stats(delta_e(blocks(ours[0][1], k), blocks(ours[1][1], k)))}")
        lit = m[..., 1] < 2.0  # leave out light sources seen directly (edge pixels dominate the mean's noise)
        print(f"  mean Y: truth {o[..., 1].mean():.5f}, Mitsuba {m[..., 1].mean():.5f} (ratio {ratio_y:.4f}); "
              f"without emitters {o[..., 1][lit].mean():.5f} vs {m[..., 1][lit].mean():.5f} "
              f"(ratio {o[..., 1][lit].mean() / m[..., 1][lit].mean():.4f})")
        print(f"  truth:   {t_o:6.1f} s, {paths / t_o / 1e6:.3f} Mpaths/s, noise (rel. RMS Y) {n_o:.4f}")
        print(f"  Mitsuba: {t_m:6.1f} s, {paths / t_m / 1e6:.3f} Mpaths/s, noise (rel. RMS Y) {n_m:.4f}")
        print(f"  speed ratio truth/Mitsuba {t_m / t_o:.2f}×, efficiency ratio (equal noise) {eff:.2f}×")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
