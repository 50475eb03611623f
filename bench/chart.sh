#!/bin/sh
# Regenerates a speed-against-accuracy chart and its data:
#   intersectors: docs/images/speed-accuracy.png, docs/speed-accuracy.csv
#   estimators:   docs/images/estimators.png, docs/estimators.csv
# The estimators chart also prints its efficiency table (bench/efficiency.py).
# Needs a build (cmake -B build) and installs gnuplot from Debian's packages
# if it is missing.
#
# Usage: bench/chart.sh intersectors|estimators [BUILD_DIR] [MAX_SPP] [REFERENCE_SPP] [SEEDS]
set -eu
cd "$(dirname "$0")/.."
chart=${1:?usage: bench/chart.sh intersectors|estimators [BUILD_DIR] [MAX_SPP] [REFERENCE_SPP] [SEEDS]}
build=${2:-build}
case $chart in
intersectors) data=docs/speed-accuracy.csv image=docs/images/speed-accuracy.png plot=bench/chart.gp ;;
estimators) data=docs/estimators.csv image=docs/images/estimators.png plot=bench/estimators.gp ;;
*) echo "bench/chart.sh: no chart '$chart' (intersectors or estimators)" >&2; exit 2 ;;
esac
cmake --build "$build" --target accuracy >/dev/null
. bench/need_gnuplot.sh
"$build/bench/accuracy" "$chart" "$data" "${3:-256}" "${4:-4096}" ${5:-}
gnuplot -e "data='$data'; out='$image'" "$plot"
echo "wrote $data and $image"
if [ "$chart" = estimators ]; then
    python3 bench/efficiency.py "$data"
fi
