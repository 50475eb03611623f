#!/usr/bin/env python3
"""An instanced node of 40,000 instances (TRANSLATION, ROTATION, SCALE and
_COLOR_0) is turned into spheres on all cores; the same instances as two
nodes of 20,000 are turned one by one. The two must give the same scene bit
for bit (--dump-scene), the same warning for a non-uniform scale (once), and,
where instances are broken, the same first error: a zero scale at instance
1,000 is reported, not the NaN translation at instance 39,000 that another
thread meets after it.
usage: check_parallel_instances.py PTR"""
import math, os, random, struct, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from glb import write_glb  # noqa: E402
from mesh_files import sphere_bytes  # noqa: E402
from parallel_import import dump_clouds, report, spheres_differ  # noqa: E402

ptr = sys.argv[1]
COUNT = 40_000  # above importers' PARALLEL_PARTS (32,768); each half below it


def instances(broken):
    rng = random.Random(5)
    t, r, s, c = [], [], [], []
    for i in range(COUNT):
        t.append((rng.uniform(-10, 10), rng.uniform(0, 6), rng.uniform(-30, -10)))
        q = [rng.uniform(-1, 1) for _ in range(4)]  # not unit: ptr normalises
        r.append(tuple(q))
        k = rng.uniform(0.5, 2)
        s.append((k, k, k) if i != 7 else (k, 2 * k, k))  # one non-uniform scale
        c.append((rng.random(), rng.random(), rng.random()))
    if broken:
        s[1_000] = (0.0, 0.0, 0.0)
        t[39_000] = (math.nan, 0.0, 0.0)
    return t, r, s, c


def write_cloud(path, nodes, broken):
    t, r, s, c = instances(broken)
    blocks = [b"".join(struct.pack("<3f", *v) for v in t), b"".join(struct.pack("<4f", *v) for v in r),
              b"".join(struct.pack("<3f", *v) for v in s), b"".join(struct.pack("<3f", *v) for v in c)]
    sphere, indices, vertices, index_count = sphere_bytes(0.05)
    binary, views = b"", []
    for block in blocks + [sphere, indices]:
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(block)})
        binary += block
    per = COUNT // nodes
    accessors, node_list = [], []
    for n in range(nodes):
        first = len(accessors)
        for k, (width, kind) in enumerate([(12, "VEC3"), (16, "VEC4"), (12, "VEC3"), (12, "VEC3")]):
            accessors.append({"bufferView": k, "byteOffset": n * per * width, "componentType": 5126,
                              "count": per, "type": kind})
        node_list.append({"mesh": 0, "name": "cloud", "extensions": {"EXT_mesh_gpu_instancing": {
            "attributes": {"TRANSLATION": first, "ROTATION": first + 1, "SCALE": first + 2,
                           "_COLOR_0": first + 3}}}})
    accessors.append({"bufferView": 4, "componentType": 5126, "count": vertices, "type": "VEC3",
                      "min": [-0.05, -0.05, -0.05], "max": [0.05, 0.05, 0.05]})
    accessors.append({"bufferView": 5, "componentType": 5123, "count": index_count,
                      "type": "SCALAR"})
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": views,
        "accessors": accessors,
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                    "indices": len(accessors) - 1, "material": 0}]}],
        "nodes": node_list + [{"camera": 0, "translation": [0, 3, 10]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "scenes": [{"nodes": list(range(nodes + 1))}],
        "scene": 0,
    }
    write_glb(path, doc, binary)


runs = dump_clouds(ptr, write_cloud)
differ = spheres_differ(runs, COUNT)
failures = [differ] if differ else []
for run in (runs[1, False], runs[2, False]):
    if run.returncode == 0 and run.stderr.count("non-uniform scale") != 1:
        failures.append(f"non-uniform scale warned {run.stderr.count('non-uniform scale')} "
                        f"times: {run.stderr.strip()}")
broken = runs[1, True]
if broken.returncode != 4 or "instance 1000 has a non-finite transform" not in broken.stderr:
    failures.append(f"broken instances: exit {broken.returncode}: {broken.stderr.strip()}")
if "instance 1000 has a non-finite transform" not in runs[2, True].stderr:
    failures.append(f"broken halves: {runs[2, True].stderr.strip()}")
report(failures, 5)
