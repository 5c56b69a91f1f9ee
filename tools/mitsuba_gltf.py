"""Writes the small glTF scenes `mitsuba_compare.py` renders with both `spectra truth` and
Mitsuba 3: a Cornell box lit by a spiky F11 fluorescent lamp (measured ColorChecker
reflectances), and a textured scene (sRGB textures upsampled by each renderer, a point light and
a directional light). Pure standard library: buffers and PNGs are embedded as data URIs.
"""

import base64
import json
import math
import struct
import zlib


class Gltf:
    """Accumulates meshes, materials, textures and lights into one self-contained .gltf."""

    def __init__(self):
        self.buf = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": "spectra tools/mitsuba_gltf.py"},
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [],
            "meshes": [],
            "materials": [],
            "accessors": [],
            "bufferViews": [],
            "buffers": [],
            "extensionsUsed": [],
        }

    def _view(self, data, target=None):
        while len(self.buf) % 4:
            self.buf.append(0)
        view = {"buffer": 0, "byteOffset": len(self.buf), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.buf += data
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, values, kind, comp):
        flat = [c for v in values for c in (v if isinstance(v, (list, tuple)) else [v])]
        fmt = "<%d%s" % (len(flat), "f" if comp == 5126 else "I")
        view = self._view(struct.pack(fmt, *flat), 34963 if comp == 5125 else 34962)
        acc = {"bufferView": view, "componentType": comp, "count": len(values), "type": kind}
        if kind == "VEC3" and comp == 5126:
            acc["min"] = [min(v[i] for v in values) for i in range(3)]
            acc["max"] = [max(v[i] for v in values) for i in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, name, base=(1, 1, 1), texture=None, extras=None, emissive=None, strength=None):
        m = {
            "name": name,
            "pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0},
        }
        if texture is not None:
            m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": texture}
        if extras:
            m["extras"] = extras
        if emissive:
            m["emissiveFactor"] = list(emissive)
        if strength:
            m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
            self._use("KHR_materials_emissive_strength")
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def _use(self, ext):
        if ext not in self.doc["extensionsUsed"]:
            self.doc["extensionsUsed"].append(ext)

    def texture(self, width, height, rgb8):
        """An sRGB texture from rows of (r, g, b) bytes, top row first, as an embedded PNG."""
        raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in rgb8)
        chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
        png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
        png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
        self.doc.setdefault("images", []).append({"uri": "data:image/png;base64," + base64.b64encode(png).decode()})
        self.doc.setdefault("samplers", []).append({"magFilter": 9729, "minFilter": 9729, "wrapS": 10497, "wrapT": 10497})
        n = len(self.doc["images"]) - 1
        self.doc.setdefault("textures", []).append({"source": n, "sampler": n})
        return len(self.doc["textures"]) - 1

    def mesh(self, positions, normals, uvs, indices, material):
        attrs = {"POSITION": self._accessor(positions, "VEC3", 5126), "NORMAL": self._accessor(normals, "VEC3", 5126)}
        if uvs:
            attrs["TEXCOORD_0"] = self._accessor(uvs, "VEC2", 5126)
        prim = {"attributes": attrs, "indices": self._accessor(indices, "SCALAR", 5125), "material": material}
        self.doc["meshes"].append({"primitives": [prim]})
        self._node({"mesh": len(self.doc["meshes"]) - 1})

    def _node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def camera(self, eye, yfov_deg, aspect):
        self.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": math.radians(yfov_deg), "znear": 0.01, "aspectRatio": aspect}}]
        self._node({"camera": 0, "translation": list(eye)})

    def light(self, kind, color, intensity, translation=None, rotation=None):
        self._use("KHR_lights_punctual")
        lights = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})["lights"]
        lights.append({"type": kind, "color": list(color), "intensity": intensity})
        node = {"extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}}
        if translation:
            node["translation"] = list(translation)
        if rotation:
            node["rotation"] = list(rotation)
        self._node(node)

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(self.buf)).decode()}]
        if not self.doc["extensionsUsed"]:
            del self.doc["extensionsUsed"]
        with open(path, "w") as f:
            json.dump(self.doc, f)


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    n = math.sqrt(sum(c * c for c in a))
    return [c / n for c in a]


def quad(g, corner, u, v, material, uv_scale=1.0):
    """The parallelogram corner + s·u + t·v; its front (CCW, normal) is u × v."""
    p = [corner, [corner[i] + u[i] for i in range(3)], [corner[i] + u[i] + v[i] for i in range(3)], [corner[i] + v[i] for i in range(3)]]
    n = norm(cross(u, v))
    uvs = [[0, uv_scale], [uv_scale, uv_scale], [uv_scale, 0], [0, 0]]
    g.mesh(p, [n] * 4, uvs, [0, 1, 2, 0, 2, 3], material)


def cuboid(g, centre_floor, size, angle_deg, material):
    """A box standing on y = 0 at centre_floor, rotated about +y, faces outwards."""
    c, s = math.cos(math.radians(angle_deg)), math.sin(math.radians(angle_deg))
    rot = lambda v: [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]
    hx, hy, hz = size[0] / 2, size[1], size[2] / 2
    at = lambda x, y, z: [centre_floor[0] + rot([x, y, z])[0], y, centre_floor[2] + rot([x, y, z])[2]]
    X, Y, Z = rot([2 * hx, 0, 0]), [0, hy, 0], rot([0, 0, 2 * hz])
    neg = lambda v: [-c_ for c_ in v]
    quad(g, at(-hx, 0, hz), X, Y, material)  # +z face
    quad(g, at(hx, 0, -hz), neg(X), Y, material)  # -z face
    quad(g, at(hx, 0, hz), neg(Z), Y, material)  # +x face
    quad(g, at(-hx, 0, -hz), Z, Y, material)  # -x face
    quad(g, at(-hx, hy, hz), X, neg(Z), material)  # top


def cornell_f11(path):
    """The Cornell box of `spectra`'s built-in, lit only by its lamp with an F11 spectrum."""
    g = Gltf()
    size, h = 0.555, 0.2775
    white = g.material("white", (0.8, 0.8, 0.8), extras={"reflectance": {"colorchecker": "white 9.5"}})
    red = g.material("red", (0.5, 0.05, 0.05), extras={"reflectance": {"colorchecker": "red"}})
    green = g.material("green", (0.1, 0.4, 0.1), extras={"reflectance": {"colorchecker": "green"}})
    lamp = g.material("lamp (F11)", (0.78, 0.78, 0.78), emissive=(1, 1, 1), strength=40.0, extras={"emission": "F11"})
    x0, x1, z0, z1 = -h, h, -h, h
    quad(g, [x0, 0, z1], [size, 0, 0], [0, 0, -size], white)  # floor
    quad(g, [x0, size, z0], [size, 0, 0], [0, 0, size], white)  # ceiling
    quad(g, [x0, 0, z0], [size, 0, 0], [0, size, 0], white)  # back
    quad(g, [x0, 0, z1], [0, 0, -size], [0, size, 0], red)  # left
    quad(g, [x1, 0, z0], [0, 0, size], [0, size, 0], green)  # right
    cuboid(g, [0.093, 0, 0.065], [0.165, 0.165, 0.165], -17, white)
    cuboid(g, [-0.095, 0, -0.075], [0.165, 0.33, 0.165], 17, white)
    lw, ld, y = 0.13, 0.105, size - 0.001
    quad(g, [-lw / 2, y, -ld / 2], [lw, 0, 0], [0, 0, ld], lamp)  # faces down
    g.camera([0, h, 1.08], 39.3, 1.0)
    g.write(path)


def textured(path):
    """sRGB-textured walls (saturated colours, where upsampling differences show) under a
    point light and a directional light."""
    g = Gltf()
    n = 8
    cells = []
    for j in range(n):
        row = []
        for i in range(n):
            hue = (i + n * j) / (n * n)
            k = lambda o: max(0.0, min(1.0, abs((hue * 6 + o) % 6 - 3) - 1))
            sat = 0.35 + 0.65 * (j % 3) / 2
            val = 0.35 + 0.65 * ((i + j) % 4) / 3
            row.append(tuple(int(round(255 * val * (1 - sat + sat * k(o)))) for o in (0, 4, 2)))
        cells.append(row)
    chart = g.texture(n, n, cells)
    check = g.texture(4, 4, [[(230, 220, 200) if (i + j) % 2 else (40, 70, 150) for i in range(4)] for j in range(4)])
    wall = g.material("chart", texture=chart)
    floor = g.material("checker floor", texture=check)
    grey = g.material("grey", (0.5, 0.45, 0.4))
    quad(g, [-1, 0, -1], [2, 0, 0], [0, 1.5, 0], wall)  # back wall, UV (0,0) top-left
    quad(g, [-1, 0, 1], [2, 0, 0], [0, 0, -2], floor, uv_scale=2.0)
    cuboid(g, [0.45, 0, 0.1], [0.3, 0.45, 0.3], 25, grey)
    g.light("point", (1.0, 0.9, 0.8), 1.2, translation=[-0.4, 1.2, 0.8])
    # Directional: glTF lights point down −z of their node; rotate so it shines down and back.
    a = math.radians(-60) / 2
    g.light("directional", (1, 1, 1), 1.5, rotation=[math.sin(a), 0, 0, math.cos(a)])
    g.camera([0, 0.7, 2.6], 45.0, 1.0)
    g.write(path)


SCENES = {"cornell_f11": cornell_f11, "textured": textured}
