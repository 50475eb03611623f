#!/bin/sh
# Regenerates the scaling chart: docs/images/bvh-scaling.png and its data,
# docs/bvh-scaling.csv, from bench/bvh (cloud scenes of 10^3 to 10^6 spheres,
# brute force and the tree, C and assembly). Needs a build (cmake -B build)
# and gnuplot (installed from Debian's packages if missing, as chart.sh does).
#
# Usage: bench/bvh.sh [BUILD_DIR] [WIDTH HEIGHT SPP]
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
[ $# -gt 0 ] && shift
cmake --build "$build" --target bvh >/dev/null
. bench/need_gnuplot.sh
"$build/bench/bvh" docs/bvh-scaling.csv 1000000 "${1:-400}" "${2:-225}" "${3:-2}"
gnuplot -e "data='docs/bvh-scaling.csv'; out='docs/images/bvh-scaling.png'" bench/bvh.gp
echo "wrote docs/bvh-scaling.csv and docs/images/bvh-scaling.png"
