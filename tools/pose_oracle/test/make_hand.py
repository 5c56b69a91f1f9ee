#!/usr/bin/env python3
"""Writes skin_morph_triangle.gltf: the hand-computable case of README.md ("Hand check").

One triangle v0 = (0,0,0), v1 = (2,0,0), v2 = (1,1,0); v0 bound to joint 0, v1 to joint 1,
v2 half to each; one morph target moving v2 by (0,0,1), mesh weight 0.5 at rest. Joint 0 at
the origin, joint 1 its child at (1,0,0); inverse bind matrices I and T(-1,0,0). Animation 0
("bend"): joint 1's rotation LINEAR from identity at t=0 to 90 deg about +Z at t=1, and the
morph weight LINEAR from 0 to 1 over the same keys. The skinned mesh's node is translated by
(100,0,0), which glTF says to ignore. A camera node at (0,0,5) turned 90 deg about +Y.
"""
import base64, json, math, os, struct

s = math.sqrt(0.5)
pos = [0, 0, 0, 2, 0, 0, 1, 1, 0]
joints = [0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0]
weights = [1, 0, 0, 0, 1, 0, 0, 0, 0.5, 0.5, 0, 0]
morph = [0, 0, 0, 0, 0, 0, 0, 0, 1]
ibm = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
       1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1]
times = [0, 1]
rots = [0, 0, 0, 1, 0, 0, s, s]
wts = [0, 1]

blob = b""
views = []

def add(data, target=None):
    global blob
    while len(blob) % 4:
        blob += b"\0"
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
    if target:
        views[-1]["target"] = target
    blob += data
    return len(views) - 1

f = lambda xs: struct.pack(f"<{len(xs)}f", *xs)
v_pos = add(f(pos), 34962)
v_j = add(struct.pack("<12B", *joints), 34962)
v_w = add(f(weights), 34962)
v_m = add(f(morph), 34962)
v_i = add(struct.pack("<3H", 0, 1, 2), 34963)
v_ibm = add(f(ibm))
v_t = add(f(times))
v_r = add(f(rots))
v_wt = add(f(wts))
while len(blob) % 4:
    blob += b"\0"

acc = [
    {"bufferView": v_pos, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [2, 1, 0]},
    {"bufferView": v_j, "componentType": 5121, "count": 3, "type": "VEC4"},
    {"bufferView": v_w, "componentType": 5126, "count": 3, "type": "VEC4"},
    {"bufferView": v_m, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 1]},
    {"bufferView": v_i, "componentType": 5123, "count": 3, "type": "SCALAR"},
    {"bufferView": v_ibm, "componentType": 5126, "count": 2, "type": "MAT4"},
    {"bufferView": v_t, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
    {"bufferView": v_r, "componentType": 5126, "count": 2, "type": "VEC4"},
    {"bufferView": v_wt, "componentType": 5126, "count": 2, "type": "SCALAR"},
]
gltf = {
    "asset": {"version": "2.0", "generator": "tools/pose_oracle/test/make_hand.py"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 3]}],
    "nodes": [
        {"name": "skinned", "mesh": 0, "skin": 0, "translation": [100, 0, 0]},
        {"name": "joint0", "children": [2]},
        {"name": "joint1", "translation": [1, 0, 0]},
        {"name": "eye", "camera": 0, "translation": [0, 0, 5], "rotation": [0, s, 0, s]},
    ],
    "meshes": [{"name": "tri", "weights": [0.5], "primitives": [{
        "attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2},
        "indices": 4, "targets": [{"POSITION": 3}]}]}],
    "skins": [{"joints": [1, 2], "inverseBindMatrices": 5, "skeleton": 1}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
    "animations": [{"name": "bend", "samplers": [
        {"input": 6, "output": 7, "interpolation": "LINEAR"},
        {"input": 6, "output": 8, "interpolation": "LINEAR"}],
        "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}},
                     {"sampler": 1, "target": {"node": 0, "path": "weights"}}]}],
    "accessors": acc,
    "bufferViews": views,
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
}
out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "skin_morph_triangle.gltf")
with open(out, "w") as fh:
    json.dump(gltf, fh, indent=1)
    fh.write("\n")
print(out)
