#!/usr/bin/env python3
"""Writes a particle cloud of N spheres above a ground as an instanced glTF
binary (EXT_mesh_gpu_instancing): the spheres fill a 20 x 6 x 20 box at a fixed
volume fraction (about 8%), 80% diffuse in random colours, 15% metal, 5% glass,
so that any N looks alike. About 40 bytes a sphere: a million spheres make a
40 MB file.

Usage: make_cloud.py N OUTPUT.glb [SEED]
"""
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_scenes  # noqa: E402  (the glTF writer)


def cloud(n, seed):
    rng = random.Random(seed)
    box = (20.0, 6.0, 20.0)
    r = (0.08 * box[0] * box[1] * box[2] / n * 3 / (4 * math.pi)) ** (1 / 3)
    spheres = [{"center": [0.0, -1000.0, 0.0], "radius": 1000.0, "material": "lambertian",
                "albedo": [0.5, 0.5, 0.5]}]
    for _ in range(n):
        centre = [rng.uniform(-box[0] / 2, box[0] / 2), rng.uniform(r, box[1]),
                  rng.uniform(-box[2] / 2, box[2] / 2)]
        kind = rng.random()
        if kind < 0.8:
            s = {"material": "lambertian", "albedo": [rng.random() * rng.random() for _ in range(3)]}
        elif kind < 0.95:
            s = {"material": "metal", "albedo": [rng.uniform(0.5, 1) for _ in range(3)],
                 "fuzz": rng.choice([0.0, 0.1, 0.2, 0.3, 0.4, 0.5])}
        else:
            s = {"material": "dielectric", "ior": 1.5}
        spheres.append(dict(s, center=centre, radius=r))
    return {"name": f"cloud{n}", "image": {"width": 400, "height": 225},
            "sky": {"type": "gradient"}, "spheres": spheres,
            "camera": {"lookfrom": [0.0, 9.0, 26.0], "lookat": [0.0, 2.0, 0.0], "vup": [0, 1, 0],
                       "vfov_deg": 40.0, "aperture": 0.0, "focus_dist": 26.0}}


def main():
    if len(sys.argv) not in (3, 4) or not sys.argv[2].endswith(".glb"):
        raise SystemExit(__doc__)
    n = int(sys.argv[1])
    make_scenes.write(*make_scenes.build(cloud(n, int(sys.argv[3]) if len(sys.argv) > 3 else 7),
                                         instanced=True), sys.argv[2])


if __name__ == "__main__":
    main()
