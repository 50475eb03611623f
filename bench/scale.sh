#!/bin/sh
# How ptr scales to 10^8 spheres: generates clouds of N spheres with
# bench/make_cloud (instanced .glb, 36 bytes a sphere; never committed) and
# renders each at 640x360, 4 spp, printing file size; import, build and render
# seconds and the rest of the wall time; the peak resident memory, that above
# a render of a cloud of one sphere (the same image, so the same framebuffer
# and threads) and bytes a sphere; rays per second against the 10^3 cloud's.
# Then one line a target: at 10^7, import + build <= 4 s and <= 600 MB above
# the one-sphere render; at 10^8, <= 10 s, <= 3 GB and rays per second >= 0.35
# of 10^3's.
#
# Usage: bench/scale.sh [--runs K] [--csv FILE] [--chart] [--all] BUILD_DIR [N ...]
#   N ...     sphere counts (default 1000 1000000 10000000; --all adds 100000000)
#   --runs K  K renders a size, each figure the median (default 1)
#   --csv     writes the table's figures as CSV
#   --chart   also draws docs/images/scale.png (gnuplot, installed if missing)
#             from the CSV, docs/scale.csv unless --csv names another
#
# Clouds go to $PTR_SCALE_DIR if set (kept, and reused by the next run: a
# 10^8 cloud is 3.6 GB), else to a temporary directory removed at exit. A size
# is skipped, with the reason, when its file does not fit on the disk or its
# render would not fit in available memory: the estimate is the bytes a
# sphere measured at the largest size so far in this run, else
# $PTR_SCALE_BYTES_PER_SPHERE (default 200, about ptr's all-in figure at 10^7
# before its import and tree were made compact), with a quarter more as margin.
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
usage="usage: bench/scale.sh [--runs K] [--csv FILE] [--chart] [--all] BUILD_DIR [N ...]"
runs=1 csv='' chart='' all='' build='' sizes=''
while [ $# -gt 0 ]; do
    case $1 in
    --runs) runs=${2:?$usage}; shift ;;
    --csv) csv=${2:?$usage}; shift ;;
    --chart) chart=1 ;;
    --all) all=1 ;;
    -*) echo "$usage" >&2; exit 2 ;;
    *[!0-9]*) [ -z "$build" ] || { echo "$usage" >&2; exit 2; }; build=$1 ;;
    *) if [ -z "$build" ]; then build=$1; else sizes="$sizes $1"; fi ;;
    esac
    shift
done
[ -n "$build" ] || { echo "$usage" >&2; exit 2; }
[ -n "$sizes" ] || sizes="1000 1000000 10000000"
[ -z "$all" ] || sizes="$sizes 100000000"
# Ascending, so that the memory check of a size can use the one before.
sizes=$(echo "$sizes" | tr -s ' ' '\n' | sort -n -u)
[ -z "$chart" ] || csv=${csv:-$root/docs/scale.csv}

cmake --build "$build" --target ptr make_cloud >/dev/null
ptr=$build/src/ptr make_cloud=$build/bench/make_cloud

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
dir=${PTR_SCALE_DIR:-$work}
mkdir -p "$dir"

median() { sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }
field() { sed -n "s/.*\"$1\": \([0-9.e+-]*\).*/\1/p" "$2"; }

# The cloud of N spheres, generated once: prints its path, or nothing (and why,
# on stderr) when the disk has no room for it.
cloud() {
    file=$dir/cloud$1.glb
    if [ ! -f "$file" ]; then
        need_kb=$(( ($1 * 36 + 2000000) / 1024 ))
        free_kb=$(df -Pk "$dir" | awk 'NR == 2 { print $4 }')
        if [ "$free_kb" -lt "$need_kb" ]; then
            echo "skipped $1 spheres: the cloud needs $((need_kb / 1024)) MB, $dir has $((free_kb / 1024)) MB free" >&2
            return 0
        fi
        if ! /usr/bin/time -f "%e" -o "$work/gen.time" "$make_cloud" "$1" "$file"; then
            echo "skipped $1 spheres: no cloud" >&2
            return 0
        fi
        # Written back now, not while the import is timed: a 10^7 cloud read
        # during its own writeback once imported in 9.9 s against 3.5 s.
        sync
        echo "generated $file: $(awk -v b="$(wc -c <"$file")" 'BEGIN { printf "%.1f", b / 1e6 }') MB in $(cat "$work/gen.time") s" >&2
    fi
    echo "$file"
}

# Renders FILE RUNS times; appends "import build render rays wall peak_kB"
# (medians) to $work/figures, or says why not. The image is the one the
# targets name: 640x360, 4 spp; EXR, so that no tone mapping is timed.
render() {
    : >"$work/runs"
    for _ in $(seq "$runs"); do
        status=0
        /usr/bin/time -f "%e %M" -o "$work/time" "$ptr" "$1" -o "$work/out.exr" \
            --width 640 --height 360 --samples 4 --json --quiet >"$work/json" 2>"$work/err" || status=$?
        if [ "$status" -ne 0 ]; then
            echo "ptr failed on $1 (exit $status): $(head -n 1 "$work/err")" >&2
            return 1
        fi
        echo "$(field import_seconds "$work/json") $(field build_seconds "$work/json")" \
             "$(field render_seconds "$work/json") $(field rays "$work/json") $(tail -n 1 "$work/time")" \
             >>"$work/runs"
    done
    for column in 1 2 3 4 5 6; do
        printf '%s ' "$(cut -d' ' -f$column "$work/runs" | median)"
    done >>"$work/figures"
    echo >>"$work/figures"
}

# The one-sphere cloud: the memory every render of this size takes anyway.
: >"$work/figures"
render "$(cloud 1)"
empty_kb=$(awk '{ print $6 }' "$work/figures")
: >"$work/figures"
: >"$work/table"
bytes_per_sphere=${PTR_SCALE_BYTES_PER_SPHERE:-200}

for n in $sizes; do
    need_kb=$(awk -v n="$n" -v b="$bytes_per_sphere" -v e="$empty_kb" 'BEGIN { printf "%d", e + 1.25 * n * b / 1024 }')
    avail_kb=$(awk '/^MemAvailable:/ { print $2 }' /proc/meminfo)
    if [ "$need_kb" -gt "$avail_kb" ]; then
        echo "skipped $n spheres: its render would need about $((need_kb / 1024)) MB" \
             "($bytes_per_sphere bytes a sphere and a quarter more), $((avail_kb / 1024)) MB available" >&2
        continue
    fi
    file=$(cloud "$n")
    [ -n "$file" ] || continue
    : >"$work/figures"
    render "$file" || continue
    echo "$n $(wc -c <"$file") $(cat "$work/figures")" >>"$work/table"
    # From 10^5 spheres on, the figure at this size is the next one's estimate
    # (below that the one-sphere render's own noise dominates).
    if [ "$n" -ge 100000 ]; then
        bytes_per_sphere=$(tail -n 1 "$work/table" | awk -v e="$empty_kb" '{ b = ($8 - e) * 1024 / $1; print (b > 1 ? int(b) + 1 : 1) }')
    fi
done

# The table (MB are 10^6 bytes; peak is GNU time's %M, in KiB), the CSV and the targets.
awk -v e="$empty_kb" -v csv="$csv" -v runs="$runs" '
function mb(kb) { return kb * 1024 / 1e6 }
BEGIN {
    printf "%11s %9s %8s %8s %8s %8s %8s %8s %9s %9s %8s %8s %8s\n", "spheres", "file MB", "import s",
        "build s", "imp+bld", "render s", "other s", "wall s", "peak MB", "above MB", "B/sphere",
        "Mrays/s", "vs 10^3"
    if (csv != "")
        print "spheres,file_mb,import_s,build_s,import_build_s,render_s,other_s,wall_s,peak_mb,above_empty_mb," \
              "bytes_per_sphere,mrays_per_s,relative_to_1000" > csv
}
{
    n = $1; mrays = $6 / $5 / 1e6; above = mb($8 - e); per = above * 1e6 / n; other = $7 - $3 - $4 - $5
    if (n == 1000) base = mrays
    rel = base ? sprintf("%.2f", mrays / base) : "-"
    printf "%11d %9.1f %8.3f %8.3f %8.3f %8.3f %8.2f %8.2f %9.0f %9.0f %8.1f %8.2f %8s\n",
        n, $2 / 1e6, $3, $4, $3 + $4, $5, other, $7, mb($8), above, per, mrays, rel
    if (csv != "")
        printf "%d,%.1f,%.3f,%.3f,%.3f,%.3f,%.2f,%.2f,%.0f,%.0f,%.1f,%.3f,%s\n", n, $2 / 1e6, $3, $4,
            $3 + $4, $5, other, $7, mb($8), above, per, mrays, (base ? rel : "") > csv
    ib[n] = $3 + $4; ab[n] = above; mr[n] = mrays
}
function check(what, value, unit, limit) {
    printf "  %-34s %10.2f %-5s <= %-8s %s\n", what, value, unit, limit, (value <= limit ? "PASS" : "miss")
}
END {
    printf "(640x360, 4 spp, %d run%s a size, medians; other: the wall time outside import, build and\n" \
        "render (start, the scene hash, the image, exit); above MB: above a one-sphere render, %.0f MB)\n",
        runs, runs == 1 ? "" : "s", mb(e)
    if (1e7 in ib || 1e8 in ib) print "targets:"
    if (1e7 in ib) {
        check("10^7 import + build", ib[1e7], "s", 4)
        check("10^7 peak above one sphere", ab[1e7], "MB", 600)
    }
    if (1e8 in ib) {
        check("10^8 import + build", ib[1e8], "s", 10)
        check("10^8 peak above one sphere", ab[1e8], "MB", 3000)
        if (base)
            printf "  %-34s %10.2f %-5s >= %-8s %s\n", "10^8 Mrays/s against 10^3", mr[1e8] / base, "x",
                "0.35", (mr[1e8] >= 0.35 * base ? "PASS" : "miss")
    }
}' "$work/table"

if [ -n "$csv" ]; then
    echo "wrote $csv"
fi
if [ -n "$chart" ]; then
    . "$root/bench/need_gnuplot.sh"
    gnuplot -e "data='$csv'; out='$root/docs/images/scale.png'" "$root/bench/scale.gp"
    echo "wrote $root/docs/images/scale.png"
fi
