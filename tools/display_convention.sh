#!/usr/bin/env bash
# The display convention across renderers (docs/cameras.md, docs/spectral-exr.md): one model
# rendered by both renderers at the default range, narrowed ranges, few nodes and the 10°
# observer, then
#   (a) the path tracer's image against the real-time one (mean ΔE2000, mean |Δ| linear), and
#   (b) the real-time `--out` against its own `--spectral-out` re-integrated by `spectra diff`.
# Usage: tools/display_convention.sh SPECTRA_BINARY MODEL.gltf|glb [OUT_DIR]
set -euo pipefail
bin=$1
model=$2
out=${3:-display-convention}
mkdir -p "$out"
stat() {
  "$bin" diff "$1" "$2" --json | python3 -c 'import json, sys
d = json.load(sys.stdin)
print("mean dE2000 %.3f  max %.3f  mean |d| %.2e" % (d["delta_e2000"]["mean"], d["delta_e2000"]["max"], d["mae_linear"]["mean"]))'
}
echo "# (a) truth (64 spp) vs real time, 128x96"
for cfg in "default|" "450-650|--range 450:650" "500-510|--range 500:510" "cie1964|--observer cie1964"; do
  tag=${cfg%%|*}
  read -r -a args <<< "${cfg#*|}"
  "$bin" render "$model" --size 128x96 "${args[@]}" --out "$out/rt-$tag.exr" > /dev/null 2>&1
  "$bin" truth "$model" --size 128x96 --spp 64 "${args[@]}" --out "$out/truth-$tag.exr" > /dev/null 2>&1
  echo "$tag: $(stat "$out/truth-$tag.exr" "$out/rt-$tag.exr")"
done
echo "# (b) --out vs its --spectral-out, 128x96"
for cfg in "N16-midpoint|--quadrature midpoint" "N3-midpoint|--wavelengths 3 --quadrature midpoint" \
  "450-650-N64-midpoint|--range 450:650 --wavelengths 64 --quadrature midpoint" \
  "500-510-midpoint|--range 500:510 --quadrature midpoint" "N16-prefiltered|" "N3-prefiltered|--wavelengths 3" \
  "450-650-N64-prefiltered|--range 450:650 --wavelengths 64"; do
  tag=${cfg%%|*}
  read -r -a args <<< "${cfg#*|}"
  "$bin" render "$model" --size 128x96 "${args[@]}" --out "$out/$tag.exr" --spectral-out "$out/$tag-s.exr" > /dev/null 2>&1
  echo "$tag: $(stat "$out/$tag.exr" "$out/$tag-s.exr")"
done
