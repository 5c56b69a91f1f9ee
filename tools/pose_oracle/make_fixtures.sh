#!/usr/bin/env bash
# Regenerates the pose fixtures in crates/scene/tests/data/pose/ with the three.js oracle.
#
#   bash tools/pose_oracle/make_fixtures.sh [ASSETS]
#
# ASSETS (default /tmp/assets/anim) holds the Khronos sample assets as <Model>/<Model>.gltf plus
# their .bin files. For each fixture model this copies the .gltf and its .bin files (never the
# images: a model that references images gets a copy of its .gltf with images, textures,
# samplers and texture references removed, see strip_images below), then writes the oracle's
# output at rest (three-rest.json) and at each (animation index, time) below
# (three-<index>-<time>.json), and an index.json listing them. LICENSE.md files are not
# touched (they are written by hand). The models that are not fixtures (too big, or not freely
# redistributable) are posed the same way into target/pose_oracle/<Model>/, for comparing by hand
# with tools/pose_check.py.
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
assets="${1:-/tmp/assets/anim}"
oracle="$repo/tools/pose_oracle/pose.mjs"
out="$repo/crates/scene/tests/data/pose"
scratch="$repo/target/pose_oracle"

if [ ! -d "$repo/tools/pose_oracle/node_modules/three" ]; then
	(cd "$repo/tools/pose_oracle" && npm ci --no-audit --no-fund)
fi

# "model|animation:time,time,... animation:time,..." (animations by index; nothing after | = rest only)
FIXTURES=(
	"SimpleSkin|0:0,1.25,2.75,10"
	"RiggedSimple|0:0,1,1.01,5"
	"SimpleMorph|0:0,1.5,2.25,6"
	"AnimatedMorphCube|0:0,2.1,2.345,10"
	"AnimatedTriangle|0:0,0.375,0.6,2"
	"BoxAnimated|0:0,1,1.875,3,5"
	"InterpolationTest|0:0,0.6,1.25,3 1:0,0.6,1.25,3 2:0,0.6,1.25,3 3:0,0.6,1.25,3 4:0,0.6,1.25,3 5:0,0.6,1.25,3 6:0,0.6,1.25,3 7:0,0.6,1.25,3 8:0,0.6,1.25,3"
	"RiggedFigure|0:0,0.6,1.13,5"
	"MorphPrimitivesTest|"
	"Fox|0:1 1:0.35 2:0.5,5"
)
SCRATCH=(
	"CesiumMan|0:0,1,1.03,5"
	"RecursiveSkeletons|0:0,1,1.5,5"
	"NegativeScaleTest|"
	"Fox|0:0,1.7,10 1:0.2,0.5 2:0,1,5"
)

# Copies MODEL's .gltf and the .bin files it names into DEST. With images, writes the .gltf
# without them instead (and says so on stderr).
copy_model() {
	local model=$1 dest=$2
	mkdir -p "$dest"
	python3 - "$assets/$model/$model.gltf" "$dest" <<'PY'
import json, os, shutil, sys
src, dest = sys.argv[1], sys.argv[2]
d = json.load(open(src))
srcdir = os.path.dirname(src)
for b in d.get("buffers", []):
    uri = b.get("uri", "")
    if uri and not uri.startswith("data:"):
        shutil.copyfile(os.path.join(srcdir, uri), os.path.join(dest, uri))
if not d.get("images"):
    shutil.copyfile(src, os.path.join(dest, os.path.basename(src)))
    sys.exit(0)

def strip(o):  # texture references: {"index": n, ...} objects under keys ending in "Texture"
    if isinstance(o, dict):
        for k in list(o):
            if k.endswith("Texture") and isinstance(o[k], dict) and "index" in o[k]:
                del o[k]
            else:
                strip(o[k])
    elif isinstance(o, list):
        for x in o:
            strip(x)

for k in ("images", "textures", "samplers"):
    d.pop(k, None)
strip(d.get("materials", []))
for k in ("extensionsUsed", "extensionsRequired"):
    if k in d:
        d[k] = [e for e in d[k] if e not in ("KHR_texture_transform", "KHR_texture_basisu", "EXT_texture_webp")]
        if not d[k]:
            del d[k]
with open(os.path.join(dest, os.path.basename(src)), "w") as f:
    json.dump(d, f, indent=2)
    f.write("\n")
print(f"{os.path.basename(src)}: copied without its images, textures and samplers", file=sys.stderr)
PY
}

# Poses DIR/MODEL.gltf once (NAME: rest or ANIM-TIME; ARGS: the oracle's options). Where
# normalising rotations first (--normalize-rotations) moves a corner by more than 1e-6 of the
# bounding-box diagonal, keeps that pose too, as three-normrot-NAME.json.
pose_one() {
	local model=$1 dir=$2 name=$3 anim=$4 t=$5; shift 5
	node "$oracle" "$dir/$model.gltf" "$@" > "$dir/three-$name.json"
	node "$oracle" "$dir/$model.gltf" "$@" --normalize-rotations > "$tmpdir/norm.json"
	local diff
	diff=$({ python3 "$repo/tools/pose_check.py" --quiet "$dir/three-$name.json" "$tmpdir/norm.json" || true; } |
		sed -n 's/.*worst \([^ ]*\) relative.*/\1/p')
	if python3 -c "import sys; sys.exit(0 if float('$diff') > 1e-6 else 1)"; then
		cp "$tmpdir/norm.json" "$dir/three-normrot-$name.json"
		echo "$model|$name|$anim|$t|$diff|three-normrot-$name.json" >> "$index_lines"
	else
		echo "$model|$name|$anim|$t|$diff|" >> "$index_lines"
	fi
}

# Poses DIR/MODEL.gltf at rest and at each time of SPEC.
pose_all() {
	local model=$1 spec=$2 dir=$3
	pose_one "$model" "$dir" rest "" ""
	local item anim t
	for item in $spec; do
		anim=${item%%:*}
		IFS=, read -r -a times <<< "${item#*:}"
		for t in "${times[@]}"; do
			pose_one "$model" "$dir" "$anim-$t" "$anim" "$t" --animation "$anim" --time "$t"
		done
	done
}

tmpdir="$(mktemp -d)"
trap 'rm -rf "$tmpdir"' EXIT
index_lines="$tmpdir/index"

for entry in "${FIXTURES[@]}"; do
	model=${entry%%|*}
	spec=${entry#*|}
	rm -f "$out/$model"/*.gltf "$out/$model"/*.bin "$out/$model"/three-*.json
	copy_model "$model" "$out/$model"
	pose_all "$model" "$spec" "$out/$model"
	echo "fixture $model" >&2
done
python3 - "$index_lines" "$out/index.json" <<'PY'
import json, sys
rows = []
for line in open(sys.argv[1]):
    model, name, anim, t, diff, normrot = line.rstrip("\n").split("|")
    d = json.load(open(f"{sys.argv[2].rsplit('/', 1)[0]}/{model}/three-{name}.json"))
    rows.append({
        "model": model,
        "gltf": f"{model}/{model}.gltf",
        "oracle": f"{model}/three-{name}.json",
        "animation": int(anim) if anim else None,
        "animation_name": (d.get("animation") or {}).get("name"),
        "time": float(t) if t else None,
        "time_arg": t or None,
        "meshes": len(d["meshes"]),
        "triangles": sum(len(m["triangles"]) for m in d["meshes"]),
        "normalize_rotations_moves": float(diff),
        "oracle_normalized_rotations": f"{model}/{normrot}" if normrot else None,
    })
with open(sys.argv[2], "w") as f:
    json.dump({"three": d.get("three"), "fixtures": rows}, f, indent=1)
    f.write("\n")
PY

for entry in "${SCRATCH[@]}"; do
	model=${entry%%|*}
	spec=${entry#*|}
	mkdir -p "$scratch/$model"
	rm -f "$scratch/$model"/three-*.json
	node "$oracle" "$assets/$model/$model.gltf" > "$scratch/$model/three-rest.json"
	for item in $spec; do
		anim=${item%%:*}
		IFS=, read -r -a times <<< "${item#*:}"
		for t in "${times[@]}"; do
			node "$oracle" "$assets/$model/$model.gltf" --animation "$anim" --time "$t" > "$scratch/$model/three-$anim-$t.json"
		done
	done
	echo "scratch $model -> $scratch/$model" >&2
done
du -sh "$out" >&2

# The hand check and the mixed-interpolation fuzz seed (crates/scene/tests/pose.rs,
# hand_derived_poses_and_the_mixed_interpolations): the hand poses are copied from test/, the
# seed's from the oracle with its keys made unit.
hand="$out/hand"
mkdir -p "$hand"
cp "$repo/tools/pose_oracle/test/skin_morph_triangle.gltf" "$repo"/tools/pose_oracle/test/expected-*.json "$hand/"
cp "$repo/crates/fuzz/corpus/gltf/skin-morph-animation.gltf" "$hand/mixed.gltf"
for t in 0.3 0.5 1 2; do
	node "$oracle" "$hand/mixed.gltf" --animation mixed --time "$t" --normalize-rotations > "$hand/three-mixed-$t.json"
done
