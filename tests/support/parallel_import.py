"""What the checks of the importers' parallel conversion share: a cloud
written as one part (converted on all cores) and as two (each below the
threshold, converted one by one), valid and broken, read by ptr --dump-scene;
and the comparison of the two valid scenes."""
import json
import os
import subprocess
import sys
import tempfile

from glb import write_glb
from mesh_files import sphere_bytes


def write_instanced_spheres(path, columns, count, parts):
    """A .glb of a sphere mesh (radius 0.05, white diffuse) instanced by
    parts nodes named 'cloud', each taking count / parts of the instances in
    order, and a camera: columns is a list of (EXT_mesh_gpu_instancing
    attribute, float32 VEC3 or VEC4, the bytes of all count instances)."""
    sphere, indices, vertices, index_count = sphere_bytes(0.05)
    binary, views = b"", []
    for block in [c[2] for c in columns] + [sphere, indices]:
        views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(block)})
        binary += block
    per = count // parts
    accessors, nodes = [], []
    for n in range(parts):
        attributes = {}
        for k, (name, kind, block) in enumerate(columns):
            attributes[name] = len(accessors)
            accessors.append({"bufferView": k, "byteOffset": n * per * len(block) // count,
                              "componentType": 5126, "count": per, "type": kind})
        nodes.append({"mesh": 0, "name": "cloud",
                      "extensions": {"EXT_mesh_gpu_instancing": {"attributes": attributes}}})
    accessors.append({"bufferView": len(columns), "componentType": 5126, "count": vertices,
                      "type": "VEC3", "min": [-0.05, -0.05, -0.05], "max": [0.05, 0.05, 0.05]})
    accessors.append({"bufferView": len(columns) + 1, "componentType": 5123,
                      "count": index_count, "type": "SCALAR"})
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": views,
        "accessors": accessors,
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1],
                                                "metallicFactor": 0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                    "indices": len(accessors) - 1, "material": 0}]}],
        "nodes": nodes + [{"camera": 0, "translation": [0, 3, 10]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "scenes": [{"nodes": list(range(parts + 1))}],
        "scene": 0,
    }
    write_glb(path, doc, binary)


def dump_clouds(ptr, write_cloud, options=()):
    """ptr --dump-scene (with options) of write_cloud(path, parts, broken)
    for 1 and 2 parts, valid and broken: {(parts, broken): CompletedProcess}."""
    runs = {}
    with tempfile.TemporaryDirectory() as d:
        for broken in (False, True):
            for parts in (1, 2):
                path = os.path.join(d, f"cloud-{parts}-{broken}.glb")
                write_cloud(path, parts, broken)
                runs[parts, broken] = subprocess.run([ptr, "--dump-scene", *options, path],
                                                     capture_output=True, text=True, timeout=120)
    return runs


def spheres_differ(runs, count):
    """Why the valid clouds' scenes are not the same count spheres bit for
    bit, or None if they are."""
    whole, halves = runs[1, False], runs[2, False]
    if whole.returncode or halves.returncode:
        return f"valid files refused: {whole.stderr.strip()} / {halves.stderr.strip()}"
    a, b = json.loads(whole.stdout)["spheres"], json.loads(halves.stdout)["spheres"]
    if len(a) == count and a == b:
        return None
    differ = next((i for i, (x, y) in enumerate(zip(a, b)) if x != y), None)
    return f"{len(a)} and {len(b)} spheres; first difference at sphere {differ}"


def report(failures, checks):
    """Prints the failures and the tally; exits 1 if any check failed."""
    for f in failures:
        print(f)
    print(f"{checks - len(failures)} passed, {len(failures)} failed")
    sys.exit(1 if failures else 0)
