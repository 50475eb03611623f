#!/bin/sh
# Regenerates a speed-against-accuracy chart and its data:
#   intersectors: docs/images/speed-accuracy.png, docs/speed-accuracy.csv
#   estimators:   docs/images/estimators.png, docs/estimators.csv
#   denoise:      docs/images/denoise-accuracy.png, docs/denoise-accuracy.csv
#                 (raw renders against --denoise at each quality; needs the
#                 weights; keeps its 16,384-spp references in
#                 BUILD_DIR/bench/references for the next run)
# The estimators chart also prints its efficiency table (bench/efficiency.py),
# the denoise chart its gains and where they end (bench/denoise_gain.py).
# Needs a build (cmake -B build) and installs gnuplot from Debian's packages
# if it is missing.
#
# Usage: bench/chart.sh intersectors|estimators [BUILD_DIR] [MAX_SPP] [REFERENCE_SPP] [SEEDS]
#        bench/chart.sh denoise [BUILD_DIR] [MAX_SPP] [REFERENCE_SPP]
set -eu
cd "$(dirname "$0")/.."
chart=${1:?usage: bench/chart.sh intersectors|estimators|denoise [BUILD_DIR] [MAX_SPP] [REFERENCE_SPP] [SEEDS]}
build=${2:-build}
case $chart in
intersectors) data=docs/speed-accuracy.csv image=docs/images/speed-accuracy.png plot=bench/chart.gp ;;
estimators) data=docs/estimators.csv image=docs/images/estimators.png plot=bench/estimators.gp ;;
denoise) data=docs/denoise-accuracy.csv image=docs/images/denoise-accuracy.png plot=bench/denoise_chart.gp ;;
*) echo "bench/chart.sh: no chart '$chart' (intersectors, estimators or denoise)" >&2; exit 2 ;;
esac
cmake --build "$build" --target accuracy >/dev/null
. bench/need_gnuplot.sh
if [ "$chart" = denoise ]; then
    mkdir -p "$build/bench/references"
    "$build/bench/accuracy" denoise "$data" "${3:-1024}" "${4:-16384}" "$build/bench/references"
else
    "$build/bench/accuracy" "$chart" "$data" "${3:-256}" "${4:-4096}" ${5:-}
fi
gnuplot -e "data='$data'; out='$image'" "$plot"
echo "wrote $data and $image"
case $chart in
estimators) python3 bench/efficiency.py "$data" ;;
denoise) python3 bench/denoise_gain.py "$data" ;;
esac
