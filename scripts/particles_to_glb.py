#!/usr/bin/env python3
"""Converts particle data to an instanced glTF binary that ptr renders.

Input, by extension:
  .csv, .txt, .xyz (or any other)  one particle a line: x y z radius [r g b],
        separated by commas and/or white space; '#' starts a comment, and a
        first line that is not numbers (a header) is skipped. Colours are
        0..1, or 0..255 when any of them exceeds 1.
  .ply  vertices with x, y, z and radius (MeshLab's name; also "scale" or
        "r"), optional red/green/blue (uchar 0..255, or float 0..1); ascii or
        binary_little_endian.
Output: OUTPUT.glb with the spheres as EXT_mesh_gpu_instancing instances of a
white diffuse sphere, each coloured by its own colour (0.8 grey without),
no camera (ptr frames every sphere) and a gradient sky.

Usage: particles_to_glb.py INPUT OUTPUT.glb [--metal FUZZ | --glass IOR]
"""
import os
import re
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_scenes  # noqa: E402  (the glTF writer)

GREY = [0.8, 0.8, 0.8]
PROGRAM = os.path.splitext(os.path.basename(sys.argv[0]))[0]  # for messages


def fail(path, line, message):
    raise SystemExit(f"{PROGRAM}: {path}:{line}: {message}")


def read_columns(path):
    particles = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            fields = [x for x in re.split(r"[,\s]+", line.split("#")[0].strip()) if x]
            if not fields:
                continue
            try:
                values = [float(x) for x in fields]
            except ValueError:
                if not particles and number == 1:
                    continue  # a header
                fail(path, number, "not a number")
            if len(values) not in (4, 7):
                fail(path, number, f"{len(values)} columns: expected x y z radius [r g b]")
            particles.append(values)
    if any(max(p[4:], default=0) > 1 for p in particles):
        particles = [p[:4] + [c / 255 for c in p[4:]] for p in particles]
    return particles


PLY_TYPES = {"char": "b", "int8": "b", "uchar": "B", "uint8": "B", "short": "h", "int16": "h",
             "ushort": "H", "uint16": "H", "int": "i", "int32": "i", "uint": "I",
             "uint32": "I", "float": "f", "float32": "f", "double": "d", "float64": "d"}


def read_ply(path):
    with open(path, "rb") as f:
        if f.readline().strip() != b"ply":
            fail(path, 1, "not a PLY file")
        fmt, elements, number = None, [], 1
        while True:
            number += 1
            words = f.readline().decode("ascii", "replace").split()
            if not words:
                fail(path, number, "the header does not end")
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                elements.append((words[1], int(words[2]), []))
            elif words[0] == "property":
                if words[1] == "list":
                    fail(path, number, "list properties are not read before the vertices")
                if words[1] not in PLY_TYPES or not elements:
                    fail(path, number, f"unknown property type {words[1]}")
                elements[-1][2].append((words[2], PLY_TYPES[words[1]]))
            elif words[0] == "end_header":
                break
        if fmt not in ("ascii", "binary_little_endian"):
            fail(path, 1, f"format {fmt}: ascii or binary_little_endian only")
        if not elements or elements[0][0] != "vertex":
            fail(path, number, "the first element is not vertex")
        _, count, props = elements[0]
        names = [p[0] for p in props]
        radius = next((n for n in ("radius", "scale", "r") if n in names), None)
        if not all(n in names for n in "xyz") or not radius:
            fail(path, number, "vertices need x, y, z and radius")
        rows = []
        if fmt == "ascii":
            for i in range(count):
                words = f.readline().split()
                if len(words) < len(props):
                    fail(path, number + 1 + i, "too few values")
                rows.append([float(w) for w in words[:len(props)]])
        else:
            record = struct.Struct("<" + "".join(p[1] for p in props))
            data = f.read(record.size * count)
            if len(data) < record.size * count:
                fail(path, number, f"{count} vertices announced, fewer stored")
            rows = [list(v) for v in record.iter_unpack(data)]
    column = {n: i for i, n in enumerate(names)}
    colour = [column.get(c) for c in ("red", "green", "blue")]
    scale = 1.0 / 255 if colour[0] is not None and props[colour[0]][1] in "bB" else 1.0
    particles = []
    for row in rows:
        p = [row[column["x"]], row[column["y"]], row[column["z"]], row[column[radius]]]
        if None not in colour:
            p += [row[c] * scale for c in colour]
        particles.append(p)
    return particles


def convert(particles, material, attributes=None):
    """The scene of particles [x, y, z, radius, (r, g, b)], each an instance of
    material; attributes: {"_NAME": [a value (number, or 2 to 4 numbers) per
    particle]}, written as per-instance attributes."""
    spheres = []
    for i, p in enumerate(particles):
        if not p[3] > 0:
            raise SystemExit(f"{PROGRAM}: particle {i}: radius {p[3]} is not positive")
        extra = {name: values[i] for name, values in (attributes or {}).items()}
        spheres.append(dict(material, center=p[:3], radius=p[3], albedo=p[4:7] or GREY,
                            attributes=extra))
    return make_scenes.build({"name": "particles", "spheres": spheres,
                              "sky": {"type": "gradient"}}, instanced=True)


def take_option(args, flag, convert_value=float):
    """The value after flag in args (both removed), or None without it."""
    if flag not in args:
        return None
    i = args.index(flag)
    if i + 1 >= len(args):
        raise SystemExit(f"{PROGRAM}: {flag} needs a value")
    try:
        value = convert_value(args[i + 1])
    except ValueError:
        raise SystemExit(f"{PROGRAM}: {flag} {args[i + 1]}: not a number") from None
    del args[i:i + 2]
    return value


def take_material(args):
    """The material --metal FUZZ or --glass IOR asks for (removed from args),
    else diffuse."""
    material = {"material": "lambertian"}
    for flag, kind, key in (("--metal", "metal", "fuzz"), ("--glass", "dielectric", "ior")):
        value = take_option(args, flag)
        if value is not None:
            material = {"material": kind, key: value}
    return material


def main():
    args = sys.argv[1:]
    material = take_material(args)
    if len(args) != 2 or not args[1].endswith(".glb"):
        raise SystemExit(__doc__)
    source, output = args
    particles = read_ply(source) if source.lower().endswith(".ply") else read_columns(source)
    if not particles:
        raise SystemExit(f"particles_to_glb: {source}: no particles")
    make_scenes.write(*convert(particles, material), output)
    print(f"{output}: {len(particles)} spheres")


if __name__ == "__main__":
    main()
