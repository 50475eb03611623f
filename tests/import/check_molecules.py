#!/usr/bin/env python3
"""scripts/molecule_to_glb.py and --color-by: a PDB file (element columns and
atom names, alternate locations, two models) and XYZ files (plain with an
extra column; extended with properties, a type that is no element, two
frames) convert to instanced .glb files that ptr imports to exactly the
spheres expected: centres to float precision (relative to the
camera), radii the van der Waals radii
of Alvarez 2013 times --radius-scale, colours Jmol's decoded from sRGB (to
ptr's 1/65535), and each atom's B-factor, occupancy or property as the value
--color-by reads. Broken files are refused naming their line; --color-by an
attribute the file lacks, and bad --colormap and --color-range values, are
one-line errors with the README's exit codes. The examples
scenes/1tii.glb and scenes/droplet.glb are what their sources make.
Usage: check_molecules.py PTR SOURCE_DIR"""
import json
import os
import struct
import subprocess
import sys
import tempfile
import zlib

ptr, src = sys.argv[1], os.path.abspath(sys.argv[2])
script = os.path.join(src, "scripts", "molecule_to_glb.py")
tmp = tempfile.mkdtemp()
failures, checks = [], 0

# Alvarez (2013) radii and Jmol's colours, as the papers and Jmol give them.
RADIUS = {"H": 1.20, "C": 1.77, "N": 1.66, "O": 1.50, "S": 1.89, "Fe": 2.44, "Ar": 1.83}
JMOL = {"H": "FFFFFF", "C": "909090", "N": "3050F8", "O": "FF0D0D", "S": "FFFF30",
        "Fe": "E06633", "Ar": "80D1E3"}
OKABE_ITO_ORANGE = "E69F00"  # the first type that is no element


def linear(hex_colour):
    out = []
    for k in range(3):
        c = int(hex_colour[2 * k:2 * k + 2], 16) / 255
        out.append(c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4)
    return out


def expect(what, ok):
    global checks
    checks += 1
    if not ok:
        failures.append(what)


def write(name, text):
    path = os.path.join(tmp, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def convert(source, output, *options):
    return subprocess.run([sys.executable, script, source, os.path.join(tmp, output), *options],
                          capture_output=True, text=True)


def dump(glb, *options):
    run = subprocess.run([ptr, "--dump-scene", os.path.join(tmp, glb), *options],
                         capture_output=True, text=True)
    return json.loads(run.stdout)["spheres"] if run.returncode == 0 else run


def check_spheres(glb, atoms, scale=1.0, value_option=None):
    """atoms: (x, y, z, element or (radius, colour), value)."""
    spheres = dump(glb, *(["--color-by", value_option] if value_option else []))
    if not isinstance(spheres, list) or len(spheres) != len(atoms):
        failures.append(f"{glb}: {spheres if not isinstance(spheres, list) else len(spheres)}")
        return
    for i, (got, atom) in enumerate(zip(spheres, atoms)):
        kind = atom[3]
        radius, colour = (RADIUS[kind] * scale, JMOL[kind]) if isinstance(kind, str) else kind
        where = f"{glb} sphere {i}"
        expect(f"{where}: centre {got['center']}, not {atom[:3]}",
               max(abs(a - b) for a, b in zip(got["center"], atom[:3])) <= 1e-5)
        expect(f"{where}: radius {got['radius']}, not {radius}", abs(got["radius"] - radius) < 1e-6)
        if value_option:
            expect(f"{where}: value {got.get('value')}, not {atom[4]}",
                   abs(got.get("value", 1e30) - atom[4]) <= 1e-5 * max(1, abs(atom[4])))
        else:
            want = linear(colour)
            expect(f"{where}: colour {got['color']}, not {want}",
                   max(abs(a - b) for a, b in zip(got["color"], want)) <= 1.01 / 65535)


def pdb_atom(record, serial, name, altloc, res, seq, xyz, occupancy, bfactor, element):
    return (f"{record:<6}{serial:>5} {name:<4}{altloc:1}{res:>3} A{seq:>4}    "
            f"{xyz[0]:8.3f}{xyz[1]:8.3f}{xyz[2]:8.3f}{occupancy:6.2f}{bfactor:6.2f}"
            f"          {element:>2}\n")


# Model 1: element columns given; then taken from names (" CA " carbon, "FE"
# left-aligned iron, "HG21" a four-character hydrogen); an atom in two places
# (B more occupied: kept, where A stood) and one in two equal ones (the first).
model1 = [
    pdb_atom("ATOM", 1, " N", " ", "MET", 1, (1.5, -2.25, 3.0), 1.0, 10.5, "N"),
    pdb_atom("ATOM", 2, " CA", " ", "MET", 1, (2.0, -1.0, 3.5), 1.0, 11.0, ""),
    pdb_atom("ATOM", 3, " SD", "A", "MET", 1, (4.0, 0.0, 0.0), 0.40, 20.0, "S"),
    pdb_atom("ATOM", 4, " O", "A", "MET", 1, (5.0, 1.0, 1.0), 0.50, 30.0, "O"),
    pdb_atom("ATOM", 5, " SD", "B", "MET", 1, (4.5, 0.5, 0.25), 0.60, 21.0, "S"),
    pdb_atom("ATOM", 6, " O", "B", "MET", 1, (6.0, 2.0, 2.0), 0.50, 31.0, "O"),
    pdb_atom("ATOM", 7, "HG21", " ", "THR", 2, (-1.0, 0.5, 0.75), 1.0, 0.0, ""),
    pdb_atom("HETATM", 8, "FE", " ", "HEM", 3, (0.0, 10.0, -5.0), 1.0, 40.25, ""),
]
model1_atoms = [(1.5, -2.25, 3.0, "N", 10.5), (2.0, -1.0, 3.5, "C", 11.0),
                (4.5, 0.5, 0.25, "S", 21.0), (5.0, 1.0, 1.0, "O", 30.0),
                (-1.0, 0.5, 0.75, "H", 0.0), (0.0, 10.0, -5.0, "Fe", 40.25)]
model2 = [pdb_atom("ATOM", 1, " N", " ", "MET", 1, (7.0, 8.0, 9.0), 0.75, 5.0, "N")]
pdb = write("two_models.pdb", "HEADER    TEST\nMODEL        1\n" + "".join(model1) +
            "TER\nENDMDL\nMODEL        2\n" + "".join(model2) + "ENDMDL\nEND\n")
run = convert(pdb, "mol.glb")
expect(f"two models: {run.stderr}", run.returncode == 0)
check_spheres("mol_0001.glb", model1_atoms)
check_spheres("mol_0001.glb", model1_atoms, value_option="bfactor")
check_spheres("mol_0001.glb", [a[:4] + (o,) for a, o in zip(model1_atoms, [1, 1, .6, .5, 1, 1])],
              value_option="_OCCUPANCY")
check_spheres("mol_0002.glb", [(7.0, 8.0, 9.0, "N", 5.0)], value_option="_bfactor")
expect("two models: mol.glb written", not os.path.exists(os.path.join(tmp, "mol.glb")))
run = convert(pdb, "half.glb", "--radius-scale", "0.5", "--frame", "1")
check_spheres("half.glb", model1_atoms, scale=0.5)
crlf = os.path.join(tmp, "crlf.pdb")
with open(crlf, "w", newline="\r\n") as f:
    f.write("".join(model1))
convert(crlf, "crlf.glb")
check_spheres("crlf.glb", model1_atoms, value_option="bfactor")

# Plain XYZ: element symbols in any case, a fifth column kept.
xyz = write("water.xyz", "3\nwater\nO 0 0 0 -0.8\nH 0.96 0 0 0.4\nh -0.24 0.93 0 0.4\n")
convert(xyz, "water.glb")
water = [(0, 0, 0, "O", -0.8), (0.96, 0, 0, "H", 0.4), (-0.24, 0.93, 0, "H", 0.4)]
check_spheres("water.glb", water)
check_spheres("water.glb", water, value_option="column5")

# Extended XYZ, two frames: a type that is no element, a scalar, a vector
# (its length), a string property left out.
header = ('4\nLattice="10 0 0 0 10 0 0 0 10" Properties=species:S:1:pos:R:3:energy:R:1:'
          'vel:R:3:tag:S:1 pbc="T T T"\n')
frame = "Ar {} 0 0 {} 3 4 0 a\nAr 0 {} 0 -1.5 0 0 2 b\nX1 0 0 {} 0.25 0 0 0 c\nar 1 1 1 7 1 0 0 d\n"
ext = write("gas.extxyz", header + frame.format(1, 2.5, 3, 4) + header + frame.format(5, 6, 7, 8))
run = convert(ext, "gas.glb")
expect(f"extended XYZ: the string property named: {run.stderr}", "tag:S:1" in run.stderr)
type_sphere = (0.5, OKABE_ITO_ORANGE)
check_spheres("gas_0002.glb", [(5, 0, 0, "Ar"), (0, 7, 0, "Ar"), (0, 0, 8, type_sphere),
                               (1, 1, 1, "Ar")])
check_spheres("gas_0001.glb", [(1, 0, 0, "Ar", 2.5), (0, 3, 0, "Ar", -1.5),
                               (0, 0, 4, type_sphere, 0.25), (1, 1, 1, "Ar", 7)],
              value_option="ENERGY")
check_spheres("gas_0001.glb", [(1, 0, 0, "Ar", 5), (0, 3, 0, "Ar", 2), (0, 0, 4, type_sphere, 0),
                               (1, 1, 1, "Ar", 1)], value_option="vel")

# --color-range: values beyond it take the ends' colours.
spheres = dump("gas_0001.glb", "--color-by", "energy", "--color-range", "0,1")
viridis_ends = [[0.267004, 0.004874, 0.329415], [0.993248, 0.906157, 0.143936]]


def decoded(srgb):
    return [c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in srgb]


for i, end in ((0, 1), (1, 0), (3, 1)):
    want = decoded(viridis_ends[end])
    expect(f"--color-range 0,1: sphere {i} {spheres[i]['color']}, not {want}",
           max(abs(a - b) for a, b in zip(spheres[i]["color"], want)) <= 1.01 / 65535)

# A render prints the data's range; its colour bar shows viridis, entry x / 2
# in column x, through the sRGB view (8-bit PNG, within a step of rounding).
def png_rgb(path):
    """The rows of an 8-bit RGB or RGBA PNG, as lists of (r, g, b)."""
    with open(path, "rb") as f:
        data = f.read()
    at, idat, width, height, channels = 8, b"", 0, 0, 3
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and colour in (2, 6), (depth, colour)
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    raw, stride, rows = zlib.decompress(idat), width * channels, []
    previous = bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        for i in range(stride):
            left = line[i - channels] if i >= channels else 0
            up, corner = previous[i], previous[i - channels] if i >= channels else 0
            p = left + up - corner
            nearest = min((abs(p - left), 0, left), (abs(p - up), 1, up),
                          (abs(p - corner), 2, corner))[2]
            line[i] = (line[i] + (0, left, up, (left + up) // 2, nearest)[kind]) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        previous = line
    return rows


bar = os.path.join(tmp, "bar.png")
run = subprocess.run([ptr, os.path.join(tmp, "gas_0001.glb"), "-o", os.path.join(tmp, "gas.exr"),
                      "--width", "8", "--height", "8", "--samples", "1", "--color-by", "energy",
                      "--color-bar", bar], capture_output=True, text=True)
expect(f"the range printed: {run.stderr!r}", run.returncode == 0 and
       "values -1.5 to 7, mapped from -1.5 to 7 through viridis" in run.stderr)
rows = png_rgb(bar) if os.path.exists(bar) else [[]]
expect(f"bar: {len(rows[0])}x{len(rows)}", len(rows) == 32 and len(rows[0]) == 512)
viridis_128 = [0.127568, 0.566949, 0.550556]
for x, entry in ((0, viridis_ends[0]), (256, viridis_128), (257, viridis_128),
                 (511, viridis_ends[1])):
    want = [round(255 * c) for c in entry]
    for y in (0, 31):
        got = rows[y][x] if len(rows) == 32 else None
        expect(f"bar pixel ({x}, {y}): {got}, not {want}",
               got is not None and max(abs(a - b) for a, b in zip(got, want)) <= 1)

# Broken inputs: one line naming the file and line; nothing written.
bad_pdb = write("bad.pdb", "".join(model1[:2]) + model1[2][:33] + "x.yyy" + model1[2][38:])
bad_xyz = write("bad.xyz", "5\ncomment\nO 0 0 0\n")
for path, line in ((bad_pdb, 3), (bad_xyz, 3)):
    run = convert(path, "bad.glb")
    expect(f"{path}: exit {run.returncode}, {run.stderr!r}",
           run.returncode != 0 and f"{path}:{line}:" in run.stderr and
           not os.path.exists(os.path.join(tmp, "bad.glb")))

# An element without a radius in the table (polonium) needs --radius.
polonium = write("po.xyz", "2\n\nPo 0 0 0\nC 2 0 0\n")
run = convert(polonium, "po.glb")
expect(f"po.xyz: {run.returncode}, {run.stderr!r}",
       run.returncode != 0 and "Po has no van der Waals radius" in run.stderr)
convert(polonium, "po.glb", "--radius", "1.25")
check_spheres("po.glb", [(0, 0, 0, (1.25, "AB5C00")), (2, 0, 0, (1.25, JMOL["C"]))])

# The command line: an attribute the file lacks is exit 4; bad values exit 2.
lacking = "'charge' (--color-by); the file has _COLOR_0, _ENERGY, _VEL"
for options, code, words in ((["--color-by", "charge"], 4, lacking),
                             (["--color-by", "energy", "--colormap", "jet"], 2, "--colormap"),
                             (["--color-by", "energy", "--color-range", "5,1"], 2, "--color-range"),
                             (["--colormap", "magma"], 2, "--color-by")):
    run = dump("gas_0001.glb", *options)
    ok = not isinstance(run, list) and run.returncode == code and words in run.stderr and \
        len(run.stderr.strip().splitlines()) == 1
    expect(f"{options}: {run if isinstance(run, list) else (run.returncode, run.stderr)}", ok)

# POINTS and instances alike: --color-by COLOR_0 finds COLOR_0 and _COLOR_0,
# a VEC3 whose length is the value.
fixtures = os.path.join(src, "tests", "fixtures", "instancing")
for form in ("instances", "points"):
    path = os.path.join(fixtures, form + ".gltf")
    plain, valued = dump(path), dump(path, "--color-by", "color_0")
    expect(f"{form}: {valued if not isinstance(valued, list) else len(valued)} valued spheres",
           isinstance(valued, list) and len(valued) == len(plain))
    for i, (p, v) in enumerate(zip(plain, valued if isinstance(valued, list) else [])):
        length = sum(c * c for c in p["color"]) ** 0.5
        expect(f"{form} sphere {i}: value {v.get('value')}, not {length}",
               abs(v.get("value", 1e30) - length) <= 2e-4)

# Broken attributes: one line naming the node, exit code 4.
sys.path.insert(0, os.path.join(src, "scripts"))
import make_scenes  # noqa: E402
import particles_to_glb  # noqa: E402


def broken(name, values, patch=None):
    doc, blob = particles_to_glb.convert([[i, 0, 0, 0.5] for i in range(3)],
                                         {"material": "lambertian"}, {"_T": values})
    if patch:
        patch(doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"], doc)
    path = os.path.join(tmp, name)
    make_scenes.write(doc, blob, path)
    return path


def point_elsewhere(attributes, doc):
    attributes["_T"] = 99


def short_count(attributes, doc):
    doc["accessors"][attributes["_T"]]["count"] = 2


def as_unsigned_int(attributes, doc):
    doc["accessors"][attributes["_T"]]["componentType"] = 5125


for path, words in ((broken("nan.gltf", [1.0, float("nan"), 2.0]), "instance 1"),
                    (broken("missing.gltf", [1.0, 2.0, 3.0], point_elsewhere), "does not exist"),
                    (broken("count.gltf", [1.0, 2.0, 3.0], short_count), "count"),
                    (broken("uint.gltf", [1.0, 2.0, 3.0], as_unsigned_int), "component type")):
    run = dump(path, "--color-by", "t")
    ok = not isinstance(run, list) and run.returncode == 4 and words in run.stderr and \
        len(run.stderr.strip().splitlines()) == 1 and run.stderr.startswith(f"ptr: {path}:")
    expect(f"{path}: {run if isinstance(run, list) else (run.returncode, run.stderr)}", ok)
    expect(f"{path} without --color-by: refused", isinstance(dump(path), list))

# ptr itself points at the converter (structures it reads: check_structures.py).
run = subprocess.run([ptr, xyz, "-o", os.path.join(tmp, "x.png")], capture_output=True, text=True)
expect(f"ptr {xyz}: {run.returncode}, {run.stderr!r}",
       run.returncode == 4 and "scripts/molecule_to_glb.py" in run.stderr)

# The examples in scenes/ are what their sources and scripts make.
frame = os.path.join(tmp, "droplet.extxyz")
subprocess.run([sys.executable, os.path.join(src, "scripts", "make_particle_frame.py"), frame],
               check=True, capture_output=True)
convert(os.path.join(src, "scenes", "1tii.pdb"), "1tii.glb")
convert(frame, "droplet.glb")
for name in ("droplet.extxyz", "1tii.glb", "droplet.glb"):
    with open(os.path.join(tmp, name), "rb") as made, \
            open(os.path.join(src, "scenes", name), "rb") as committed:
        expect(f"scenes/{name} differs from what its script makes", made.read() == committed.read())

for f in failures:
    print(f)
print(f"{checks - len(failures)} passed, {len(failures)} failed")
sys.exit(1 if failures else 0)
