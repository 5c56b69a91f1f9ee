#!/usr/bin/env python3
"""FLIP test data from NVIDIA's reference implementation (the `flip-evaluator` PyPI package, the
C++ FLIP through nanobind), read by crates/compare/tests/flip_reference.rs:
- LDR: crates/compare/tests/data/flip_{reference,test}.rgb8 (raw 8-bit sRGB, 64×48, row-major
  RGB) and flip_expected.json (LDR-FLIP at the default 67 pixels per degree: the mean and the
  whole error map, no magma);
- HDR: flip_hdr_{reference,test}.f32 (raw little-endian float32 linear RGB, 64×48, values up to
  about 12) and flip_hdr_expected.json (HDR-FLIP with the reference's defaults: ACES, exposures
  from the reference image; the exposures it chose, the mean and the map).

The FLIP repository's own example pair (images/reference.png, test.png; published LDR mean
0.159691) is not used: the example images are 4 MB, too large for the test data.

With --large SPECTRA (the path of a built `spectra` binary), it also compares `spectra diff
--metric flip` with the reference on a 1280×720 pair it writes to a temporary directory (EXR
for HDR-FLIP, 8-bit PNG for LDR-FLIP), means to 1e-6, and prints both times.

Run: python3 tools/check_flip.py (what `cargo xtask test` does) checks that a fresh run of the
reference implementation reproduces the checked-in expectations (mean to 1e-6, map to 1e-6);
with --write it regenerates them.
"""

import json
import os
import subprocess
import sys
from importlib import metadata

import numpy as np

try:
    import flip_evaluator as flip
except ImportError:
    print("check_flip: flip-evaluator missing, installing it with pip (test oracle only)")
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "flip-evaluator==1.7"], check=True)
    import flip_evaluator as flip

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "crates", "compare", "tests", "data")
W, H = 64, 48


def images():
    """A render-like reference (gradients, an edge, texture) and a test with noise, a colour
    shift in one region and a blurred edge: errors of the kinds FLIP weighs differently."""
    rng = np.random.default_rng(2020)
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    ref = np.stack([x / W, y / H, 0.5 + 0.4 * np.sin(x / 5.0) * np.cos(y / 7.0)], axis=-1)
    ref[:, 30:34] = [0.9, 0.9, 0.85]
    test = ref.copy()
    test += rng.normal(0, 0.03, test.shape)
    test[5:20, 40:60] *= [1.0, 0.8, 1.1]
    test[:, 29:35] = 0.5 * (test[:, 28:34] + test[:, 30:36])
    to8 = lambda a: np.round(np.clip(a, 0, 1) * 255).astype(np.uint8)
    return to8(ref), to8(test)


def hdr_images():
    """Linear HDR pair: a dim background, a bright light-like blob well above 1, and a test with
    noise that grows with the signal (Monte-Carlo-like), a hue shift and a dimmed highlight."""
    rng = np.random.default_rng(2021)
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    ref = np.stack([0.05 + 0.3 * x / W, 0.04 + 0.2 * y / H, 0.1 + 0.05 * np.sin(x / 4.0) ** 2], axis=-1)
    blob = 12.0 * np.exp(-((x - 20) ** 2 + (y - 24) ** 2) / 30.0)
    ref += blob[..., None] * np.array([1.0, 0.9, 0.7])
    ref[:, 44:48] = [2.0, 1.6, 1.2]
    test = ref * (1.0 + rng.normal(0, 0.08, ref.shape))
    test[30:44, 4:30] *= [1.0, 0.85, 1.15]
    test[:, 44:48] *= 0.7
    return ref.astype(np.float32), np.clip(test, 0, None).astype(np.float32)


def evaluate_hdr(ref, test):
    err, mean, params = flip.evaluate(ref, test, "HDR", applyMagma=False)
    return np.asarray(err, np.float64).reshape(H, W), float(mean), params


def evaluate(ref8, test8):
    err, mean, _ = flip.evaluate(ref8.astype(np.float32) / 255.0, test8.astype(np.float32) / 255.0, "LDR", applyMagma=False)
    return np.asarray(err, np.float64).reshape(H, W), float(mean)


def large(spectra):
    """1280×720: a render-sized pair through the whole command line, files and all."""
    import tempfile
    import time
    import OpenEXR
    from PIL import Image

    h, w = 720, 1280
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    ref = np.stack([0.2 + 0.6 * x / w, 0.1 + 0.5 * y / h, 0.3 + 0.2 * np.sin(x / 13) * np.cos(y / 17)], -1).astype(np.float32)
    ref += (6 * np.exp(-((x - 400) ** 2 + (y - 300) ** 2) / 2000.0))[..., None] * np.array([1, 0.9, 0.8], np.float32)
    test = np.clip(ref * (1 + rng.normal(0, 0.05, ref.shape)), 0, None).astype(np.float32)

    def srgb8(a):
        a = np.clip(a, 0, 1)
        return np.round(np.where(a <= 0.0031308, 12.92 * a, 1.055 * a ** (1 / 2.4) - 0.055) * 255).astype(np.uint8)

    ok = True
    with tempfile.TemporaryDirectory() as d:
        p = lambda n: os.path.join(d, n)
        for n, a in (("r", ref), ("t", test)):
            with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}, {"RGB": a}) as f:
                f.write(p(n + ".exr"))
            Image.fromarray(srgb8(a)).save(p(n + ".png"))
        for kind, ext in (("HDR", "exr"), ("LDR", "png")):
            t0 = time.time()
            _, want, _ = flip.evaluate(p("r." + ext), p("t." + ext), kind, applyMagma=False)
            t1 = time.time()
            out = subprocess.run([spectra, "diff", p("r." + ext), p("t." + ext), "--metric", "flip", "--json"],
                                 check=True, capture_output=True, text=True).stdout
            t2 = time.time()
            got = json.loads(out)["flip"]["mean"]
            good = abs(got - want) <= 1e-6
            ok &= good
            print(f"check_flip: 1280×720 {kind}-FLIP mean: spectra {got:.6f} ({t2 - t1:.1f} s with ΔE2000), "
                  f"reference {want:.6f} ({t1 - t0:.1f} s): {'ok' if good else 'FAIL'}")
    return ok


def main():
    if "--large" in sys.argv:
        return 0 if large(sys.argv[sys.argv.index("--large") + 1]) else 1
    ref8, test8 = images()
    err, mean = evaluate(ref8, test8)
    href, htest = hdr_images()
    herr, hmean, hparams = evaluate_hdr(href, htest)
    version = f"flip-evaluator {metadata.version('flip-evaluator')}"
    if "--write" in sys.argv:
        os.makedirs(DATA, exist_ok=True)
        ref8.tofile(os.path.join(DATA, "flip_reference.rgb8"))
        test8.tofile(os.path.join(DATA, "flip_test.rgb8"))
        with open(os.path.join(DATA, "flip_expected.json"), "w") as f:
            # float32 values printed as the shortest float64 repr: exact.
            json.dump({"width": W, "height": H, "ppd": 67.0, "implementation": version,
                       "mean": mean, "map": err.ravel().tolist()}, f)
            f.write("\n")
        href.tofile(os.path.join(DATA, "flip_hdr_reference.f32"))
        htest.tofile(os.path.join(DATA, "flip_hdr_test.f32"))
        with open(os.path.join(DATA, "flip_hdr_expected.json"), "w") as f:
            json.dump({"width": W, "height": H, "implementation": version, "tonemapper": hparams["tonemapper"],
                       "start_exposure": hparams["startExposure"], "stop_exposure": hparams["stopExposure"],
                       "num_exposures": hparams["numExposures"], "mean": hmean, "map": herr.ravel().tolist()}, f)
            f.write("\n")
        print(f"check_flip: wrote test data ({version}), LDR-FLIP mean {mean:.6f}, HDR-FLIP mean {hmean:.6f} "
              f"(exposures {hparams['startExposure']:.4f} to {hparams['stopExposure']:.4f}, {hparams['numExposures']})")
        return 0
    exp = json.load(open(os.path.join(DATA, "flip_expected.json")))
    same_inputs = np.array_equal(np.fromfile(os.path.join(DATA, "flip_reference.rgb8"), np.uint8), ref8.ravel()) and np.array_equal(
        np.fromfile(os.path.join(DATA, "flip_test.rgb8"), np.uint8), test8.ravel())
    ok = same_inputs and abs(exp["mean"] - mean) <= 1e-6 and np.max(np.abs(np.array(exp["map"]) - err.ravel())) <= 1e-6
    print(f"check_flip: LDR-FLIP of the reference implementation {mean:.6f}, checked-in {exp['mean']:.6f}: {'ok' if ok else 'FAIL'}")
    hexp = json.load(open(os.path.join(DATA, "flip_hdr_expected.json")))
    hsame = np.array_equal(np.fromfile(os.path.join(DATA, "flip_hdr_reference.f32"), np.float32), href.ravel()) and np.array_equal(
        np.fromfile(os.path.join(DATA, "flip_hdr_test.f32"), np.float32), htest.ravel())
    hok = hsame and abs(hexp["mean"] - hmean) <= 1e-6 and np.max(np.abs(np.array(hexp["map"]) - herr.ravel())) <= 1e-6
    print(f"check_flip: HDR-FLIP of the reference implementation {hmean:.6f}, checked-in {hexp['mean']:.6f}: {'ok' if hok else 'FAIL'}")
    return 0 if ok and hok else 1


if __name__ == "__main__":
    sys.exit(main())
