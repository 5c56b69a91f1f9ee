#!/usr/bin/env python3
"""Plots and summarises the light-field table against the path tracer in an empty water column.

Input: the CSV of `cargo run --release -p spectra --example lf_column -- --out FILE.csv`
(one row per water type, camera depth, view direction and wavelength; see that example for
what each column is). Output: one PNG per water type (radiance spectra and the ratio
table/truth with the truth's ±2σ, per depth) and a Markdown summary on stdout.

    python3 tools/lf_column_plot.py FILE.csv --out-dir docs/images [--prefix lf-check]

Needs matplotlib (pip install matplotlib).
"""

import argparse
import csv
import math
import sys
from collections import defaultdict
from pathlib import Path


def load(path):
    rows = []
    try:
        with open(path, newline="") as f:
            for i, r in enumerate(csv.DictReader(f), start=2):
                try:
                    for k in ("depth_m", "lambda_nm", "truth", "truth_se", "table", "ratio", "ratio_se"):
                        r[k] = float(r[k])
                    r["ratio_hi"] = float(r["ratio_hi"]) if r.get("ratio_hi") else None
                    r["table_hi"] = float(r["table_hi"]) if r.get("table_hi") else None
                except (KeyError, TypeError, ValueError) as e:
                    sys.exit(f"{path} line {i}: bad or missing field ({e})")
                rows.append(r)
    except OSError as e:
        sys.exit(f"{path}: {e.strerror}")
    if not rows:
        sys.exit(f"{path}: no rows")
    return rows


MAX_SE = 0.03


def summary(rows, label, key):
    """Markdown rows: per type and depth, the spread of table/truth over directions and λ."""
    groups = defaultdict(list)
    for r in rows:
        # Rows where the truth itself is uncertain (deep red or blue at depth, a few 1e-6 of the
        # brightest radiance) say nothing about the table.
        if r[key] is not None and r["truth_se"] < MAX_SE * r["truth"]:
            groups[(r["type"], r["depth_m"])].append(r)
    out = []
    for (ty, z), rs in groups.items():
        dev = [abs(r[key] - 1.0) for r in rs]
        # Beyond the truth's own noise: |ratio − 1| > 3σ of the truth.
        beyond = sum(1 for r in rs if abs(r[key] - 1.0) > 3.0 * r["ratio_se"])
        rms = math.sqrt(sum(d * d for d in dev) / len(dev))
        # The part of the error that changes colour: each direction's ratio over the mean of its
        # ratios across wavelengths (a common factor only changes brightness).
        by_dir = defaultdict(list)
        for r in rs:
            by_dir[r["direction"]].append(r[key])
        shape = [x / (sum(v) / len(v)) - 1.0 for v in by_dir.values() for x in v]
        rms_shape = math.sqrt(sum(d * d for d in shape) / len(shape))
        se = sorted(r["ratio_se"] for r in rs)[len(rs) // 2]
        out.append(
            f"| {ty} | {z:g} | {label} | {sorted(dev)[len(dev) // 2]:.3f} | {rms:.3f} | {max(dev):.3f} | {rms_shape:.3f} | {beyond}/{len(rs)} | {se:.3f} |"
        )
    return out


def plot(rows, out_dir, prefix):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    types = sorted({r["type"] for r in rows}, key=lambda t: [r["type"] for r in rows].index(t))
    written = []
    for ty in types:
        rs = [r for r in rows if r["type"] == ty]
        depths = sorted({r["depth_m"] for r in rs})
        dirs = list(dict.fromkeys(r["direction"] for r in rs))
        fig, axes = plt.subplots(2, len(depths), figsize=(4.2 * len(depths), 7.2), squeeze=False)
        colours = plt.get_cmap("tab10")
        for j, z in enumerate(depths):
            top, bot = axes[0][j], axes[1][j]
            for k, d in enumerate(dirs):
                pts = sorted((r for r in rs if r["depth_m"] == z and r["direction"] == d),
                             key=lambda r: r["lambda_nm"])
                lam = [r["lambda_nm"] for r in pts]
                col = colours(k)
                top.errorbar(lam, [r["truth"] for r in pts], yerr=[2 * r["truth_se"] for r in pts],
                             fmt="o", ms=3, color=col, label=d)
                top.plot(lam, [r["table"] for r in pts], "-", color=col, lw=1)
                bot.errorbar(lam, [r["ratio"] for r in pts], yerr=[2 * r["ratio_se"] for r in pts],
                             fmt="o-", ms=3, lw=1, color=col, label=d)
                if all(r["ratio_hi"] is not None for r in pts):
                    bot.plot(lam, [r["ratio_hi"] for r in pts], ":", color=col, lw=1)
            top.set_yscale("log")
            top.set_title(f"Jerlov {ty}, camera {z:g} m")
            top.set_xlabel("wavelength (nm)")
            top.set_ylabel("radiance (tracer units): dots truth ±2σ, lines table")
            bot.axhline(1.0, color="k", lw=0.8)
            for y in (0.9, 1.1):
                bot.axhline(y, color="grey", lw=0.5, ls="--")
            bot.set_ylim(0.4, 1.8)
            bot.set_xlabel("wavelength (nm)")
            bot.set_ylabel("table / truth (±2σ truth); dotted: finer table")
        axes[0][0].legend(fontsize=7, loc="lower left")
        fig.tight_layout()
        path = Path(out_dir) / f"{prefix}-{ty}.png"
        fig.savefig(path, dpi=72)
        plt.close(fig)
        # A palette image: a few tens of KB in the repository instead of ~200.
        from PIL import Image

        with Image.open(path) as im:
            im.convert("RGB").quantize(colors=64).save(path, optimize=True)
        written.append(path)
    return written


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("--out-dir", default="docs/images")
    ap.add_argument("--prefix", default="lf-check")
    ap.add_argument("--no-plots", action="store_true")
    a = ap.parse_args()
    rows = load(a.csv)
    print(f"Rows whose truth has a relative standard error < {MAX_SE:g}; 'beyond 3σ' counts the truth's σ only.")
    print()
    print("| type | depth (m) | table | median abs(ratio − 1) | RMS of ratio − 1 | max abs(ratio − 1) | RMS across λ (colour) "
          "| beyond 3σ of truth | median σ of ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    for line in summary(rows, "default", "ratio") + summary(rows, "finer", "ratio_hi"):
        print(line)
    if not a.no_plots:
        Path(a.out_dir).mkdir(parents=True, exist_ok=True)
        for p in plot(rows, a.out_dir, a.prefix):
            print(f"wrote {p}", file=sys.stderr)


if __name__ == "__main__":
    main()
