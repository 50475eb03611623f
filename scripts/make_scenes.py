#!/usr/bin/env python3
"""Writes a glTF scene (.gltf with an embedded buffer, or .glb) from a neutral
JSON scene description (the format of shared/bench-scenes/*.json).

Every sphere is a node that instances one shared unit UV sphere (bounds exactly
[-1, 1]^3) with translation = centre and uniform scale = radius, so ptr's
import (docs/scenes.md) recovers the centre and radius exactly, and other glTF
viewers show round spheres. A sphere may carry "emission": [r, g, b], its
emitted radiance. The camera node looks from `lookfrom` towards
`lookat`; depth of field is carried in the camera's extras.

With --instanced, the spheres of one material are instead one node with
EXT_mesh_gpu_instancing (TRANSLATION = centre, SCALE = radius, _COLOR_0 =
albedo over a white base colour, and a float attribute for each of the
sphere's "attributes", e.g. "_TEMPERATURE"): the compact form for large sets,
a few dozen bytes a sphere. Without a "camera" the file has none (ptr then frames
every sphere); "image" and "sky" are optional too.

Usage: make_scenes.py [--instanced] INPUT.json OUTPUT.gltf|OUTPUT.glb
"""
import base64
import json
import math
import struct
import sys

SEGMENTS, RINGS = 32, 16  # multiples of 4 and 2: the bounds are exactly +-1


def unit_sphere(segments=SEGMENTS, rings=RINGS):
    """Positions (also the normals) and triangle indices of a UV sphere
    (segments a multiple of 4 and rings even: the bounds are exactly +-1)."""
    verts = [(0.0, 1.0, 0.0)]
    for ring in range(1, rings):
        theta = math.pi * ring / rings
        y = 0.0 if 2 * ring == rings else math.cos(theta)
        s = math.sin(theta)
        for seg in range(segments):
            phi = 2.0 * math.pi * seg / segments
            quarter = 4 * seg % segments == 0  # exact +-1 where the bounds are
            x = s * (round(math.cos(phi)) if quarter else math.cos(phi))
            z = s * (round(math.sin(phi)) if quarter else math.sin(phi))
            verts.append((x, y, z))
    verts.append((0.0, -1.0, 0.0))
    bottom = len(verts) - 1

    def ring_vertex(ring, seg):
        return 1 + (ring - 1) * segments + seg % segments

    tris = []
    for seg in range(segments):
        tris.append((0, ring_vertex(1, seg + 1), ring_vertex(1, seg)))
        tris.append((bottom, ring_vertex(rings - 1, seg), ring_vertex(rings - 1, seg + 1)))
    for ring in range(1, rings - 1):
        for seg in range(segments):
            a, b = ring_vertex(ring, seg), ring_vertex(ring, seg + 1)
            c, d = ring_vertex(ring + 1, seg), ring_vertex(ring + 1, seg + 1)
            tris += [(a, b, d), (a, d, c)]
    return verts, tris


def normalize(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def look_rotation(lookfrom, lookat, vup):
    """Quaternion (x, y, z, w) turning a camera that looks down -Z with +Y up
    to look from `lookfrom` at `lookat`."""
    w = normalize([f - t for f, t in zip(lookfrom, lookat)])
    u = normalize(cross(vup, w))
    v = cross(w, u)
    m = [[u[0], v[0], w[0]], [u[1], v[1], w[1]], [u[2], v[2], w[2]]]  # columns u, v, w
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 0.5 / math.sqrt(trace + 1.0)
        q = [(m[2][1] - m[1][2]) * s, (m[0][2] - m[2][0]) * s, (m[1][0] - m[0][1]) * s, 0.25 / s]
    elif m[0][0] > m[1][1] and m[0][0] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[0][0] - m[1][1] - m[2][2])
        q = [0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s, (m[2][1] - m[1][2]) / s]
    elif m[1][1] > m[2][2]:
        s = 2.0 * math.sqrt(1.0 + m[1][1] - m[0][0] - m[2][2])
        q = [(m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s, (m[0][2] - m[2][0]) / s]
    else:
        s = 2.0 * math.sqrt(1.0 + m[2][2] - m[0][0] - m[1][1])
        q = [(m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s, (m[1][0] - m[0][1]) / s]
    return normalize(q)


def gltf_material(sphere):
    mat = base_material(sphere)
    emission = sphere.get("emission")
    if emission and max(emission) > 0:
        # glTF factors stop at 1: the colour, then the strength that scales it.
        strength = max(emission)
        mat["emissiveFactor"] = [e / strength for e in emission]
        mat.setdefault("extensions", {})["KHR_materials_emissive_strength"] = {
            "emissiveStrength": strength}
    return mat


def base_material(sphere):
    kind = sphere["material"]
    if kind == "lambertian":
        return {"pbrMetallicRoughness": {"baseColorFactor": sphere["albedo"] + [1.0],
                                         "metallicFactor": 0.0, "roughnessFactor": 1.0}}
    if kind == "metal":
        return {"pbrMetallicRoughness": {"baseColorFactor": sphere["albedo"] + [1.0],
                                         "metallicFactor": 1.0,
                                         "roughnessFactor": sphere.get("fuzz", 0.0)}}
    if kind == "dielectric":
        return {"pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                                         "metallicFactor": 0.0, "roughnessFactor": 0.0},
                "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                               "KHR_materials_ior": {"ior": sphere["ior"]}}}
    raise SystemExit(f"unknown material kind {kind!r}")


class Buffer:
    """The one binary buffer, with a view and an accessor per array added."""

    def __init__(self):
        self.blob, self.views, self.accessors = bytearray(), [], []

    def add(self, data, component_type, count, kind, target=None, **extra):
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.blob += data + b"\0" * (-len(data) % 4)
        self.views.append(view)
        self.accessors.append(dict(bufferView=len(self.views) - 1, componentType=component_type,
                                   count=count, type=kind, **extra))
        return len(self.accessors) - 1


def add_instances(buffer, spheres, name):
    """A node with EXT_mesh_gpu_instancing for spheres of one material."""
    pack = struct.Struct("<3f").pack
    n = len(spheres)
    attributes = {
        "TRANSLATION": buffer.add(b"".join(pack(*s["center"]) for s in spheres), 5126, n, "VEC3"),
        "SCALE": buffer.add(b"".join(pack(*[s["radius"]] * 3) for s in spheres), 5126, n, "VEC3"),
        "_COLOR_0": buffer.add(b"".join(pack(*s.get("albedo", [1.0, 1.0, 1.0])) for s in spheres),
                               5126, n, "VEC3"),
    }
    # Per-sphere quantities ("attributes": {"_NAME": number or [2 to 4 numbers]}),
    # as Blender writes custom point attributes: float SCALAR or VECn.
    for name, first in spheres[0].get("attributes", {}).items():
        width = len(first) if isinstance(first, list) else 1
        values = [s["attributes"][name] for s in spheres]
        flat = [x for v in values for x in (v if width > 1 else [v])]
        attributes[name] = buffer.add(struct.pack(f"<{len(flat)}f", *flat), 5126, n,
                                      "SCALAR" if width == 1 else f"VEC{width}")
    return {"name": name, "extensions": {"EXT_mesh_gpu_instancing": {"attributes": attributes}}}


def build(desc, instanced=False, segments=SEGMENTS, rings=RINGS):
    verts, tris = unit_sphere(segments, rings)
    buffer = Buffer()
    buffer.add(b"".join(struct.pack("<3f", *v) for v in verts), 5126, len(verts), "VEC3", 34962,
               min=[-1.0, -1.0, -1.0], max=[1.0, 1.0, 1.0])
    buffer.add(b"".join(struct.pack("<3H", *t) for t in tris), 5123, 3 * len(tris), "SCALAR",
               34963)

    materials, material_index, meshes, nodes, groups = [], {}, [], [], {}
    for i, sphere in enumerate(desc["spheres"]):
        # Instanced spheres keep their albedo as their own colour.
        mat = gltf_material(dict(sphere, albedo=[1.0, 1.0, 1.0]) if instanced else sphere)
        key = json.dumps(mat, sort_keys=True)
        if key not in material_index:
            material_index[key] = len(materials)
            materials.append(dict(mat, name=f"{sphere['material']}.{len(materials):03d}"))
            meshes.append({"name": f"Sphere.{len(meshes):03d}",
                           "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 0},
                                           "indices": 1, "material": material_index[key]}]})
        if instanced:
            groups.setdefault(material_index[key], []).append(sphere)
            continue
        r = sphere["radius"]
        nodes.append({"name": f"Sphere.{i:03d}", "mesh": material_index[key],
                      "translation": sphere["center"], "scale": [r, r, r]})
    for mesh, spheres in groups.items():
        nodes.append(dict(add_instances(buffer, spheres, f"Spheres.{mesh:03d}"), mesh=mesh))

    doc = {
        "asset": {"version": "2.0", "generator": "ptr scripts/make_scenes.py"},
        "scene": 0,
        "scenes": [{"name": desc.get("name", "spheres"), "nodes": [], "extras": {}}],
        "nodes": nodes,
        "cameras": [],
        "meshes": meshes,
        "materials": materials,
        "accessors": buffer.accessors,
        "bufferViews": buffer.views,
        "buffers": [{"byteLength": len(buffer.blob)}],
    }
    extras = doc["scenes"][0]["extras"]
    if "sky" in desc:
        extras["sky"] = desc["sky"]["type"]
    if "image" in desc:
        extras["resolution"] = [desc["image"]["width"], desc["image"]["height"]]
    if "camera" in desc:
        cam = desc["camera"]
        nodes.append({"name": "Camera", "camera": 0,
                      "translation": cam["lookfrom"],
                      "rotation": look_rotation(cam["lookfrom"], cam["lookat"], cam["vup"])})
        perspective = {"yfov": math.radians(cam["vfov_deg"])}
        if "image" in desc:
            perspective["aspectRatio"] = desc["image"]["width"] / desc["image"]["height"]
        perspective["znear"] = 0.001
        doc["cameras"].append({"name": "Camera", "type": "perspective", "perspective": perspective,
                           "extras": {"aperture": cam["aperture"],
                                      "focus_distance": cam["focus_dist"]}})
    doc["scenes"][0]["nodes"] = list(range(len(nodes)))
    if not doc["cameras"]:
        del doc["cameras"]
    used = []
    if any(s["material"] == "dielectric" for s in desc["spheres"]):
        used += ["KHR_materials_transmission", "KHR_materials_ior"]
    if any(max(s.get("emission", [0])) > 0 for s in desc["spheres"]):
        used.append("KHR_materials_emissive_strength")
    if instanced:
        used.append("EXT_mesh_gpu_instancing")
        doc["extensionsRequired"] = ["EXT_mesh_gpu_instancing"]
    if used:
        doc["extensionsUsed"] = used
    return doc, bytes(buffer.blob)


def write_gltf(doc, blob, path):
    doc["buffers"][0]["uri"] = ("data:application/octet-stream;base64," +
                                base64.b64encode(blob).decode("ascii"))
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def write_glb(doc, blob, path):
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    blob += b"\0" * (-len(blob) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(text), b"JSON") + text)
        f.write(struct.pack("<I4s", len(blob), b"BIN\0") + blob)


def write(doc, blob, path):
    if path.endswith(".glb"):
        write_glb(doc, blob, path)
    else:
        write_gltf(doc, blob, path)


def main():
    args = sys.argv[1:]
    instanced = "--instanced" in args
    args = [a for a in args if a != "--instanced"]
    if len(args) != 2:
        raise SystemExit(__doc__)
    with open(args[0]) as f:
        desc = json.load(f)
    write(*build(desc, instanced), args[1])


if __name__ == "__main__":
    main()
