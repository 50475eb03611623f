#!/bin/sh
# Runs the GNU parallel recipes of docs/distributed.md as written there (the
# fenced blocks tagged recipe=...), on a small image, and checks that the merged
# image equals a single render to within float rounding.
# Usage: test_parallel_recipe.sh PTR_BUILD_BIN_DIR SOURCE_DIR
set -eu
bin=$(cd "$1" && pwd)
src=$(cd "$2" && pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
export PATH="$bin:$PATH"

recipe() {
    awk -v tag="recipe=$1" '
        $0 ~ "^```sh " tag "$" { on = 1; next }
        on && /^```/ { exit }
        on { print }' "$src/docs/distributed.md"
}

passed=0
failed=0
cd "$dir"
cp "$src/scenes/final.gltf" scene.gltf
ptr scene.gltf -o single.exr --samples 16 --width 96 --quiet

for name in parallel-local parallel-ssh; do
    script=$(recipe "$name")
    if [ -z "$script" ]; then
        echo "FAIL: no recipe=$name block in docs/distributed.md" >&2
        failed=$((failed + 1))
        continue
    fi
    rm -rf parts merged.exr
    if SCENE=scene.gltf OUT=merged.exr PARTS=4 SPP=16 JOBS=2 OPTS="--width 96" HOSTS=: \
        sh -eu -c "$script" && oiiotool single.exr merged.exr --diff --fail 1e-5 >diff.log 2>&1; then
        passed=$((passed + 1))
    else
        echo "FAIL: recipe $name" >&2
        cat diff.log >&2 2>/dev/null || true
        failed=$((failed + 1))
    fi
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
