#!/usr/bin/env python3
"""Instances without a ROTATION under an identity world take a shorter road
to their transform than instances with one (importers/gltf/gltf_instances.c,
moved_and_scaled). The same instances with every rotation the identity
quaternion (0, 0, 0, 1) take the general one. The two must give the same
scene bit for bit (--dump-scene), the same warnings and the same first
error: with translations of -0, 0 and every sign, uniform and non-uniform
scales from 1e-30 to 1e30, with TRANSLATION or SCALE alone, and with a zero
scale, an infinite scale and a NaN translation.
usage: check_instance_transforms.py PTR"""
import json, math, os, random, struct, subprocess, sys, tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from parallel_import import report, write_instanced_spheres  # noqa: E402

ptr = sys.argv[1]
COUNT = 40_000  # above importers' PARALLEL_PARTS (32,768): converted on all cores


def instances(broken):
    rng = random.Random(9)
    t, s = [], []
    for i in range(COUNT):
        t.append(tuple(rng.choice((-0.0, 0.0, rng.uniform(-10, 10))) for _ in range(3)))
        k = 10.0 ** rng.uniform(-30, 30) if i % 100 == 0 else rng.uniform(0.5, 2)
        s.append((k, k, k) if i % 7 else (k, rng.uniform(0.5, 2), k))
    if broken == "zero scale":
        s[1_000] = (1.0, 0.0, 1.0)
    if broken == "infinite scale":
        s[1_000] = (math.inf, 1.0, 1.0)
    if broken == "nan translation":
        t[1_000] = (0.0, math.nan, 0.0)
    return t, s


def write_cloud(path, attributes, rotated, broken):
    t, s = instances(broken)
    columns = {"TRANSLATION": ("VEC3", b"".join(struct.pack("<3f", *v) for v in t)),
               "SCALE": ("VEC3", b"".join(struct.pack("<3f", *v) for v in s)),
               "ROTATION": ("VEC4", struct.pack("<4f", 0, 0, 0, 1) * COUNT)}
    names = list(attributes) + (["ROTATION"] if rotated else [])
    write_instanced_spheres(path, [(n, *columns[n]) for n in names], COUNT, 1)


def dump(d, attributes, rotated, broken):
    """ptr --dump-scene of the cloud, its file named the same whether rotated
    or not, so that messages naming it can be compared."""
    path = os.path.join(d, str(rotated), "cloud.glb")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    write_cloud(path, attributes, rotated, broken)
    run = subprocess.run([ptr, "--dump-scene", path], capture_output=True, text=True,
                         timeout=120)
    run.stderr = run.stderr.replace(path, "cloud.glb")
    return run


failures, checks = [], 0
with tempfile.TemporaryDirectory() as d:
    cases = [(a, None) for a in (("TRANSLATION", "SCALE"), ("TRANSLATION",), ("SCALE",))]
    cases += [(("TRANSLATION", "SCALE"), b)
              for b in ("zero scale", "infinite scale", "nan translation")]
    for attributes, broken in cases:
        checks += 1
        plain, rotated = dump(d, attributes, False, broken), dump(d, attributes, True, broken)
        name = f"{'+'.join(attributes)}, {broken or 'valid'}"
        if broken:
            if plain.returncode != 4 or "instance 1000 has a non-finite transform" not in plain.stderr:
                failures.append(f"{name}: exit {plain.returncode}: {plain.stderr.strip()}")
            elif plain.stderr != rotated.stderr:
                failures.append(f"{name}: {plain.stderr.strip()} / {rotated.stderr.strip()}")
            continue
        if plain.returncode or rotated.returncode:
            failures.append(f"{name}: refused: {plain.stderr.strip()} / {rotated.stderr.strip()}")
            continue
        a, b = json.loads(plain.stdout), json.loads(rotated.stdout)
        for key in ("scene", "warnings"):  # the file's path, in stderr too
            a.pop(key), b.pop(key)
        if len(a["spheres"]) != COUNT or a["spheres"] != b["spheres"]:
            differ = next((i for i, (x, y) in enumerate(zip(a["spheres"], b["spheres"]))
                           if x != y), None)
            failures.append(f"{name}: {len(a['spheres'])} and {len(b['spheres'])} spheres; "
                            f"first difference at sphere {differ}")
        elif a != b or plain.stderr != rotated.stderr:
            failures.append(f"{name}: the scenes' other entries or the warnings differ: "
                            f"{plain.stderr.strip()} / {rotated.stderr.strip()}")
report(failures, checks)
