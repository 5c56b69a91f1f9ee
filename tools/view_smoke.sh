#!/usr/bin/env bash
# Smoke test of `spectra view` as a user would drive it, under a virtual X server.
#
#   tools/view_smoke.sh [OUT_DIR]      (default OUT_DIR: target/view-smoke)
#   SMOKE_ARGS="underwater --water II --depth 8" tools/view_smoke.sh   (other scene and flags)
#
# Starts Xvfb, opens `spectra view cornell` (or $SMOKE_ARGS), sends keys with xdotool (mode → rgb, N up, mode →
# spectral, screenshot key), drags the mouse to orbit, captures the whole screen with
# ImageMagick's `import`, and checks that the screenshot key wrote a non-empty PNG. Leaves
# screen-*.png and screenshot-*.png in OUT_DIR for a person to look at.
#
# Needs: apt-get install xvfb xdotool imagemagick mesa-vulkan-drivers
# Not run in CI: it takes about a minute on lavapipe and needs the packages above.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
OUT=${1:-$ROOT/target/view-smoke}
BIN=${SPECTRA_BIN:-$ROOT/target/debug/spectra}
DISPLAY_NUM=${SMOKE_DISPLAY:-:99}
read -r -a VIEW_ARGS <<<"${SMOKE_ARGS:-cornell}"
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
for tool in Xvfb xdotool import; do
    command -v "$tool" >/dev/null || { echo "missing $tool: apt-get install xvfb xdotool imagemagick" >&2; exit 2; }
done
[ -x "$BIN" ] || (cd "$ROOT" && cargo build -p spectra)
rm -f "$OUT"/screenshot-*.png "$OUT"/screen-*.png

Xvfb "$DISPLAY_NUM" -screen 0 1280x800x24 >/dev/null 2>&1 &
XVFB=$!
VIEW=
cleanup() {
    [ -n "$VIEW" ] && kill "$VIEW" 2>/dev/null || true
    kill "$XVFB" 2>/dev/null || true
}
trap cleanup EXIT
export DISPLAY=$DISPLAY_NUM
sleep 2

# No display at all must be a clear error, not a panic.
if env -u DISPLAY "$BIN" view cornell 2>"$OUT/no-display.txt"; then
    echo "FAIL: view without DISPLAY succeeded" >&2; exit 1
fi
grep -q "no window system" "$OUT/no-display.txt" || { echo "FAIL: $(cat "$OUT/no-display.txt")" >&2; exit 1; }
echo "ok: without DISPLAY: $(cat "$OUT/no-display.txt")"

(cd "$OUT" && exec "$BIN" view "${VIEW_ARGS[@]}" --size 640x480 >"$OUT/view-stdout.txt" 2>"$OUT/view-stderr.txt") &
VIEW=$!
# Wait for the window (the first frames compile pipelines on the CPU driver).
WIN=
for _ in $(seq 60); do
    WIN=$(xdotool search --name "spectra view" 2>/dev/null | head -1) && [ -n "$WIN" ] && break
    kill -0 "$VIEW" 2>/dev/null || { echo "FAIL: viewer exited:" >&2; cat "$OUT/view-stderr.txt" >&2; exit 1; }
    sleep 1
done
[ -n "$WIN" ] || { echo "FAIL: no window" >&2; exit 1; }
sleep 5
import -window root "$OUT/screen-1-start.png"

key() { xdotool windowfocus --sync "$WIN" 2>/dev/null || true; xdotool key --window "$WIN" "$@"; sleep 3; }
key 1                                  # mode rgb
import -window root "$OUT/screen-2-rgb.png"
key 3 bracketright bracketright        # spectral, N 16 → 18
key shift+bracketleft                  # N ÷ 2 → 9
key F12                                # screenshot of the render
# Orbit: drag with the left button in the right half (away from the panel).
xdotool mousemove --window "$WIN" 480 240 mousedown 1 mousemove --window "$WIN" 560 220 mouseup 1
sleep 3
key p                                  # second screenshot, after the orbit
import -window root "$OUT/screen-3-spectral-orbit.png"
# Fly forward: hold W for a second and a half.
xdotool keydown --window "$WIN" w; sleep 1.5; xdotool keyup --window "$WIN" w; sleep 2
key p                                  # third screenshot, closer to the box
import -window root "$OUT/screen-4-flown.png"
kill "$VIEW"; wait "$VIEW" 2>/dev/null || true; VIEW=

n=$(ls "$OUT"/screenshot-*.png 2>/dev/null | wc -l)
[ "$n" -ge 3 ] || { echo "FAIL: expected 3 screenshots, found $n" >&2; cat "$OUT/view-stderr.txt" >&2; exit 1; }
cmp -s "$OUT/screenshot-2.png" "$OUT/screenshot-3.png" && { echo "FAIL: flying did not change the view" >&2; exit 1; }
echo "ok: screenshot key wrote: $(tr '\n' ' ' <"$OUT/view-stdout.txt")"
echo "screens: $(ls "$OUT"/screen-*.png | tr '\n' ' ')"
