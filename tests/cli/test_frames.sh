#!/bin/sh
# Sequences: numbered scenes to numbered images, --frames, --turntable, and
# --skip-existing resuming an interrupted sequence and sharing one among
# processes through claims. Needs iinfo and idiff (openimageio-tools).
# Usage: test_frames.sh PTR SOURCE_DIR
set -u
ptr=$1
src=$2
. "$src/tests/support/shell_test.sh"

samples_of() { iinfo -v "$1" 2>/dev/null | sed -n 's/.*ptr:samples: //p'; }
# Inode and modification time to the nanosecond: a file left alone keeps both.
identity() { stat -c '%i %y' "$1"; }

mkdir "$dir/in"
for i in 01 02 03 04 05 06 07 08 09 10; do
    cp "$src/scenes/seed.gltf" "$dir/in/f_00$i.gltf"
done
opts="--width 80 --samples 128"

# An interrupted sequence resumes without redoing its finished frames.
mkdir "$dir/out"
"$ptr" "$dir/in/f_####.gltf" -o "$dir/out/f_####.exr" --skip-existing $opts 2>"$dir/first.log" &
pid=$!
wait_until '[ -f "$dir/out/f_0003.exr" ]' || fail "the first frames were not written"
kill -TERM $pid
wait $pid
code=$?
[ $code -eq 8 ] || fail "an interrupted sequence exits 8 (got $code)"
finished=$(ls "$dir/out" | grep -c '^f_.*\.exr$')
[ "$finished" -lt 10 ] || fail "the interruption came after the last frame: nothing to resume"
[ -z "$(ls -A "$dir/out" | grep -v '^f_00[0-9][0-9]\.exr$')" ] ||
    fail "claims or temporary files left after the interruption: $(ls -A "$dir/out")"
for f in "$dir"/out/f_*.exr; do
    [ "$(samples_of "$f")" = 128 ] || fail "$f is not a whole frame ($(samples_of "$f") samples)"
    identity "$f" >>"$dir/before"
done
"$ptr" "$dir/in/f_####.gltf" -o "$dir/out/f_####.exr" --skip-existing $opts 2>"$dir/second.log"
code=$?
[ $code -eq 0 ] || fail "the resumed sequence exits 0 (got $code)"
[ "$(grep -c 'exists: skipped' "$dir/second.log")" -eq "$finished" ] ||
    fail "the resumed run skips the $finished finished frames: $(cat "$dir/second.log")"
i=0
for f in "$dir"/out/f_*.exr; do
    i=$((i + 1))
    [ "$(samples_of "$f")" = 128 ] || fail "$f is not a whole frame after resuming"
    [ $i -le "$finished" ] && identity "$f" >>"$dir/after"
done
[ $i -eq 10 ] || fail "10 frames after resuming (got $i)"
cmp -s "$dir/before" "$dir/after" || fail "finished frames were written again: $(cat "$dir/before" "$dir/after")"

# Two processes on one folder render every frame once between them.
mkdir "$dir/shared"
for n in 1 2; do
    "$ptr" "$dir/in/f_####.gltf" -o "$dir/shared/f_####.exr" --skip-existing --json $opts \
        >"$dir/shared$n.jsonl" 2>"$dir/shared$n.log" &
    eval "pid$n=\$!"
done
wait $pid1
code1=$?
wait $pid2
code2=$?
[ $code1 -eq 0 ] && [ $code2 -eq 0 ] || fail "both processes exit 0 (got $code1 and $code2)"
cat "$dir/shared1.jsonl" "$dir/shared2.jsonl" | sed -n 's/.*"output": *"\([^"]*\)".*/\1/p' |
    sort >"$dir/rendered"
ls "$dir"/shared/f_*.exr >"$dir/expected"
[ "$(wc -l <"$dir/expected")" -eq 10 ] || fail "10 frames in the shared folder"
cmp -s "$dir/rendered" "$dir/expected" ||
    fail "each frame rendered exactly once: $(cat "$dir/rendered")"
echo "two processes: $(wc -l <"$dir/shared1.jsonl") and $(wc -l <"$dir/shared2.jsonl") frames"

# Claims: a live one is respected, a stale one (a process gone on this host,
# or a file untouched for over 10 minutes from another) is taken over.
mkdir "$dir/claims"
host=$(hostname)
echo "$host $$" >"$dir/claims/f_0001.exr.claim"
echo "$host 999999999" >"$dir/claims/f_0002.exr.claim"
echo "elsewhere 42" >"$dir/claims/f_0003.exr.claim"
echo "elsewhere 42" >"$dir/claims/f_0004.exr.claim"
touch -d '1 hour ago' "$dir/claims/f_0004.exr.claim"
"$ptr" "$dir/in/f_####.gltf" -o "$dir/claims/f_####.exr" --skip-existing --frames 1:4 \
    --width 16 --samples 1 --quiet 2>"$dir/claims.log"
code=$?
[ $code -eq 0 ] || fail "claims: exit 0 (got $code)"
[ ! -f "$dir/claims/f_0001.exr" ] && [ -f "$dir/claims/f_0001.exr.claim" ] ||
    fail "a live claim on this host is respected"
[ -f "$dir/claims/f_0002.exr" ] && [ ! -f "$dir/claims/f_0002.exr.claim" ] ||
    fail "the claim of a process gone is taken over"
[ ! -f "$dir/claims/f_0003.exr" ] || fail "a fresh claim from another host is respected"
[ -f "$dir/claims/f_0004.exr" ] || fail "a claim untouched for an hour is taken over"

# --frames A:B:STEP renders those frames, numbered by the pattern.
mkdir "$dir/some"
"$ptr" "$dir/in/f_####.gltf" -o "$dir/some/g_##.png" --frames 2:8:3 --width 16 --samples 1 \
    --quiet || fail "--frames 2:8:3 exits 0"
[ "$(ls "$dir/some" | tr '\n' ' ')" = "g_02.png g_05.png g_08.png " ] ||
    fail "--frames 2:8:3 renders frames 2, 5 and 8: $(ls "$dir/some")"

# --turntable: frame 0 is the plain render, the others turn the camera.
"$ptr" "$src/scenes/seed.gltf" -o "$dir/plain.exr" --width 48 --samples 4 --quiet
"$ptr" "$src/scenes/seed.gltf" -o "$dir/turn_###.exr" --turntable 4 --width 48 --samples 4 \
    --quiet || fail "--turntable 4 exits 0"
[ "$(ls "$dir" | grep -c '^turn_00[0-3]\.exr$')" -eq 4 ] || fail "--turntable 4 writes 4 frames"
idiff -q -a -fail 0 -failpercent 0 "$dir/plain.exr" "$dir/turn_000.exr" >/dev/null 2>&1 ||
    fail "turntable frame 0 is the plain render"
idiff -q -a "$dir/plain.exr" "$dir/turn_002.exr" >/dev/null 2>&1 &&
    fail "turntable frame 2 looks from the other side"

# Usage: a turntable needs # in -o; a pattern must find files; --frames is
# A:B or A:B:STEP and nothing more.
"$ptr" "$src/scenes/seed.gltf" -o "$dir/x.png" --turntable 4 2>/dev/null
[ $? -eq 2 ] || fail "--turntable without # in -o is a usage error"
"$ptr" "$dir/in/none_####.gltf" -o "$dir/y_####.png" 2>/dev/null
[ $? -eq 3 ] || fail "a pattern that finds no file cannot be read"
"$ptr" "$dir/in/f_####.gltf" -o "$dir/one.png" 2>/dev/null
[ $? -eq 2 ] || fail "a sequence into one file name is a usage error"
for range in 1:10: 5:3 1:10:0 x; do
    "$ptr" "$dir/in/f_####.gltf" -o "$dir/z_####.png" --frames "$range" 2>/dev/null
    [ $? -eq 2 ] || fail "--frames $range is a usage error"
done

finish "sequences: resumed after an interruption, shared by two processes, claims, --frames, --turntable"
