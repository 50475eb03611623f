#!/usr/bin/env python3
"""A small file that claims more spheres than the machine holds: 10,000
instanced nodes sharing one TRANSLATION accessor of 100,000 instances, 10^9
spheres in 1.3 MB (valid glTF). ptr must refuse it from the accessors' counts
alone: exit 6, one line naming the file and what the spheres would need, an
existing output left as it was, and no memory taken for the spheres (peak
resident size under 200 MB: the file, the libraries, nothing a sphere). Then
the same file with one instanced node (10^5 spheres) renders, so the check
refuses by count, not by shape.
usage: check_claimed_spheres.py PTR"""
import json, os, resource, struct, subprocess, sys, tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from glb import write_glb  # noqa: E402
from mesh_files import sphere_bytes  # noqa: E402

ptr = sys.argv[1]
INSTANCES = 100_000


def write_claim(path, nodes):
    translations = b"".join(struct.pack("<3f", (i % 100) * 0.1, (i // 100 % 100) * 0.1,
                                        (i // 10000) * 0.1) for i in range(INSTANCES))
    sphere, indices, vertices, index_count = sphere_bytes(0.01)
    binary = translations + sphere + indices
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(translations)},
                        {"buffer": 0, "byteOffset": len(translations), "byteLength": len(sphere)},
                        {"buffer": 0, "byteOffset": len(translations) + len(sphere),
                         "byteLength": len(indices)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": INSTANCES, "type": "VEC3"},
                      {"bufferView": 1, "componentType": 5126, "count": vertices, "type": "VEC3",
                       "min": [-0.01, -0.01, -0.01], "max": [0.01, 0.01, 0.01]},
                      {"bufferView": 2, "componentType": 5123, "count": index_count,
                       "type": "SCALAR"}],
        "meshes": [{"name": "sphere", "primitives": [{"attributes": {"POSITION": 1}, "indices": 2}]}],
        "nodes": [{"mesh": 0, "translation": [0, 0, -20 - n * 0.001],
                   "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 0}}}}
                  for n in range(nodes)],
        "scenes": [{"nodes": list(range(nodes))}],
        "scene": 0,
    }
    write_glb(path, doc, binary)


def run(args):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    p = subprocess.run([ptr] + args, capture_output=True, text=True, timeout=120)
    peak_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return p, peak_kb if peak_kb > before else None


failures = []
with tempfile.TemporaryDirectory() as d:
    claim = os.path.join(d, "billion.glb")
    write_claim(claim, 10_000)
    out = os.path.join(d, "out.exr")
    with open(out, "w") as f:
        f.write("an existing image")
    p, peak_kb = run([claim, "-o", out, "--samples", "1", "--width", "16"])
    lines = p.stderr.strip().splitlines()
    print(f"10^9 claimed in {os.path.getsize(claim)} bytes: exit {p.returncode}, peak "
          f"{peak_kb} kB: {p.stderr.strip()}")
    if p.returncode != 6:
        failures.append(f"exit {p.returncode}, not 6")
    if len(lines) != 1 or claim not in lines[0] or "1000000000 spheres" not in lines[0]:
        failures.append(f"not one line naming the file and the spheres: {p.stderr!r}")
    if open(out).read() != "an existing image":
        failures.append("the existing output was touched")
    if peak_kb is not None and peak_kb > 200_000:
        failures.append(f"peak resident size {peak_kb} kB: memory was taken for the spheres")

    one = os.path.join(d, "one.glb")
    write_claim(one, 1)
    p, _ = run([one, "-o", out, "--samples", "1", "--width", "16", "--quiet", "--json"])
    spheres = json.loads(p.stdout)["spheres"] if p.returncode == 0 else None
    if p.returncode != 0 or spheres != INSTANCES:
        failures.append(f"the 10^5-sphere file: exit {p.returncode}, {spheres} spheres, "
                        f"{p.stderr.strip()}")

for f in failures:
    print("FAIL:", f, file=sys.stderr)
sys.exit(1 if failures else 0)
