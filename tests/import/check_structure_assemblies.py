#!/usr/bin/env python3
"""Biological assemblies and colour schemes of structures.

Assemblies (tests/fixtures/structures/assembly.cif and .pdb, made by
make_assembly.py): --assembly none gives the asymmetric unit as the file
places it; each assembly gives one block of spheres an instance, in the
file's order of generators and operators, each sphere its atom placed by the
operator the file writes (an mmCIF product "(2)(3,4)" as 2 after 3, then 2
after 4), with the atom's radius and colour; an mmCIF generator names
subchains (label_asym_id), a PDB one author chains; the default is the
first assembly; an assembly the file lacks is a usage error naming those it
has.

Colour schemes (--color-by): chain and entity follow the categorical
palette (Tableau 10) by order of first appearance and of the file's
entities; residue follows the shapely table; secondary the records' helices
and strands; none takes a colormap.
Usage: check_structure_assemblies.py PTR SOURCE_DIR"""
import os
import shlex
import subprocess
import sys

ptr, src = sys.argv[1], os.path.abspath(sys.argv[2])
fixtures = os.path.join(src, "tests", "fixtures", "structures")
sys.path.insert(0, os.path.join(src, "tests", "support"))
from dump_checks import Checks  # noqa: E402

checks = Checks("check_structure_assemblies", ptr)
expect, dump = checks.expect, checks.dump


# Centres are stored in float relative to the camera: a few of float's steps
# at the scene's size (under 512 angstrom from the camera here). An operator
# misread in any digit the files write moves a centre far more.
CENTRE_TOLERANCE = 4 * 2.0 ** -23 * 512


def cif_rows(text, category):
    """The rows of an mmCIF loop as dicts (the fixtures' loops only)."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(category + "."))
    tags = []
    i = start
    while lines[i].startswith(category + "."):
        tags.append(lines[i][len(category) + 1:].strip())
        i += 1
    rows = []
    while i < len(lines) and lines[i].strip() and not lines[i].startswith(("_", "loop_", "#")):
        rows.append(dict(zip(tags, shlex.split(lines[i]))))
        i += 1
    return rows


def cif_atoms(text):
    return [(float(r["Cartn_x"]), float(r["Cartn_y"]), float(r["Cartn_z"]), r["auth_asym_id"],
             r["label_asym_id"], r["label_entity_id"], r["label_comp_id"], int(r["auth_seq_id"]))
            for r in cif_rows(text, "_atom_site") if r["label_comp_id"] != "HOH"]


def pdb_atoms(text):
    return [(float(line[30:38]), float(line[38:46]), float(line[46:54]), line[21], None, None,
             line[17:20].strip(), int(line[22:26]))
            for line in text.splitlines()
            if line.startswith(("ATOM  ", "HETATM")) and line[17:20] != "HOH"]


def cif_operators(text):
    return {r["id"]: ([[float(r[f"matrix[{i}][{j}]"]) for j in (1, 2, 3)] for i in (1, 2, 3)],
                      [float(r[f"vector[{i}]"]) for i in (1, 2, 3)])
            for r in cif_rows(text, "_pdbx_struct_oper_list")}


def pdb_operators(text):
    """Each REMARK 350 BIOMT operator by its serial (the same serial, the
    same operator, in the fixture)."""
    ops = {}
    for line in text.splitlines():
        if line.startswith("REMARK 350   BIOMT"):
            rotation, vector = ops.setdefault(line[20:23].strip(), ([None] * 3, [None] * 3))
            row = int(line[18]) - 1
            rotation[row] = [float(line[23:33]), float(line[33:43]), float(line[43:53])]
            vector[row] = float(line[58:68])
    return ops


def after(second, first):
    """second applied after first, as one operator."""
    (r2, t2), (r1, t1) = second, first
    return ([[sum(r2[i][k] * r1[k][j] for k in range(3)) for j in range(3)] for i in range(3)],
            [sum(r2[i][k] * t1[k] for k in range(3)) + t2[i] for i in range(3)])


def place(op, atom):
    rotation, vector = op
    return [rotation[i][0] * atom[0] + rotation[i][1] * atom[1] + rotation[i][2] * atom[2] +
            vector[i] for i in range(3)]


def same_blocks(what, got, unit, atoms, blocks):
    """got: the spheres of blocks, each (operator, the atoms' indices)."""
    want = sum(len(indices) for _, indices in blocks)
    expect(f"{what}: {len(got)} spheres, not {want}", len(got) == want)
    if len(got) != want:
        return
    n = 0
    for b, (op, indices) in enumerate(blocks):
        for a in indices:
            centre, g = place(op, atoms[a]), got[n]
            where = f"{what}: instance {b}, sphere {n}"
            expect(f"{where}: centre {g['center']}, not {centre}",
                   max(abs(x - y) for x, y in zip(g["center"], centre)) <= CENTRE_TOLERANCE)
            expect(f"{where}: radius or colour not its atom's",
                   g["radius"] == unit[a]["radius"] and g["color"] == unit[a]["color"])
            n += 1


IDENTITY = ([[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0, 0, 0])
for name in ("assembly.cif", "assembly.pdb"):
    path = os.path.join(fixtures, name)
    with open(path) as f:
        text = f.read()
    cif = name.endswith(".cif")
    atoms = cif_atoms(text) if cif else pdb_atoms(text)
    ops = cif_operators(text) if cif else pdb_operators(text)
    unit = dump(path, "--assembly", "none")
    chain_d = [i for i, a in enumerate(atoms) if a[3] == "D"]
    chain_c = [i for i, a in enumerate(atoms) if a[3] == "C"]
    expect(f"{name}: chains D and C", chain_d and chain_c and len(chain_d + chain_c) == len(atoms))
    same_blocks(f"{name} --assembly none", unit, unit, atoms, [(IDENTITY, range(len(atoms)))])
    first = [(ops["1"], range(len(atoms))), (ops["2"], range(len(atoms)))]
    same_blocks(f"{name} --assembly 1", dump(path, "--assembly", "1"), unit, atoms, first)
    same_blocks(f"{name} (the first assembly)", dump(path), unit, atoms, first)
    second = ([(after(ops["2"], ops["3"]), chain_d), (after(ops["2"], ops["4"]), chain_d),
               (ops["1"], chain_c)] if cif else [(ops["3"], chain_d), (ops["1"], chain_c)])
    same_blocks(f"{name} --assembly 2", dump(path, "--assembly", "2"), unit, atoms, second)
    run = subprocess.run([ptr, "--dump-scene", path, "--assembly", "3"], capture_output=True,
                         text=True)
    expect(f"{name} --assembly 3: exit {run.returncode}, {run.stderr!r}",
           run.returncode == 2 and run.stderr == f"ptr: {path}: no assembly '3' (--assembly); "
                                                 "it has 1, 2\n")

# Colour schemes, on 1tii in both formats (no assembly: the asymmetric unit).
TABLEAU_10 = ["1f77b4", "ff7f0e", "2ca02c", "d62728", "9467bd", "8c564b", "e377c2", "7f7f7f",
              "bcbd22", "17becf"]
SHAPELY = {"ALA": "8cff8c", "GLY": "ffffff", "LEU": "455e45", "SER": "ff7042", "VAL": "ff8cff",
           "THR": "b84c00", "LYS": "4747b8", "ASP": "a00042", "ILE": "004c00", "ASN": "ff7c70",
           "GLU": "660000", "PRO": "525252", "ARG": "00007c", "PHE": "534c42", "GLN": "ff4c4c",
           "TYR": "8c704c", "HIS": "7070ff", "CYS": "ffff70", "MET": "b8a042", "TRP": "4f4600"}
STRUCTURE = {"coil": "ffffff", "helix": "ff0080", "sheet": "ffc800"}


def linear(hex_colour):
    def decode(c):
        c /= 255.0
        return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4
    return [decode(int(hex_colour[k:k + 2], 16)) for k in (0, 2, 4)]


def same_colours(what, got, want):
    expect(f"{what}: {len(got)} spheres, not {len(want)}", len(got) == len(want))
    wrong = [i for i, (g, w) in enumerate(zip(got, want))
             if max(abs(a - b) for a, b in zip(g["color"], linear(w))) > 1.01 / 65535]
    expect(f"{what}: {len(wrong)} colours off the palette, first sphere {wrong[:1]}", not wrong)


pdb = os.path.join(src, "scenes", "1tii.pdb")
cif = os.path.join(fixtures, "1tii.cif")
with open(pdb) as f:
    pdb_text = f.read()
with open(cif) as f:
    cif_text = f.read()
atoms = pdb_atoms(pdb_text)
chains = list(dict.fromkeys(a[3] for a in atoms))
expect(f"1tii: chains {chains}", chains == ["D", "E", "F", "G", "H", "A", "C"])
entities = [r["id"] for r in cif_rows(cif_text, "_entity")]
cif_entity = [entities.index(a[5]) for a in cif_atoms(cif_text)]
expect(f"1tii.cif: entities {entities}", entities[:3] == ["D", "A", "C"])
helices = [(line[19], int(line[21:25]), int(line[33:37]))
           for line in pdb_text.splitlines() if line.startswith("HELIX ")]
strands = [(line[21], int(line[22:26]), int(line[33:37]))
           for line in pdb_text.splitlines() if line.startswith("SHEET ")]


def secondary(atom):
    for kind, ranges in (("helix", helices), ("sheet", strands)):
        if any(atom[3] == c and lo <= atom[7] <= hi for c, lo, hi in ranges):
            return STRUCTURE[kind]
    return STRUCTURE["coil"]


for path in (pdb, cif):
    name = os.path.basename(path)
    same_colours(f"{name} --color-by chain", dump(path, "--color-by", "chain"),
                 [TABLEAU_10[chains.index(a[3]) % 10] for a in atoms])
    same_colours(f"{name} --color-by entity", dump(path, "--color-by", "entity"),
                 [TABLEAU_10[e % 10] for e in cif_entity])
    same_colours(f"{name} --color-by residue", dump(path, "--color-by", "residue"),
                 [SHAPELY.get(a[6], "ff00ff") for a in atoms])
    same_colours(f"{name} --color-by secondary", dump(path, "--color-by", "secondary"),
                 [secondary(a) for a in atoms])
    expect(f"{name} --color-by element: the default",
           dump(path, "--color-by", "element") == dump(path))
expect("1tii: a helix, a strand and coil among its atoms",
       {secondary(a) for a in atoms} == set(STRUCTURE.values()))
run = subprocess.run([ptr, "--dump-scene", cif, "--color-by", "chain", "--colormap", "magma"],
                     capture_output=True, text=True)
expect(f"--color-by chain --colormap: exit {run.returncode}, {run.stderr!r}",
       run.returncode == 2 and "is a colour scheme, not a quantity" in run.stderr)

checks.finish()
