#!/usr/bin/env python3
"""Issue 18's rendered study (docs/rgb-media.md): real time against the path-traced truth.

water: Jerlov types on the built-in `underwater` scene at several depths: (b) the measured
spectra (the existing pipeline), (a) their RGB projections upsampled back as an RGB medium
(box, unbounded), (c) RGB rendering with the projections (and with the coefficients sampled at
the RGB mode's three wavelengths), all against `spectra truth underwater` with the measured
spectra. The real-time images come from `cargo run --release -p spectra --example rgb_water`.

fog: the built-in `fog` and `tinted-fog` scenes (an RGB medium with lights inside it), real time
(spectral, naive, rgb, with multiple scattering; spectral without in-scattering, --scatter-steps 0;
spectral with single scattering only, --single-scattering) against
`spectra truth` of the same scene (the same upsampled medium): the full tracer, and its direct
light only (--direct-only), which is the real-time model (no global illumination, single
scattering); and the same scene in clear air, for what the renderers differ by without a medium.

Two figures per cell, mean ΔE2000 per pixel and on BLOCK×BLOCK block means (`spectra diff
--block`); the truth's noise floor is a second truth seed measured the same way.

Usage: tools/rgb_media_study.py [--parts water,fog] [--size 48x32] [--spp 1024] [--block 8]
       [--types IB,3C] [--depths 1,5,10,20] [--fog-size 64x64] [--fog-spp 1024] [--out FILE.md]
       [--truth-cache DIR]

Every number comes from `spectra truth`, `spectra render`, the example and `spectra diff --json`.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    return r.stdout


def diff(bin_, ref, img, block):
    out = {}
    for b in (1, block):
        d = json.loads(run([bin_, "diff", ref, img, "--json", "--block", str(b)]))
        out[b] = d["delta_e2000"]["mean"]
    return out


def cell(d, block):
    return f"{d[1]:.2f} / {d[block]:.2f}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", default="target/release/spectra")
    ap.add_argument("--example", default="target/release/examples/rgb_water")
    ap.add_argument("--parts", default="water,fog")
    ap.add_argument("--size", default="48x32")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--block", type=int, default=8)
    ap.add_argument("--types", default="IB,3C")
    ap.add_argument("--depths", default="1,5,10,20")
    ap.add_argument("--fog-size", default="64x64")
    ap.add_argument("--fog-spp", type=int, default=1024)
    ap.add_argument("--truth-cache")
    ap.add_argument("--out")
    a = ap.parse_args()
    parts = a.parts.split(",")
    if a.truth_cache:
        os.makedirs(a.truth_cache, exist_ok=True)
    text = ""
    t_start = time.time()
    with tempfile.TemporaryDirectory() as tmp:
        def truth(name, args, seed, size, spp):
            path = os.path.join(a.truth_cache or tmp, f"truth-{name}-{size}-{spp}-{seed}.exr")
            if not (a.truth_cache and os.path.exists(path)):
                run([a.bin, "truth", *args, "--size", size, "--spp", str(spp), "--seed", str(seed), "--out", path])
            return path

        if "water" in parts:
            cols = [("(b) measured", "b.exr"), ("(a) box", "a-box.exr"), ("(a) unbounded", "a-unbounded.exr"),
                    ("(c) RGB, projection", "c-rgb.exr"), ("(c) RGB, sampled", "c-rgb-sampled.exr")]
            lines = ["| type | depth (m) | " + " | ".join(c for c, _ in cols) + " | truth noise |",
                     "|" + "---|" * (len(cols) + 3)]
            sums = [0.0] * len(cols)
            n = 0
            for ty in a.types.split(","):
                for depth in a.depths.split(","):
                    args = ["underwater", "--water", ty, "--depth", depth]
                    ref = truth(f"uw-{ty}-{depth}", args, 1, a.size, a.spp)
                    noise = diff(a.bin, ref, truth(f"uw-{ty}-{depth}", args, 2, a.size, a.spp), a.block)
                    out = os.path.join(tmp, f"rt-{ty}-{depth}")
                    proj = run([a.example, ty, depth, a.size, out]).strip()
                    ds = [diff(a.bin, ref, os.path.join(out, f), a.block) for _, f in cols]
                    for i, d in enumerate(ds):
                        sums[i] += d[a.block]
                    n += 1
                    lines.append(f"| {ty} | {depth} | " + " | ".join(cell(d, a.block) for d in ds)
                                 + f" | {cell(noise, a.block)} |")
                    print(f"{proj}; {ty} {depth} m: " + ", ".join(f"{c} {cell(d, a.block)}"
                          for (c, _), d in zip(cols, ds)) + f", noise {cell(noise, a.block)}", file=sys.stderr)
            lines.append("| **mean (blocks)** | | " + " | ".join(f"{s / n:.2f}" for s in sums) + " | |")
            text += ("**Jerlov water given by RGB**: mean ΔE2000 per pixel / on "
                     f"{a.block}×{a.block} block means against the measured-spectra truth\n\n"
                     + "\n".join(lines) + f"\n\n{a.size} px, truth {a.spp} spp (noise: seed 1 vs 2), real time "
                     "N = 16, default underwater model.\n\n")
        if "fog" in parts:
            modes = [("spectral", ["--mode", "spectral"]), ("naive", ["--mode", "naive"]), ("rgb", ["--mode", "rgb"]),
                     ("spectral, no in-scattering", ["--mode", "spectral", "--scatter-steps", "0"]),
                     ("spectral, single scattering", ["--mode", "spectral", "--single-scattering"])]
            # The real-time renderer has no global illumination; with --single-scattering the
            # tracer's direct light (--direct-only: light sampled at the camera ray's first
            # vertex, in the medium or on a surface) is its model; the full tracer is the truth.
            # "clear" is the fog scene in (practically) clear air: what the renderers differ by
            # without a medium.
            clear = ["--rgb-medium", '{"absorption": [1e-9, 1e-9, 1e-9]}']
            lines = ["| scene | reference | " + " | ".join(m for m, _ in modes) + " | truth noise |",
                     "|" + "---|" * (len(modes) + 3)]
            for sc, extra in [("fog", []), ("tinted-fog", []), ("clear", clear)]:
                scene_name = "fog" if sc == "clear" else sc
                imgs = []
                for m, flags in modes:
                    img = os.path.join(tmp, f"{sc}-{m.replace(' ', '').replace(',', '')}.exr")
                    run([a.bin, "render", scene_name, *extra, "--size", a.fog_size, *flags, "--out", img])
                    imgs.append(img)
                for ref_name, ref_flags in [("full", []), ("direct only", ["--direct-only"])]:
                    tag = f"{sc}{'-direct' if ref_flags else ''}"
                    targs = [scene_name, *extra, *ref_flags]
                    ref = truth(tag, targs, 1, a.fog_size, a.fog_spp)
                    noise = diff(a.bin, ref, truth(tag, targs, 2, a.fog_size, a.fog_spp), a.block)
                    ds = [diff(a.bin, ref, img, a.block) for img in imgs]
                    lines.append(f"| {sc} | {ref_name} | " + " | ".join(cell(d, a.block) for d in ds)
                                 + f" | {cell(noise, a.block)} |")
                    print(f"{sc} vs {ref_name}: " + ", ".join(f"{m} {cell(d, a.block)}" for (m, _), d in zip(modes, ds))
                          + f", noise {cell(noise, a.block)}", file=sys.stderr)
            text += ("**Fog scenes** (RGB media with lights inside): mean ΔE2000 per pixel / on "
                     f"{a.block}×{a.block} block means against `spectra truth` of the same scene, full and "
                     "--direct-only\n\n"
                     + "\n".join(lines) + f"\n\n{a.fog_size} px, truth {a.fog_spp} spp (noise: seed 1 vs 2), "
                     "real time N = 16, 16 march steps.\n\n")
    text += (f"{(time.time() - t_start) / 60:.0f} min. `tools/rgb_media_study.py --parts {a.parts} --size {a.size} "
             f"--spp {a.spp} --block {a.block} --types {a.types} --depths {a.depths} --fog-size {a.fog_size} "
             f"--fog-spp {a.fog_spp}`\n")
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
