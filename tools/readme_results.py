#!/usr/bin/env python3
"""README's results table from a `spectra eval` results.json (the full run's sweep).

Rows: the cases by id (their titles are in the report). Columns: ours (prefiltered) at N = 8 / 16 / 64, the paper's midpoint rule at N = 8 / 16, naive
(prefiltered) at N = 16, rgb, and the truth's noise (mean ΔE2000 between two independent halves
of its samples). The smallest of ours N = 16, naive N = 16 and rgb is bold. A column whose N
was not swept shows "–".

    python3 tools/readme_results.py docs/results/eval-full/results.json
"""
import argparse
import json
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", help="results.json of a `spectra eval` run")
    a = ap.parse_args()
    try:
        with open(a.results) as f:
            r = json.load(f)
        cases = r["cases"]
    except (OSError, ValueError, KeyError) as e:
        sys.exit(f"readme_results: {a.results}: {e}")

    print("| case | ours N=8 | ours N=16 | ours N=64 | paper's midpoint N=8 / 16 | naive N=16 | rgb | truth noise |")
    print("|---|---|---|---|---|---|---|---|")
    for c in cases:
        def sweep(mode, quad, n):
            for s in c.get("sweep", []):
                if s["mode"] == mode and s["quadrature"] == quad and s["wavelengths"] == n:
                    return s["delta_e2000_mean"]
            return None

        rgb = next(m for m in c["modes"] if m["mode"] == "rgb")["errors"]["delta_e2000"]["mean"]
        ours16, naive16 = sweep("ours", "prefiltered", 16), sweep("naive", "prefiltered", 16)
        best = min(v for v in (ours16, naive16, rgb) if v is not None)

        def fmt(v, bold=True):
            if v is None:
                return "–"
            s = f"{v:.3f}"
            return f"**{s}**" if bold and v == best else s

        row = [
            c["id"],
            fmt(sweep("ours", "prefiltered", 8), False),
            fmt(ours16),
            fmt(sweep("ours", "prefiltered", 64), False),
            f"{fmt(sweep('ours', 'midpoint', 8), False)} / {fmt(sweep('ours', 'midpoint', 16), False)}",
            fmt(naive16),
            fmt(rgb),
            f"{c['noise_floor']['delta_e2000']['mean']:.3f}",
        ]
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
