#!/usr/bin/env python3
"""The same 40 spheres under a transformed parent, written as nodes, as
EXT_mesh_gpu_instancing instances (float, in a .gltf, in a .gltf whose buffer is
an external .bin and in a .glb whose BIN chunk, both read where they lie, and
quantized rotations and colours) and as a
POINTS primitive (tests/fixtures/make_instancing.py), import to the
same sphere list: centres and radii within float rounding (relative 1e-6 of
the scene's size), the same materials, and the same per-sphere colours where
the form carries them (within 1/65535, ptr's colour precision).
Usage: check_instancing.py PTR FIXTURE_DIR"""
import json
import subprocess
import sys

ptr, folder = sys.argv[1], sys.argv[2]


def dump(name):
    file = name if "." in name else f"{name}.gltf"
    out = subprocess.run([ptr, "--dump-scene", f"{folder}/{file}"], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)["spheres"]


forms = {name: dump(name) for name in ("nodes", "instances", "instances.glb", "instances_bin",
                                       "quantized", "points")}
reference = forms["nodes"]
size = max(abs(x) for s in reference for x in s["center"])
failures = []
for name, spheres in forms.items():
    if len(spheres) != len(reference):
        failures.append(f"{name}: {len(spheres)} spheres, not {len(reference)}")
        continue
    for i, (got, want) in enumerate(zip(spheres, reference)):
        if max(abs(a - b) for a, b in zip(got["center"], want["center"])) > 1e-6 * size:
            failures.append(f"{name}: sphere {i}: centre {got['center']}, not {want['center']}")
        if abs(got["radius"] - want["radius"]) > 1e-6 * want["radius"]:
            failures.append(f"{name}: sphere {i}: radius {got['radius']}, not {want['radius']}")
        if got["material"] != want["material"]:
            failures.append(f"{name}: sphere {i}: material {got['material']}")
        if name != "nodes":
            colour = forms["instances"][i]["color"]
            if max(abs(a - b) for a, b in zip(got["color"], colour)) > 1.01 / 65535:
                failures.append(f"{name}: sphere {i}: colour {got['color']}, not {colour}")
for f in failures:
    print(f)
checked = len(reference) * len(forms)
print(f"{checked - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
