#!/bin/sh
# A large biological assembly read by ptr from mmCIF, expanded from one copy
# of its atoms, against the same spheres as an instanced .glb (both made by
# bench/make_assembly.py: 60 operators over ATOMS atoms), runs alternating:
# the medians of import_seconds (--json, a 2x2 render by brute force), of
# the whole process and of its peak RSS (/usr/bin/time's maximum resident
# set size, as -v reports it), and the ratios mmCIF / .glb.
# Usage: bench/assembly.sh BUILD_DIR [ATOMS] [RUNS]
set -eu
build=$1 atoms=${2:-20000} runs=${3:-5}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
python3 "$(dirname "$0")/make_assembly.py" "$out/capsid.cif" "$out/capsid.glb" "$atoms"
median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
for run in $(seq "$runs"); do
    for format in cif glb; do
        /usr/bin/time -f "%e %M" -a -o "$out/$format.process" "$build/src/ptr" \
            "$out/capsid.$format" -o "$out/x.exr" --samples 1 --width 2 --height 2 \
            --accel brute --quiet --json |
            sed 's/.*"import_seconds": \([0-9.]*\).*/\1/' >>"$out/$format.import"
    done
done
for format in cif glb; do
    median <"$out/$format.import" >"$out/$format.i"
    cut -d' ' -f1 "$out/$format.process" | median >"$out/$format.s"
    cut -d' ' -f2 "$out/$format.process" | median >"$out/$format.m"
    echo "$format: import $(cat "$out/$format.i") s, process $(cat "$out/$format.s") s," \
         "peak $(cat "$out/$format.m") kB"
done
for what in i:import s:process m:peak; do
    echo "mmCIF / .glb, ${what#*:}: $(echo "$(cat "$out/cif.${what%:*}") $(cat "$out/glb.${what%:*}")" |
        awk '{ printf "%.2f", $1 / $2 }')"
done
