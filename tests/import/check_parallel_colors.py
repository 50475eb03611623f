#!/usr/bin/env python3
"""The colours of a primitive of 50,400 vertices (above importers'
PARALLEL_COLORS, 32,768) are read on all cores; the same vertices as two
primitives of 25,200 are read one by one. The two must give the same scene
bit for bit (--dump-scene: spheres and materials): each of 1,200 spheres
reads a base colour, emissive and metallic-roughness texel of 16 x 16
palettes and COLOR_0, and every fourth reads texels that vary over it (the
mean, summed in vertex order). Broken, with a NaN texture coordinate at
vertex 40,000 (the last thread's range), both refuse the file with the same error.
usage: check_parallel_colors.py PTR"""
import json
import math
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
import mesh_files as mf  # noqa: E402
import texture_files as tf  # noqa: E402
from parallel_import import dump_clouds, report  # noqa: E402

ptr = sys.argv[1]
SPHERES = 1_200  # of 42 vertices: 50,400 in all
SIDE = 16  # the palettes' width and height
BROKEN_VERTEX = 40_000


def write_cloud(path, parts, broken):
    rng = random.Random(7)
    palettes = [[[rng.randrange(256) for _ in range(3)] + [255] for _ in range(SIDE * SIDE)]
                for _ in range(3)]
    spheres = [mf.uv_sphere((3 * (i % 40), 3 * (i // 40), 0), 0.5 + 0.0001 * i)
               for i in range(SPHERES)]
    uv, colour = [], []
    for i, (verts, _) in enumerate(spheres):
        texel = rng.randrange(SIDE * SIDE)
        centre = ((texel % SIDE + 0.5) / SIDE, (texel // SIDE + 0.5) / SIDE)
        grey = rng.random()
        for _ in verts:
            uv.append((rng.random(), rng.random()) if i % 4 == 0 else centre)
            colour.append((grey, rng.random() if i % 4 == 0 else grey, grey, 1.0))
    if broken:
        uv[BROKEN_VERTEX] = (math.nan, 0.5)
    w = tf.Writer()
    textures = [w.texture(w.image(tf.png(p, SIDE))) for p in palettes]
    m = w.material(pbrMetallicRoughness={"baseColorTexture": {"index": textures[0]},
                                         "metallicRoughnessTexture": {"index": textures[2]}},
                   emissiveTexture={"index": textures[1]}, emissiveFactor=[0.5, 0.5, 0.5])
    per_part = SPHERES // parts
    shapes = [mf.combine(*spheres[k * per_part:(k + 1) * per_part]) for k in range(parts)]
    mesh = w.mesh("cloud", [(shape, m) for shape in shapes])
    at = 0
    for k, (verts, _) in enumerate(shapes):
        w.attribute(mesh, k, "TEXCOORD_0", uv[at:at + len(verts)])
        w.attribute(mesh, k, "COLOR_0", colour[at:at + len(verts)])
        at += len(verts)
    w.node("Cloud", mesh)
    w.write(path)


def stderr(run):
    """The run's standard error without the file's name, which differs."""
    return run.stderr.replace(run.args[-1], "FILE")


def main():
    runs = dump_clouds(ptr, write_cloud)
    failures = []
    whole, halves = runs[1, False], runs[2, False]
    if whole.returncode or halves.returncode:
        failures.append(f"valid files refused: {whole.stderr.strip()} / {halves.stderr.strip()}")
    else:
        a, b = json.loads(whole.stdout), json.loads(halves.stdout)
        if len(a["spheres"]) != SPHERES:
            failures.append(f"{len(a['spheres'])} spheres, not {SPHERES}")
        for key in ("spheres", "materials"):
            if a[key] != b[key]:
                differ = next((i for i, (x, y) in enumerate(zip(a[key], b[key])) if x != y), None)
                failures.append(f"{key} differ: {len(a[key])} and {len(b[key])}, first at {differ}")
        if stderr(whole) != stderr(halves):
            failures.append(f"warnings differ: {stderr(whole)!r} / {stderr(halves)!r}")
    for parts in (1, 2):
        run = runs[parts, True]
        if run.returncode == 0 or "not finite" not in run.stderr:
            failures.append(f"{parts} parts, NaN texture coordinate: exit {run.returncode}, "
                            f"{run.stderr.strip()}")
    if stderr(runs[1, True]) != stderr(runs[2, True]):
        failures.append(f"errors differ: {stderr(runs[1, True])!r} / {stderr(runs[2, True])!r}")
    report(failures, 4)


if __name__ == "__main__":
    main()
