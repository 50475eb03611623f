#!/usr/bin/env python3
"""scripts/particles_to_glb.py: the same eight particles written as CSV (with a
header, a comment and 0..255 colours), as whitespace columns without colours,
and as PLY (ascii, and binary little-endian with uchar colours and an alpha,
as MeshLab writes them) convert to instanced .glb files that ptr imports to
exactly those spheres (centres and radii to float precision, colours to
ptr's 1/65535). A broken file is refused with a message naming its line.
Usage: check_particles.py PTR SOURCE_DIR"""
import json
import os
import struct
import subprocess
import sys
import tempfile

ptr, src = sys.argv[1], sys.argv[2]
script = os.path.join(src, "scripts", "particles_to_glb.py")
particles = [[i * 0.5 - 2, (i % 3) * 0.25, -i * 0.125, 0.05 + 0.01 * i, 16 * i, 255 - 16 * i, 100]
             for i in range(8)]
tmp = tempfile.mkdtemp()
failures = []


def write(name, data):
    path = os.path.join(tmp, name)
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())
    return path


def check(path, with_colour):
    glb = path + ".glb"
    subprocess.run([sys.executable, script, path, glb], check=True, capture_output=True)
    spheres = json.loads(subprocess.run([ptr, "--dump-scene", glb], check=True,
                                        capture_output=True, text=True).stdout)["spheres"]
    if len(spheres) != len(particles):
        failures.append(f"{path}: {len(spheres)} spheres")
        return
    for got, p in zip(spheres, particles):
        if max(abs(a - b) for a, b in zip(got["center"], p[:3])) > 1e-6:
            failures.append(f"{path}: centre {got['center']}, not {p[:3]}")
        if abs(got["radius"] - p[3]) > 1e-7:
            failures.append(f"{path}: radius {got['radius']}, not {p[3]}")
        want = [c / 255 for c in p[4:]] if with_colour else [0.8] * 3
        if max(abs(a - b) for a, b in zip(got["color"], want)) > 1.01 / 65535:
            failures.append(f"{path}: colour {got['color']}, not {want}")


check(write("a.csv", "x,y,z,radius,r,g,b\n# a comment\n" +
            "".join(",".join(str(v) for v in p) + "\n" for p in particles)), True)
check(write("b.xyz", "".join(" ".join(str(v) for v in p[:4]) + "\n" for p in particles)), False)
header = "ply\nformat {}\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n" \
         "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n" \
         "property float radius\nend_header\n"
check(write("c.ply", header.format("ascii 1.0") +
            "".join("{} {} {} {} {} {} 255 {}\n".format(*p[:3], *p[4:], p[3]) for p in particles)), True)
check(write("d.ply", header.format("binary_little_endian 1.0").encode() +
            b"".join(struct.pack("<3f4Bf", *p[:3], *p[4:], 255, p[3]) for p in particles)), True)

bad = write("bad.csv", "1 2 3 0.5\n1 2 x 0.5\n")
run = subprocess.run([sys.executable, script, bad, bad + ".glb"], capture_output=True, text=True)
if run.returncode == 0 or f"{bad}:2:" not in run.stderr or os.path.exists(bad + ".glb"):
    failures.append(f"bad.csv: exit {run.returncode}, {run.stderr!r}")
for f in failures:
    print(f)
print(f"{4 * len(particles) + 1 - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
