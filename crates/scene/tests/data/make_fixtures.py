#!/usr/bin/env python3
"""Writes the small glTF fixtures the scene crate's tests load (standard library only).

Run from anywhere: python3 crates/scene/tests/data/make_fixtures.py
Outputs, next to this script:
  textured.gltf   external buffer (quad.bin), external PNGs, one data-URI image, three lights,
                  a camera, spectral extras on materials, lights, root and scene
  quad.bin        its binary buffer
  base.png        4x4 sRGB base colour: two palette colours in checks
  normal.png      2x2 tangent-space normal map (flat +Z)
  textured.glb    the same document as one binary file, images in buffer views
"""
import base64, json, os, struct, zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def png(w, h, rgba_rows):
    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(row) for row in rgba_rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


RED, BLUE = [178, 47, 58], [44, 79, 160]
base_png = png(4, 4, [[c for x in range(4) for c in ((RED if (x + y) % 2 == 0 else BLUE) + [255])] for y in range(4)])
normal_png = png(2, 2, [[128, 128, 255, 255] * 2] * 2)
emissive_png = png(1, 1, [[255, 255, 255, 255]])

# Quad in the XY plane (normals, uvs, u16 indices), then a triangle with positions only.
quad_pos = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]
quad_nrm = [(0, 0, 1)] * 4
quad_uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
quad_idx = [0, 1, 2, 0, 2, 3]
tri_pos = [(0, 0, 0), (1, 0, 0), (0, 0, -1)]

buf = b""
views, accessors = [], []


def add(data, target=None):
    global buf
    while len(buf) % 4:
        buf += b"\x00"
    views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data), **({"target": target} if target else {})})
    buf += data
    return len(views) - 1


def acc(view, ctype, count, typ, mn=None, mx=None):
    a = {"bufferView": view, "componentType": ctype, "count": count, "type": typ}
    if mn is not None:
        a["min"], a["max"] = mn, mx
    accessors.append(a)
    return len(accessors) - 1


F32, U16 = 5126, 5123
flat = lambda vs: [c for v in vs for c in v]
a_pos = acc(add(struct.pack("<12f", *flat(quad_pos)), 34962), F32, 4, "VEC3", [-1, -1, 0], [1, 1, 0])
a_nrm = acc(add(struct.pack("<12f", *flat(quad_nrm)), 34962), F32, 4, "VEC3")
a_uv = acc(add(struct.pack("<8f", *flat(quad_uv)), 34962), F32, 4, "VEC2")
a_idx = acc(add(struct.pack("<6H", *quad_idx), 34963), U16, 6, "SCALAR")
a_tri = acc(add(struct.pack("<9f", *flat(tri_pos)), 34962), F32, 3, "VEC3", [0, 0, -1], [1, 0, 0])
geometry_len = len(buf)

doc = {
    "asset": {"version": "2.0", "generator": "spectra make_fixtures.py"},
    "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
    "extras": {"spectra": {"observer": "cie1931", "range": [380, 730], "wavelengths": 16, "white": "D65"}},
    "scene": 0,
    "scenes": [{"nodes": [0, 3, 4, 5, 6], "extras": {"water": {"type": "II", "depth": 10, "sun_direction": [0, 2, 0], "scale": 1}}}],
    "nodes": [
        # Parent moves +2 in x and turns 90° about +Y; the child quad is scaled ×2 in x.
        {"name": "parent", "translation": [2, 0, 0], "rotation": [0, 0.7071067811865476, 0, 0.7071067811865476], "children": [1, 2]},
        {"name": "quad", "mesh": 0, "scale": [2, 1, 1]},
        {"name": "triangle", "mesh": 1},
        {"name": "camera", "camera": 0, "translation": [0, 1, 5]},
        {"name": "point", "translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "spot", "translation": [1, 2, 0], "rotation": [-0.7071067811865476, 0, 0, 0.7071067811865476],
         "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"name": "sun", "extensions": {"KHR_lights_punctual": {"light": 2}}},
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.05, "zfar": 100, "aspectRatio": 1.5}}],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 0.9, 0.8], "intensity": 20, "extras": {"spectrum": "F11"}},
        {"type": "spot", "intensity": 15, "range": 10, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6},
         "extras": {"spectrum": {"blackbody": 3200}}},
        {"type": "directional", "intensity": 3,
         "extras": {"spectrum": {"sampled": {"wavelengths": [380, 550, 730], "values": [0.5, 1, 0.5]}}}},
    ]}},
    "meshes": [
        {"name": "quad", "primitives": [{"attributes": {"POSITION": a_pos, "NORMAL": a_nrm, "TEXCOORD_0": a_uv}, "indices": a_idx, "material": 0}]},
        {"name": "triangle", "primitives": [{"attributes": {"POSITION": a_tri}, "material": 1}]},
    ],
    "materials": [
        {"name": "textured",
         "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.25, "roughnessFactor": 0.5},
         "normalTexture": {"index": 1, "scale": 0.8},
         "emissiveFactor": [1, 0.5, 0.25], "emissiveTexture": {"index": 2},
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}},
         "extras": {"reflectance_palette": [
             {"rgb8": RED, "spectrum": {"colorchecker": "red"}},
             {"rgb8": BLUE, "spectrum": {"csv": "reflectance.csv"}}]}},
        {"name": "plain", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]},
         "emissiveFactor": [0.2, 0.2, 0.2],
         "extras": {"reflectance": {"colorchecker": 20}, "emission": "LED-B3"}},
    ],
    "textures": [{"source": 0}, {"source": 1}, {"source": 2}],
    "images": [{"uri": "base.png"}, {"uri": "normal.png"},
               {"uri": "data:image/png;base64," + base64.b64encode(emissive_png).decode()}],
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"uri": "quad.bin", "byteLength": geometry_len}],
}

with open(os.path.join(HERE, "quad.bin"), "wb") as f:
    f.write(buf)
for name, data in [("base.png", base_png), ("normal.png", normal_png)]:
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)
with open(os.path.join(HERE, "textured.gltf"), "w") as f:
    json.dump(doc, f, indent=1)
    f.write("\n")
with open(os.path.join(HERE, "reflectance.csv"), "w") as f:
    f.write("# a smooth bluish reflectance\nwavelength_nm,reflectance\n")
    for l in range(380, 781, 20):
        f.write(f"{l},{0.6 - 0.5 * (l - 380) / 400:.4f}\n")

# GLB: the images move into buffer views; the buffer is the BIN chunk.
for img, data in zip(doc["images"], [base_png, normal_png, emissive_png]):
    img.pop("uri")
    img["bufferView"] = add(data)
    img["mimeType"] = "image/png"
while len(buf) % 4:
    buf += b"\x00"
doc["buffers"] = [{"byteLength": len(buf)}]
js = json.dumps(doc).encode()
js += b" " * (-len(js) % 4)
glb = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(js) + 8 + len(buf))
glb += struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(buf), b"BIN\x00") + buf
with open(os.path.join(HERE, "textured.glb"), "wb") as f:
    f.write(glb)
print("wrote fixtures to", HERE)
