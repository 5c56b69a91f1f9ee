#!/usr/bin/env python3
"""A second, independent pose evaluator straight from the glTF 2.0 specification (numpy only),
used to cross-check the three.js oracle: same arguments and JSON as pose.mjs.

    python3 tools/pose_oracle/test/gltf_ref.py FILE.gltf [--animation NAME|INDEX] [--time T]

Covers node TRS / matrix, animation of translation / rotation / scale / weights with STEP,
LINEAR (slerp, shortest path, for rotations) and CUBICSPLINE (normalised for rotations),
holding the first / last key outside the keys; morph targets (POSITION deltas; a target
without POSITION moves nothing); skins with JOINTS_n / WEIGHTS_n sets as given, NOT
renormalised, the skinned mesh node's own transform ignored; sparse and normalised accessors;
TRIANGLES, TRIANGLE_STRIP and TRIANGLE_FAN. Not: extensions, .glb, cameras' projection.
"""
import argparse
import base64
import json
import math
import os
import sys
import urllib.parse

import numpy as np

DT = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
NC = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
NORM = {5120: 127.0, 5121: 255.0, 5122: 32767.0, 5123: 65535.0}


def load(path):
    d = json.load(open(path))
    base = os.path.dirname(path)
    bufs = []
    for b in d.get("buffers", []):
        uri = b["uri"]
        if uri.startswith("data:"):
            bufs.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            bufs.append(open(os.path.join(base, urllib.parse.unquote(uri)), "rb").read())
    return d, bufs


def read_view(d, bufs, view, offset, dtype, ncomp, count, elem_bytes):
    bv = d["bufferViews"][view]
    buf = bufs[bv["buffer"]]
    start = bv.get("byteOffset", 0) + offset
    stride = bv.get("byteStride") or elem_bytes
    out = np.empty((count, ncomp), dtype=dtype)
    for i in range(count):
        out[i] = np.frombuffer(buf, dtype=dtype, count=ncomp, offset=start + i * stride)
    return out


def accessor(d, bufs, i):
    a = d["accessors"][i]
    ct, n, count = a["componentType"], NC[a["type"]], a["count"]
    dt = np.dtype(DT[ct]).newbyteorder("<")
    if a["type"] == "MAT3" and dt.itemsize < 4 or a["type"] == "MAT2" and dt.itemsize == 1:
        raise NotImplementedError("padded matrix accessors")
    if "bufferView" in a:
        x = read_view(d, bufs, a["bufferView"], a.get("byteOffset", 0), dt, n, count, dt.itemsize * n)
    else:
        x = np.zeros((count, n), dtype=dt)
    x = x.astype(np.float64) if ct == 5126 or a.get("normalized") else x.astype(np.int64)
    if a.get("normalized") and ct in NORM:
        x = np.maximum(x / NORM[ct], -1.0)
    sp = a.get("sparse")
    if sp:
        ii = sp["indices"]
        idt = np.dtype(DT[ii["componentType"]]).newbyteorder("<")
        idx = read_view(d, bufs, ii["bufferView"], ii.get("byteOffset", 0), idt, 1, sp["count"], idt.itemsize)[:, 0]
        vv = sp["values"]
        val = read_view(d, bufs, vv["bufferView"], vv.get("byteOffset", 0), dt, n, sp["count"], dt.itemsize * n)
        val = val.astype(np.float64) if ct == 5126 or a.get("normalized") else val.astype(np.int64)
        if a.get("normalized") and ct in NORM:
            val = np.maximum(val / NORM[ct], -1.0)
        x = x.copy()
        x[idx.astype(np.int64)] = val
    return x


def quat_mat(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def trs(t, r, s):
    m = np.eye(4)
    m[:3, :3] = quat_mat(r) * np.asarray(s)[None, :]
    m[:3, 3] = t
    return m


def slerp(a, b, u):
    dot = float(np.dot(a, b))
    if dot < 0:
        b, dot = -b, -dot
    if dot > 1 - 1e-12:
        r = a + u * (b - a)
        return r / np.linalg.norm(r)
    th = math.acos(min(1.0, dot))
    return (math.sin((1 - u) * th) * a + math.sin(u * th) * b) / math.sin(th)


def sample(times, values, interp, t, is_rot):
    """values: (keys, n) for STEP/LINEAR; (keys, 3, n) for CUBICSPLINE (in, value, out)."""
    k = len(times)
    if interp == "CUBICSPLINE":
        vals = values[:, 1]
    else:
        vals = values
    if t <= times[0] or k == 1:
        return vals[0].copy()
    if t >= times[-1]:
        return vals[-1].copy()
    i = int(np.searchsorted(times, t, side="right")) - 1
    t0, t1 = times[i], times[i + 1]
    u = (t - t0) / (t1 - t0)
    if interp == "STEP":
        return vals[i].copy()
    if interp == "CUBICSPLINE":
        td = t1 - t0
        p0, m0 = values[i, 1], values[i, 2] * td
        p1, m1 = values[i + 1, 1], values[i + 1, 0] * td
        u2, u3 = u * u, u * u * u
        r = (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1
        return r / np.linalg.norm(r) if is_rot else r
    if is_rot:
        return slerp(vals[i], vals[i + 1], u)
    return vals[i] + u * (vals[i + 1] - vals[i])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("file")
    ap.add_argument("--animation")
    ap.add_argument("--time", type=float)
    ap.add_argument("--normalize-rotations", action="store_true",
                    help="normalise node rotations and rotation keys (else slerp non-unit keys as given)")
    a = ap.parse_args()
    d, bufs = load(a.file)
    nodes = d.get("nodes", [])
    T = [np.array(n.get("translation", [0, 0, 0]), float) for n in nodes]
    R = [np.array(n.get("rotation", [0, 0, 0, 1]), float) for n in nodes]
    S = [np.array(n.get("scale", [1, 1, 1]), float) for n in nodes]
    W = {}
    for i, n in enumerate(nodes):
        if "mesh" in n:
            m = d["meshes"][n["mesh"]]
            ntg = len(m["primitives"][0].get("targets", []))
            W[i] = np.array(n.get("weights", m.get("weights", [0.0] * ntg)), float)
    if a.normalize_rotations:
        R = [r / np.linalg.norm(r) for r in R]
    animated = set()
    if a.animation is not None:
        anims = d.get("animations", [])
        ai = int(a.animation) if a.animation.isdigit() else [x.get("name") for x in anims].index(a.animation)
        an = anims[ai]
        t = a.time or 0.0
        for ch in an["channels"]:
            tg = ch["target"]
            if "node" not in tg:
                continue
            s = an["samplers"][ch["sampler"]]
            interp = s.get("interpolation", "LINEAR")
            times = accessor(d, bufs, s["input"])[:, 0]
            out = accessor(d, bufs, s["output"])
            k = len(times)
            out = out.reshape(k, 3, -1) if interp == "CUBICSPLINE" else out.reshape(k, -1)
            if a.normalize_rotations and tg["path"] == "rotation" and interp != "CUBICSPLINE":
                out = out / np.linalg.norm(out, axis=1, keepdims=True)
            v = sample(times, out, interp, t, tg["path"] == "rotation")
            nid = tg["node"]
            animated.add(nid)
            if tg["path"] == "translation":
                T[nid] = v
            elif tg["path"] == "rotation":
                R[nid] = v
            elif tg["path"] == "scale":
                S[nid] = v
            elif tg["path"] == "weights":
                W[nid] = v
    world = [None] * len(nodes)
    order = []

    def walk(i, parent):
        n = nodes[i]
        local = np.array(n["matrix"], float).reshape(4, 4).T if "matrix" in n and i not in animated else trs(T[i], R[i], S[i])
        world[i] = parent @ local
        order.append(i)
        for c in n.get("children", []):
            walk(c, world[i])

    scene = d.get("scenes", [{}])[d.get("scene", 0)]
    for r in scene.get("nodes", []):
        walk(r, np.eye(4))

    result = {"meshes": [], "camera": None}
    for i in order:
        n = nodes[i]
        if "camera" in n and result["camera"] is None:
            m = world[i]
            f = m[:3, :3] @ [0, 0, -1]
            u = m[:3, :3] @ [0, 1, 0]
            result["camera"] = {"node": i, "camera": n["camera"], "position": m[:3, 3].tolist(),
                                "forward": (f / np.linalg.norm(f)).tolist(), "up": (u / np.linalg.norm(u)).tolist()}
        if "mesh" not in n:
            continue
        mesh = d["meshes"][n["mesh"]]
        for pi, p in enumerate(mesh["primitives"]):
            mode = p.get("mode", 4)
            if mode not in (4, 5, 6):
                continue
            at = p["attributes"]
            pos = accessor(d, bufs, at["POSITION"])[:, :3].astype(float)
            w = W.get(i, [])
            for ti, tgt in enumerate(p.get("targets", [])):
                if ti < len(w) and w[ti] != 0 and "POSITION" in tgt:
                    pos = pos + w[ti] * accessor(d, bufs, tgt["POSITION"])
            hom = np.c_[pos, np.ones(len(pos))]
            if "skin" in n and "JOINTS_0" in at:
                skin = d["skins"][n["skin"]]
                nj = len(skin["joints"])
                ibm = (accessor(d, bufs, skin["inverseBindMatrices"]).reshape(nj, 4, 4).transpose(0, 2, 1)
                       if "inverseBindMatrices" in skin else np.tile(np.eye(4), (nj, 1, 1)))
                jm = np.array([world[j] @ ibm[k] for k, j in enumerate(skin["joints"])])
                out = np.zeros_like(hom)
                s = 0
                while f"JOINTS_{s}" in at:
                    J = accessor(d, bufs, at[f"JOINTS_{s}"]).astype(np.int64)
                    Wt = accessor(d, bufs, at[f"WEIGHTS_{s}"]).astype(float)
                    for c in range(4):
                        out += Wt[:, c:c + 1] * np.einsum("vij,vj->vi", jm[J[:, c]], hom)
                    s += 1
                wp = out[:, :3]
            else:
                wp = (hom @ world[i].T)[:, :3]
            if "indices" in p:
                idx = accessor(d, bufs, p["indices"])[:, 0]
            else:
                idx = np.arange(len(pos))
            if mode == 4:
                tris = idx[: len(idx) // 3 * 3].reshape(-1, 3)
            elif mode == 5:
                tris = np.array([[idx[k], idx[k + 1], idx[k + 2]] for k in range(len(idx) - 2)]).reshape(-1, 3)
            else:
                tris = np.array([[idx[0], idx[k + 1], idx[k + 2]] for k in range(len(idx) - 2)]).reshape(-1, 3)
            if len(tris) == 0:
                continue
            result["meshes"].append({"node": i, "mesh": n["mesh"], "primitive": pi,
                                     "triangles": wp[tris].tolist()})
    json.dump(result, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
