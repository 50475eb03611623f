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
from parallel_import import (dump_clouds, report, spheres_differ,  # noqa: E402
                             write_instanced_spheres)

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
    write_instanced_spheres(path, [
        ("TRANSLATION", "VEC3", b"".join(struct.pack("<3f", *v) for v in t)),
        ("ROTATION", "VEC4", b"".join(struct.pack("<4f", *v) for v in r)),
        ("SCALE", "VEC3", b"".join(struct.pack("<3f", *v) for v in s)),
        ("_COLOR_0", "VEC3", b"".join(struct.pack("<3f", *v) for v in c))], COUNT, nodes)


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
