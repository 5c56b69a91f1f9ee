#!/usr/bin/env python3
"""How an underwater table moved: two `tools/underwater_table.py --json` files of the same rows
(e.g. before/after a change), per row and model the per-pixel and block ΔE2000 and the block
MAE, old → new, and the largest increase of a model's block ΔE2000 (the acceptance figure of
issue 27: ≤ 0.02 where only the real-time renderer changed).

With --caches OLD_DIR NEW_DIR (the two runs' --truth-cache directories, when the *truth*
changed), also each type and depth's mean luminance of the truth, new/old, averaged over the
seeds both hold, with the spread between seeds as its noise (issue 28: the truth's camera rays
start at the eye).

Usage: tools/underwater_table_diff.py OLD.json NEW.json [--caches OLD_DIR NEW_DIR]
(--caches needs numpy and the OpenEXR Python package, as the oracles)
"""
import argparse
import glob
import json
import os


def rows(path):
    return {(r["type"], r["depth"]): r for r in json.load(open(path))["rows"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--caches", nargs=2, metavar=("OLD_DIR", "NEW_DIR"))
    a = ap.parse_args()
    old, new = rows(a.old), rows(a.new)
    common = [k for k in old if k in new]
    if not common:
        raise SystemExit(f"{a.old} and {a.new} share no (type, depth) row")
    worst = (0.0, None)
    print("| type | depth (m) | model | ΔE00 per pixel | ΔE00 8×8 blocks | block MAE |")
    print("|---|---|---|---|---|---|")
    for k in common:
        for m in [m for m in ("ours", "isotropic", "paper", "split", "surface", "naive", "rgb", "noise") if m in old[k] and m in new[k]]:
            blk = max(b for b in old[k][m] if b != "1")
            o, n = old[k][m], new[k][m]
            d = n[blk][0] - o[blk][0]
            if m != "noise" and d > worst[0]:
                worst = (d, f"{k[0]} {k[1]:g} m {m}")
            print(f"| {k[0]} | {k[1]:g} | {m} | {o['1'][0]:.2f} → {n['1'][0]:.2f} | "
                  f"{o[blk][0]:.3f} → {n[blk][0]:.3f} ({d:+.3f}) | {o[blk][1]:.4f} → {n[blk][1]:.4f} |")
    print(f"\nlargest increase of a model's block ΔE2000: {worst[0]:+.3f}" + (f" ({worst[1]})" if worst[1] else ""))
    if a.caches:
        import numpy as np
        from exr_rows import read

        def lum(p):
            im = read(p)
            return float((0.2126 * im[..., 0] + 0.7152 * im[..., 1] + 0.0722 * im[..., 2]).mean())

        print("\n| type | depth (m) | truth mean Y old | new | new/old | ± (seed spread) |")
        print("|---|---|---|---|---|---|")
        for t, depth in common:
            pat = f"truth-{t}-{depth:g}-*.exr"
            names = sorted({os.path.basename(p) for p in glob.glob(os.path.join(a.caches[0], pat))}
                           & {os.path.basename(p) for p in glob.glob(os.path.join(a.caches[1], pat))})
            if not names:
                continue
            yo = [lum(os.path.join(a.caches[0], n)) for n in names]
            yn = [lum(os.path.join(a.caches[1], n)) for n in names]
            mo, mn = np.mean(yo), np.mean(yn)
            spread = (np.hypot(np.std(yo, ddof=1) / mo, np.std(yn, ddof=1) / mn) / np.sqrt(len(names))
                      if len(names) > 1 else float("nan"))
            print(f"| {t} | {depth:g} | {mo:.5f} | {mn:.5f} | {mn / mo:.4f} | {spread:.4f} |")


if __name__ == "__main__":
    main()
