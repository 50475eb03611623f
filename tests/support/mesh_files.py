#!/usr/bin/env python3
"""glTF files of triangle meshes for the sphere rule of docs/scenes.md
("What becomes a sphere"): joined spheres, unwelded ones, quantised ones, and shapes that
are not spheres (cube, torus, plane, cylinder), each mesh a list of
primitives of (positions, triangles, material).

Run as a script, writes the hostile files of component finding into DIR
(tests/fixtures/hostile): indices past the vertices, an index accessor
claiming more than its buffer holds, float indices.

Usage: mesh_files.py DIR"""
import math
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "../../scripts"))
import make_scenes  # noqa: E402
from glb import write_glb  # noqa: E402

FLOAT, UBYTE, USHORT, UINT = 5126, 5121, 5123, 5125


def uv_sphere(centre, radius, segments=8, rings=6, turn=0.0):
    """Positions and triangles of scripts/make_scenes.py's UV sphere, turned
    by `turn` radians about the axis (1, 1, 1) (so that its bounds are not
    its sphere's)."""
    axis = [1 / math.sqrt(3)] * 3
    c, s = math.cos(turn), math.sin(turn)

    def rotate(v):
        dot = sum(a * b for a, b in zip(axis, v))
        cross = (axis[1] * v[2] - axis[2] * v[1], axis[2] * v[0] - axis[0] * v[2],
                 axis[0] * v[1] - axis[1] * v[0])
        return [v[k] * c + cross[k] * s + axis[k] * dot * (1 - c) for k in range(3)]

    verts, tris = make_scenes.unit_sphere(segments, rings)
    return [[centre[k] + radius * x for k, x in enumerate(rotate(v))] for v in verts], tris


def sphere_bytes(radius):
    """A UV sphere of 8 segments and 6 rings about the origin, bounds exactly
    [-radius, radius]^3, as float VEC3 positions and unsigned-short indices,
    with its vertex and index counts."""
    verts, tris = uv_sphere((0, 0, 0), radius)
    return (b"".join(struct.pack("<3f", *v) for v in verts),
            b"".join(struct.pack("<3H", *t) for t in tris), len(verts), 3 * len(tris))


def cube(centre, half):
    corners = [[centre[0] + x * half, centre[1] + y * half, centre[2] + z * half]
               for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    tris = []
    for axis in range(3):
        for side in (0, 1):
            f = [i for i in range(8) if (i >> (2 - axis)) & 1 == side]
            tris += [(f[0], f[1], f[3]), (f[0], f[3], f[2])]
    return corners, tris


def torus(centre, big, small, segments=24, sides=12):
    verts, tris = [], []
    for i in range(segments):
        u = 2 * math.pi * i / segments
        for j in range(sides):
            v = 2 * math.pi * j / sides
            r = big + small * math.cos(v)
            verts.append([centre[0] + r * math.cos(u), centre[1] + small * math.sin(v),
                          centre[2] + r * math.sin(u)])
    for i in range(segments):
        for j in range(sides):
            a, b = i * sides + j, ((i + 1) % segments) * sides + j
            c, d = i * sides + (j + 1) % sides, ((i + 1) % segments) * sides + (j + 1) % sides
            tris += [(a, b, d), (a, d, c)]
    return verts, tris


def plane(centre, half, cells=4):
    verts = [[centre[0] + half * (2 * i / cells - 1), centre[1], centre[2] + half * (2 * j / cells - 1)]
             for i in range(cells + 1) for j in range(cells + 1)]
    tris = []
    for i in range(cells):
        for j in range(cells):
            a, b = i * (cells + 1) + j, (i + 1) * (cells + 1) + j
            tris += [(a, b, b + 1), (a, b + 1, a + 1)]
    return verts, tris


def cylinder(centre, radius, height, segments=32):
    verts = [[centre[0] + radius * math.cos(2 * math.pi * i / segments), centre[1] + y,
              centre[2] + radius * math.sin(2 * math.pi * i / segments)]
             for y in (-height / 2, height / 2) for i in range(segments)]
    tris = []
    for i in range(segments):
        j = (i + 1) % segments
        tris += [(i, j, segments + i), (j, segments + j, segments + i)]
    for i in range(1, segments - 1):
        tris += [(0, i, i + 1), (segments, segments + i, segments + i + 1)]
    return verts, tris


def combine(*shapes):
    """One vertex and triangle list of several shapes (a joined mesh)."""
    verts, tris = [], []
    for v, t in shapes:
        tris += [tuple(i + len(verts) for i in tri) for tri in t]
        verts += v
    return verts, tris


def unweld(shape):
    """Every triangle its own three vertices, as flat-shaded exports write."""
    verts, tris = shape
    return [list(verts[i]) for t in tris for i in t], [(3 * k, 3 * k + 1, 3 * k + 2)
                                                      for k in range(len(tris))]


class Writer:
    def __init__(self):
        self.blob = bytearray()
        self.doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}],
                    "nodes": [], "meshes": [], "accessors": [], "bufferViews": [],
                    "materials": [{"name": f"m{k}", "pbrMetallicRoughness": {
                        "baseColorFactor": [0.25 * (k + 1), 0.5, 0.5, 1], "metallicFactor": 0}}
                        for k in range(3)]}

    def view(self, data):
        self.blob += b"\0" * (-len(self.blob) % 4)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.blob),
                                        "byteLength": len(data)})
        self.blob += data
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, data, component, count, kind, **extra):
        self.doc["accessors"].append(dict(bufferView=self.view(data), componentType=component,
                                          count=count, type=kind, **extra))
        return len(self.doc["accessors"]) - 1

    def positions(self, verts, quantise=None):
        """quantise: None (float), "short" (normalised uint16 over [0, 1]) or
        "byte" (unsigned bytes 0 .. 255 as they are)."""
        lo = [min(v[k] for v in verts) for k in range(3)]
        hi = [max(v[k] for v in verts) for k in range(3)]
        if quantise is None:
            return self.accessor(b"".join(struct.pack("<3f", *v) for v in verts), FLOAT,
                                 len(verts), "VEC3", min=lo, max=hi)
        top = 65535 if quantise == "short" else 255
        q = [[round(x) for x in v] if quantise == "byte" else [round(x * top) for x in v]
             for v in verts]
        fmt = "<3H2x" if quantise == "short" else "<3B1x"
        data = b"".join(struct.pack(fmt, *v) for v in q)
        lo = [min(v[k] for v in q) for k in range(3)]
        hi = [max(v[k] for v in q) for k in range(3)]
        self.doc["accessors"].append(dict(
            bufferView=self.view(data), componentType=USHORT if quantise == "short" else UBYTE,
            normalized=quantise == "short", count=len(q), type="VEC3", min=lo, max=hi))
        self.doc["bufferViews"][-1]["byteStride"] = 8 if quantise == "short" else 4
        return len(self.doc["accessors"]) - 1

    def mesh(self, name, primitives, quantise=None):
        """primitives: (shape, material) pairs."""
        prims = []
        for (verts, tris), material in primitives:
            idx = self.accessor(b"".join(struct.pack("<3I", *t) for t in tris), UINT, 3 * len(tris),
                                "SCALAR")
            prims.append({"attributes": {"POSITION": self.positions(verts, quantise)},
                          "indices": idx, "material": material})
        self.doc["meshes"].append({"name": name, "primitives": prims})
        return len(self.doc["meshes"]) - 1

    def node(self, name, mesh, **transform):
        self.doc["nodes"].append(dict(name=name, mesh=mesh, **transform))
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, path):
        if any(a["componentType"] != FLOAT and a["type"] == "VEC3" for a in self.doc["accessors"]):
            self.doc["extensionsUsed"] = ["KHR_mesh_quantization"]
            self.doc["extensionsRequired"] = ["KHR_mesh_quantization"]
        self.doc["buffers"] = [{"byteLength": len(self.blob)}]
        write_glb(path, self.doc, self.blob)


def write_hostile(folder):
    sphere = uv_sphere((0, 0, 0), 1)
    w = Writer()
    w.node("past", w.mesh("past", [(sphere, 0)]))
    index = w.doc["meshes"][0]["primitives"][0]["indices"]
    view = w.doc["bufferViews"][w.doc["accessors"][index]["bufferView"]]
    w.blob[view["byteOffset"]:view["byteOffset"] + 4] = struct.pack("<I", len(sphere[0]))
    w.write(os.path.join(folder, "mesh_index_past_vertices.glb"))

    w = Writer()
    w.node("huge", w.mesh("huge", [(sphere, 0)]))
    w.doc["accessors"][w.doc["meshes"][0]["primitives"][0]["indices"]]["count"] = 2 ** 31
    w.write(os.path.join(folder, "mesh_index_count_huge.glb"))

    w = Writer()
    w.node("float", w.mesh("float", [(sphere, 0)]))
    w.doc["accessors"][w.doc["meshes"][0]["primitives"][0]["indices"]].update(
        componentType=FLOAT)
    w.write(os.path.join(folder, "mesh_index_float.glb"))


if __name__ == "__main__":
    write_hostile(sys.argv[1])
