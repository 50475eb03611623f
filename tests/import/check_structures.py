#!/usr/bin/env python3
"""Structures read by ptr itself (PDB, mmCIF, gzipped or not): the same entry
in the four forms (scenes/1tii.pdb; tests/fixtures/structures, made by
gemmi's converter) gives the same spheres, which are those
scripts/molecule_to_glb.py's .glb gives (centres to float precision, radii,
colours to ptr's 1/65535, B-factors and occupancies as --color-by reads them).
A file with alternate locations, hydrogens, a ligand, waters and two models
gives the converter's first frame; --select and --hydrogens keep what they
say; bad option values, --color-by a value structures lack and hostile files
are one-line errors with the README's exit codes.
Usage: check_structures.py PTR SOURCE_DIR"""
import json
import math
import os
import subprocess
import sys
import tempfile

ptr, src = sys.argv[1], os.path.abspath(sys.argv[2])
fixtures = os.path.join(src, "tests", "fixtures", "structures")
tmp = tempfile.mkdtemp()
sys.path.insert(0, os.path.join(src, "tests", "support"))
from dump_checks import Checks  # noqa: E402

checks = Checks("check_structures", ptr)
expect, dump = checks.expect, checks.dump


def to_glb(source):
    glb = os.path.join(tmp, os.path.basename(source) + ".glb")
    run = subprocess.run([sys.executable, os.path.join(src, "scripts", "molecule_to_glb.py"),
                          source, glb, "--frame", "1"], capture_output=True, text=True)
    expect(f"{source}: converter: {run.stderr}", run.returncode == 0)
    return glb


# Centres are stored in float relative to the camera, and the .glb rounds them
# to float once more: two steps of float's spacing below 256 angstrom, which
# the camera-relative coordinates here stay under.
CENTRE_TOLERANCE = 2 * 2.0 ** -23 * 256


def same_spheres(what, got, want, value=False):
    if len(got) != len(want):
        expect(f"{what}: {len(got)} spheres, not {len(want)}", False)
        return
    for i, (g, w) in enumerate(zip(got, want)):
        where = f"{what} sphere {i}"
        expect(f"{where}: centre {g['center']}, not {w['center']}",
               max(abs(a - b) for a, b in zip(g["center"], w["center"])) <= CENTRE_TOLERANCE)
        expect(f"{where}: radius {g['radius']}, not {w['radius']}", g["radius"] == w["radius"])
        expect(f"{where}: colour {g['color']}, not {w['color']}",
               max(abs(a - b) for a, b in zip(g["color"], w["color"])) <= 1.01 / 65535)
        if value:
            expect(f"{where}: value {g.get('value')}, not {w.get('value')}",
                   abs(g.get("value", 1e30) - w["value"]) <= 1e-5 * max(1, abs(w["value"])))


# The entry in four forms, everything kept, against the converter's .glb.
pdb = os.path.join(src, "scenes", "1tii.pdb")
forms = [pdb] + [os.path.join(fixtures, f) for f in ("1tii.pdb.gz", "1tii.cif", "1tii.cif.gz")]
glb = to_glb(pdb)
for by in (None, "bfactor", "occupancy"):
    options = ["--color-by", by] if by else []
    want = dump(glb, *options)
    expect("1tii.glb: spheres", len(want) > 5000)
    for form in forms:
        same_spheres(f"{os.path.basename(form)} {options}", dump(form, "--select", "all",
                                                                 *options), want, bool(by))


def pdb_atom(record, serial, name, altloc, res, chain, seq, xyz, occupancy, element):
    return (f"{record:<6}{serial:>5} {name:<4}{altloc:1}{res:>3} {chain}{seq:>4}    "
            f"{xyz[0]:8.3f}{xyz[1]:8.3f}{xyz[2]:8.3f}{occupancy:6.2f}{serial * 1.5:6.2f}"
            f"          {element:>2}\n")


# Alternate locations (B more occupied: kept, where A stood), a hydrogen, a
# DNA nucleotide, a ligand, two waters; a second model.
atoms = [
    pdb_atom("ATOM", 1, " N", " ", "ALA", "A", 1, (1.5, -2.25, 3.0), 1.0, "N"),
    pdb_atom("ATOM", 2, " CA", "A", "ALA", "A", 1, (2.0, -1.0, 3.5), 0.4, "C"),
    pdb_atom("ATOM", 3, " CA", "B", "ALA", "A", 1, (2.5, -1.5, 3.25), 0.6, "C"),
    pdb_atom("ATOM", 4, " H", " ", "ALA", "A", 1, (1.0, -2.0, 3.0), 1.0, "H"),
    pdb_atom("ATOM", 5, " P", " ", " DA", "B", 1, (8.0, 1.0, 0.0), 1.0, "P"),
    pdb_atom("HETATM", 6, "FE", " ", "HEM", "A", 2, (0.0, 10.0, -5.0), 1.0, "FE"),
    pdb_atom("HETATM", 7, " O", " ", "HOH", "A", 3, (4.0, 4.0, 4.0), 1.0, "O"),
    pdb_atom("HETATM", 8, " O", " ", "HOH", "A", 4, (-4.0, 4.0, 4.0), 1.0, "O"),
]
second = pdb_atom("ATOM", 1, " N", " ", "ALA", "A", 1, (7.0, 8.0, 9.0), 1.0, "N")
mixed = os.path.join(tmp, "mixed.pdb")
with open(mixed, "w") as f:
    f.write("MODEL        1\n" + "".join(atoms) + "ENDMDL\nMODEL        2\n" + second +
            "ENDMDL\nEND\n")
run = subprocess.run([ptr, "--dump-scene", mixed], capture_output=True, text=True)
expect(f"mixed.pdb: the second model named: {run.stdout[-300:]!r}",
       "the first of 2 models is read" in run.stdout)
mixed_glb = to_glb(mixed)
same_spheres("mixed.pdb", dump(mixed, "--select", "all", "--color-by", "occupancy"),
             dump(mixed_glb, "--color-by", "occupancy"), True)
want = dump(mixed_glb)
kept = {  # --select and --hydrogens: which of the converter's spheres remain
    (): [0, 1, 2, 3, 4], ("--select", "water"): [5, 6], ("--select", "protein"): [0, 1, 2],
    ("--select", "nucleic,ligand"): [3, 4], ("--hydrogens", "off"): [0, 1, 3, 4],
    ("--select", "protein,water", "--hydrogens", "off"): [0, 1, 5, 6],
}
for options, indices in kept.items():
    same_spheres(f"mixed.pdb {options}", dump(mixed, *options), [want[i] for i in indices])

# The models as frames: # in -o renders model k as frame k (from 1), each
# with the spheres of its own model; --frames picks some, a model the file
# lacks is a usage error.
def frames(*options):
    run = subprocess.run([ptr, mixed, "-o", os.path.join(tmp, "m_#.exr"), "--width", "8",
                          "--samples", "1", "--quiet", "--json", *options], capture_output=True,
                         text=True)
    reports = [json.loads(line) for line in run.stdout.splitlines() if line.startswith("{")]
    return run, [(os.path.basename(r["output"]), r["spheres"]) for r in reports]


run, made = frames()
expect(f"mixed.pdb as frames: {made}, exit {run.returncode}",
       run.returncode == 0 and made == [("m_1.exr", 5), ("m_2.exr", 1)])
run, made = frames("--frames", "2:2")
expect(f"mixed.pdb --frames 2:2: {made}", run.returncode == 0 and made == [("m_2.exr", 1)])
run, made = frames("--frames", "1:3")
expect(f"mixed.pdb --frames 1:3: exit {run.returncode}, {run.stderr!r}",
       run.returncode == 2 and run.stderr == "ptr: --frames: " + mixed +
       " has no model 3 (frames 1 to 2)\n")

# One-line errors with the README's exit codes (2: usage, 4: the scene).
for options, code, says in (
        (["--select", "proteins"], 2, "--select"), (["--select", "protein,"], 2, "--select"),
        (["--hydrogens", "no"], 2, "--hydrogens"), (["--color-by", "temperature"], 4, "_BFACTOR"),
        (["--select", "water", "--hydrogens", "on"], 0, "")):
    path = os.path.join(fixtures, "1tii.cif")
    run = subprocess.run([ptr, "--dump-scene", path, *options], capture_output=True, text=True)
    expect(f"{options}: exit {run.returncode}, not {code}", run.returncode == code)
    if code:
        expect(f"{options}: {run.stderr!r}", says in run.stderr and run.stderr.count("\n") == 1)

# One command renders a PDB file.
image = os.path.join(tmp, "1tii.png")
run = subprocess.run([ptr, pdb, "-o", image, "--width", "32", "--samples", "1", "--quiet"],
                     capture_output=True, text=True)
expect(f"ptr 1tii.pdb -o 1tii.png: exit {run.returncode}, {run.stderr!r}",
       run.returncode == 0 and os.path.getsize(image) > 0)

hostile = os.path.join(src, "tests", "fixtures", "hostile")

# Alternate locations in two subchains of one chain, at one residue number,
# are not alternates of one atom: both are kept, each in its own subchain,
# whichever the assembly names (its two operators: x, y, z and -x, -y, z).
for name, atoms in (("structure_altloc_across_subchains_winner.cif",
                     [(42.704, -10.253, 18.851), (43.104, -10.953, 19.851)]),
                    ("structure_altloc_across_subchains_loser.cif", [(42.053, -9.336, 17.867)])):
    got = [tuple(sphere["center"]) for sphere in dump(os.path.join(hostile, name))]
    want = atoms + [(-x, -y, z) for x, y, z in atoms]
    expect(f"{name}: {got}, not {want}", len(got) == len(want) and all(
        math.dist(g, w) < 1e-4 for g, w in zip(got, want)))

# An assembly not asked for is not expanded: the asymmetric unit of a file
# whose only assembly asks for too many operators.
got = dump(os.path.join(hostile, "structure_assembly_many_rows.cif"), "--assembly", "none")
expect(f"structure_assembly_many_rows.cif --assembly none: {len(got)} spheres, not 2",
       len(got) == 2)

# Hostile files (tests/fixtures/hostile; test_hostile.sh runs them under time
# and memory bounds): exit 4 and the problem named, in one line that names
# the file, within seconds (an assembly's operators are counted as they are
# made, not after all are).
for name, says in (
        ("structure_truncated.pdb", ":23: an atom line of 40 columns, short of its coordinates (31-54)"),
        ("structure_truncated.cif", "structure_truncated.cif:820:1: Wrong number of values"),
        ("structure_wrong_columns.pdb", ":2: x (columns 31-38) '42.704 -' is not a number"),
        ("structure_loop_missing_values.cif", ":2:1: Wrong number of values in the loop"),
        ("structure_missing_columns.cif", "_atom_site lacks the columns label_alt_id, auth_seq_id"),
        ("structure_coordinates_unknown.cif", "atom 2 (CA of GLY 1, chain A) has no finite"),
        ("structure_coordinate_infinite.cif", "atom 2 (CA of GLY 1, chain A) has no finite"),
        ("structure_absurd_numbers.cif", "'99999999999999999999999' has more digits than"),
        ("structure_unknown_element.pdb", "atom 1: no element ptr knows"),
        ("structure_non_ascii_record.pdb", ":1: not ASCII text, as PDB and mmCIF files are"),
        ("structure_non_ascii_residue.pdb", ":1: not ASCII text, as PDB and mmCIF files are"),
        ("structure_non_ascii_residue.cif", ":19: not ASCII text, as PDB and mmCIF files are"),
        ("structure_non_ascii_mangled_tag.cif", ":19: not ASCII text, as PDB and mmCIF files are"),
        ("structure_no_atoms.pdb", "no atoms of those --select keeps"),
        ("structure_bomb.pdb.gz", "Cannot determine uncompressed size"),
        ("structure_not_gzip.cif.gz", "Cannot determine uncompressed size"),
        ("structure_assembly_missing_operator.cif",
         "assembly 1: operator '7' is not in _pdbx_struct_oper_list"),
        ("structure_assembly_operator_range.cif",
         "oper_expression '(1-999999999)' names more operators than ptr builds (100000)"),
        ("structure_assembly_operator_product.cif",
         "assembly 1 has more operators than ptr builds (100000)"),
        ("structure_assembly_many_rows.cif",
         "assembly 1 has more operators than ptr builds (100000)"),
        ("structure_assembly_operator_expression.cif",
         "oper_expression '(1-2' is not a list of operators or a product of lists"),
        ("structure_assembly_operator_not_a_number.cif", "operator 1: 'x' is not a number"),
        ("structure_assembly_operator_not_a_number.pdb",
         ":8: an operator's rotation (columns 24-33) '  0.95I057' is not a number")):
    path = os.path.join(hostile, name)
    try:
        run = subprocess.run([ptr, "--dump-scene", path], capture_output=True, text=True,
                             timeout=10)
    except subprocess.TimeoutExpired:
        expect(f"{name}: still running after 10 s", False)
        continue
    expect(f"{name}: exit {run.returncode}, {run.stderr!r}",
           run.returncode == 4 and run.stderr.startswith(f"ptr: {path}") and
           says in run.stderr and run.stderr.count("\n") == 1)

checks.finish()
