#!/bin/sh
# End-to-end render benchmark: scenes/seed.gltf and scenes/final.gltf at their
# own sizes and 10 samples per pixel, each rendered RUNS times (default 3);
# prints the fastest run's seconds and millions of rays per second (a ray is
# one closest-hit query, camera or scattered).
#
# Usage: bench/render.sh [PTR] [RUNS] [extra ptr options...]
set -eu
cd "$(dirname "$0")/.."
ptr=${1:-build/src/ptr}
runs=${2:-3}
[ $# -gt 0 ] && shift
[ $# -gt 0 ] && shift
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

printf '%-8s %9s %7s %9s %11s %10s\n' scene size spp threads seconds Mrays/s
for scene in seed final; do
    best=
    for _ in $(seq "$runs"); do
        # ptr: OUT: WxH, N spp, T threads, K intersector: S s, R Mrays/s (N rays)
        line=$("$ptr" "scenes/$scene.gltf" -o "$out/$scene.exr" --samples 10 "$@" 2>&1 >/dev/null |
               grep 'Mrays/s')
        secs=$(echo "$line" | sed -E 's/.*: ([0-9.]+) s, .*/\1/')
        if [ -z "$best" ] || awk "BEGIN { exit !($secs < $best) }"; then
            best=$secs
            best_line=$line
        fi
    done
    size=$(echo "$best_line" | sed -E 's/^ptr: [^:]*: ([0-9]+x[0-9]+),.*/\1/')
    threads=$(echo "$best_line" | sed -E 's/.* ([0-9]+) threads.*/\1/')
    mrays=$(echo "$best_line" | sed -E 's/.* ([0-9.]+) Mrays\/s.*/\1/')
    printf '%-8s %9s %7s %9s %11s %10s\n' "$scene" "$size" 10 "$threads" "$best" "$mrays"
done
