"""`spectra demo`'s table, computed from Python: the built-in `metamerism` scene path-traced
(direct lighting, the like-for-like reference) and rendered in real time in the rgb, naive and
spectral modes, each measured against the reference. Prints the table `spectra demo` prints,
number for number (same defaults: 480×360, 256 spp).

    python python/examples/demo_table.py [--scene metamerism] [--size 480x360] [--spp 256]
"""

import argparse
import sys

import spectra


def table(scene_name="metamerism", size=(480, 360), spp=256):
    """The demo's rows: (mode, mean ΔE2000, p95 ΔE2000, mean linear MAE) per mode."""
    scene = spectra.load(scene_name)
    reference = spectra.truth(scene, spp=spp, size=size, direct_only=True)
    renderer = spectra.Renderer(scene, size=size)
    rows = []
    for mode in ("rgb", "naive", "spectral"):
        d = spectra.diff(reference, renderer.render(mode))
        rows.append((mode, d["delta_e2000"]["mean"], d["delta_e2000"]["p95"], d["mae_linear"]["mean"]))
    return rows


def format_table(scene_name, spp, rows):
    """The rows as `spectra demo` prints them."""
    lines = [
        f"{scene_name} against its path-traced ground truth ({spp} spp, direct lighting):",
        "",
        f"{'mode':<10} {'mean ΔE2000':>12} {'p95 ΔE2000':>12} {'MAE (linear)':>14}",
    ]
    for mode, mean, p95, mae in rows:
        lines.append(f"{mode:<10} {mean:>12.3f} {p95:>12.3f} {mae:>14.5f}")
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default="metamerism")
    p.add_argument("--size", default="480x360", help="WIDTHxHEIGHT")
    p.add_argument("--spp", type=int, default=256)
    a = p.parse_args(argv)
    try:
        w, h = (int(v) for v in a.size.lower().split("x"))
    except ValueError:
        p.error(f"--size {a.size}: expected WIDTHxHEIGHT")
    print(format_table(a.scene, a.spp, table(a.scene, (w, h), a.spp)))


if __name__ == "__main__":
    sys.exit(main())
