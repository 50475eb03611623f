#!/usr/bin/env python3
"""A POINTS primitive of 40,000 points (POSITION, _RADIUS, COLOR_0 and
_TEMPERATURE, under a scaled and moved node) is turned into spheres on all
cores; the same points as two primitives of 20,000 are turned one by one. The
two must give the same scene bit for bit (--dump-scene), with and without
their values (--color-by _TEMPERATURE), and, where points are broken, the
same first error: the zero radius at point 1,000 is reported, not the NaN
position at point 39,000 that another thread meets after it; with values,
the NaN value at point 500 before either.
usage: check_parallel_points.py PTR"""
import json, math, os, random, struct, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from glb import write_glb  # noqa: E402
from parallel_import import dump_clouds, report, spheres_differ  # noqa: E402

ptr = sys.argv[1]
COUNT = 40_000  # above importers' PARALLEL_PARTS (32,768); each half below it


def points(broken):
    rng = random.Random(9)
    pos = [(rng.uniform(-10, 10), rng.uniform(0, 6), rng.uniform(-30, -10)) for _ in range(COUNT)]
    rad = [rng.uniform(0.01, 0.1) for _ in range(COUNT)]
    col = [(rng.random(), rng.random(), rng.random(), 1.0) for _ in range(COUNT)]
    val = [rng.uniform(200, 400) for _ in range(COUNT)]
    if broken:
        rad[1_000] = 0.0
        pos[39_000] = (math.nan, 0.0, 0.0)
        val[500] = math.nan
    return pos, rad, col, val


def write_cloud(path, primitives, broken):
    pos, rad, col, val = points(broken)
    blocks = [(b"".join(struct.pack("<3f", *v) for v in pos), 12, "VEC3"),
              (b"".join(struct.pack("<f", v) for v in rad), 4, "SCALAR"),
              (b"".join(struct.pack("<4f", *v) for v in col), 16, "VEC4"),
              (b"".join(struct.pack("<f", v) for v in val), 4, "SCALAR")]
    binary, views = b"", []
    for block, _, _ in blocks:
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(block)})
        binary += block
    per = COUNT // primitives
    accessors, prims = [], []
    for p in range(primitives):
        first = len(accessors)
        for k, (_, width, kind) in enumerate(blocks):
            accessors.append({"bufferView": k, "byteOffset": p * per * width, "componentType": 5126,
                              "count": per, "type": kind})
        accessors[first]["min"] = [-10, 0, -30]
        accessors[first]["max"] = [10, 6, -10]
        prims.append({"mode": 0, "material": 0, "attributes": {
            "POSITION": first, "_RADIUS": first + 1, "COLOR_0": first + 2,
            "_TEMPERATURE": first + 3}})
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": views,
        "accessors": accessors,
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0}}],
        "meshes": [{"primitives": prims}],
        "nodes": [{"mesh": 0, "name": "cloud", "translation": [0.5, -1, 2], "scale": [2, 2, 2]},
                  {"camera": 0, "translation": [0, 3, 10]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "scenes": [{"nodes": [0, 1]}],
        "scene": 0,
    }
    write_glb(path, doc, binary)


failures = []
for options, first_error in (((), "point 1000 gives a sphere"),
                             (("--color-by", "_TEMPERATURE"),
                              "point 500: attribute '_TEMPERATURE' is not finite")):
    runs = dump_clouds(ptr, write_cloud, options)
    differ = spheres_differ(runs, COUNT)
    if differ:
        failures.append(f"{' '.join(options)}: {differ}")
    elif options and "value" not in json.loads(runs[1, False].stdout)["spheres"][-1]:
        failures.append("--color-by: the spheres have no value")
    for primitives in (1, 2):
        run = runs[primitives, True]
        if run.returncode != 4 or first_error not in run.stderr:
            failures.append(f"{' '.join(options)}: broken points in {primitives} primitives: "
                            f"exit {run.returncode}: {run.stderr.strip()}")
report(failures, 6)
