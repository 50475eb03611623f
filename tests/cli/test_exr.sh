#!/bin/sh
# EXR files are the same whichever library writes them. tests/fixtures/exr holds
# renders written through OpenImageIO, before ptr wrote EXR through OpenEXR
# (made by this script with --write-fixtures, ptr 0.1.0 at commit 3f97619).
# Every case is rendered again and read back by OpenImageIO: the same pixels,
# bit for bit, and the same attributes (but for those that change from run to
# run: the date, the timings, the kernel this CPU picked; and the scene's
# fingerprint, which the fixtures record as ptr then did, ptr:scene_hash, and
# which is now ptr:scene_xxh3, its value held below). ptr merge takes the old
# parts together, and refuses them beside new ones. (test_startup.sh checks
# that they load no OpenImageIO.)
# Usage: test_exr.sh PTR SOURCE_DIR [--write-fixtures]
# (--write-fixtures would write ptr:scene_xxh3, and the checks of old parts
# below would then fail: the fixtures stay as that build wrote them.)
set -u
ptr=$1
src=$2
. "$src/tests/support/shell_test.sh"
fixtures=$src/tests/fixtures/exr

# render_cases DIR: every EXR feature, one file each (the scene path as the
# attribute ptr:scene records it, relative to the source folder).
render_cases() {
    common="scenes/seed.gltf --width 16 --samples 4 --quiet"
    # shellcheck disable=SC2086 # $common is split on purpose
    (cd "$src" &&
        "$ptr" $common -o "$1/float.exr" &&
        "$ptr" $common -o "$1/half_region.exr" --depth half --region 2,3,10,12 &&
        "$ptr" $common -o "$1/adaptive.exr" --noise-threshold 0.05 --min-samples 2 &&
        "$ptr" $common -o "$1/part0.exr" --sample-range 0:2 &&
        "$ptr" $common -o "$1/part1.exr" --sample-range 2:4 --depth half)
}

if [ "${3:-}" = --write-fixtures ]; then
    mkdir -p "$fixtures" && render_cases "$fixtures" && exit 0
    exit 1
fi

# What OpenImageIO reads of a file's header, less what changes between runs
# and the scene's fingerprint, which the fixtures record as ptr did before
# (ptr:scene_hash, FNV-1a; now ptr:scene_xxh3).
header() {
    iinfo -v "$1" | tail -n +2 |
        grep -v -e DateTime -e '_seconds:' -e 'ptr:kernel:' -e 'Software:' \
            -e 'ptr:scene_hash:' -e 'ptr:scene_xxh3:'
}

render_cases "$dir" || fail "render: exit code $?"
for file in "$fixtures"/*.exr; do
    name=$(basename "$file")
    idiff -q -a -fail 0 -failpercent 0 "$file" "$dir/$name" >"$dir/idiff" 2>&1 ||
        fail "$name: the pixels differ from the OpenImageIO-written file: $(cat "$dir/idiff")"
    header "$file" >"$dir/old.txt"
    header "$dir/$name" >"$dir/new.txt"
    diff "$dir/old.txt" "$dir/new.txt" >"$dir/diff" ||
        fail "$name: the header reads differently: $(cat "$dir/diff")"
    iinfo -v "$dir/$name" | grep -q 'Software: "ptr ' || fail "$name: no Software attribute"
    iinfo -v "$dir/$name" | grep -q 'DateTime: "' || fail "$name: no DateTime attribute"
    # The fingerprint of scenes/seed.gltf: parts written by this build must
    # merge with parts of later ones, so its value is part of the format.
    iinfo -v "$dir/$name" | grep -q 'ptr:scene_xxh3: "fc392ac48e808c75"' ||
        fail "$name: not seed.gltf's ptr:scene_xxh3 fc392ac48e808c75: $(iinfo -v "$dir/$name" | grep scene_)"
done

# Parts written by the OpenImageIO build merge into the render of all samples.
"$ptr" merge "$fixtures/part0.exr" "$fixtures/part1.exr" -o "$dir/merged.exr" --quiet ||
    fail "merge of old parts: exit code $?"
"$ptr" merge "$dir/part0.exr" "$dir/part1.exr" -o "$dir/merged_new.exr" --quiet ||
    fail "merge of new parts: exit code $?"
idiff -q -a -fail 0 -failpercent 0 "$dir/merged.exr" "$dir/merged_new.exr" >/dev/null 2>&1 ||
    fail "old parts merge to other pixels than new ones"
# Old parts merged keep their fingerprint under its own name.
old_hash=$(iinfo -v "$fixtures/part0.exr" | grep 'ptr:scene_hash:')
[ -n "$old_hash" ] && [ "$(iinfo -v "$dir/merged.exr" | grep 'ptr:scene_hash:')" = "$old_hash" ] &&
    ! iinfo -v "$dir/merged.exr" | grep -q 'ptr:scene_xxh3:' ||
    fail "old parts merged: not their own ptr:scene_hash"
# Old parts beside new ones cannot be matched to their scene: refused, in
# either order, one line naming the first old part and how many are old, no
# output.
mixed() {
    expected=$1
    shift
    "$ptr" merge "$@" -o "$dir/mixed.exr" --quiet 2>"$dir/err"
    code=$?
    [ $code = 2 ] || fail "merge of old and new parts ($*): exit code $code, not 2"
    [ "$(wc -l <"$dir/err")" = 1 ] && grep -q "^ptr: $expected" "$dir/err" ||
        fail "merge of old and new parts ($*): not one line saying '$expected': $(cat "$dir/err")"
    [ ! -e "$dir/mixed.exr" ] || fail "merge of old and new parts ($*) wrote an output"
}
mixed "$fixtures/part1.exr: written by an older ptr than $dir/part0.exr .*; parts so written: 1 of 2" \
    "$dir/part0.exr" "$fixtures/part1.exr"
mixed "$fixtures/part0.exr: written by an older ptr than $dir/part1.exr .*; parts so written: 2 of 3" \
    "$fixtures/part0.exr" "$fixtures/part1.exr" "$dir/part1.exr"

# Broken parts: exit 2 and one line naming the file, the output untouched.
: >"$dir/empty.exr"
printf 'not an image at all' >"$dir/garbage.exr"
head -c 400 "$fixtures/float.exr" >"$dir/header_cut.exr"
head -c 3000 "$fixtures/float.exr" >"$dir/pixels_cut.exr"
for name in empty garbage header_cut pixels_cut; do
    echo "an existing image" >"$dir/out.exr"
    "$ptr" merge "$dir/$name.exr" -o "$dir/out.exr" --quiet 2>"$dir/err"
    code=$?
    [ $code = 2 ] || fail "merge $name.exr: exit code $code, not 2"
    [ "$(wc -l <"$dir/err")" = 1 ] && grep -q "^ptr: $dir/$name.exr: " "$dir/err" ||
        fail "merge $name.exr: not one line naming the file: $(cat "$dir/err")"
    [ "$(cat "$dir/out.exr")" = "an existing image" ] || fail "merge $name.exr: output changed"
done

finish "EXR through OpenEXR: the same files as through OpenImageIO"
