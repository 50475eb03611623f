#!/bin/sh
# Renders every scene in scenes/ and every valid scene file among the test
# fixtures with two builds of ptr and compares the EXR pixels bit for bit
# (idiff, from openimageio-tools): for a change that must not change any
# image. Extra arguments go to both (e.g. --c); OLD_PTR and NEW_PTR may carry
# options of their own: "build/src/ptr --integrator paths".
# Usage: scripts/compare_builds.sh OLD_PTR NEW_PTR [ptr options]   (from the source folder)
set -u
old=$1 new=$2
shift 2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
same=0 differ=0 failed=0
for scene in scenes/*.gltf tests/fixtures/*.gltf tests/fixtures/*.glb \
    tests/fixtures/instancing/*.gltf tests/fixtures/instancing/*.glb \
    tests/fixtures/blender/*.gltf tests/fixtures/blender/*.glb tests/fixtures/blender/*.obj \
    tests/fixtures/obj/*.obj; do
    [ -f "$scene" ] || continue
    $old "$scene" -o "$out/old.exr" --width 160 --samples 16 --quiet "$@" 2>/dev/null
    old_code=$?
    $new "$scene" -o "$out/new.exr" --width 160 --samples 16 --quiet "$@" 2>/dev/null
    new_code=$?
    if [ $old_code -ne 0 ] && [ $old_code -eq $new_code ]; then
        failed=$((failed + 1))
        echo "both refuse: $scene (exit $old_code)"
    elif [ $old_code -eq 0 ] && [ $new_code -eq 0 ] &&
        idiff -q -a -fail 0 -failpercent 0 "$out/old.exr" "$out/new.exr" >/dev/null 2>&1; then
        same=$((same + 1))
    else
        differ=$((differ + 1))
        echo "DIFFER: $scene (exit $old_code, then $new_code)"
    fi
    rm -f "$out"/*.exr
done
echo "$same scenes identical, $differ differ, $failed refused by both"
[ $differ -eq 0 ]
