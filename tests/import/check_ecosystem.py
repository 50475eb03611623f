#!/usr/bin/env python3
"""The files of tests/fixtures/ecosystem/, written by three.js, the glTF
Transform CLI and gltfpack (tests/fixtures/ecosystem/make_fixtures.sh) and by
Blender (make_blender.py), import as the scenes they were made from, and
render.

- three_instanced.glb (three.js GLTFExporter, an InstancedMesh) against
  three_instanced.json, the centres, radii and colours the script used.
- instance, quantize, meshopt, draco, optimize, instance_meshopt, gltfpack,
  join and join_meshopt (.glb) against nodes.glb, the node-per-sphere scene
  they were made from (which itself must match nodes.json exactly); and
  palette_optimize and palette_join against palette.glb (which must match
  palette.json): join merges the spheres into one mesh of a primitive a
  material, optimize first merges the materials into a few with palette
  textures (make_nodes.py says when), and ptr finds each sphere again as a
  connected component, with its own texels for its material.
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
  optimize and palette_optimize are also simplified, with gltf-transform's
  default error, 1e-4 of the mesh's extent (here the joined mesh's, SPAN):
  meshoptimizer's error is a distance to the surface's planes, not to its
  bounds, which move by up to 2.5 times it here: their tolerance adds 3 times
  it.
  Files without quantisation (three_instanced, instance) get 1e-6 * SIZE only.
  Materials: the same kind, fuzz and ior within 1e-6, and the colour (the
  material's albedo times the sphere's own colour, where it has one) and
  the emission within 1/255 (colours are not quantised by these tools unless
  instanced, where 8-bit colour is their default). In the files with palette
  textures (PALETTE) colours are 8-bit sRGB texels and metallic and roughness
  8-bit: there the colour and the emission (over the brightest of the
  reference's, the emissive strength) are compared sRGB-encoded, within 1/255
  of each other, and fuzz within 1/255.
- blender_join.glb and blender_join.obj (make_blender.py: Blender's Join of
  three UV spheres, two ico spheres and a cube, exported with the glTF and
  the OBJ exporters' defaults) against blender_join.json, the spheres as set
  in Blender: the same comparison, unquantised (float32 in the .glb, 6
  decimals in the OBJ, both within 1e-6 * SIZE: a UV sphere's and an ico
  sphere's vertices lie on their sphere and reach it along each axis, so
  centre and radius come out all but exact), each sphere with its own
  material; and one warning, that 1 mesh part (the cube) is not drawn,
  naming the node or the object. Blender's OBJ exporter without its PBR
  extensions (its default) writes no transmission: there the glass sphere
  is a diffuse one of its base colour. blender_join.obj with
  --fit-all-objects is one sphere, the bounds of all the joined object
  holds, the cube's included, in its first face's material (the first
  sphere's), and no warning.
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
# The tools' files and the source each was made from.
GLTF_TRANSFORM = {"instance": "nodes", "quantize": "nodes", "meshopt": "nodes", "draco": "nodes",
                  "optimize": "nodes", "instance_meshopt": "nodes", "gltfpack": "nodes",
                  "join": "nodes", "join_meshopt": "nodes", "palette_optimize": "palette",
                  "palette_join": "palette"}
# Quantised over each sphere's mesh, or over one mesh holding them all.
QUANTISED = {"quantize", "meshopt", "draco", "instance_meshopt", "gltfpack"}
QUANTISED_JOINED = {"join_meshopt", "optimize", "palette_optimize"}
PALETTE = {"optimize", "palette_optimize"}
# Simplified by optimize, with its default error: 1e-4 of the mesh's extent,
# 3 times it for the bounds (see the docstring).
SIMPLIFIED = {"optimize", "palette_optimize"}
SIMPLIFY_ERROR = 1e-4 * 3


class Failure(Exception):
    pass


def dump(name, *options):
    run = subprocess.run([ptr, "--dump-scene", *options, os.path.join(folder, name)],
                         capture_output=True, text=True, timeout=60)
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


def srgb(x):
    """A linear value sRGB-encoded, as an 8-bit texel stores it (over 255)."""
    x = min(max(x, 0.0), 1.0)
    return 12.92 * x if x <= 0.0031308 else 1.055 * x ** (1 / 2.4) - 0.055


def colour_error(g, w, palette):
    """The largest difference of colour and emission, sRGB-encoded in a
    palette (the emission over the reference's brightest)."""
    if not palette:
        return max(abs(a - b) for a, b in zip(g["colour"] + g["emission"],
                                              w["colour"] + w["emission"]))
    strength = max(max(w["emission"]), 1.0)
    return max([abs(srgb(a) - srgb(b)) for a, b in zip(g["colour"], w["colour"])] +
               [abs(srgb(a / strength) - srgb(b / strength))
                for a, b in zip(g["emission"], w["emission"])])


def compare(got, want, quantised, joined=False, palette=False, simplified=False):
    """Problems of `got` against `want` (lists from flatten), at most a few;
    quantised over each sphere's bounds, or (joined) over all of them;
    colours from palette textures, vertices moved by simplify (see the
    docstring)."""
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
        tol = (1e-6 * size + (extent / (2 ** POSITION_BITS - 1) if quantised else 0) +
               (SIMPLIFY_ERROR * extent if simplified else 0))
        err = max(abs(a - b) for a, b in zip(g["center"], w["center"]))
        if err > tol:
            problems.append(f"sphere {i}: centre {g['center']}, not {w['center']} "
                            f"(off by {err:.3g} > {tol:.3g})")
        if abs(g["radius"] - w["radius"]) > tol:
            problems.append(f"sphere {i}: radius {g['radius']}, not {w['radius']} (tolerance "
                            f"{tol:.3g})")
        if g["kind"] != w["kind"]:
            problems.append(f"sphere {i}: material {g['kind']}, not {w['kind']}")
        elif (abs(g["fuzz"] - w["fuzz"]) > (1.0 / 255 if palette else 1e-6) or
              abs(g["ior"] - w["ior"]) > 1e-6):
            problems.append(f"sphere {i}: fuzz/ior {g['fuzz']}/{g['ior']}, not "
                            f"{w['fuzz']}/{w['ior']}")
        if colour_error(g, w, palette) > 1.0 / 255:
            problems.append(f"sphere {i}: colour {g['colour']} emission {g['emission']}, not "
                            f"{w['colour']} {w['emission']}")
    return problems


def reference(stem):
    """The spheres of the description stem.json (make_nodes.py)."""
    with open(os.path.join(folder, stem + ".json")) as f:
        desc = json.load(f)
    kinds = {"lambertian": "diffuse", "metal": "metal", "dielectric": "dielectric"}
    return [{"center": s["center"], "radius": s["radius"], "kind": kinds[s["material"]],
             "colour": s.get("albedo", [1, 1, 1]), "fuzz": s.get("fuzz", 0),
             "ior": s.get("ior", 0), "emission": s.get("emission", [0, 0, 0])}
            for s in desc["spheres"]]


def reference_three():
    with open(os.path.join(folder, "three_instanced.json")) as f:
        desc = json.load(f)
    return [{"center": s["center"], "radius": s["radius"], "kind": "diffuse",
             "colour": s["color"], "fuzz": 0, "ior": 0, "emission": [0, 0, 0]}
            for s in desc["spheres"]]


def blender_reference(obj):
    """The spheres of blender_join.json; in the OBJ, whose .mtl has no
    transmission, the glass sphere is diffuse (see the docstring)."""
    want = reference("blender_join")
    if obj:
        want = [dict(w, kind="diffuse", ior=0) if w["kind"] == "dielectric" else w for w in want]
    return want


def check_blender(name, part):
    """Blender's Join: the spheres, and the cube skipped with the warning
    naming part."""
    scene = dump(name)
    problems = compare(flatten(scene), blender_reference(name.endswith(".obj")), False)
    skipped = ('1 mesh part not drawn: it is not a sphere'
               f' (docs/scenes.md, "What becomes a sphere"): {part}')
    if len(scene["warnings"]) != 1 or not scene["warnings"][0].endswith(skipped):
        problems.append(f"warnings {scene['warnings']}, not one ending in: {skipped}")
    return problems


def check_blender_fit_all():
    """--fit-all-objects: the joined object is one sphere, its bounds'."""
    scene = dump("blender_join.obj", "--fit-all-objects")
    with open(os.path.join(folder, "blender_join.json")) as f:
        desc = json.load(f)
    balls = ([(s["center"], s["radius"]) for s in desc["spheres"]] +
             [(c["center"], c["size"] / 2) for c in desc["cubes"]])
    lo = [min(c[k] - r for c, r in balls) for k in range(3)]
    hi = [max(c[k] + r for c, r in balls) for k in range(3)]
    bounds = dict(blender_reference(True)[0], center=[(a + b) / 2 for a, b in zip(lo, hi)],
                  radius=max(b - a for a, b in zip(lo, hi)) / 2)
    problems = compare(flatten(scene), [bounds], False)
    return problems + [f"warning: {w}" for w in scene["warnings"]]


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
        def check(name, test, label=None):
            try:
                problems = test()
                render(name, scratch)
            except Failure as e:
                problems = [str(e)]
            except Exception as e:  # a dump that is not the JSON expected
                problems = [f"{type(e).__name__}: {e}"]
            results[label or name] = problems

        sources = {}

        def check_source(stem):
            sources[stem] = flatten(dump(stem + ".glb"))
            return compare(sources[stem], reference(stem), False)

        for stem in ("nodes", "palette"):
            check(stem + ".glb", lambda: check_source(stem))
        check("three_instanced.glb",
              lambda: compare(flatten(dump("three_instanced.glb")), reference_three(), False))
        for stem, source in GLTF_TRANSFORM.items():
            name = stem + ".glb"
            if source not in sources:
                results[name] = [f"{source}.glb, the reference, did not import"]
                continue
            check(name, lambda: compare(flatten(dump(name)), sources[source],
                                        stem in QUANTISED | QUANTISED_JOINED,
                                        stem in QUANTISED_JOINED, stem in PALETTE,
                                        stem in SIMPLIFIED))
        check("ortho.gltf", lambda: check_ortho(dump("ortho.gltf")))
        check("blender_join.glb", lambda: check_blender("blender_join.glb",
                                                        "node 'Sphere' (mesh 'Sphere')"))
        check("blender_join.obj", lambda: check_blender("blender_join.obj",
                                                        "object 'Sphere' (line 4)"))
        check("blender_join.obj", check_blender_fit_all, "blender_join.obj --fit-all-objects")

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
