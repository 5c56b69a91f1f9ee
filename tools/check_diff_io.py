#!/usr/bin/env python3
"""Checks our EXR and PNG reader/writer (crate `compare`) against OpenEXR and libpng, through
Mitsuba's Bitmap (which links both), using the `convert` example of the compare crate.

  1. EXR written by OpenEXR (PIZ compression, f32 and f16, HDR and negative values) is read
     by us and rewritten (ZIP): OpenEXR reads back bit-identical values.
  2. PNG written by us (8- and 16-bit) from linear f32 values: libpng reads exactly the codes
     round(sRGB_encode(clamp(v, 0, 1)) * max), with the encoding from colour-science.
  3. PNG written by libpng (8-bit RGB, 8-bit RGBA, 16-bit RGB) is read by us (sRGB-decoded)
     and written as f32 EXR: OpenEXR reads float32(colour-science's sRGB decoding of the codes),
     alpha dropped.
Exit status non-zero on any disagreement.
"""

import os
import subprocess
import sys
import tempfile
import warnings

import numpy as np

warnings.filterwarnings("ignore")
import colour  # noqa: E402

try:
    import mitsuba as mi
except ImportError:
    # The oracle is a test-only dependency; install it like `cargo xtask setup` installs colour.
    print("check_diff_io: mitsuba missing, installing it with pip (test oracle only)")
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "mitsuba"], check=True)
    import mitsuba as mi

mi.set_variant("scalar_rgb")
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FAILURES = []


def fail(msg):
    FAILURES.append(msg)
    print("FAIL:", msg)


def convert(src, dst, *flags):
    r = subprocess.run([BIN, src, dst, *flags], capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"convert {os.path.basename(src)} -> {os.path.basename(dst)}: {r.stderr.strip()}")
        return False
    return True


def read(path):
    return np.array(mi.Bitmap(path))


def compare(name, got, want, tol=0.0):
    if got.shape != want.shape:
        fail(f"{name}: shape {got.shape} != {want.shape}")
        return
    dev = np.nanmax(np.abs(got.astype(np.float64) - want.astype(np.float64)))
    print(f"{name}: {got.shape[1]}x{got.shape[0]}, max deviation {dev:.3g} (allowed {tol:g})")
    if dev > tol:
        fail(f"{name}: deviates by {dev}")


def main():
    global BIN
    if subprocess.run(["cargo", "build", "-q", "-p", "compare", "--example", "convert"], cwd=ROOT).returncode:
        sys.exit("cannot build the convert example")
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    BIN = os.path.join(target, "debug", "examples", "convert")
    rng = np.random.default_rng(7)
    hdr = rng.uniform(-0.25, 40.0, size=(23, 37, 3)).astype(np.float32)
    hdr[::3] = rng.uniform(0.0, 1.0, size=hdr[::3].shape)
    with tempfile.TemporaryDirectory() as tmp:
        p = lambda n: os.path.join(tmp, n)  # noqa: E731

        # 1. OpenEXR → us → OpenEXR.
        mi.Bitmap(hdr, mi.Bitmap.PixelFormat.RGB).write(p("ox32.exr"))
        if convert(p("ox32.exr"), p("us32.exr")):
            compare("OpenEXR f32 (PIZ) -> compare -> OpenEXR", read(p("us32.exr")), hdr)
        half = mi.Bitmap(hdr, mi.Bitmap.PixelFormat.RGB).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float16, False)
        half.write(p("ox16.exr"))
        want16 = np.array(half)
        if convert(p("ox16.exr"), p("us16.exr"), "--half"):
            got = read(p("us16.exr"))
            if got.dtype != np.float16:
                fail(f"--half wrote {got.dtype}, not float16")
            compare("OpenEXR f16 (PIZ) -> compare f16 -> OpenEXR", got, want16)

        # 2. us → libpng, codes.
        lin = (hdr / 40.0 * 1.3 - 0.1).astype(np.float32)  # values below 0 and above 1 on purpose
        mi.Bitmap(lin, mi.Bitmap.PixelFormat.RGB).write(p("lin.exr"))
        enc = colour.cctf_encoding(np.clip(lin.astype(np.float64), 0.0, 1.0), function="sRGB")
        for bits, flags in ((8, ()), (16, ("--png16",))):
            out = p(f"us{bits}.png")
            if convert(p("lin.exr"), out, *flags):
                got = read(out)
                if got.dtype != (np.uint8 if bits == 8 else np.uint16):
                    fail(f"{bits}-bit PNG read by libpng as {got.dtype}")
                compare(f"compare PNG{bits} -> libpng codes", got, np.round(enc * (2**bits - 1)))

        # 3. libpng → us (decode) → OpenEXR.
        cases = (
            ("RGB8", rng.integers(0, 256, (19, 29, 3)).astype(np.uint8), mi.Bitmap.PixelFormat.RGB, 255),
            ("RGBA8", rng.integers(0, 256, (19, 29, 4)).astype(np.uint8), mi.Bitmap.PixelFormat.RGBA, 255),
            ("RGB16", rng.integers(0, 65536, (19, 29, 3)).astype(np.uint16), mi.Bitmap.PixelFormat.RGB, 65535),
        )
        for name, codes, fmt, top in cases:
            bmp = mi.Bitmap(codes, fmt)
            bmp.set_srgb_gamma(True)
            src = p(f"lib_{name}.png")
            bmp.write(src)
            if convert(src, p(f"lib_{name}.exr")):
                want = colour.cctf_decoding(codes[..., :3].astype(np.float64) / top, function="sRGB").astype(np.float32)
                compare(f"libpng {name} -> compare (decode) -> OpenEXR", read(p(f"lib_{name}.exr")), want)

    if FAILURES:
        print(f"check_diff_io: {len(FAILURES)} failure(s)")
        sys.exit(1)
    print("check_diff_io: EXR and PNG agree with OpenEXR and libpng")


if __name__ == "__main__":
    main()
