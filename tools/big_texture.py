#!/usr/bin/env python3
"""A glTF quad with one N×N sRGB base-colour texture, for measuring the memory and time a large
texture costs (docs/limits.md, "Large textures"). Python standard library only.

    tools/big_texture.py 8192 /tmp/big      # writes /tmp/big/quad.gltf and /tmp/big/big.png
    /usr/bin/time -f '%M KB' spectra render /tmp/big/quad.gltf --size 320x240 --out q.png

The texture is a smooth gradient (red steps along x, green along x, blue along y) compressed
with zlib level 1, so that writing it takes seconds, not minutes; the quad faces a camera at 3
units and a point light at 2.
"""

import base64
import json
import os
import struct
import sys
import zlib


def png(path, n):
    row = bytearray(1 + 3 * n)
    for x in range(n):
        row[1 + 3 * x] = ((x * 7) // n * 37) % 256
        row[2 + 3 * x] = (x * 255) // n
    c = zlib.compressobj(1)
    parts = []
    for y in range(n):
        row[3::3] = bytes([(y * 255) // n]) * n
        parts.append(c.compress(bytes(row)))
    parts.append(c.flush())

    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", b"".join(parts)))
        f.write(chunk(b"IEND", b""))


def main():
    if len(sys.argv) != 3 or not sys.argv[1].isdigit() or int(sys.argv[1]) < 1:
        sys.exit("usage: tools/big_texture.py N OUT_DIR")
    n, out = int(sys.argv[1]), sys.argv[2]
    os.makedirs(out, exist_ok=True)
    png(os.path.join(out, "big.png"), n)
    pos = struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0)
    nor = struct.pack("<12f", *([0, 0, 1] * 4))
    uv = struct.pack("<8f", 0, 1, 1, 1, 1, 0, 0, 0)
    idx = struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    buf = pos + nor + uv + idx
    views = [(0, 48), (48, 48), (96, 32), (128, 12)]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "translation": [0, 0, 3]},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [0, 0, 2]},
        ],
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 20}]}},
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "big.png"}],
        "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": l} for o, l in views],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
    }
    with open(os.path.join(out, "quad.gltf"), "w") as f:
        json.dump(doc, f)


if __name__ == "__main__":
    main()
