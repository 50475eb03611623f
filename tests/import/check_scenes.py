#!/usr/bin/env python3
"""Checks that ptr imports a glTF scene as exactly the spheres, materials,
camera, sky and image size of a neutral JSON scene description.

Usage: check_scenes.py PTR SCENE.gltf DESCRIPTION.json
Every value must match to float precision (a relative 1e-6). Exits 77
(skipped, for ctest) when the description is not on this machine."""
import json
import math
import os
import subprocess
import sys

KINDS = {"lambertian": "diffuse", "metal": "metal", "dielectric": "dielectric"}
failures = []


def close(a, b, what):
    if not math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-6):
        failures.append(f"{what}: {a!r} != {b!r}")


def close_vec(a, b, what):
    if len(a) != len(b):
        failures.append(f"{what}: {a!r} != {b!r}")
        return
    for i, (x, y) in enumerate(zip(a, b)):
        close(x, y, f"{what}[{i}]")


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def main():
    ptr, scene, description = sys.argv[1:4]
    if not os.path.isfile(description):
        print(f"skipped: no {description} (set PTR_BENCH_SCENES_DIR)")
        return 77
    dump = json.loads(subprocess.run([ptr, "--dump-scene", scene], check=True,
                                     capture_output=True, text=True).stdout)
    with open(description) as f:
        want = json.load(f)

    if len(dump["spheres"]) != len(want["spheres"]):
        failures.append(f"{len(dump['spheres'])} spheres, not {len(want['spheres'])}")
    for i, (got, exp) in enumerate(zip(dump["spheres"], want["spheres"])):
        close_vec(got["center"], exp["center"], f"sphere {i} centre")
        close(got["radius"], exp["radius"], f"sphere {i} radius")
        mat = dump["materials"][got["material"]]
        if mat["kind"] != KINDS[exp["material"]]:
            failures.append(f"sphere {i}: {mat['kind']}, not {exp['material']}")
        close_vec(mat["emission"], [0, 0, 0], f"sphere {i} emission")
        if exp["material"] == "dielectric":
            close(mat["ior"], exp["ior"], f"sphere {i} ior")
            close_vec(mat["albedo"], [1, 1, 1], f"sphere {i} attenuation")
        else:
            close_vec(mat["albedo"], exp["albedo"], f"sphere {i} albedo")
        if exp["material"] == "metal":
            close(mat["fuzz"], exp["fuzz"], f"sphere {i} fuzz")

    cam, exp = dump["camera"], want["camera"]
    close_vec(cam["lookfrom"], exp["lookfrom"], "camera lookfrom")
    close_vec(unit([a - b for a, b in zip(cam["lookat"], cam["lookfrom"])]),
              unit([a - b for a, b in zip(exp["lookat"], exp["lookfrom"])]), "camera direction")
    close(cam["vfov_deg"], exp["vfov_deg"], "camera vfov")
    close(cam["aperture"], exp["aperture"], "camera aperture")
    close(cam["focus_distance"], exp["focus_dist"], "camera focus distance")
    image = want["image"]
    if dump.get("resolution") != [image["width"], image["height"]]:
        failures.append(f"resolution {dump.get('resolution')}, not {image}")
    if dump["sky"] != want["sky"]["type"]:
        failures.append(f"sky {dump['sky']!r}, not {want['sky']['type']!r}")
    if dump["warnings"]:
        failures.append(f"warnings: {dump['warnings']}")

    for line in failures[:20]:
        print(f"{scene}: {line}", file=sys.stderr)
    checked = 2 * len(want["spheres"]) + 5
    print(f"{max(0, checked - len(failures))} passed, {len(failures)} failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
