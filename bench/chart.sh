#!/bin/sh
# Regenerates the speed-against-accuracy chart: docs/images/speed-accuracy.png
# and its data, docs/speed-accuracy.csv. Needs a build (cmake -B build) and
# installs gnuplot from Debian's packages if it is missing.
#
# Usage: bench/chart.sh [BUILD_DIR] [MAX_SPP] [REFERENCE_SPP]
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
cmake --build "$build" --target accuracy >/dev/null
if ! command -v gnuplot >/dev/null; then
    run() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
    run apt-get update -qq
    DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq --no-install-recommends gnuplot-nox >/dev/null
fi
"$build/bench/accuracy" docs/speed-accuracy.csv "${2:-256}" "${3:-4096}"
gnuplot -e "data='docs/speed-accuracy.csv'; out='docs/images/speed-accuracy.png'" bench/chart.gp
echo "wrote docs/speed-accuracy.csv and docs/images/speed-accuracy.png"
