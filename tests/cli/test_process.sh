#!/bin/sh
# A real ptr process under signals and --watch.
# Usage: test_process.sh PTR SOURCE_DIR
set -u
ptr=$1
src=$2
. "$src/tests/support/shell_test.sh"
passed=0

check() {
    if eval "$2"; then
        passed=$((passed + 1))
    else
        failed=$((failed + 1))
        echo "FAIL: $1" >&2
    fi
}

meta() { iinfo -v "$1" 2>/dev/null; }

# A first SIGINT or SIGTERM: the pass finishes, its samples are written, exit 8.
for sig in INT TERM; do
    # The background job truncates its log only when it starts: remove the last
    # one first, or its "spp" lets the signal come before the handler is in.
    rm -f "$dir/stop.log"
    "$ptr" "$src/scenes/final.gltf" -o "$dir/stop.exr" --samples 1000000 --width 80 \
        2>"$dir/stop.log" &
    pid=$!
    wait_until 'grep -q "spp" "$dir/stop.log"'
    kill -$sig $pid
    wait $pid
    code=$?
    check "first SIG$sig exits 8 (got $code)" '[ $code -eq 8 ]'
    check "SIG$sig: the samples done are written" 'meta "$dir/stop.exr" | grep -q "ptr:interrupted: 1"'
    samples=$(meta "$dir/stop.exr" | sed -n 's/.*ptr:samples: //p')
    check "SIG$sig: metadata counts the samples taken ($samples)" \
        '[ -n "$samples" ] && [ "$samples" -ge 1 ] && [ "$samples" -lt 1000000 ]'
    rm -f "$dir/stop.exr"
done

# A second signal aborts at once: exit 130, the existing file untouched, no temporary left.
# The first pass (one sample of a 4000x2250 image) takes seconds, so both signals land in
# it; sent at once they would arrive as one.
echo "an existing image" >"$dir/keep.exr"
"$ptr" "$src/scenes/final.gltf" -o "$dir/keep.exr" --samples 1000000 --width 4000 \
    2>"$dir/keep.log" &
pid=$!
wait_until 'grep -q "spp" "$dir/keep.log"'
kill -INT $pid
sleep 0.2
kill -INT $pid
wait $pid
code=$?
check "a second SIGINT exits 130 (got $code)" '[ $code -eq 130 ]'
check "the existing output is untouched" '[ "$(cat "$dir/keep.exr")" = "an existing image" ]'
check "no temporary file is left" '[ -z "$(ls -A "$dir" | grep ptr-)" ]'

# --watch: renders, renders again on a save, keeps the last good image on a broken save,
# ends cleanly (exit 0) on SIGINT while waiting.
cp "$src/scenes/seed.gltf" "$dir/watched.gltf"
"$ptr" "$dir/watched.gltf" -o "$dir/watched.exr" --watch --samples 1 --width 32 \
    2>"$dir/watch.log" &
pid=$!
wait_until '[ -s "$dir/watched.exr" ]'
first=$(cksum <"$dir/watched.exr")
sed 's/"sky": "gradient"/"sky": "black"/' "$src/scenes/seed.gltf" >"$dir/watched.gltf.new"
mv "$dir/watched.gltf.new" "$dir/watched.gltf"
check "a save renders again" 'wait_until "[ \"\$(cksum <\"$dir/watched.exr\")\" != \"$first\" ]"'
second=$(cksum <"$dir/watched.exr")
echo '{ "asset": ' >"$dir/watched.gltf"
check "a broken save is reported" 'wait_until "grep -q \"keeping the last good image\" \"$dir/watch.log\""'
check "and the last good image kept" '[ "$(cksum <"$dir/watched.exr")" = "$second" ]'
kill -INT $pid
wait $pid
code=$?
check "SIGINT while watching exits 0 (got $code)" '[ $code -eq 0 ]'

# The threads --json reports: --threads N as asked; by default one per CPU
# the process may run on, which taskset (like a container's or a batch
# system's cpuset) can make fewer than the machine's. Pinned to the first CPU
# the test may use, which need not be CPU 0.
threads_of() {
    "$@" "$src/scenes/seed.gltf" -o "$dir/threads.exr" --samples 1 --width 16 --quiet --json |
        sed -E 's/.*"threads": ([0-9]+).*/\1/'
}
usable=$(python3 -c 'import os; print(min(len(os.sched_getaffinity(0)), 1024))')
first_cpu=$(python3 -c 'import os; print(min(os.sched_getaffinity(0)))')
asked=$(threads_of "$ptr" --threads 3)
check "--threads 3 reports 3 threads (got $asked)" '[ "$asked" = 3 ]'
pinned=$(threads_of taskset -c "$first_cpu" "$ptr")
check "under taskset -c $first_cpu, one thread by default (got $pinned)" '[ "$pinned" = 1 ]'
default=$(threads_of "$ptr")
check "by default, one per CPU the process may run on: $usable (got $default)" \
    '[ "$default" = "$usable" ]'
# ptr merge reports the threads its denoiser would take, by the same rule.
check "two parts to merge render" \
    '"$ptr" "$src/scenes/seed.gltf" -o "$dir/part0.exr" --width 16 --sample-range 0:1 --quiet &&
     "$ptr" "$src/scenes/seed.gltf" -o "$dir/part1.exr" --width 16 --sample-range 1:2 --quiet'
merge_threads() {
    "$ptr" merge "$dir/part0.exr" "$dir/part1.exr" -o "$dir/merged.exr" --quiet --json "$@" |
        sed -E 's/.*"threads": ([0-9]+).*/\1/'
}
merged=$(merge_threads)
check "ptr merge reports $usable threads by default (got $merged)" '[ "$merged" = "$usable" ]'
merged=$(merge_threads --threads 3)
check "ptr merge --threads 3 reports 3 (got $merged)" '[ "$merged" = 3 ]'

echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
