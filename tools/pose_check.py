#!/usr/bin/env python3
"""Compare posed glTF triangle corners: the three.js oracle's JSON against ours.

    python3 tools/pose_check.py ORACLE.json OURS.json [--tol 1e-4] [--quiet]

Both files have the format written by tools/pose_oracle/pose.mjs (and by
`cargo run --release -p scene --example posed_positions`):

    {"meshes": [{"node": i, "mesh": m, "primitive": p,
                 "triangles": [[[x,y,z],[x,y,z],[x,y,z]], ...]}, ...],
     "camera": {"position": [x,y,z], "forward": [x,y,z], ...} | null}

Meshes without triangles are ignored on both sides. Meshes are matched by
(node, mesh, primitive) when every mesh on both sides gives all three, else by order.
Triangles are matched by order, each compared as an unordered triple of corners (a
loader may swap two corners when a transform mirrors). Distances are relative to the
diagonal of the oracle's bounding box over all corners. The camera's position is
compared the same way, its forward direction as the distance of the unit vectors.

Exit status: 0 when everything is within --tol, 1 when not, 2 on bad input.
"""

import argparse
import itertools
import json
import math
import sys

PERMS = list(itertools.permutations(range(3)))


def load(path):
    with (sys.stdin if path == "-" else open(path)) as f:
        data = json.load(f)
    if not isinstance(data, dict) or not isinstance(data.get("meshes"), list):
        raise ValueError(f"{path}: no 'meshes' list")
    meshes = [m for m in data["meshes"] if m.get("triangles")]
    return meshes, data.get("camera")


def key(m):
    k = (m.get("node"), m.get("mesh"), m.get("primitive"))
    return None if any(x is None for x in k) else k


def dist(a, b):
    return math.sqrt((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2 + (a[2] - b[2]) ** 2)


def tri_dist(t, u):
    """Max corner distance of the best matching of u's corners to t's."""
    best = math.inf
    for p in PERMS:
        d = max(dist(t[0], u[p[0]]), dist(t[1], u[p[1]]), dist(t[2], u[p[2]]))
        if d < best:
            best = d
            if d == 0.0:
                break
    return best


def bbox_diagonal(meshes):
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for m in meshes:
        for t in m["triangles"]:
            for c in t:
                for k in range(3):
                    lo[k] = min(lo[k], c[k])
                    hi[k] = max(hi[k], c[k])
    if lo[0] == math.inf:
        return 0.0
    return math.sqrt(sum((hi[k] - lo[k]) ** 2 for k in range(3)))


def label(m, i):
    k = key(m)
    return f"node {k[0]} mesh {k[1]} prim {k[2]}" if k else f"#{i}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("oracle", help="the three.js oracle's JSON (the reference; '-' for stdin)")
    ap.add_argument("ours", help="our loader's JSON")
    ap.add_argument("--tol", type=float, default=1e-4, help="relative tolerance (default 1e-4)")
    ap.add_argument("--quiet", action="store_true", help="print only failures and the summary")
    a = ap.parse_args()

    try:
        ref, ref_cam = load(a.oracle)
        our, our_cam = load(a.ours)
    except (OSError, ValueError) as e:
        print(f"pose_check: {e}", file=sys.stderr)
        return 2

    diag = bbox_diagonal(ref)
    scale = diag if diag > 0 else 1.0
    failures = 0
    worst = 0.0

    by_key = all(key(m) for m in ref) and all(key(m) for m in our)
    pairs = []
    if by_key:
        ours_by_key = {}
        for m in our:
            ours_by_key.setdefault(key(m), []).append(m)
        for i, m in enumerate(ref):
            lst = ours_by_key.get(key(m))
            pairs.append((i, m, lst.pop(0) if lst else None))
        extra = [m for lst in ours_by_key.values() for m in lst]
    else:
        for i, m in enumerate(ref):
            pairs.append((i, m, our[i] if i < len(our) else None))
        extra = our[len(ref):]

    print(f"matching {'by (node, mesh, primitive)' if by_key else 'by order'}; "
          f"bounding-box diagonal {diag:.6g}; tolerance {a.tol:g} relative")
    for i, r, o in pairs:
        name = label(r, i)
        if o is None:
            print(f"FAIL {name}: missing on our side ({len(r['triangles'])} triangles)")
            failures += 1
            continue
        rt, ot = r["triangles"], o["triangles"]
        if len(rt) != len(ot):
            print(f"FAIL {name}: {len(rt)} triangles in the oracle, {len(ot)} ours")
            failures += 1
            continue
        dmax, at = 0.0, 0
        for j, (t, u) in enumerate(zip(rt, ot)):
            d = tri_dist(t, u)
            if d > dmax:
                dmax, at = d, j
        rel = dmax / scale
        worst = max(worst, rel)
        bad = not rel <= a.tol
        failures += bad
        if bad or not a.quiet:
            where = f" (worst triangle {at})" if dmax > 0 else ""
            print(f"{'FAIL' if bad else 'ok  '} {name}: {len(rt)} triangles, "
                  f"max corner distance {dmax:.3g} = {rel:.3g} relative{where}")
    for m in extra:
        print(f"FAIL {label(m, -1)}: only on our side ({len(m['triangles'])} triangles)")
        failures += 1

    if ref_cam or our_cam:
        if not (ref_cam and our_cam):
            print(f"FAIL camera: {'missing on our side' if ref_cam else 'only on our side'}")
            failures += 1
        else:
            dp = dist(ref_cam["position"], our_cam["position"]) / scale
            df = dist(ref_cam["forward"], our_cam["forward"])
            bad = not (dp <= a.tol and df <= a.tol)
            failures += bad
            worst = max(worst, dp, df)
            if bad or not a.quiet:
                print(f"{'FAIL' if bad else 'ok  '} camera: position {dp:.3g} relative, "
                      f"forward {df:.3g}")

    print(f"{'FAILED' if failures else 'passed'}: {len(pairs)} meshes, worst {worst:.3g} relative, "
          f"{failures} over tolerance or unmatched")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
