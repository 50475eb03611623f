#!/bin/sh
# ptr's import of a glTF file against tinygltf's own load of it
# (bench/tinygltf_load.cpp: the parse and nothing else), runs alternating:
# the medians of ptr's import_seconds (--json, a 2x2 render by brute force)
# and of tinygltf_load's whole process, and the peak RSS of each process.
# Usage: bench/import.sh BUILD_DIR FILE.gltf|FILE.glb [RUNS]
set -eu
build=$1 file=$2 runs=${3:-5}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
for run in $(seq "$runs"); do
    /usr/bin/time -f "%M" -a -o "$out/ptr.rss" "$build/src/ptr" "$file" -o "$out/x.exr" \
        --samples 1 --width 2 --height 2 --accel brute --quiet --json |
        sed 's/.*"import_seconds": \([0-9.]*\).*/\1/' >>"$out/ptr.s"
    /usr/bin/time -f "%e %M" -a -o "$out/tinygltf" "$build/bench/tinygltf_load" "$file" >/dev/null
done
echo "ptr import:       $(median <"$out/ptr.s") s, peak $(median <"$out/ptr.rss") kB"
echo "tinygltf's load:  $(cut -d' ' -f1 "$out/tinygltf" | median) s (whole process)," \
     "peak $(cut -d' ' -f2 "$out/tinygltf" | median) kB"
