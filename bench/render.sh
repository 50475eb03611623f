#!/bin/sh
# End-to-end render benchmark: scenes/seed.gltf and scenes/final.gltf at their
# own sizes and 10 samples per pixel, with the C intersector and with the best
# assembly one, alternating, each RUNS times (default 3). Prints the fastest
# run of each in seconds and millions of rays per second (a ray is one
# closest-hit query, camera or scattered), and the asm/C speed ratio.
#
# Usage: bench/render.sh [PTR] [RUNS] [extra ptr options...]
set -eu
cd "$(dirname "$0")/.."
ptr=${1:-build/src/ptr}
runs=${2:-3}
[ $# -gt 0 ] && shift
[ $# -gt 0 ] && shift
extra="$*" # further ptr options, word-split on use
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# Prints "SECONDS MRAYS KERNEL" of the fastest of $runs renders.
fastest() {
    scene=$1; shift
    best=
    for _ in $(seq "$runs"); do
        # ptr: OUT: WxH, N spp, S spheres, A, K intersector: import I s, build B s,
        # render R s, M Mrays/s (N rays)
        # shellcheck disable=SC2086
        line=$("$ptr" "scenes/$scene.gltf" -o "$out/$scene.exr" --samples 10 $extra "$@" 2>&1 >/dev/null |
               grep ' intersector: ')
        secs=$(echo "$line" | sed -E 's/.* render ([0-9.]+) s, .*/\1/')
        if [ -z "$best" ] || awk "BEGIN { exit !($secs < $best) }"; then
            best=$secs
            mrays=$(echo "$line" | sed -E 's/.* ([0-9.]+) Mrays\/s.*/\1/')
            kernel=$(echo "$line" | sed -E 's/.* ([a-z0-9]+) intersector.*/\1/')
            size=$(echo "$line" | sed -E 's/^ptr: [^:]*: ([0-9]+x[0-9]+),.*/\1/')
        fi
    done
    echo "$best $mrays $kernel $size"
}

printf '%-6s %8s %8s %9s %9s %8s %9s %9s %9s\n' \
    scene size kernel seconds Mrays/s kernel seconds Mrays/s asm/c
for scene in seed final; do
    # shellcheck disable=SC2046
    set -- $(fastest "$scene" --c) $(fastest "$scene" --asm)
    printf '%-6s %8s %8s %9s %9s %8s %9s %9s %8.2fx\n' "$scene" "$4" "$3" "$1" "$2" "$7" "$5" "$6" \
        "$(awk "BEGIN { print $1 / $5 }")"
done
