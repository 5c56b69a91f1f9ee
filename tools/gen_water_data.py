#!/usr/bin/env python3
"""Regenerates crates/color/src/data/water.rs: Jerlov water types (a, b, Kd per metre).

Source: the PyPI package `jerlov` 0.22.0 (Apache-2.0), which carries the published tables with a
per-cell `status` column and documents every known defect in its DATA.md. We read its CSV files
directly (not its interpolating API) so that every number we embed is a tabulated cell, and we
decide here, visibly, what to do with each flagged one. Run after `pip install jerlov==0.22.0`:

    python3 tools/gen_water_data.py

Two datasets are generated:

* Solonenko & Mobley 2015 (Appl. Opt. 54, 5392, doi:10.1364/AO.54.005392), Tables 4-8: all ten
  Jerlov types, a, b and the model Kd at 17 wavelengths 300-700 nm. a and b were retrieved by
  inverting Jerlov's Kd; it is the only source covering all ten types.
* Williamson & Hollins 2022 (Appl. Opt. 61, 9951, doi:10.1364/AO.470464), measured a and b at
  1 nm for IB, II, III, 1C, 3C, 5C; Kd for those types from Jerlov (1976) Table XXVII as
  resampled at 1 nm in the same Dstl dataset. Both files: (c) Crown copyright 2022, Dstl,
  Open Government Licence v3.0 (figshare doi:10.6084/m9.figshare.20290782, v3).

Defect handling (jerlov DATA.md section numbers):

* §1 Solonenko & Mobley Table 7 duplicated rows (3C at 675-700 nm, 5C at 600-700 nm are copies of
  the 300-400 nm rows). b: the package's reconstruction from the paper's own Eq. (8)
  (status `reconstructed`). a: the values Williamson & Hollins substituted in their spreadsheet
  (`Sol_Mob data` sheet; carried in the `williamson2022_value_per_m` column). Kd (unrecoverable
  in the source): Jerlov (1976)'s printed Kd of the same type (Table XXVII), the quantity the
  paper's model Kd was fitted to (within 15 percent). Scaling it to meet the last sound model
  value was tried and rejected: for 5C it drives Kd down to a at 675 nm (Kd/a = 0.995).
* §4 b for types I and IA is flagged `suspect` only because the paper's Table 3 parameters do
  not reproduce it; DATA.md concludes the b column is right, so it is used as published.
* Above 700 nm (past every Jerlov table, needed because renderers integrate to 730 nm and
  beyond) both datasets are extended by the same rule: a(λ) = a(700) + aw(λ) - aw(700) with the
  pure-water absorption aw that Williamson & Hollins built their a on (DATA.md §20), b held at
  b(700), Kd(λ) = Kd(700)·a(λ)/a(700) (in the red Kd is absorption-dominated). For
  Williamson & Hollins only Kd needs this (their a and b run to 800 nm; Dstl's linear
  extrapolation of Jerlov's Kd past 700 nm is replaced by this rule).

The script checks a > 0, b > 0, Kd > a (required physically: Kd >= a/mu_d >= a) over 360-800 nm and
stops if any check fails.
"""
import csv
import pathlib
from importlib import resources

import jerlov
import numpy as np

OUT = pathlib.Path(__file__).resolve().parent.parent / "crates" / "color" / "src" / "data" / "water.rs"
TYPES = ["I", "IA", "IB", "II", "III", "1C", "3C", "5C", "7C", "9C"]
WH_TYPES = ["IB", "II", "III", "1C", "3C", "5C"]
EXT = np.arange(710.0, 801.0, 10.0)  # extension grid for the 17-wavelength table


def rows(name):
    with resources.files("jerlov.data").joinpath(name).open("r", encoding="utf-8", newline="") as f:
        return list(csv.DictReader(f))


SM = rows("solonenko2015_iop.csv")
WH = rows("williamson2022_iop.csv")
J76 = rows("jerlov1976_kd.csv")
AW = {float(r["wavelength_nm"]): float(r["aw_per_m"]) for r in rows("williamson2022_aw.csv")}
WH_KD_BELOW_A = []  # (type, count, first, last): measured a above Jerlov's Kd
ORACLE = [0]  # cells cross-checked against jerlov's API
MODIFIED = []  # (type, lambda, quantity, how) for the Solonenko & Mobley table


def aw(l):
    return AW[float(l)]


def j76(t, l):
    r = next(r for r in J76 if r["water_type"] == t and float(r["wavelength_nm"]) == l)
    return float(r["Kd_downwelling_per_m"]), r["status"]


def sm_cell(t, l, q):
    return next(r for r in SM if r["water_type"] == t and float(r["wavelength_nm"]) == l and r["quantity"] == q)


def solonenko(t):
    lam = sorted({float(r["wavelength_nm"]) for r in SM if r["water_type"] == t})
    a, b, kd = [], [], []
    for l in lam:
        ra, rb, rk = (sm_cell(t, l, q) for q in ("a", "b", "Kd"))
        # a
        if ra["status"] == "missing":
            a.append(float(ra["williamson2022_value_per_m"]))
            MODIFIED.append((t, l, "a", "Williamson & Hollins substitution (Dstl spreadsheet)"))
        else:
            assert ra["status"] == "ok", ra
            a.append(float(ra["value_per_m"]))
        # b
        assert rb["status"] in ("ok", "suspect", "reconstructed"), rb
        b.append(float(rb["value_per_m"]))
        if rb["status"] == "reconstructed":
            MODIFIED.append((t, l, "b", "reconstructed from Solonenko & Mobley Eq. (8)"))
        # Kd
        if rk["status"] == "missing":
            kd.append(None)
        else:
            assert rk["status"] == "ok", rk
            kd.append(float(rk["value_per_m"]))
    for i, l in enumerate(lam):
        if kd[i] is None:
            j, st = j76(t, l)
            assert st == "ok", (t, l, st)
            kd[i] = j
            MODIFIED.append((t, l, "Kd", "Jerlov 1976 Table XXVII printed Kd of the same type"))
    # Extension past 700 nm.
    a700, b700, k700 = a[-1], b[-1], kd[-1]
    for l in EXT:
        al = a700 + aw(l) - aw(700)
        lam.append(float(l))
        a.append(al)
        b.append(b700)
        kd.append(k700 * al / a700)
    return lam, a, b, kd


def williamson(t):
    lam = sorted({float(r["wavelength_nm"]) for r in WH if r["water_type"] == t})
    val = {(float(r["wavelength_nm"]), r["quantity"]): float(r["value_per_m"]) for r in WH if r["water_type"] == t}
    a = [val[(l, "a")] for l in lam]
    b = [val[(l, "b")] for l in lam]
    kd = []
    k700, _ = j76(t, 700.0)
    a700 = val[(700.0, "a")]
    for l in lam:
        if l <= 700:
            k, st = j76(t, l)
            assert st in ("ok", "interpolated", "extrapolated_by_dataset"), (t, l, st)
            kd.append(k)
        else:
            kd.append(k700 * val[(l, "a")] / a700)
    return lam, a, b, kd


def check(name, lam, a, b, kd, strict=True):
    """Positivity always; Kd > a only for a self-consistent dataset (returns the violations)."""
    lam = np.asarray(lam)
    a, b, kd = (np.asarray(x) for x in (a, b, kd))
    for x, q in ((a, "a"), (b, "b"), (kd, "Kd")):
        assert np.all(np.isfinite(x)) and np.all(x > 0), (name, q)
    m = lam >= 360
    bad = lam[m][kd[m] <= a[m]]
    assert np.all(np.diff(lam) > 0), name
    assert bad.size == 0 or not strict, f"{name}: Kd <= a at {bad}"
    return bad


def oracle_check(source, t, lam, a, b, kd):
    """Cross-check against jerlov's own API at every wavelength it serves without a flag."""
    import warnings
    w = jerlov.water(t, source=source)
    kdw = jerlov.water(t, source="jerlov1976") if source == "williamson2022" else w
    n = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for l, av, bv, kv in zip(lam, a, b, kd):
            if l > 700 or (source == "solonenko2015" and any(m[0] == t and m[1] == l for m in MODIFIED)):
                continue
            for got, want in ((av, w.a(l)), (bv, w.b(l)), (kv, kdw.kd(l))):
                assert abs(got - float(want)) <= 1e-12 * abs(float(want)), (source, t, l, got, want)
                n += 1
    return n


def arr(v):
    return "&[" + ", ".join(repr(float(x)) for x in v) + "]"


def main():
    src = [
        f"// @generated by tools/gen_water_data.py from the PyPI package jerlov {jerlov.__version__} (Apache-2.0).\n",
        "// Do not edit by hand: change the script and run it again.\n",
        "//! Jerlov water types: absorption a, scattering b and downwelling diffuse attenuation Kd, per metre.\n",
        "//!\n",
        "//! Sources (full provenance and defect list: jerlov's DATA.md; summary: docs/underwater.md):\n",
        "//! - [`SOLONENKO2015`]: Solonenko & Mobley 2015, Appl. Opt. 54, 5392, doi:10.1364/AO.54.005392,\n",
        "//!   Tables 4-8 (a, b and model Kd; ten types, 300-700 nm at 17 wavelengths).\n",
        "//! - [`WILLIAMSON2022`]: Williamson & Hollins 2022, Appl. Opt. 61, 9951, doi:10.1364/AO.470464,\n",
        "//!   measured a and b at 1 nm (six types); Kd of the same types from Jerlov (1976) Table XXVII\n",
        "//!   as resampled at 1 nm in the same dataset. Contains public sector information licensed under\n",
        "//!   the Open Government Licence v3.0: (c) Crown copyright 2022, Dstl, figshare\n",
        "//!   doi:10.6084/m9.figshare.20290782 (v3). Measured points exist for 412-715 nm only; the rest\n",
        "//!   is the authors' model.\n",
        "//!\n",
        "//! Defects handled (jerlov DATA.md section numbers):\n",
        "//! - §1 duplicated rows in Solonenko & Mobley Table 7 (3C 675-700 nm, 5C 600-700 nm): b from the\n",
        "//!   paper's own Eq. (8) (jerlov's reconstruction); a from the Williamson & Hollins substitution\n",
        "//!   in their spreadsheet; Kd from Jerlov (1976)'s printed Kd of the same type (Table XXVII), which\n",
        "//!   the paper's model Kd was fitted to. Every such cell is listed in [`SOLONENKO2015_MODIFIED`].\n",
        "//! - §4 b of types I and IA (flagged `suspect`): used as published; DATA.md shows the b column is\n",
        "//!   right and the paper's Table 3 parameters are wrong.\n",
        "//! - Beyond 700 nm (no Jerlov table goes further): a(λ) = a(700) + aw(λ) − aw(700) with the pure\n",
        "//!   water absorption aw of Williamson & Hollins, b held at b(700), Kd(λ) = Kd(700)·a(λ)/a(700).\n",
        "//!   For Williamson & Hollins only Kd is extended this way (their a and b reach 800 nm).\n",
        "//!\n",
        "//! Checked by the generator: a, b, Kd finite and positive everywhere, Kd > a from 360 nm up\n",
        "//! (Solonenko & Mobley; see the caveat on [`WILLIAMSON2022`]).\n\n",
        "// Measured values that happen to look like 1/π etc. are data, not constants.\n",
        "#![allow(clippy::approx_constant)]\n\n",
        "/// One water type: values at `lambda` (nm, strictly increasing), all per metre.\n",
        "#[derive(Clone, Copy, Debug)]\n",
        "pub struct WaterTable {\n    pub name: &'static str,\n    pub lambda: &'static [f64],\n",
        "    pub a: &'static [f64],\n    pub b: &'static [f64],\n    pub kd: &'static [f64],\n}\n\n",
    ]
    src.append("/// Solonenko & Mobley 2015, the ten types in Jerlov's order (clearest oceanic first).\n")
    src.append("pub const SOLONENKO2015: [WaterTable; 10] = [\n")
    for t in TYPES:
        lam, a, b, kd = solonenko(t)
        check(f"SM {t}", lam, a, b, kd)
        ORACLE[0] += oracle_check("solonenko2015", t, lam, a, b, kd)
        src.append(f"    WaterTable {{ name: {t!r}, lambda: {arr(lam)}, a: {arr(a)}, b: {arr(b)}, kd: {arr(kd)} }},\n".replace("'", '"'))
    src.append("];\n\n")
    src.append("/// Cells of [`SOLONENKO2015`] that are not the published value: (type, nm, quantity, how).\n")
    src.append("pub const SOLONENKO2015_MODIFIED: &[(&str, f64, &str, &str)] = &[\n")
    for t, l, q, how in MODIFIED:
        src.append(f'    ("{t}", {l!r}, "{q}", "{how}"),\n')
    src.append("];\n\n")
    wl = None
    body = []
    for t in WH_TYPES:
        lam, a, b, kd = williamson(t)
        bad = check(f"WH {t}", lam, a, b, kd, strict=False)
        ORACLE[0] += oracle_check("williamson2022", t, lam, a, b, kd)
        if bad.size:
            WH_KD_BELOW_A.append((t, bad.size, bad.min(), bad.max()))
        assert wl is None or wl == lam
        wl = lam
        body.append(f"    WaterTable {{ name: {t!r}, lambda: WILLIAMSON2022_LAMBDA, a: {arr(a)}, b: {arr(b)}, kd: {arr(kd)} }},\n".replace("'", '"'))
    src.append("/// Wavelengths of [`WILLIAMSON2022`]: 300-800 nm at 1 nm.\n")
    src.append(f"pub const WILLIAMSON2022_LAMBDA: &[f64] = {arr(wl)};\n\n")
    src.append("/// Williamson & Hollins 2022 (a, b) with Jerlov 1976 Kd, six types in Jerlov's order.\n///\n")
    src.append("/// Caveat: a and Kd come from different campaigns, and the measured a exceeds Jerlov's Kd\n")
    src.append("/// (physically Kd > a) at: " + "; ".join(f"{t} {n} wavelengths within {lo:.0f}-{hi:.0f} nm" for t, n, lo, hi in WH_KD_BELOW_A) + ".\n")
    src.append("pub const WILLIAMSON2022: [WaterTable; 6] = [\n")
    src.extend(body)
    src.append("];\n")
    OUT.write_text("".join(src))
    print("wrote", OUT, f"({ORACLE[0]} cells agree with jerlov.water(...) to 1e-12)")
    for m in MODIFIED:
        print("modified:", m)


if __name__ == "__main__":
    main()
