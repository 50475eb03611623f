#!/bin/sh
# ptr against the Embree 3 peer (../shared/peers/embree_pt.c) on the same
# neutral scene descriptions, runs alternated: build + render seconds of each
# (ptr's from --json; Embree's bvh= + render=) and the whole process's wall
# time, and Embree's best over ptr's for both.
# Usage: bench/embree.sh PTR SCENE.json SPP [RUNS [ptr options]]
# ($EMBREE_PT_SOURCE: the peer's source, if not beside the repository)
#   e.g. bench/embree.sh build/src/ptr ../shared/bench-scenes/final.json 100 2
# The scene is written for ptr as an instanced .glb (scripts/make_scenes.py).
set -eu
ptr=$1 json=$2 spp=$3 runs=${4:-2}
shift 3; [ $# -gt 0 ] && shift
src=$(cd "$(dirname "$0")/.." && pwd)
peer=${EMBREE_PT_SOURCE:-$src/../shared/peers/embree_pt.c}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
gcc -O3 -march=native "$peer" -o "$dir/embree_pt" -lembree3 -lcjson -lpthread -lm || {
    echo "bench/embree.sh: the peer did not build: it needs Embree 3 and cJSON" \
        "(apt-get install libembree-dev libcjson-dev)" >&2
    exit 2
}
python3 "$src/scripts/make_scenes.py" --instanced "$json" "$dir/scene.glb"
# Each run: ptr, then each Embree mode, with their build + render seconds and
# the whole process's wall time (/usr/bin/time: loading, import, writing).
for run in $(seq "$runs"); do
    # The JSON goes to a file, read after: a reader starting beside the render
    # would take a core from it.
    /usr/bin/time -f "%e" -o "$dir/wall" "$ptr" "$dir/scene.glb" -o "$dir/out.exr" \
        --samples "$spp" --quiet --json "$@" >"$dir/ptr.json"
    ptr_s=$(python3 -c 'import json, sys; r = json.load(open(sys.argv[1]))
print("%.3f" % (r["build_seconds"] + r["render_seconds"]))' "$dir/ptr.json")
    ptr_wall=$(cat "$dir/wall")
    times=
    walls=
    for mode in "-m 1" "-m 16 -g user"; do
        # shellcheck disable=SC2086
        line=$(/usr/bin/time -f "%e" -o "$dir/wall" "$dir/embree_pt" "$json" -t 2 -spp "$spp" $mode)
        s=$(echo "$line" | sed 's/.*bvh=\([0-9.]*\)s render=\([0-9.]*\)s.*/\1 \2/' | awk '{printf "%.3f", $1 + $2}')
        echo "run $run: embree $mode: $s s, whole process $(cat "$dir/wall") s"
        times="$times $s"
        walls="$walls $(cat "$dir/wall")"
    done
    best=$(printf '%s\n' $times | sort -g | head -n 1)
    best_wall=$(printf '%s\n' $walls | sort -g | head -n 1)
    echo "run $run: ptr: $ptr_s s, whole process $ptr_wall s;" \
         "Embree best / ptr = $(echo "$best $ptr_s" | awk '{printf "%.2f", $1 / $2}')x," \
         "whole process $(echo "$best_wall $ptr_wall" | awk '{printf "%.2f", $1 / $2}')x"
done
