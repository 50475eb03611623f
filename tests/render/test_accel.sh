#!/bin/sh
# --accel brute and --accel bvh (C, and the fastest kernels the CPU has) give
# the same pixels, bit for bit, through the command line: on the committed
# scenes and on sphere sets hard for a tree (tests/support/hard_scenes.py).
# Also checks the metadata the choice leaves, and that parts rendered with
# each merge.
# Usage: test_accel.sh PTR SOURCE_DIR
set -u
ptr=$1
src=$2
. "$src/tests/support/shell_test.sh"
# Whether two images hold the same pixels, bit for bit.
same_pixels() { idiff -q -fail 0 -failpercent 0 -warn 0 "$1" "$2" >/dev/null; }
python3 "$src/tests/support/hard_scenes.py" "$dir" || exit 1
scenes="$src/scenes/seed.gltf $src/scenes/final.gltf"
for json in "$dir"/*.json; do
    python3 "$src/scripts/make_scenes.py" "$json" "${json%.json}.gltf" || exit 1
    scenes="$scenes ${json%.json}.gltf"
done
for scene in $scenes; do
    name=$(basename "$scene" .gltf)
    for accel in brute bvh; do
        "$ptr" "$scene" -o "$dir/$name-$accel.exr" --accel $accel --c --samples 3 --width 96 \
            --threads 2 --quiet || fail "$name: ptr --accel $accel failed"
    done
    same_pixels "$dir/$name-brute.exr" "$dir/$name-bvh.exr" ||
        fail "$name: --accel brute and --accel bvh differ"
    # The fastest kernels the machine has (brute force and traversal in
    # assembly where there are), against brute force in C.
    "$ptr" "$scene" -o "$dir/$name-fastest.exr" --accel bvh --samples 3 --width 96 --threads 2 \
        --quiet || fail "$name: ptr --accel bvh failed"
    same_pixels "$dir/$name-brute.exr" "$dir/$name-fastest.exr" ||
        fail "$name: --accel brute --c and --accel bvh with the fastest kernels differ"
    for accel in brute bvh; do
        iinfo -v "$dir/$name-$accel.exr" | grep -q "ptr:accel: \"$accel\"" ||
            fail "$name: no ptr:accel \"$accel\" in the metadata"
    done
    hashes=$(for accel in brute bvh; do iinfo -v "$dir/$name-$accel.exr" | grep scene_xxh3; done | sort -u | wc -l)
    [ "$hashes" = 1 ] || fail "$name: the scene hash depends on the structure"
done
# A part rendered with the tree merges with one rendered by brute force (the
# scene hash does not see the tree's order), into the very image two brute
# force parts give.
final="$src/scenes/final.gltf"
for accel in brute bvh; do
    "$ptr" "$final" -o "$dir/part-$accel.exr" --accel $accel --sample-range 2:4 --width 64 --quiet ||
        fail "rendering a part with --accel $accel"
done
"$ptr" "$final" -o "$dir/part0.exr" --accel brute --sample-range 0:2 --width 64 --quiet &&
"$ptr" merge "$dir/part0.exr" "$dir/part-bvh.exr" -o "$dir/merged.exr" --quiet &&
"$ptr" merge "$dir/part0.exr" "$dir/part-brute.exr" -o "$dir/merged-brute.exr" --quiet ||
    fail "merging the parts"
same_pixels "$dir/merged.exr" "$dir/merged-brute.exr" ||
    fail "parts of brute force and the tree do not merge as brute force parts do"
iinfo -v "$dir/merged.exr" | grep -q 'ptr:accel: "mixed"' ||
    fail "the merged image does not say its parts used both"
# The JSON names the integrator: by default what --print-dispatch shows for
# the level in use; --c changes the kernel, not the integrator; --integrator
# and $PTR_INTEGRATOR choose it, the option first; one the CPU level cannot
# run is refused before any scene is read.
integrator_of() {
    "$ptr" "$src/scenes/seed.gltf" -o "$dir/p.exr" --samples 1 --width 16 --quiet --json "$@" |
        sed -E 's/.*"integrator": "([a-z]*)".*/\1/'
}
expected=$("$ptr" --print-dispatch | grep 'in use' | awk '{print $3}')
[ "$(integrator_of)" = "$expected" ] ||
    fail "the JSON's integrator is not what --print-dispatch shows in use ($expected)"
[ "$(integrator_of --c)" = "$expected" ] || fail "--c changed the integrator"
[ "$(integrator_of --integrator paths)" = paths ] || fail "--integrator paths was not used"
[ "$(PTR_INTEGRATOR=paths integrator_of)" = paths ] || fail "PTR_INTEGRATOR=paths was not used"
if [ "$expected" = bundles ]; then
    [ "$(PTR_INTEGRATOR=paths integrator_of --integrator bundles)" = bundles ] ||
        fail "--integrator does not override \$PTR_INTEGRATOR"
    [ "$(integrator_of --c --integrator bundles)" = bundles ] ||
        fail "--integrator bundles with --c was not used"
else
    "$ptr" "$src/scenes/seed.gltf" -o "$dir/p.exr" --integrator bundles 2>"$dir/err"
    [ $? = 2 ] && grep -q -- "--integrator bundles" "$dir/err" ||
        fail "--integrator bundles below AVX2 is not refused: $(cat "$dir/err")"
fi
PTR_INTEGRATOR=sideways "$ptr" "$src/scenes/seed.gltf" -o "$dir/p.exr" 2>/dev/null
[ $? = 2 ] || fail "a bad PTR_INTEGRATOR is not refused"
finish "all scenes identical, parts merge, integrator reported and chosen"
