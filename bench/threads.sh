#!/bin/sh
# How a whole ptr process scales from one thread to two: for each build given
# and each scene, runs with --threads 1 and --threads 2 taken in turn (so that
# both see the same machine), the median over RUNS of the render's rays per
# second (--json) and of the process's wall time (/usr/bin/time), and the
# ratios 2 threads / 1 thread.
# Usage: bench/threads.sh RUNS PTR... (from the source folder)
set -eu
runs=$1
shift
builds=$*
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

# scene NAME ARGS: every build, 1 and 2 threads, RUNS times in turn.
scene() {
    name=$1
    args=$2
    rm -f "$out"/*.wall "$out"/*.rays
    i=0
    while [ $i -lt "$runs" ]; do
        b=0
        for ptr in $builds; do
            b=$((b + 1))
            for t in 1 2; do
                # shellcheck disable=SC2086 # $args is split on purpose
                /usr/bin/time -f "%e" -a -o "$out/$b-$t.wall" "$ptr" $args -o "$out/x.exr" \
                    --threads $t --quiet --json 2>/dev/null |
                    sed 's/.*"rays_per_second": \([0-9]*\).*/\1/' >>"$out/$b-$t.rays"
            done
        done
        i=$((i + 1))
    done
    b=0
    for ptr in $builds; do
        b=$((b + 1))
        r1=$(median <"$out/$b-1.rays") r2=$(median <"$out/$b-2.rays")
        w1=$(median <"$out/$b-1.wall") w2=$(median <"$out/$b-2.wall")
        echo "$name $ptr: Mrays/s $(echo "$r1 $r2" | awk '{printf "%.1f -> %.1f (%.2fx)", $1/1e6, $2/1e6, $2/$1}');" \
             "wall $w1 s -> $w2 s ($(echo "$w1 $w2" | awk '{printf "%.2f", $2/$1}')x)"
    done
}

scene final-16spp "scenes/final.gltf --samples 16"
scene seed-20spp "scenes/seed.gltf --samples 20"
