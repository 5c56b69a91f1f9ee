#!/usr/bin/env bash
# Checks the oracle against the hand-computed poses of skin_morph_triangle.gltf (README.md,
# "Hand check"), and pose_check.py against itself and a perturbed copy.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
oracle="$here/../pose.mjs"
check="$here/../../pose_check.py"
gltf="$here/skin_morph_triangle.gltf"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
pass=0 fail=0
expect() { # NAME EXPECTED_STATUS COMMAND...
	local name=$1 want=$2; shift 2
	local got=0
	"$@" > "$tmp/log" 2>&1 || got=$?
	if [ "$got" = "$want" ]; then pass=$((pass + 1)); echo "ok   $name"
	else fail=$((fail + 1)); echo "FAIL $name (exit $got, wanted $want)"; cat "$tmp/log"; fi
}
node "$oracle" "$gltf" > "$tmp/rest.json"
expect "rest pose" 0 python3 "$check" --tol 1e-6 "$tmp/rest.json" "$here/expected-rest.json"
for t in 0 0.5 1; do
	node "$oracle" "$gltf" --animation bend --time $t > "$tmp/bend-$t.json"
	expect "bend t=$t" 0 python3 "$check" --tol 1e-6 "$tmp/bend-$t.json" "$here/expected-bend-$t.json"
done
node "$oracle" "$gltf" --animation 0 --time 2 > "$tmp/bend-2.json"
expect "bend t=2 holds the last key" 0 python3 "$check" --tol 1e-6 "$tmp/bend-2.json" "$here/expected-bend-1.json"
node "$oracle" "$gltf" --animation 0 --time -1 > "$tmp/bend--1.json"
expect "bend t=-1 holds the first key" 0 python3 "$check" --tol 1e-6 "$tmp/bend--1.json" "$here/expected-bend-0.json"
expect "t=0.5 is not the rest pose" 1 python3 "$check" --tol 1e-6 "$tmp/bend-0.5.json" "$here/expected-rest.json"
python3 - "$tmp/bend-0.5.json" "$tmp/perturbed.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
t = d["meshes"][0]["triangles"][0]
t[0], t[1] = t[1], t[0]          # a mirrored winding: still the same triangle
json.dump(d, open(sys.argv[2].replace(".json", "-swapped.json"), "w"))
t[2][2] += 1e-3                   # 1e-3 / diagonal ~ 4e-4 relative
json.dump(d, open(sys.argv[2], "w"))
PY
expect "swapped corners compare equal" 0 python3 "$check" "$tmp/bend-0.5.json" "$tmp/perturbed-swapped.json"
expect "perturbed corner fails at 1e-4" 1 python3 "$check" "$tmp/bend-0.5.json" "$tmp/perturbed.json"
expect "perturbed corner passes at 1e-3" 0 python3 "$check" --tol 1e-3 "$tmp/bend-0.5.json" "$tmp/perturbed.json"
expect "unknown animation is refused" 2 node "$oracle" "$gltf" --animation nope
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
