#!/usr/bin/env python3
"""Diff two `spectra eval` results.json files: the accuracy contract of a change meant to be faster.

    tools/eval_diff.py OLD/results.json NEW/results.json [--tolerance 0.005] [--top 12]

Compares every error statistic (every numeric leaf under a `delta_e2000*`, `mae*` or `flip*` key,
in every case, mode, N, sweep and jitter row; timings and settings are ignored), prints how many
are bit-identical, the largest differences with their paths, and whether every ΔE2000 statistic
is within the tolerance. Exit status 1 when one is not, or when the two files do not describe the
same cases. Python 3 standard library only.
"""
import argparse
import json
import sys

ERROR_KEYS = ("delta_e", "mae", "flip")


def label(item, index):
    if not isinstance(item, dict):
        return str(index)
    parts = [str(item.get(k, "")) for k in ("id", "mode", "wavelengths", "quadrature")]
    tag = ":".join(p for p in parts if p)
    return f"{index}:{tag}" if tag else str(index)


def walk(a, b, path, rows, problems):
    if isinstance(a, dict):
        if not isinstance(b, dict):
            problems.append(f"{path}: object in one file, not in the other")
            return
        for k, v in a.items():
            if k not in b:
                problems.append(f"{path}.{k}: missing in the new file")
            else:
                walk(v, b[k], f"{path}.{k}", rows, problems)
    elif isinstance(a, list):
        if not isinstance(b, list) or len(a) != len(b):
            problems.append(f"{path}: lists of different lengths")
            return
        for i, (u, v) in enumerate(zip(a, b)):
            walk(u, v, f"{path}[{label(u, i)}]", rows, problems)
    elif isinstance(a, (int, float)) and not isinstance(a, bool):
        stat = any(k in path for k in ERROR_KEYS) and not any(k in path for k in ("_ms", "seconds", "time"))
        if stat:
            if not isinstance(b, (int, float)) or isinstance(b, bool):
                problems.append(f"{path}: number in one file, not in the other")
            else:
                rows.append((abs(a - b), path, a, b))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("old")
    p.add_argument("new")
    p.add_argument("--tolerance", type=float, default=0.005, help="largest allowed ΔE2000 change")
    p.add_argument("--top", type=int, default=12, help="differences to list")
    args = p.parse_args()
    try:
        with open(args.old) as f:
            old = json.load(f)
        with open(args.new) as f:
            new = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"eval_diff: {e}")
    rows, problems = [], []
    walk(old, new, "", rows, problems)
    rows.sort(key=lambda r: -r[0])
    same = sum(1 for r in rows if r[0] == 0)
    print(f"{len(rows)} error statistics: {same} bit-identical, largest difference {rows[0][0] if rows else 0:.6g}")
    for d, path, a, b in rows[: args.top]:
        print(f"  {d:.6g}  {path}  {a!r} -> {b!r}")
    for m in problems[:20]:
        print(f"  structure: {m}")
    worst = max((r[0] for r in rows if "delta_e" in r[1]), default=0.0)
    over = [r for r in rows if "delta_e" in r[1] and r[0] > args.tolerance]
    verdict = "within" if not over else f"{len(over)} statistic(s) beyond"
    print(f"largest ΔE2000 statistic change {worst:.6g}: {verdict} {args.tolerance}")
    sys.exit(1 if over or problems else 0)


if __name__ == "__main__":
    main()
