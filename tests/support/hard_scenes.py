#!/usr/bin/env python3
"""Writes sphere sets that are hard for a tree as neutral scene descriptions
(the format of scripts/make_scenes.py's input), for the --accel tests.

Usage: hard_scenes.py FOLDER   (writes FOLDER/NAME.json for every scene)
"""
import json
import random
import sys

MATERIALS = [
    {"material": "lambertian", "albedo": [0.7, 0.3, 0.2]},
    {"material": "metal", "albedo": [0.8, 0.8, 0.9], "fuzz": 0.0},
    {"material": "dielectric", "ior": 1.5},
    {"material": "metal", "albedo": [0.9, 0.6, 0.2], "fuzz": 0.3},
]


def sphere(rng, c, r):
    return dict(rng.choice(MATERIALS), center=[round(x, 6) for x in c], radius=r)


def scene(name, spheres, lookfrom, lookat):
    return {"name": name, "image": {"width": 96, "height": 54}, "spp": 4, "max_depth": 20,
            "tmin": 0.001, "sky": {"type": "gradient", "bottom": [1, 1, 1], "top": [0.5, 0.7, 1.0]},
            "camera": {"lookfrom": lookfrom, "lookat": lookat, "vup": [0, 1, 0], "vfov_deg": 40.0,
                       "defocus_angle_deg": 0.0, "aperture": 0.0, "focus_dist": 10.0},
            "spheres": spheres}


def main():
    rng = random.Random(10)
    out = {}
    # A radius 1000 ground and a 1e5 one under tiny spheres.
    for name, g in (("ground", 1000.0), ("big_ground", 1e5)):
        s = [sphere(rng, [0, -g, 0], g)]
        s += [sphere(rng, [rng.uniform(-3, 3), rng.uniform(0, 1.5), rng.uniform(-3, 3)],
                     round(rng.uniform(0.02, 0.2), 4)) for _ in range(400)]
        out[name] = scene(name, s, [0, 2, 8], [0, 0.5, 0])
    # Overlapping clusters, exact duplicates, concentric shells, one centre.
    s = [sphere(rng, [c * 1.5 + rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)],
                round(rng.uniform(0.1, 0.8), 4)) for c in range(-2, 3) for _ in range(60)]
    s += [dict(s[i]) for i in range(0, 60, 3)]
    s += [sphere(rng, [0, 2.5, 0], 0.1 * k) for k in range(1, 8)]
    s += [sphere(rng, [2, 2.5, 0], 0.4) for _ in range(20)]
    out["clusters"] = scene("clusters", s, [0, 3, 10], [0, 0.5, 0])
    # A flat sheet and a line of spheres, far from the origin.
    far = 1e6
    s = [sphere(rng, [far + i * 0.5, 0, j * 0.5], 0.25) for i in range(-12, 13) for j in range(-12, 13)]
    s += [sphere(rng, [far + t, 1 + 0.5 * t, -t], 0.3) for t in [x * 0.2 for x in range(-20, 21)]]
    out["far_sheet"] = scene("far_sheet", s, [far, 6, 10], [far, 0, 0])
    for name, desc in out.items():
        with open(f"{sys.argv[1]}/{name}.json", "w") as f:
            json.dump(desc, f)


main()
