#!/usr/bin/env python3
"""Converts a copy of Jiang, Liu, Gu & Süsstrunk 2013's camera sensitivity database
(`camspec_database.txt`, 28 cameras; CC BY-NC-SA, so spectra does not ship it) into one CSV per
camera that `--observer FILE.csv` reads.

The database is plain text: a camera's name on a line of its own, then three lines — its R, G
and B sensitivities at 400, 410, …, 720 nm (33 values separated by tabs or spaces) — and the
next camera. Each CSV gets a header, `wavelength_nm,r,g,b`, and the values as written.

    python3 tools/camspec_to_csv.py camspec_database.txt --out cameras/
    spectra render cornell --observer cameras/Canon_5D_Mark_II.csv --out c.png

Standard library only. A malformed file stops with its line number; nothing is written then.
"""
import argparse
import pathlib
import re
import sys

WAVELENGTHS = list(range(400, 721, 10))


def parse(text, source="camspec_database.txt"):
    """{camera name: [(nm, r, g, b), …]} in the file's order."""
    cameras = {}
    name, rows = None, []

    def close(line_no):
        if name is None:
            return
        if len(rows) != 3:
            raise ValueError(f"{source}: camera '{name}' has {len(rows)} rows of values before line {line_no}; expected 3 (R, G, B)")
        if name in cameras:
            raise ValueError(f"{source}: camera '{name}' appears twice (line {line_no})")
        cameras[name] = [(l, *vals) for l, vals in zip(WAVELENGTHS, zip(*rows))]

    for i, raw in enumerate(text.splitlines(), 1):
        line = raw.strip()
        if not line:
            continue
        fields = line.split()
        try:
            values = [float(f) for f in fields]
        except ValueError:
            close(i)
            name, rows = line, []
            continue
        if name is None:
            raise ValueError(f"{source}: line {i}: values before any camera name")
        if len(values) != len(WAVELENGTHS):
            raise ValueError(f"{source}: line {i}: {len(values)} values; expected {len(WAVELENGTHS)} (400–720 nm at 10 nm)")
        if len(rows) == 3:
            raise ValueError(f"{source}: line {i}: a fourth row of values for camera '{name}'")
        rows.append(values)
    close(len(text.splitlines()) + 1)
    if not cameras:
        raise ValueError(f"{source}: no cameras found")
    return cameras


def file_name(camera):
    return re.sub(r"[^A-Za-z0-9]+", "_", camera).strip("_") + ".csv"


def write(cameras, out):
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for camera, rows in cameras.items():
        path = out / file_name(camera)
        tmp = path.with_suffix(".csv.tmp")
        lines = ["wavelength_nm,r,g,b", f"# {camera}: Jiang et al. 2013 camera sensitivity database (CC BY-NC-SA)"]
        lines += [",".join(repr(v) if isinstance(v, float) else str(v) for v in row) for row in rows]
        tmp.write_text("\n".join(lines) + "\n")
        tmp.replace(path)
        written.append(path)
    return written


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("database", help="camspec_database.txt")
    ap.add_argument("--out", required=True, help="directory for the CSV files (created)")
    a = ap.parse_args(argv)
    try:
        cameras = parse(pathlib.Path(a.database).read_text(encoding="utf-8"), a.database)
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    for p in write(cameras, a.out):
        print(p)
    return 0


if __name__ == "__main__":
    sys.exit(main())
