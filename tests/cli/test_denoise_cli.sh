#!/bin/sh
# Denoising where users meet it: --denoise on a render, ptr denoise on an EXR
# with the passes, ptr merge --denoise, --transparent, threads and CPU levels,
# and the errors (missing weights, an image without the passes). The weights
# come from $PTR_WEIGHTS_DIR, else where scripts/install-deps.sh puts them;
# without them only the missing-weights error is checked, and the test is
# skipped. Needs iinfo, idiff and oiiotool (openimageio-tools).
# Usage: test_denoise_cli.sh PTR SOURCE_DIR
set -u
ptr=$1
src=$2
. "$src/tests/support/shell_test.sh"

scene="$src/scenes/seed.gltf --width 48 --quiet"
# shellcheck disable=SC2086 # $scene and the options are split on purpose
render() { "$ptr" $scene "$@"; }

# same A B [WHAT]: every channel of two images holds the same bits.
same() { idiff -q -a -fail 0 -failpercent 0 "$1" "$2" >/dev/null 2>&1; }
# channels IN OUT SPEC: the channels oiiotool's --ch SPEC names, as R, G, B.
channels() { oiiotool "$1" --ch "$3" -o "$2"; }
# rms A B: the root-mean-square difference of two images' R, G and B.
rms() { idiff -a "$1" "$2" 2>/dev/null | sed -n 's/.*RMS error = //p'; }
# one_line FILE PATTERN: FILE (ptr's stderr) is one line matching PATTERN.
one_line() { [ "$(wc -l <"$1")" = 1 ] && grep -q -- "$2" "$1"; }

# A missing weight file: exit 10, one line naming the folder and the fix,
# and no output written over the existing one.
mkdir "$dir/empty"
echo "an existing image" >"$dir/kept.exr"
PTR_WEIGHTS_DIR=$dir/empty render --samples 1 --denoise -o "$dir/kept.exr" 2>"$dir/err"
code=$?
[ $code = 10 ] || fail "missing weights: exit code $code, not 10"
one_line "$dir/err" "^ptr: $dir/empty/" ||
    fail "missing weights: not one line naming the file: $(cat "$dir/err")"
[ "$(cat "$dir/kept.exr")" = "an existing image" ] || fail "missing weights: output changed"

weights=${PTR_WEIGHTS_DIR:-/usr/local/share/ptr/weights}
if [ ! -f "$weights/rt_hdr_alb_nrm.tza" ]; then
    echo "skipped: no weights in $weights (scripts/install-deps.sh installs them)"
    exit 77
fi

# --denoise writes the denoised colour, the noisy one and the passes.
render --samples 4 --denoise -o "$dir/denoised.exr" || fail "--denoise: exit code $?"
iinfo -v "$dir/denoised.exr" >"$dir/info"
for channel in R G B noisy.R noisy.G noisy.B albedo.R albedo.G albedo.B normal.X normal.Y normal.Z
do
    grep -q "channel list:.* $channel\(,\|$\)" "$dir/info" || fail "--denoise: no channel $channel"
done
grep -q 'ptr:denoised: "balanced"' "$dir/info" || fail "--denoise: no ptr:denoised in the header"

# Its noisy layer is the plain render's colour, and the denoised colour is
# another, closer to a 1024-sample render: its RMS error at most 0.8 times
# the noisy colour's (0.65 with OIDN's default network on this image).
render --samples 4 -o "$dir/noisy.exr" || fail "plain render: exit code $?"
render --samples 1024 -o "$dir/reference.exr" || fail "reference: exit code $?"
channels "$dir/denoised.exr" "$dir/rgb.exr" R,G,B
channels "$dir/denoised.exr" "$dir/noisy_layer.exr" R=noisy.R,G=noisy.G,B=noisy.B
same "$dir/noisy.exr" "$dir/noisy_layer.exr" || fail "noisy.R/G/B is not the render's colour"
same "$dir/noisy.exr" "$dir/rgb.exr" && fail "the denoised colour is the noisy one"
noisy_error=$(rms "$dir/reference.exr" "$dir/noisy.exr")
denoised_error=$(rms "$dir/reference.exr" "$dir/rgb.exr")
awk "BEGIN { exit !($denoised_error <= 0.8 * $noisy_error) }" ||
    fail "denoised RMS error $denoised_error, not at most 0.8 x the noisy $noisy_error"

# ptr denoise on the render with its passes gives the --denoise render; on
# a denoised image, the same again from its noisy layer.
render --samples 4 --passes albedo,normal -o "$dir/passes.exr" || fail "--passes: exit code $?"
"$ptr" denoise "$dir/passes.exr" -o "$dir/later.exr" --quiet || fail "ptr denoise: exit code $?"
same "$dir/denoised.exr" "$dir/later.exr" || fail "ptr denoise differs from --denoise"
"$ptr" denoise "$dir/denoised.exr" -o "$dir/again.exr" --quiet ||
    fail "ptr denoise of a denoised image: exit code $?"
same "$dir/denoised.exr" "$dir/again.exr" || fail "a denoised image is denoised again"
"$ptr" denoise "$dir/passes.exr" -o "$dir/fast.exr" --denoise fast --quiet ||
    fail "ptr denoise --denoise fast: exit code $?"
iinfo -v "$dir/fast.exr" | grep -q 'ptr:denoised: "fast"' || fail "--denoise fast: not recorded"

# Other formats get the denoised colour through the view, as any output.
render --samples 4 --denoise -o "$dir/denoised.png" || fail "--denoise to PNG: exit code $?"
"$ptr" denoise "$dir/passes.exr" -o "$dir/later.png" --quiet || fail "ptr denoise to PNG: $?"
same "$dir/denoised.png" "$dir/later.png" || fail "PNG: ptr denoise differs from --denoise"

# Any thread count and CPU level: the same bits.
for options in "--threads 1" "--threads 2" "--cpumask none"; do
    # shellcheck disable=SC2086 # $options is split on purpose
    render --samples 4 --denoise $options -o "$dir/other.exr" || fail "$options: exit code $?"
    same "$dir/denoised.exr" "$dir/other.exr" || fail "--denoise $options: other bits"
done

# Merged, then denoised: region parts give the whole render bit for bit,
# denoised parts give their noisy colour to the merge.
render --samples 4 --passes albedo,normal --region 0,0,48,20 -o "$dir/top.exr" &&
    render --samples 4 --denoise --region 0,20,48,48 -o "$dir/bottom.exr" ||
    fail "region parts: exit code $?"
"$ptr" merge "$dir/top.exr" "$dir/bottom.exr" -o "$dir/regions.exr" --denoise --quiet ||
    fail "merge --denoise of regions: exit code $?"
same "$dir/denoised.exr" "$dir/regions.exr" || fail "regions merged and denoised differ"
# Sample ranges merge to the whole render within float rounding (their means
# are rounded; docs/distributed.md): merge --denoise is the merge denoised.
render --samples 4 --passes albedo,normal --sample-range 0:1 -o "$dir/early.exr" &&
    render --samples 4 --passes albedo,normal --sample-range 1:4 -o "$dir/late.exr" ||
    fail "sample-range parts: exit code $?"
"$ptr" merge "$dir/early.exr" "$dir/late.exr" -o "$dir/ranges.exr" --denoise --quiet &&
    "$ptr" merge "$dir/early.exr" "$dir/late.exr" -o "$dir/merged.exr" --quiet &&
    "$ptr" denoise "$dir/merged.exr" -o "$dir/merged_denoised.exr" --quiet ||
    fail "merge of sample ranges: exit code $?"
same "$dir/ranges.exr" "$dir/merged_denoised.exr" || fail "merge --denoise is not the merge denoised"
idiff -a -fail 1e-5 "$dir/denoised.exr" "$dir/ranges.exr" >/dev/null 2>&1 ||
    fail "sample ranges merged and denoised: not the whole render denoised within 1e-5"

# --transparent: the colour denoised, alpha exactly the render's, in EXR
# (premultiplied colour) as in PNG (straight).
for ext in exr png; do
    render --width 16 --samples 4 --transparent -o "$dir/clear.$ext" &&
        render --width 16 --samples 4 --transparent --denoise -o "$dir/clear_denoised.$ext" ||
        fail "--transparent --denoise to .$ext: exit code $?"
    channels "$dir/clear.$ext" "$dir/alpha.$ext" A
    channels "$dir/clear_denoised.$ext" "$dir/alpha_denoised.$ext" A
    same "$dir/alpha.$ext" "$dir/alpha_denoised.$ext" || fail "--transparent --denoise changed .$ext alpha"
done

# A sequence: every frame denoised.
render --width 16 --samples 2 --turntable 2 --denoise -o "$dir/turn_#.exr" ||
    fail "--turntable: exit code $?"
for frame in 0 1; do
    iinfo -v "$dir/turn_$frame.exr" | grep -q 'ptr:denoised: "balanced"' ||
        fail "frame $frame of a sequence not denoised"
done

# An image without the passes: exit 2, one line naming it and the layers,
# the existing output untouched.
echo "an existing image" >"$dir/kept.exr"
"$ptr" denoise "$dir/noisy.exr" -o "$dir/kept.exr" 2>"$dir/err"
code=$?
[ $code = 2 ] || fail "ptr denoise without passes: exit code $code, not 2"
one_line "$dir/err" "^ptr: $dir/noisy.exr: no albedo.R/G/B and normal.X/Y/Z layers" ||
    fail "ptr denoise without passes: not one line naming the file: $(cat "$dir/err")"
[ "$(cat "$dir/kept.exr")" = "an existing image" ] || fail "ptr denoise without passes: output changed"

finish "--denoise, ptr denoise and ptr merge --denoise: the layers, the same bits every way"
