#!/bin/sh
# Whole-process wall time and peak RSS of two ptr builds, alternating A and B
# run by run so that both see the same machine: the median of RUNS runs of
# `/usr/bin/time -f "%e %M"` for each command.
# Usage: bench/startup.sh PTR_A PTR_B [RUNS]   (from the source folder)
set -eu
a=$1
b=$2
runs=${3:-20}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

median() { sort -n | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

measure() {
    name=$1
    shift
    : >"$out/a"
    : >"$out/b"
    i=0
    while [ $i -lt "$runs" ]; do
        for which in a b; do
            eval "ptr=\$$which"
            /usr/bin/time -f "%e %M" -a -o "$out/$which" "$ptr" "$@" >/dev/null 2>&1
        done
        i=$((i + 1))
    done
    for which in a b; do
        wall=$(cut -d' ' -f1 "$out/$which" | median)
        rss=$(cut -d' ' -f2 "$out/$which" | median)
        printf '%-16s %s  %6s s  %7s kB\n' "$name" "$which" "$wall" "$rss"
    done
}

measure --version --version
measure --help --help
measure --dump-scene --dump-scene scenes/seed.gltf
measure --print-dispatch --print-dispatch
measure --list-views --list-views
measure render-64 scenes/seed.gltf -o "$out/x.png" --width 64 --height 64 --samples 4
measure render-500 scenes/seed.gltf -o "$out/y.png" --width 500 --height 500 --samples 20
measure render-250-t1 scenes/seed.gltf -o "$out/z.png" --width 250 --height 250 --samples 20 --threads 1
measure exr-500 scenes/seed.gltf -o "$out/y.exr" --width 500 --height 500 --samples 20
measure exr-500-t1 scenes/seed.gltf -o "$out/z.exr" --width 500 --height 500 --samples 20 --threads 1
measure final-exr-16 scenes/final.gltf -o "$out/f.exr" --samples 16
