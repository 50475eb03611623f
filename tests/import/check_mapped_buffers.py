#!/usr/bin/env python3
"""A glTF buffer is read where it lies, never copied whole: a .glb's BIN
chunk and a .gltf's external .bin are mapped, and only the pages the
accessors read become resident. The same 1,000 instanced spheres are written
three ways: their data alone in a .glb (the baseline), and after 64 MB that
no accessor reads, in a .glb and in a .gltf with an external .bin. Each form
renders the same sphere count, and its peak resident size stays within 16 MB
of the baseline's (a copy of the buffer would add 64 MB).
usage: check_mapped_buffers.py PTR"""
import json, os, struct, subprocess, sys, tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from glb import write_glb  # noqa: E402
from mesh_files import sphere_bytes  # noqa: E402

ptr = sys.argv[1]
INSTANCES = 1000
UNREAD = 64 << 20
ALLOWANCE_KB = 16 << 10


def scene(unread):
    """The glTF JSON and its buffer: unread zero bytes, then the data."""
    translations = b"".join(struct.pack("<3f", (i % 10) * 0.3, (i // 10 % 10) * 0.3,
                                        (i // 100) * 0.3) for i in range(INSTANCES))
    sphere, indices, vertices, index_count = sphere_bytes(0.1)
    binary = bytes(unread) + translations + sphere + indices
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["EXT_mesh_gpu_instancing"],
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [{"buffer": 0, "byteOffset": unread, "byteLength": len(translations)},
                        {"buffer": 0, "byteOffset": unread + len(translations),
                         "byteLength": len(sphere)},
                        {"buffer": 0, "byteOffset": unread + len(translations) + len(sphere),
                         "byteLength": len(indices)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": INSTANCES, "type": "VEC3"},
                      {"bufferView": 1, "componentType": 5126, "count": vertices, "type": "VEC3",
                       "min": [-0.1, -0.1, -0.1], "max": [0.1, 0.1, 0.1]},
                      {"bufferView": 2, "componentType": 5123, "count": index_count,
                       "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 1}, "indices": 2}]}],
        "nodes": [{"mesh": 0, "translation": [-1.5, -1.5, -8],
                   "extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": 0}}}}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    return doc, binary


def peak_kb_and_spheres(path, out):
    """ptr's peak resident size (its own process's, through a fresh parent) and
    the spheres it rendered."""
    measure = ("import resource, subprocess, sys\n"
               "p = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
               "sys.stderr.write(p.stderr)\n"
               "print(p.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, p.stdout)")
    p = subprocess.run([sys.executable, "-c", measure, ptr, path, "-o", out, "--samples", "1",
                        "--width", "32", "--quiet", "--json"],
                       capture_output=True, text=True, timeout=120)
    code, peak, report = p.stdout.split(" ", 2)
    if code != "0":
        return None, f"exit {code}: {p.stderr.strip()}"
    return int(peak), json.loads(report)["spheres"]


failures = []
with tempfile.TemporaryDirectory() as d:
    out = os.path.join(d, "out.exr")
    small = os.path.join(d, "small.glb")
    write_glb(small, *scene(0))
    padded_glb = os.path.join(d, "padded.glb")
    write_glb(padded_glb, *scene(UNREAD))
    padded_gltf = os.path.join(d, "padded.gltf")
    doc, binary = scene(UNREAD)
    with open(os.path.join(d, "padded.bin"), "wb") as f:
        f.write(binary)
    doc["buffers"][0]["uri"] = "padded.bin"
    with open(padded_gltf, "w") as f:
        json.dump(doc, f)

    base, spheres = peak_kb_and_spheres(small, out)
    if base is None or spheres != INSTANCES:
        failures.append(f"the baseline: {spheres}")
    for name, path in ((".glb", padded_glb), (".gltf and .bin", padded_gltf)):
        peak, spheres = peak_kb_and_spheres(path, out)
        print(f"{name}: {spheres} spheres, peak {peak} kB against {base} kB with no unread bytes")
        if peak is None or spheres != INSTANCES:
            failures.append(f"{name}: {spheres}")
        elif base is not None and peak > base + ALLOWANCE_KB:
            failures.append(f"{name}: peak {peak} kB, {peak - base} kB above the baseline: "
                            f"the {UNREAD >> 20} MB no accessor reads were read")

for f in failures:
    print("FAIL:", f, file=sys.stderr)
sys.exit(1 if failures else 0)
