#!/usr/bin/env bash
# Screenshot an eval report (DIR/index.html) in headless Chromium, as a new user would see it.
# Usage: tools/report_screenshot.sh DIR [OUT.png]   (default OUT: DIR/screenshot.png)
set -euo pipefail
dir=${1:?usage: tools/report_screenshot.sh DIR [OUT.png]}
out=${2:-$dir/screenshot.png}
[ -f "$dir/index.html" ] || { echo "error: $dir/index.html not found (run spectra eval --out $dir first)" >&2; exit 1; }
browser=$(command -v chromium || command -v chromium-browser || true)
[ -n "$browser" ] || { echo "error: chromium not installed (apt-get install chromium)" >&2; exit 1; }
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
"$browser" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
  --disable-component-update --disable-sync --user-data-dir="$profile" --screenshot="$(realpath -m "$out")" \
  --window-size=1400,2000 "file://$(realpath "$dir")/index.html" >/dev/null 2>&1
[ -s "$out" ] || { echo "error: chromium wrote no screenshot to $out" >&2; exit 1; }
echo "$out"
