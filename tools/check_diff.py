#!/usr/bin/env python3
"""Oracle check for `spectra diff`: every pixel's CIEDE2000 and MAE against colour-science.

Builds image pairs without any image library (an uncompressed OpenEXR written by hand with
`struct`, 8- and 16-bit PNGs written with `zlib`), so this also checks our readers against an
independent writer. Runs `spectra diff --json --per-pixel-out`, then recomputes each pixel with
colour-science 0.4.x:

    linear sRGB --(RGB_to_XYZ, sRGB matrix derived from the primaries and D65 xy)--> XYZ
    XYZ / Y_white --(XYZ_to_Lab, D65 xy (0.3127, 0.3290))--> Lab
    colour.delta_E(Lab_ref, Lab_test, method="CIE 2000")

and requires agreement to 1e-4 ΔE00 per pixel, 1e-9 on per-pixel MAE, and the JSON statistics
(mean, nearest-rank median/p95/p99, max) to match numpy on the same per-pixel values. Also
checks the heat map is a PNG and that bad input fails with a clear message.
Exit status non-zero on any disagreement; prints the maximum deviations.
"""

import json
import os
import struct
import subprocess
import sys
import tempfile
import warnings
import zlib

import numpy as np

warnings.filterwarnings("ignore")
import colour  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOL_DE = 1e-4
TOL_MAE = 1e-9
FAILURES = []


def fail(msg):
    FAILURES.append(msg)
    print("FAIL:", msg)


# ---------------------------------------------------------------- writers (no image libraries)


def write_exr_f32(path, rgb):
    """Single-part scan-line OpenEXR, uncompressed, FLOAT channels B, G, R."""
    h, w, _ = rgb.shape

    def attr(name, typ, data):
        return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(data)) + data

    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (
        struct.pack("<ii", 20000630, 2)
        + attr("channels", "chlist", chlist)
        + attr("compression", "compression", b"\0")
        + attr("dataWindow", "box2i", box)
        + attr("displayWindow", "box2i", box)
        + attr("lineOrder", "lineOrder", b"\0")
        + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
        + attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
        + attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
        + b"\0"
    )
    blocks = []
    for y in range(h):
        row = rgb[y].astype("<f4")
        data = row[:, 2].tobytes() + row[:, 1].tobytes() + row[:, 0].tobytes()
        blocks.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(header) + 8 * h
    table = b""
    for b in blocks:
        table += struct.pack("<Q", offset)
        offset += len(b)
    with open(path, "wb") as f:
        f.write(header + table + b"".join(blocks))


def write_png(path, codes, bits):
    """RGB PNG of integer codes (h, w, 3) at 8 or 16 bits, filter 0 on every row."""
    h, w, _ = codes.shape
    dtype = ">u2" if bits == 16 else "u1"
    raw = b"".join(b"\0" + codes[y].astype(dtype).tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, bits, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


# ---------------------------------------------------------------- test images


def make_pair(rng, w, h, lo, hi):
    """Reference: random colours in the left half, a smooth gradient in the right half.
    Test: the reference with perturbations from invisible to large, and some pixels equal."""
    ref = rng.uniform(lo, hi, size=(h, w, 3))
    yy, xx = np.mgrid[0:h, 0:w]
    grad = np.stack([xx / (w - 1), yy / (h - 1), 0.5 + 0.5 * np.sin(xx / 3.0)], axis=-1) * (hi - max(lo, 0)) + max(lo, 0)
    ref[:, w // 2 :] = grad[:, w // 2 :]
    scale = np.exp(rng.uniform(np.log(1e-4), np.log(0.5), size=(h, w, 1)))
    test = ref + rng.normal(size=(h, w, 3)) * scale
    same = rng.uniform(size=(h, w)) < 0.1
    test[same] = ref[same]
    return np.clip(ref, lo, hi), np.clip(test, lo, hi)


def srgb_decode_codes(codes, bits):
    v = codes.astype(np.float64) / (2**bits - 1)
    # Rust decodes in f64 and stores f32; mirror that so the inputs are bit-identical.
    return colour.cctf_decoding(v, function="sRGB").astype(np.float32).astype(np.float64)


# ---------------------------------------------------------------- oracle


def oracle(ref, test, white_y):
    cs = colour.RGB_COLOURSPACES["sRGB"].copy()
    cs.use_derived_transformation_matrices(True)
    d65 = np.array([0.3127, 0.3290])

    def lab(rgb):
        xyz = colour.RGB_to_XYZ(rgb.reshape(-1, 3), cs, apply_cctf_decoding=False)
        return colour.XYZ_to_Lab(xyz / white_y, d65)

    de = colour.delta_E(lab(ref), lab(test), method="CIE 2000")
    a, b = ref.reshape(-1, 3), test.reshape(-1, 3)
    lin = np.abs(a - b).mean(axis=1)
    enc = lambda v: colour.cctf_encoding(np.clip(v, 0.0, 1.0), function="sRGB")  # noqa: E731
    disp = np.abs(enc(a) - enc(b)).mean(axis=1)
    return de, lin, disp


def nearest_rank(v, p):
    s = np.sort(v)
    k = int(np.ceil(p * len(s)))
    return s[min(max(k, 1), len(s)) - 1]


def spectra(*args):
    return subprocess.run([BIN, *args], capture_output=True, text=True)


def check_pair(name, ref_path, test_path, ref, test, white_y, tmp):
    csv = os.path.join(tmp, name + ".csv")
    heat = os.path.join(tmp, name + "_heat.png")
    r = spectra("diff", ref_path, test_path, "--json", "--per-pixel-out", csv, "--heatmap", heat, "--white-y", str(white_y))
    if r.returncode != 0:
        fail(f"{name}: spectra diff exited {r.returncode}: {r.stderr.strip()}")
        return
    out = json.loads(r.stdout)
    h, w, _ = ref.shape
    if (out["width"], out["height"]) != (w, h):
        fail(f"{name}: size {out['width']}x{out['height']} != {w}x{h}")
    rows = np.loadtxt(csv, delimiter=",", skiprows=1)
    if rows.shape != (w * h, 5):
        fail(f"{name}: per-pixel CSV has shape {rows.shape}, expected ({w * h}, 5)")
        return
    xs, ys = rows[:, 0].astype(int), rows[:, 1].astype(int)
    if not (np.array_equal(xs, np.tile(np.arange(w), h)) and np.array_equal(ys, np.repeat(np.arange(h), w))):
        fail(f"{name}: per-pixel CSV is not in row-major order")
    de, lin, disp = oracle(ref, test, white_y)
    dev_de = np.abs(rows[:, 2] - de)
    dev_lin = np.abs(rows[:, 3] - lin)
    dev_disp = np.abs(rows[:, 4] - disp)
    i = int(np.argmax(dev_de))
    print(
        f"{name}: {w}x{h}, white Y={white_y}, dE00 range {de.min():.4g}..{de.max():.4g}; max |dE00 - colour| = "
        f"{dev_de.max():.3e} (pixel {i % w},{i // w}), max |MAE lin dev| = {dev_lin.max():.3e}, "
        f"max |MAE sRGB dev| = {dev_disp.max():.3e}"
    )
    if dev_de.max() > TOL_DE:
        fail(f"{name}: dE00 differs from colour-science by {dev_de.max():.3e} at pixel ({i % w},{i // w})")
    if dev_lin.max() > TOL_MAE or dev_disp.max() > TOL_MAE:
        fail(f"{name}: per-pixel MAE differs by {max(dev_lin.max(), dev_disp.max()):.3e}")
    for key, vals in (("delta_e2000", de), ("mae_linear", lin), ("mae_srgb", disp)):
        st = out[key]
        want = {
            "mean": vals.mean(),
            "median": nearest_rank(vals, 0.5),
            "p95": nearest_rank(vals, 0.95),
            "p99": nearest_rank(vals, 0.99),
            "max": vals.max(),
        }
        tol = TOL_DE if key == "delta_e2000" else TOL_MAE
        for k, v in want.items():
            if abs(st[k] - v) > tol:
                fail(f"{name}: {key}.{k} = {st[k]} but colour-science/numpy gives {v}")
    with open(heat, "rb") as f:
        head = f.read(24)
    hw, hh = struct.unpack(">II", head[16:24]) if len(head) == 24 else (0, 0)
    if head[:8] != b"\x89PNG\r\n\x1a\n" or hw <= w or hh < h:
        fail(f"{name}: heat map is not a PNG larger than the image ({hw}x{hh})")
    if out["heatmap"]["max_delta_e"] < de.max() - TOL_DE:
        fail(f"{name}: auto heat-map maximum {out['heatmap']['max_delta_e']} below the largest dE00 {de.max()}")


def check_errors(tmp, a_path, small_path):
    r = spectra("diff", a_path, small_path)
    if r.returncode == 0 or "48×32" not in r.stderr or "20×10" not in r.stderr:
        fail(f"size mismatch not reported with both sizes: rc={r.returncode} {r.stderr.strip()!r}")
    bad = os.path.join(tmp, "image.tga")
    open(bad, "wb").close()
    r = spectra("diff", bad, a_path)
    if r.returncode == 0 or "image.tga" not in r.stderr or "unsupported" not in r.stderr:
        fail(f"unsupported extension not reported: {r.stderr.strip()!r}")
    junk = os.path.join(tmp, "junk.exr")
    with open(junk, "wb") as f:
        f.write(b"not an exr at all")
    r = spectra("diff", a_path, junk)
    if r.returncode == 0 or "junk.exr" not in r.stderr:
        fail(f"invalid EXR not reported: {r.stderr.strip()!r}")
    print("error cases: size mismatch, unsupported extension, invalid file -> clear errors")


def main():
    global BIN
    build = subprocess.run(["cargo", "build", "-q", "-p", "spectra"], cwd=ROOT)
    if build.returncode != 0:
        sys.exit("cannot build spectra")
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    BIN = os.path.join(target, "debug", "spectra")
    rng = np.random.default_rng(20240607)
    with tempfile.TemporaryDirectory() as tmp:
        # EXR: HDR and slightly negative values, float32 exact; white luminance 1.5.
        ref, test = make_pair(rng, 48, 32, -0.02, 1.6)
        ref, test = ref.astype(np.float32), test.astype(np.float32)
        a, b = os.path.join(tmp, "ref.exr"), os.path.join(tmp, "test.exr")
        write_exr_f32(a, ref)
        write_exr_f32(b, test)
        check_pair("exr-f32", a, b, ref.astype(np.float64), test.astype(np.float64), 1.5, tmp)
        # PNG, 16 and 8 bits: sRGB-encoded codes, decoded to linear by the reader.
        for bits, (w, h) in ((16, (40, 24)), (8, (33, 17))):
            ref, test = make_pair(rng, w, h, 0.0, 1.0)
            top = 2**bits - 1
            codes = [np.round(colour.cctf_encoding(x, function="sRGB") * top).astype(np.int64) for x in (ref, test)]
            pa, pb = os.path.join(tmp, f"ref{bits}.png"), os.path.join(tmp, f"test{bits}.png")
            write_png(pa, codes[0], bits)
            write_png(pb, codes[1], bits)
            check_pair(f"png{bits}", pa, pb, srgb_decode_codes(codes[0], bits), srgb_decode_codes(codes[1], bits), 1.0, tmp)
        small = os.path.join(tmp, "small.exr")
        write_exr_f32(small, np.zeros((10, 20, 3), np.float32))
        check_errors(tmp, a, small)
    if FAILURES:
        print(f"check_diff: {len(FAILURES)} failure(s)")
        sys.exit(1)
    print("check_diff: all pixels agree with colour-science")


if __name__ == "__main__":
    main()
