#!/bin/bash
# Fills .dev/ and .gl/ for tools/device_bench.sh (a lent GPU machine; see its header):
#   tools/device_pack.sh OLD_SPECTRA_BINARY DAMAGED_HELMET_DIR [TEST ...]
# (DAMAGED_HELMET_DIR holds DamagedHelmet.gltf with its files, or DamagedHelmet.glb. The Khronos
# sample repositories are larger than this workplace's fetch tool brings (500 MB); the fetchable
# github:googlestadia/PorQue4K holds the model's earlier export (same textures, 552 200-byte .bin):
#   git -C /work/.mirror/googlestadia+PorQue4K/repo archive HEAD assets/models/DamagedHelmet/glTF | tar x -C /tmp/dh
#   -> /tmp/dh/assets/models/DamagedHelmet/glTF)
# builds this checkout's release binary and render tests, strips and packs them (xz) with the
# old binary to compare against, the asset, the cached coefficient table and the run script,
# and downloads the Vulkan loader debs. Prints what will travel; keep it under 64 MiB.
# Then: run `bash .dev/run.sh SECONDS` there, carrying .gl and .dev.
set -euo pipefail
old=${1:?old spectra binary}
asset=${2:?directory holding DamagedHelmet.gltf or DamagedHelmet.glb}
shift 2
tests=("$@")
[ ${#tests[@]} -gt 0 ] || tests=(shading_stage environment underwater pipeline material_spectra films transmission shadows gltf_features accumulation)
cd "$(git rev-parse --show-toplevel)"
[ -f "$asset/DamagedHelmet.gltf" ] || [ -f "$asset/DamagedHelmet.glb" ] || { echo "no DamagedHelmet.gltf or .glb in $asset" >&2; exit 1; }
table=${SPECTRA_CACHE_DIR:-$HOME/.cache/spectra}/srgb-64-v8.coeff
[ -f "$table" ] || { echo "no $table: run \`spectra lut\` once" >&2; exit 1; }
grep -qx '/.dev/' .git/info/exclude 2>/dev/null || printf '/.gl/\n/.dev/\n' >> .git/info/exclude
cargo build --release -p spectra
exes=$(cargo test --release -p render --no-run 2>&1 | sed -n 's/.*Executable tests\/\(.*\)\.rs (\(.*\))/\1 \2/p')
p=$(mktemp -d)
mkdir "$p/bin" "$p/tests"
cp target/release/spectra "$p/bin/spectra-new"
cp "$old" "$p/bin/spectra-old"
for t in "${tests[@]}"; do
    f=$(echo "$exes" | awk -v t="$t" '$1 == t {print $2}')
    [ -n "$f" ] || { echo "no render test named $t" >&2; exit 1; }
    cp "$f" "$p/tests/$t"
done
strip "$p"/bin/* "$p"/tests/*
rm -rf .dev && mkdir -p .dev/cache .gl
tar cf - -C "$p" bin tests | xz -T0 > .dev/pack.tar.xz
rm -rf "$p"
cp -r "$asset" .dev/DamagedHelmet
cp "$table" .dev/cache/
cp tools/device_bench.sh .dev/run.sh
if ! ls .gl/libvulkan1_*.deb > /dev/null 2>&1; then
    mkdir -p /tmp/amd64/partial
    o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
    apt-get $o update > /dev/null
    (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
fi
du -sh .dev .gl
echo "travels with the tree: $(( $(du -sb .dev | cut -f1) / 1048576 + $(du -sb .gl | cut -f1) / 1048576 )) MiB + the checkout"
