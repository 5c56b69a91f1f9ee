#!/usr/bin/env python3
"""Underwater acceptance table: mean CIEDE2000 and MAE of the real-time renderer against the
path-traced ground truth, for every Jerlov type at 1, 5, 10, 20 and 50 m (the original
evaluation's depths), on the built-in `underwater` scene. Modes: ours (spectral, default
model: the light-field source term + single scattering), `--isotropic` (the paper's term +
single scattering, the previous default), the paper's model alone (`--paper-model`), naive and
rgb (default model).

Two figures per cell: per pixel, and on BLOCK×BLOCK block means (`spectra diff --block`),
which cut the path tracer's noise by BLOCK; the truth's own noise floor (two seeds) is
measured the same way for the rows in --noise-depths.

Usage: tools/underwater_table.py [--bin target/release/spectra] [--size 72x48] [--spp 4096]
       [--block 8] [--wavelengths 16] [--types I,IB] [--depths 2,10] [--noise-depths all]
       [--truth-cache DIR] [--models ours,naive] [--out FILE.md] [--json FILE.json]
       [--render-args '--forward-cone 5']

--truth-cache DIR is `spectra truth --truth-cache DIR` (docs/ground-truth.md): the path-traced
samples are kept by everything they depend on, so a second run with a changed real-time model
renders no truth, and one with a higher --spp renders only the samples it lacks.

--ray [--ray-chunks K]: every truth of the table is submitted at once as Ray tasks through the
Python package (`spectra.distributed`, docs/python.md; K sample chunks each, default 8) on the
Ray instance of $RAY_ADDRESS or a new local one, and written as the EXR `spectra truth` would
write; the real-time renders and the statistics stay on this machine. Needs
`pip install './python[distributed]'`.

Every number comes from `spectra truth`, `spectra render` and `spectra diff --json`; nothing is
computed here but the table layout and means.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

TYPES = ["I", "IA", "IB", "II", "III", "1C", "3C", "5C", "7C", "9C"]
DEPTHS = [1, 5, 10, 20, 50]
# (column, render mode, extra flags)
ALL_MODELS = [("ours", "spectral", []), ("isotropic", "spectral", ["--isotropic"]),
              ("paper", "spectral", ["--paper-model"]), ("split", "spectral", ["--split-beams"]),
              ("surface", "spectral", ["--water-surface"]), ("naive", "naive", []), ("rgb", "rgb", [])]
DEFAULT_MODELS = "ours,isotropic,paper,naive,rgb"


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    return r.stdout


def diff(bin_, ref, img, block):
    out = {}
    for b in (1, block):
        d = json.loads(run([bin_, "diff", ref, img, "--json", "--block", str(b)]))
        out[b] = (d["delta_e2000"]["mean"], d["mae_linear"]["mean"])
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/spectra")
    ap.add_argument("--size", default="72x48")
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--block", type=int, default=8)
    ap.add_argument("--wavelengths", type=int, default=16)
    ap.add_argument("--types", default=",".join(TYPES))
    ap.add_argument("--depths", default=",".join(map(str, DEPTHS)))
    ap.add_argument("--noise-depths", default="all", help="depths with a second truth seed, or 'all'")
    ap.add_argument("--truth-cache")
    ap.add_argument("--ray", action="store_true", help="render the truths as Ray tasks (spectra.distributed)")
    ap.add_argument("--ray-chunks", type=int, default=8)
    ap.add_argument("--models", default=DEFAULT_MODELS)
    ap.add_argument("--out")
    ap.add_argument("--json")
    ap.add_argument("--render-args", default="",
                    help="extra flags for every real-time render, e.g. '--forward-cone 5' (a sweep)")
    a = ap.parse_args()
    noise_depths = set(a.depths.split(",")) if a.noise_depths == "all" else (
        set(a.noise_depths.split(",")) if a.noise_depths else set())
    wanted = a.models.split(",")
    MODELS = [m for m in ALL_MODELS if m[0] in wanted]
    if a.truth_cache:
        os.makedirs(a.truth_cache, exist_ok=True)

    if a.ray and a.truth_cache:
        sys.exit("--ray and --truth-cache: pick one (the cache is the command line's)")
    jobs = {}
    if a.ray:
        import spectra
        import spectra.distributed
        scene = spectra.load("underwater")
        w, h = (int(v) for v in a.size.lower().split("x"))
        for ty in a.types.split(","):
            for depth in a.depths.split(","):
                for seed in (1, 2) if depth in noise_depths else (1,):
                    jobs[(ty, depth, seed)] = spectra.distributed.submit(
                        scene, spp=a.spp, size=(w, h), seed=seed, water=ty, depth=float(depth),
                        chunks=a.ray_chunks, label=f"{ty} {depth} m seed {seed}")

    def truth_image(tmp, ty, depth, seed):
        path = os.path.join(tmp, f"truth-{ty}-{depth}-{seed}.exr")
        if a.ray:
            spectra.write_image(path, jobs[(ty, depth, seed)].result())
            return path
        cache = ["--truth-cache", a.truth_cache] if a.truth_cache else []
        run([a.bin, "truth", "underwater", "--water", ty, "--depth", depth, "--size", a.size,
             "--spp", str(a.spp), "--seed", str(seed), *cache, "--out", path])
        return path
    rows = []
    t_start = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        for ty in a.types.split(","):
            for depth in a.depths.split(","):
                common = ["underwater", "--water", ty, "--depth", depth, "--size", a.size]
                t0 = time.time()
                truth = truth_image(tmp, ty, depth, 1)
                row = {"type": ty, "depth": float(depth), "truth_seconds": round(time.time() - t0, 1)}
                for col, mode, flags in MODELS:
                    img = os.path.join(tmp, f"{col}.exr")
                    run([a.bin, "render", *common, "--mode", mode, "--wavelengths", str(a.wavelengths), *flags,
                         *a.render_args.split(), "--out", img])
                    row[col] = diff(a.bin, truth, img, a.block)
                if depth in noise_depths:
                    second = truth_image(tmp, ty, depth, 2)
                    row["noise"] = diff(a.bin, truth, second, a.block)
                rows.append(row)
                if a.json:
                    # Written after every row, so an interrupted run keeps what it measured.
                    with open(a.json + ".partial", "w") as f:
                        json.dump({"args": vars(a), "rows": [{k: ({str(b): v for b, v in val.items()}
                                   if isinstance(val, dict) else val) for k, val in r.items()} for r in rows]}, f)
                print(f"{ty:>4} {depth:>3} m  " + "  ".join(
                    f"{c} {row[c][1][0]:.2f}/{row[c][a.block][0]:.2f} (MAE {row[c][a.block][1]:.4f})" for c, _, _ in MODELS) +
                    (f"  noise {row['noise'][1][0]:.2f}/{row['noise'][a.block][0]:.2f}" if "noise" in row else "") +
                    f"  (truth {row['truth_seconds']} s)", file=sys.stderr)
    elapsed = time.time() - t_start
    cols = [c for c, _, _ in MODELS]
    text = ""
    for blk, title in ((1, "per pixel"), (a.block, f"{a.block}×{a.block} block means")):
        lines = [f"**Mean ΔE2000 ({title})** and MAE of linear sRGB against the truth:", "",
                 "| type | depth (m) | " + " | ".join(f"{c} ΔE00" for c in cols) + " | truth noise ΔE00 | "
                 + " | ".join(f"{c} MAE" for c in cols) + " |",
                 "|" + "---|" * (3 + 2 * len(cols))]
        for r in rows:
            noise = f"{r['noise'][blk][0]:.2f}" if "noise" in r else ""
            lines.append(f"| {r['type']} | {r['depth']:g} | " + " | ".join(f"{r[c][blk][0]:.2f}" for c in cols)
                         + f" | {noise} | " + " | ".join(f"{r[c][blk][1]:.4f}" for c in cols) + " |")
        n = len(rows)
        mean = lambda c, k: sum(r[c][blk][k] for r in rows) / n
        lines.append("| **mean** | | " + " | ".join(f"{mean(c, 0):.2f}" for c in cols) + " | | "
                     + " | ".join(f"{mean(c, 1):.4f}" for c in cols) + " |")
        # Compared at the table's precision: where nothing but water is visible ours and
        # naive agree to 1e-4 and float noise must not decide the count.
        le = lambda x, c: sum(round(r[x][blk][0], 2) <= round(r[c][blk][0], 2) for r in rows)

        def beyond(x, c):
            """Rows where x and c differ by more than the truth's noise floor, and of those how
            many have x < c."""
            rs = [r for r in rows if "noise" in r and abs(r[x][blk][0] - r[c][blk][0]) > r["noise"][blk][0]]
            return sum(r[x][blk][0] < r[c][blk][0] for r in rs), len(rs)

        lines.append("")
        summary = [f"ours ΔE ≤ 2: {sum(r['ours'][blk][0] <= 2 for r in rows)}/{n}"]
        for x, c in (("ours", "naive"), ("naive", "rgb"), ("ours", "rgb"), ("ours", "isotropic"), ("ours", "paper")):
            if x in cols and c in cols:
                w, m = beyond(x, c)
                summary.append(f"{x} ≤ {c}: {le(x, c)}/{n} ({x} < {c} in {w} of the {m} rows where the gap exceeds the noise floor)")
        lines.append("; ".join(summary))
        text += "\n".join(lines) + "\n\n"
    text += (f"{a.size} px, truth {a.spp} spp (seed 1; noise = seed 1 vs seed 2), real time N = {a.wavelengths}, "
             f"scene `underwater`; {elapsed / 60:.0f} min. `tools/underwater_table.py --size {a.size} --spp {a.spp} "
             f"--block {a.block} --wavelengths {a.wavelengths} --types {a.types} --depths {a.depths} "
             f"--noise-depths {a.noise_depths} --models {a.models}"
             + (f" --render-args '{a.render_args}'" if a.render_args else "") + "`\n")
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"args": vars(a), "minutes": elapsed / 60,
                       "rows": [{k: ({str(b): v for b, v in val.items()} if isinstance(val, dict) else val)
                                 for k, val in r.items()} for r in rows]}, f, indent=1)


if __name__ == "__main__":
    main()
