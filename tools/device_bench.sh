#!/bin/bash
# The benchmark suite, the render crate's GPU tests and `spectra eval --quick` on a lent GPU
# machine, in one prepared run (docs/benchmark.md "A real GPU"). Not used by CI.
#
# Prepare with `tools/device_pack.sh OLD_BINARY DAMAGED_HELMET_DIR [TEST ...]`, which does this,
# in the repository root of a checkout (x86-64, the binaries built here):
#   mkdir -p .dev .gl; printf '/.gl/\n/.dev/\n' >> .git/info/exclude
#   (Vulkan loader debs into .gl: /work/.library/device/README.md)
#   cargo build --release -p spectra; cargo test --release -p render --no-run
#   p=$(mktemp -d); mkdir $p/bin $p/tests
#   cp target/release/spectra $p/bin/spectra-new; cp OLD_BINARY $p/bin/spectra-old
#   cp target/release/deps/<test>-<hash> $p/tests/<test>   (the tests to run there)
#   strip $p/bin/* $p/tests/*; tar cf - -C $p bin tests | xz > .dev/pack.tar.xz
#   cp -r path/to/DamagedHelmet/glTF .dev/DamagedHelmet
#   mkdir .dev/cache; cp ~/.cache/spectra/srgb-64-v8.coeff .dev/cache/   (no table fit there)
#   cp tools/device_bench.sh .dev/run.sh
# Run there: `bash .dev/run.sh SECONDS`, carrying .gl and .dev; everything comes back in
# $OUT/res.tar, rewritten after each step so that a run cut short keeps what finished.
# DRY=1 OUT=dir S720=64x36 S1080=64x36 TESTS=... runs it here on lavapipe (no loader install).
set -u
START=$(date +%s)
BUDGET=${1:-500}
left() { echo $((START + BUDGET - $(date +%s))); }
R=/tmp/res
mkdir -p $R
pack() { tar cf "$OUT/res.tar" -C $R . 2>/dev/null; }
log() { echo "== $(date +%T) [$(left)s left] $*" | tee -a $R/steps.log; }

if [ -z "${DRY:-}" ]; then for f in .gl/*.deb; do dpkg -x "$f" /; done; ldconfig; fi
S720=${S720:-1280x720}
S1080=${S1080:-1920x1080}
TESTS=${TESTS:-/tmp/p/tests/*}
mkdir -p /tmp/p && tar xJf .dev/pack.tar.xz -C /tmp/p
NEW=/tmp/p/bin/spectra-new
OLD=/tmp/p/bin/spectra-old
export SPECTRA_CACHE_DIR=/tmp/cache
cp -r .dev/cache /tmp/cache
export XDG_RUNTIME_DIR=/tmp/xdg
mkdir -p /tmp/xdg
ASSET=$PWD/.dev/DamagedHelmet/DamagedHelmet.gltf
[ -f "$ASSET" ] || ASSET=$PWD/.dev/DamagedHelmet/DamagedHelmet.glb
(nvidia-smi; nvidia-smi -q | grep -iE "driver version|product name|clocks" ; nproc; uname -a) > $R/machine.txt 2>&1

log probe
timeout 60 $NEW bench cornell --env none --size 64x64 --frames 2 --warmup 1 --wavelengths 1 > $R/probe.txt 2>&1
if ! grep -qi nvidia $R/probe.txt; then
    export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
    log "probe again with VK_DRIVER_FILES"
    timeout 60 $NEW bench cornell --env none --size 64x64 --frames 2 --warmup 1 --wavelengths 1 > $R/probe2.txt 2>&1
    grep -qi nvidia $R/probe2.txt || { unset VK_DRIVER_FILES __EGL_VENDOR_LIBRARY_FILENAMES; log 'no NVIDIA adapter: running on what the first probe found'; }
fi
pack

suite() { # label binary size [bench flags, e.g. --shading-stage fragment]
    local t=$(( $(left) - 20 ))
    [ $t -gt 30 ] || { log "skip $1 (no time)"; return; }
    [ $t -gt 200 ] && t=200
    log "suite $1 ($2, $3 ${*:4}, timeout $t)"
    timeout $t "$2" bench --suite --suite-asset "$ASSET" --suite-sizes "$3" "${@:4}" \
        --csv $R/suite-$1.csv --markdown $R/suite-$1.md > $R/suite-$1.log 2>&1
    echo "exit $?" >> $R/suite-$1.log
    pack
}

log tests
[ -n "${DRY:-}" ] || { mkdir -p /work && ln -sfn "$PWD" /work/main; }
for t in $TESTS; do
    [ $(left) -gt 60 ] || { log "skip tests from $t"; break; }
    echo "### $(basename $t)" >> $R/tests.log
    timeout 90 "$t" --test-threads=8 --nocapture >> $R/tests.log 2>&1
    echo "exit $?" >> $R/tests.log
done
grep -E "^### |^test result|FAILED|panicked|^exit" $R/tests.log > $R/tests-summary.txt
pack

# The new binary shades in a compute pass (its default on a GPU) and, for the same run's
# comparison, in the fragment stage the old binary uses (docs/benchmark.md, "Shading in a
# compute pass").
suite new-720 $NEW $S720 --shading-stage compute
suite new-720-fragment $NEW $S720 --shading-stage fragment
suite old-720 $OLD $S720

log reference
for st in compute fragment; do
    timeout 60 $NEW bench cornell --env none --size $S720 --frames 60 --warmup 10 --wavelengths 1 --reference \
        --shading-stage $st --csv $R/reference-$st.csv > $R/reference-$st.log 2>&1
done
pack

suite new-1080 $NEW $S1080

t=$(( $(left) - 15 ))
if [ $t -gt 60 ]; then
    log "eval --quick (timeout $t)"
    timeout $t $NEW eval --quick ${EVALARGS:-} --out /tmp/evq > $R/eval.log 2>&1
    echo "exit $?" >> $R/eval.log
    cp /tmp/evq/results.json $R/eval-results.json 2>/dev/null
    cp /tmp/evq/results.csv $R/eval-results.csv 2>/dev/null
    pack
fi

log done
pack
