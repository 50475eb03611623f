# Sourced by the chart scripts: installs gnuplot from Debian's packages when
# it is missing (as root, else through sudo), so that a clean machine can
# redraw the charts.
if ! command -v gnuplot >/dev/null; then
    run() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
    run apt-get update -qq
    DEBIAN_FRONTEND=noninteractive run apt-get install -y -qq --no-install-recommends gnuplot-nox >/dev/null
fi
