#!/usr/bin/env python3
"""The files of tests/fixtures/ecosystem/, written by three.js, the glTF
Transform CLI and gltfpack (tests/fixtures/ecosystem/make_fixtures.sh), import
as the scenes they were made from, and render.

- three_instanced.glb (three.js GLTFExporter, an InstancedMesh) against
  three_instanced.json, the centres, radii and colours the script used.
- instance, quantize, meshopt, draco, optimize, instance_meshopt, gltfpack,
  join and join_meshopt (.glb) against nodes.glb, the node-per-sphere scene
  they were made from (which itself must match nodes.json exactly): join
  merges the 60 spheres into one mesh of 4 primitives, one a material, and
  ptr finds each sphere again as a connected component.
  Compared: the number of spheres; each reference sphere is paired with the
  nearest one imported (instancing reorders them); centre components and
  radius within TOL(r) = 2 * r / (2^14 - 1) + 1e-6 * SIZE: 14 bits is the
  POSITION quantisation of gltf-transform (quantize, meshopt, draco, optimize)
  and gltfpack, over the mesh's bounds (the sphere's diameter 2r in world
  units), so a bound, the centre and the radius each move by at most one step
  2r / (2^14 - 1); SIZE (the largest centre coordinate) covers float rounding.
  join_meshopt is quantised over the joined mesh's bounds, the whole scene:
  its step is SPAN / (2^14 - 1), SPAN the largest extent of the spheres'
  bounds.
  Files without quantisation (three_instanced, instance) get 1e-6 * SIZE only.
  Materials: the same kind, fuzz and ior within 1e-6, and the colour (the
  material's albedo times the sphere's own colour, where it has one) within
  1/255 (colours are not quantised by these tools unless instanced, where
  8-bit colour is their default).
- Each file renders: ptr FILE -o out.exr --samples 1 --width 16, exit 0.
- ortho.gltf (three.js, an OrthographicCamera xmag 6, ymag 4, znear 0.5,
  zfar 50 at (0, 2, 10) looking down -Z) shows in --dump-scene as an
  orthographic camera (projection "orthographic", ymag 4), looking from
  (0, 2, 10) down -Z, with no warning that it is ignored; 3 spheres.

Each file gets one line: PASS, or FAIL with what failed.
Usage: check_ecosystem.py PTR FIXTURES_DIR"""
import json
import math
import os
import subprocess
import sys
import tempfile

ptr, folder = sys.argv[1], sys.argv[2]
POSITION_BITS = 14
GLTF_TRANSFORM = ["instance", "quantize", "meshopt", "draco", "optimize", "instance_meshopt",
                  "gltfpack", "join", "join_meshopt"]
# Quantised over each sphere's mesh, or over one mesh holding them all.
QUANTISED = {"quantize", "meshopt", "draco", "optimize", "instance_meshopt", "gltfpack"}
QUANTISED_JOINED = {"join_meshopt"}


class Failure(Exception):
    pass


def dump(name):
    run = subprocess.run([ptr, "--dump-scene", os.path.join(folder, name)], capture_output=True,
                         text=True, timeout=60)
    if run.returncode != 0:
        raise Failure(f"--dump-scene exit {run.returncode}: {run.stderr.strip()[:300]}")
    return json.loads(run.stdout)


def render(name, scratch):
    run = subprocess.run([ptr, os.path.join(folder, name), "-o", os.path.join(scratch, "out.exr"),
                          "--samples", "1", "--width", "16", "--quiet"], capture_output=True,
                         text=True, timeout=60)
    if run.returncode != 0:
        raise Failure(f"render exit {run.returncode}: {run.stderr.strip()[:300]}")


def flatten(scene):
    """Spheres with their material and effective colour (albedo x own colour)."""
    out = []
    for s in scene["spheres"]:
        m = scene["materials"][s["material"]]
        colour = [a * c for a, c in zip(m["albedo"], s.get("color", [1, 1, 1]))]
        out.append({"center": s["center"], "radius": s["radius"], "kind": m["kind"],
                    "colour": colour, "fuzz": m.get("fuzz", 0), "ior": m.get("ior", 0),
                    "emission": m.get("emission", [0, 0, 0])})
    return out


def compare(got, want, quantised, joined=False):
    """Problems of `got` against `want` (lists from flatten), at most a few;
    quantised over each sphere's bounds, or (joined) over all of them."""
    if len(got) != len(want):
        return [f"{len(got)} spheres, not {len(want)}"]
    size = max(abs(x) for s in want for x in s["center"])
    span = max(max(s["center"][k] + s["radius"] for s in want) -
               min(s["center"][k] - s["radius"] for s in want) for k in range(3))
    problems, free = [], list(range(len(got)))
    for i, w in enumerate(want):
        j = min(free, key=lambda k: sum((a - b) ** 2 for a, b in zip(got[k]["center"],
                                                                     w["center"])))
        free.remove(j)
        g = got[j]
        extent = span if joined else 2 * w["radius"]
        tol = 1e-6 * size + (extent / (2 ** POSITION_BITS - 1) if quantised else 0)
        err = max(abs(a - b) for a, b in zip(g["center"], w["center"]))
        if err > tol:
            problems.append(f"sphere {i}: centre {g['center']}, not {w['center']} "
                            f"(off by {err:.3g} > {tol:.3g})")
        if abs(g["radius"] - w["radius"]) > tol:
            problems.append(f"sphere {i}: radius {g['radius']}, not {w['radius']} (tolerance "
                            f"{tol:.3g})")
        if g["kind"] != w["kind"]:
            problems.append(f"sphere {i}: material {g['kind']}, not {w['kind']}")
        elif abs(g["fuzz"] - w["fuzz"]) > 1e-6 or abs(g["ior"] - w["ior"]) > 1e-6:
            problems.append(f"sphere {i}: fuzz/ior {g['fuzz']}/{g['ior']}, not "
                            f"{w['fuzz']}/{w['ior']}")
        if max(abs(a - b) for a, b in zip(g["colour"] + g["emission"],
                                          w["colour"] + w["emission"])) > 1.0 / 255:
            problems.append(f"sphere {i}: colour {g['colour']}, not {w['colour']}")
    return problems


def reference_nodes():
    with open(os.path.join(folder, "nodes.json")) as f:
        desc = json.load(f)
    kinds = {"lambertian": "diffuse", "metal": "metal", "dielectric": "dielectric"}
    return [{"center": s["center"], "radius": s["radius"], "kind": kinds[s["material"]],
             "colour": s.get("albedo", [1, 1, 1]), "fuzz": s.get("fuzz", 0),
             "ior": s.get("ior", 0), "emission": [0, 0, 0]} for s in desc["spheres"]]


def reference_three():
    with open(os.path.join(folder, "three_instanced.json")) as f:
        desc = json.load(f)
    return [{"center": s["center"], "radius": s["radius"], "kind": "diffuse",
             "colour": s["color"], "fuzz": 0, "ior": 0, "emission": [0, 0, 0]}
            for s in desc["spheres"]]


def check_ortho(scene):
    problems = []
    cam = scene["camera"]
    if cam.get("projection") != "orthographic":
        problems.append(f"camera is not orthographic: {json.dumps(cam)}")
    elif abs(cam.get("ymag", 0) - 4) > 1e-6:
        problems.append(f"camera ymag {cam.get('ymag')}, not 4")
    if max(abs(a - b) for a, b in zip(cam["lookfrom"], [0, 2, 10])) > 1e-6:
        problems.append(f"camera looks from {cam['lookfrom']}, not [0, 2, 10]")
    d = [a - b for a, b in zip(cam["lookat"], cam["lookfrom"])]
    n = math.sqrt(sum(x * x for x in d)) or 1
    if abs(d[2] / n + 1) > 1e-6:
        problems.append(f"camera looks along {d}, not -Z")
    problems += [f"warning: {w}" for w in scene["warnings"] if "camera" in w]
    if len(scene["spheres"]) != 3:
        problems.append(f"{len(scene['spheres'])} spheres, not 3")
    return problems


def main():
    results = {}
    with tempfile.TemporaryDirectory() as scratch:
        def check(name, test):
            try:
                problems = test()
                render(name, scratch)
            except Failure as e:
                problems = [str(e)]
            except Exception as e:  # a dump that is not the JSON expected
                problems = [f"{type(e).__name__}: {e}"]
            results[name] = problems

        nodes = None

        def check_nodes():
            nonlocal nodes
            nodes = flatten(dump("nodes.glb"))
            return compare(nodes, reference_nodes(), False)

        check("nodes.glb", check_nodes)
        check("three_instanced.glb",
              lambda: compare(flatten(dump("three_instanced.glb")), reference_three(), False))
        for stem in GLTF_TRANSFORM:
            name = stem + ".glb"
            if nodes is None:
                results[name] = ["nodes.glb, the reference, did not import"]
                continue
            check(name, lambda: compare(flatten(dump(name)), nodes,
                                        stem in QUANTISED | QUANTISED_JOINED,
                                        stem in QUANTISED_JOINED))
        check("ortho.gltf", lambda: check_ortho(dump("ortho.gltf")))

    failed = 0
    for name, problems in results.items():
        if not problems:
            print(f"PASS {name}")
            continue
        failed += 1
        more = f" (and {len(problems) - 3} more)" if len(problems) > 3 else ""
        print(f"FAIL {name}: " + "; ".join(problems[:3]) + more)
    print(f"{len(results) - failed} files passed, {failed} failed")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
