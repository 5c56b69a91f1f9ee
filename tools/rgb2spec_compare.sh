#!/usr/bin/env bash
# Fit time and accuracy: rgb2spec_opt (Jakob & Hanika's reference fitter, built from its source)
# against spectra's fitter, in one run, same space and resolution, same adversarial checker.
#
#   tools/rgb2spec_compare.sh RGB2SPEC_SRC [RES] [SPACE]
#
# RGB2SPEC_SRC: a checkout of https://github.com/mitsuba-renderer/rgb2spec (not vendored here;
# nothing of it is copied into spectra). RES defaults to 64, SPACE to srgb (rgb2spec_opt spells
# it sRGB). Times are CPU seconds (user + sys, /usr/bin/time) and wall seconds; on a shared
# machine compare the CPU seconds. Writes the tables to $OUT (default /tmp/rgb2spec_compare).
set -euo pipefail
src=${1:?usage: tools/rgb2spec_compare.sh RGB2SPEC_SRC [RES] [SPACE]}
res=${2:-64}
space=${3:-srgb}
out=${OUT:-/tmp/rgb2spec_compare}
# Spaces both fitters know (rgb2spec_opt has no Display P3 and no ACEScg, only ACES2065-1).
case $space in
  srgb) rspace=sRGB ;;
  rec2020) rspace=REC2020 ;;
  *) echo "tools/rgb2spec_compare.sh: SPACE must be srgb or rec2020 (what rgb2spec_opt also fits), not $space" >&2; exit 2 ;;
esac
mkdir -p "$out"
root=$(cd "$(dirname "$0")/.." && pwd)
g++ -O3 -fopenmp -std=c++11 "$src/rgb2spec_opt.cpp" -o "$out/rgb2spec_opt"
(cd "$root" && cargo build -q --release -p color --example fit_time --example adversarial)
bin="$root/target/release/examples"
t() { /usr/bin/time -f "%U %S %e" -o "$out/time" "$@" > /dev/null; awk '{printf "cpu %.1f s  wall %.1f s", $1 + $2, $3}' "$out/time"; }
echo "== fit, ${res}^3 $space ($(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg))"
echo "rgb2spec_opt                       : $(t "$out/rgb2spec_opt" "$res" "$out/rgb2spec.coeff" "$rspace")"
echo "spectra, rgb2spec grid+clamp       : $(t "$bin/fit_time" "$space" "$res" "$out/spectra-rgb2spec.coeff" rgb2spec)"
echo "spectra, own grid, unrefined       : $(t "$bin/fit_time" "$space" "$res" "$out/spectra-unrefined.coeff" unrefined)"
echo "spectra, default (fit + refinement): $(t "$bin/fit_time" "$space" "$res" "$out/spectra-default.coeff" default)"
echo "== adversarial check (seed 1): max / p99 / mean ΔE2000"
summ() { python3 -c 'import json,sys
for line in sys.stdin:
    if line.startswith("adversarial (own cube"):
        d=json.loads(line.split(": ",1)[1]); s=d["stats"]
        print("%.4f / %.4f / %.4f  (%d colours, worst %s)" % (s["max"], s["p99"], s["mean"], d["colours"], [round(v, 4) for v in d["worst"][0]["rgb"]]))'; }
echo "rgb2spec_opt table, rgb2spec fetch : $("$bin/adversarial" "$space" "$out/rgb2spec.coeff" --rgb2spec-fetch | summ)"
echo "rgb2spec_opt table, spectra fetch  : $("$bin/adversarial" "$space" "$out/rgb2spec.coeff" | summ)"
echo "spectra rgb2spec grid+clamp, spectra fetch: $("$bin/adversarial" "$space" "$out/spectra-rgb2spec.coeff" | summ)"
echo "spectra unrefined, spectra fetch   : $("$bin/adversarial" "$space" "$out/spectra-unrefined.coeff" | summ)"
echo "spectra default, spectra fetch     : $("$bin/adversarial" "$space" "$out/spectra-default.coeff" | summ)"
