#!/bin/sh
# Where the time of a ray goes, by stage, for ptr's render of a scene and for
# the closest-hit query alone, ptr's and Embree's on the same rays
# (bench/query): CPU-clock samples of perf (virtual machines have no cycle
# counter), each symbol put in its stage, each stage's share of the CPU time
# divided by the rays. Cycles are at the clock /proc/cpuinfo gives.
# Usage: bench/stages.sh BUILD SCENE SPP [QUERY_SPP]
#   e.g. bench/stages.sh build /tmp/final.glb 100 2
# BUILD is a build folder (its src/ptr and bench/query); QUERY_SPP (default
# 2) sets the rays bench/query records.
set -eu
build=$1 scene=$2 spp=$3 query_spp=${4:-2}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
hz=$(awk '/^cpu MHz/ { print $4 * 1e6; exit }' /proc/cpuinfo)
if [ ! -x "$build/bench/query" ]; then
    echo "bench/stages.sh: $build/bench/query is not built: it needs Embree 3" \
        "(apt-get install libembree-dev), then cmake -S . -B $build again" >&2
    exit 2
fi

perf record -q -o "$dir/render.perf" "$build/src/ptr" "$scene" -o "$dir/out.exr" \
    --samples "$spp" --quiet --json >"$dir/render.json" 2>/dev/null
perf report -i "$dir/render.perf" --stdio --sort dso,sym -F period,dso,sym 2>/dev/null \
    >"$dir/render.txt"
methods="as asked|embree user 16"
for m in "as asked" "embree user 16"; do
    perf record -q -o "$dir/query.perf" "$build/bench/query" "$scene" "$query_spp" 3 "$m" \
        >"$dir/query_$m.txt" 2>/dev/null
    perf report -i "$dir/query.perf" --stdio --sort dso,sym -F period,dso,sym 2>/dev/null \
        >"$dir/query_$m.perf.txt"
done

python3 - "$dir" "$hz" "$methods" <<'EOF'
import json, re, sys
dir, hz, methods = sys.argv[1], float(sys.argv[2]), sys.argv[3].split("|")

def periods(path):
    """(dso, symbol) -> nanoseconds of CPU (cpu-clock periods)."""
    out = {}
    for line in open(path):
        m = re.match(r"\s*(\d+)\s+(\S+)\s+\[.\]\s+(.*\S)", line)
        if m:
            key = (m.group(2), m.group(3))
            out[key] = out.get(key, 0) + int(m.group(1))
    return out

# A leaf's test: the one-ray kernels' test_leaf and the test_eight it calls
# for each eight spheres (asm/bvh.inc), the packet kernels' test_leaf. (The C
# traversal tests its leaves inline: its time is the traversal's.)
LEAF_SYMBOLS = ("test_leaf", "test_eight")

# First match wins: a leaf's symbols before the traversal's, a path's steps
# before "trace".
RENDER_STAGES = [
    ("sampling", ("bounce_numbers", "pair_bits", "sobol", "owen", "ptr_sampler", "ptr_rng")),
    ("camera rays", ("camera_rays", "make_camera_batch", "ptr_path_camera_ray", "ptr_camera")),
    ("leaves", LEAF_SYMBOLS),
    ("shading", ("find_surfaces", "scatter", "continue_or_end", "add_sky_and_emission",
                 "emission_weights", "refill", "ptr_path_", "sample_emitters", "render_round",
                 "ptr_render_tile", "trace_path", "lights", "ptr_sky")),
    ("traversal", ("bvh_closest_hit", "trace", "closest_hit", "ptr_huge")),
]

def stage_of(dso, sym, stages):
    for name, keys in stages:
        if any(k in sym for k in keys):
            return name
    return "other"

def table(title, ns_by_stage, rays, names):
    print(title)
    print("  %-12s %9s %11s %7s" % ("stage", "ns/ray", "cycles/ray", "share"))
    total = sum(ns_by_stage.get(n, 0) for n in names)
    for n in names:
        ns = ns_by_stage.get(n, 0)
        print("  %-12s %9.1f %11.0f %6.1f%%" % (n, ns / rays, ns / rays * hz * 1e-9,
                                                100.0 * ns / total if total else 0))
    print("  %-12s %9.1f %11.0f" % ("all", total / rays, total / rays * hz * 1e-9))

render = json.load(open(dir + "/render.json"))
by = {}
other = {}
for (dso, sym), ns in periods(dir + "/render.txt").items():
    s = stage_of(dso, sym, RENDER_STAGES)
    by[s] = by.get(s, 0) + ns
    if s == "other":
        other[sym] = other.get(sym, 0) + ns
table("ptr render: %s, %d spp, %s, %s, %d rays" % (render["scene"], render["samples"],
      render["kernel"], render["integrator"], render["rays"]), by, render["rays"],
      ["sampling", "camera rays", "traversal", "leaves", "shading", "other"])
# What "other" holds, so that a symbol renamed out of its stage shows here.
largest = sorted(other.items(), key=lambda kv: -kv[1])[:4]
total = sum(by.values())
if largest:
    print("  other's largest: " + ", ".join("%s %.1f%%" % (sym, 100.0 * ns / total)
                                           for sym, ns in largest))

# The query: the method's measured ns/ray split by its symbols' shares.
for m in methods:
    lines = open("%s/query_%s.txt" % (dir, m)).read().splitlines()
    row = [l for l in lines if l.startswith(m)][0]
    ns_per_ray = float(row[len(m):].split()[1])
    trav = leaf = 0
    for (dso, sym), ns in periods("%s/query_%s.perf.txt" % (dir, m)).items():
        if m.startswith("embree"):
            if "user_intersect" in sym:
                leaf += ns
            elif "libembree" in dso:
                trav += ns
        elif any(k in sym for k in LEAF_SYMBOLS):
            leaf += ns
        elif "bvh_closest_hit" in sym:
            trav += ns
    share = trav / (trav + leaf)
    print("query %s: %s" % (m, lines[0]))
    print("  traversal %.1f ns/ray (%.0f cycles), leaves %.1f ns/ray (%.0f cycles)" % (
        ns_per_ray * share, ns_per_ray * share * hz * 1e-9,
        ns_per_ray * (1 - share), ns_per_ray * (1 - share) * hz * 1e-9))
EOF
