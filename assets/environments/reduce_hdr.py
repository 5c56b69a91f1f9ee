#!/usr/bin/env python3
"""Reduce an equirectangular Radiance .hdr by an integer box filter, keeping linear radiance.

Used once to make the files in this folder from Poly Haven's 1k (1024x512) HDRIs:

    python3 reduce_hdr.py in_1k.hdr out.hdr --factor 2      # 1024x512 -> 512x256

Each output texel is the plain mean of the factor x factor input texels it covers (a box filter
in linear radiance, so the integral of the map over the sphere is kept). The output is written as
new-style run-length encoded RGBE with a minimal header. Needs numpy; nothing else.
"""

import argparse
import sys

import numpy as np


def read_hdr(path):
    with open(path, "rb") as f:
        data = f.read()
    if not (data.startswith(b"#?RADIANCE") or data.startswith(b"#?RGBE")):
        raise ValueError(f"{path}: not a Radiance .hdr (no #?RADIANCE / #?RGBE magic)")
    pos = 0
    fmt = None
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end]
        pos = end + 1
        if line.startswith(b"FORMAT="):
            fmt = line[7:].strip()
        if line == b"":
            break
    if fmt not in (None, b"32-bit_rle_rgbe"):
        raise ValueError(f"{path}: unsupported format {fmt!r}")
    end = data.index(b"\n", pos)
    res = data[pos:end].split()
    pos = end + 1
    if len(res) != 4 or res[0] != b"-Y" or res[2] != b"+X":
        raise ValueError(f"{path}: unsupported orientation {res!r}")
    h, w = int(res[1]), int(res[3])
    out = np.zeros((h, w, 4), dtype=np.uint8)
    buf = np.frombuffer(data, dtype=np.uint8)
    for y in range(h):
        if w >= 8 and w < 32768 and buf[pos] == 2 and buf[pos + 1] == 2 and (buf[pos + 2] & 0x80) == 0:
            sw = (int(buf[pos + 2]) << 8) | int(buf[pos + 3])
            if sw != w:
                raise ValueError(f"{path}: scanline width mismatch")
            pos += 4
            for c in range(4):
                x = 0
                while x < w:
                    n = int(buf[pos])
                    pos += 1
                    if n > 128:
                        n -= 128
                        out[y, x : x + n, c] = buf[pos]
                        pos += 1
                    else:
                        out[y, x : x + n, c] = buf[pos : pos + n]
                        pos += n
                    x += n
        else:  # flat (or old-style without repeats)
            out[y] = buf[pos : pos + 4 * w].reshape(w, 4)
            pos += 4 * w
    rgbe = out.astype(np.float64)
    scale = np.where(out[..., 3] > 0, np.ldexp(1.0, out[..., 3].astype(np.int32) - 136), 0.0)
    return rgbe[..., :3] * scale[..., None]


def to_rgbe(img):
    m = img.max(axis=2)
    mant, ex = np.frexp(m)
    rgbe = np.zeros(img.shape[:2] + (4,), dtype=np.uint8)
    ok = m > 1e-32
    sc = np.where(ok, mant * 256.0 / np.where(ok, m, 1.0), 0.0)
    # round to nearest (readers such as stb_image and the image crate decode c * 2^(e-136), no +0.5)
    rgbe[..., :3] = np.clip(np.rint(img * sc[..., None]), 0, 255).astype(np.uint8)
    rgbe[..., 3] = np.where(ok, ex + 128, 0).astype(np.uint8)
    return rgbe


def rle_channel(row):
    out = bytearray()
    n = len(row)
    i = 0
    while i < n:
        # run length at i
        j = i + 1
        while j < n and j - i < 127 and row[j] == row[i]:
            j += 1
        if j - i >= 4:
            out += bytes((128 + j - i, row[i]))
            i = j
            continue
        # literal until a run of >= 4 starts (max 128)
        k = i
        while k < n and k - i < 128:
            r = k + 1
            while r < n and r - k < 4 and row[r] == row[k]:
                r += 1
            if r - k >= 4:
                break
            k += 1
        out += bytes((k - i,)) + bytes(row[i:k])
        i = k
    return out


def write_hdr(path, img):
    h, w, _ = img.shape
    rgbe = to_rgbe(img)
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(f"-Y {h} +X {w}\n".encode())
        for y in range(h):
            f.write(bytes((2, 2, w >> 8, w & 255)))
            for c in range(4):
                f.write(rle_channel(rgbe[y, :, c].tolist()))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("src")
    ap.add_argument("dst")
    ap.add_argument("--factor", type=int, default=2)
    a = ap.parse_args()
    img = read_hdr(a.src)
    h, w, _ = img.shape
    f = a.factor
    if h % f or w % f:
        sys.exit(f"{a.src}: {w}x{h} is not divisible by {f}")
    small = img.reshape(h // f, f, w // f, f, 3).mean(axis=(1, 3))
    write_hdr(a.dst, small)
    back = read_hdr(a.dst)
    rel = abs(back.mean() - small.mean()) / max(small.mean(), 1e-12)
    print(f"{a.src}: {w}x{h} -> {w // f}x{h // f}, mean {img.mean():.4f} -> {back.mean():.4f} "
          f"(rgbe rounding {rel:.2e}), max {img.max():.1f} -> {back.max():.1f}")


if __name__ == "__main__":
    main()
