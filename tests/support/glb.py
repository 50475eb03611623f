"""Writes a glTF binary: a JSON chunk and one BIN chunk, both padded to 4 bytes
as the format asks (the JSON with spaces, the binary with zeros)."""
import json
import math
import struct


def write_glb(path, doc, binary):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    binary = bytes(binary) + b"\0" * (-len(binary) % 4)
    with open(path, "wb") as f:
        f.write(struct.pack("<3I", 0x46546C67, 2, 12 + 8 + len(text) + 8 + len(binary)))
        f.write(struct.pack("<2I", len(text), 0x4E4F534A) + text)
        f.write(struct.pack("<2I", len(binary), 0x004E4942) + binary)


def uv_sphere(radius, segments=8, rings=6):
    """A UV sphere's float VEC3 positions and unsigned-short triangle indices,
    as bytes, with its vertex and index counts: every vertex on the sphere
    and the bounds exactly [-radius, radius]^3 (segments a multiple of 4,
    rings even), so that ptr reads it as that sphere."""
    def exact(x):
        return 0.0 if abs(x) < 1e-12 else x

    verts = [(0.0, radius, 0.0)]
    for j in range(1, rings):
        theta = math.pi * j / rings
        for i in range(segments):
            phi = 2 * math.pi * i / segments
            verts.append(tuple(radius * exact(v) for v in (
                math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))))
    verts.append((0.0, -radius, 0.0))
    last = len(verts) - 1

    def at(ring, seg):
        return 1 + (ring - 1) * segments + seg % segments

    tris = []
    for seg in range(segments):
        tris += [(0, at(1, seg + 1), at(1, seg)), (last, at(rings - 1, seg), at(rings - 1, seg + 1))]
        for ring in range(1, rings - 1):
            a, b, c, d = at(ring, seg), at(ring, seg + 1), at(ring + 1, seg), at(ring + 1, seg + 1)
            tris += [(a, b, d), (a, d, c)]
    positions = b"".join(struct.pack("<3f", *v) for v in verts)
    indices = b"".join(struct.pack("<3H", *t) for t in tris)
    return positions, indices, len(verts), 3 * len(tris)
