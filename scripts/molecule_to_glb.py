#!/usr/bin/env python3
"""Converts a molecule or a particle file to instanced glTF binaries that ptr
renders: one sphere an atom, its radius the element's van der Waals radius
(S. Alvarez, Dalton Trans. 42 (2013) 8617) times --radius-scale, its colour
Jmol's CPK colour, decoded from sRGB so that a white-lit sphere shows it.

Input, by extension:
  .pdb, .ent  ATOM and HETATM records; the element from columns 77-78, else
        from the atom name (columns 13-16); of an atom's alternate locations
        the one of highest occupancy (the first of equals); every MODEL a
        frame. Each atom keeps its B-factor and occupancy as the instance
        attributes _BFACTOR and _OCCUPANCY (blank: 0 and 1).
  .xyz, .extxyz (or any other)  XYZ: a count line, a comment line, then one
        atom a line: element or type, x, y, z, and more columns kept as
        _COLUMN5, _COLUMN6, ...; extended XYZ (Properties=species:S:1:pos:R:3:...
        on the comment line) keeps every other numeric property as _NAME
        (upper case; 2 to 4 numbers a vector), reads a radius property as the
        radius and Z (atomic numbers) as the element. A type that names no
        element gets radius 0.5 and the Okabe-Ito colours, in order of first
        appearance. Frames follow one another in the file.
Output: OUTPUT.glb, or with several frames OUTPUT_0001.glb, OUTPUT_0002.glb, ...
(no camera: ptr frames every sphere).

Usage: molecule_to_glb.py INPUT OUTPUT.glb [--radius-scale S] [--radius R]
                          [--frame N] [--metal FUZZ | --glass IOR]
  --radius-scale S  multiplies the table's radii (default 1: space filling)
  --radius R        every atom's radius, whatever its element
  --frame N         only frame (model) N, counted from 1, to OUTPUT.glb
"""
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import particles_to_glb  # noqa: E402  (the scene it writes, its options and errors)
from element_table import ELEMENTS  # noqa: E402
from particles_to_glb import PROGRAM, fail  # noqa: E402

# Okabe and Ito, "Color Universal Design" (2008): told apart by colour-blind
# readers too; black, their eighth, is left for grey.
TYPE_COLOURS = [(230, 159, 0), (86, 180, 233), (0, 158, 115), (240, 228, 66), (0, 114, 178),
                (213, 94, 0), (204, 121, 167), (153, 153, 153)]
TYPE_RADIUS = 0.5  # what OVITO gives a particle type it does not know


def srgb_to_linear(byte):
    """IEC 61966-2-1's decoding of an 8-bit sRGB channel."""
    c = byte / 255
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


class Atoms:
    """One frame: positions, the species of each atom (an element's symbol, or a
    type's number), its own radius (or None) and named per-atom values."""

    def __init__(self):
        self.positions, self.species, self.radii, self.attributes = [], [], [], {}

    def add(self, position, species, radius=None, **values):
        for name, value in values.items():
            self.attributes.setdefault(name, []).append(value)
        self.positions.append(position)
        self.species.append(species)
        self.radii.append(radius)


def element_symbol(text):
    """The element text names (any case), or None."""
    symbol = text.strip().capitalize()
    return symbol if symbol in ELEMENTS else None


# ---- PDB (wwPDB format 3.3, "Coordinate Section") ----

def pdb_element(line):
    """The element of an ATOM/HETATM record: columns 77-78, else from the atom
    name. Names are aligned so that column 13-14 hold the element (a blank or
    digit in 13 for one letter), except four-character hydrogen names."""
    given = line[76:78].strip()
    if given:
        return element_symbol(given)
    name = line[12:16]
    if name[0] in " 0123456789":
        return element_symbol(name[1])
    if name[0] == "H" and len(name.strip()) == 4:
        return "H"
    return element_symbol(name[:2]) or element_symbol(name[0])


def pdb_number(path, number, line, start, end, what, blank=None):
    text = line[start:end].strip()
    if not text and blank is not None:
        return blank
    try:
        return float(text)
    except ValueError:
        fail(path, number, f"{what} (columns {start + 1}-{end}) {text!r} is not a number")


def read_pdb(path):
    frames, atoms, first_of = [], None, {}
    with open(path, encoding="ascii", errors="replace") as f:
        for number, line in enumerate(f, 1):
            record = line[:6]
            if record.startswith("MODEL"):
                atoms, first_of = Atoms(), {}
                frames.append(atoms)
            elif record.startswith("ENDMDL"):
                atoms = None
            elif record.rstrip() == "END":
                break
            elif record in ("ATOM  ", "HETATM"):
                line = line.rstrip("\r\n")
                if len(line) < 54:
                    fail(path, number, "an atom record shorter than its coordinates (54 columns)")
                line = line.ljust(80)
                if atoms is None:  # atoms outside MODEL records: one frame
                    atoms, first_of = Atoms(), {}
                    frames.append(atoms)
                element = pdb_element(line)
                if not element:
                    fail(path, number, f"no element: columns 77-78 {line[76:78]!r}, "
                                       f"atom name {line[12:16]!r}")
                position = [pdb_number(path, number, line, a, a + 8, axis)
                            for a, axis in ((30, "x"), (38, "y"), (46, "z"))]
                occupancy = pdb_number(path, number, line, 54, 60, "occupancy", 1.0)
                bfactor = pdb_number(path, number, line, 60, 66, "B-factor", 0.0)
                altloc = line[16]
                if altloc != " ":
                    # One atom (chain, residue, insertion code, name) in several
                    # places: keep the most occupied, where the first stood.
                    key = (line[21], line[22:27], line[12:16])
                    if key in first_of:
                        kept = first_of[key]
                        if occupancy > atoms.attributes["_OCCUPANCY"][kept]:
                            atoms.positions[kept], atoms.species[kept] = position, element
                            atoms.attributes["_OCCUPANCY"][kept] = occupancy
                            atoms.attributes["_BFACTOR"][kept] = bfactor
                        continue
                    first_of[key] = len(atoms.positions)
                atoms.add(position, element, _BFACTOR=bfactor, _OCCUPANCY=occupancy)
    return frames


# ---- XYZ and extended XYZ ----

def xyz_properties(path, number, comment):
    """The columns of an extended XYZ comment's Properties=, as (name, kind,
    count); the plain XYZ columns if it has none."""
    pairs = re.findall(r'(\w+)\s*=\s*("[^"]*"|\{[^}]*\}|\S+)', comment)
    spec = next((v.strip('"') for k, v in pairs if k.lower() == "properties"), None)
    if spec is None:
        return None
    fields = spec.split(":")
    if len(fields) % 3 or not all(f.isdigit() and int(f) > 0 for f in fields[2::3]):
        fail(path, number, f"Properties={spec}: not NAME:TYPE:COUNT triples")
    return [(fields[i], fields[i + 1].upper(), int(fields[i + 2]))
            for i in range(0, len(fields), 3)]


def xyz_value(path, number, kind, text):
    if kind == "L":
        if text.upper() not in ("T", "F", "TRUE", "FALSE"):
            fail(path, number, f"{text!r} is not a logical value")
        return 1.0 if text.upper() in ("T", "TRUE") else 0.0
    try:
        return float(text)
    except ValueError:
        fail(path, number, f"{text!r} is not a number")


def xyz_columns(path, number, properties, skipped):
    """Column slices of the properties ptr uses: species, pos, radius, Z and
    the numeric rest (attribute name -> (start, count, kind))."""
    start, used = 0, {}
    for name, kind, count in properties:
        lower = name.lower()
        if lower in ("species", "element") and kind == "S" and count == 1:
            used["species"] = (start, 1, kind)
        elif lower in ("pos", "positions") and kind == "R" and count == 3:
            used["pos"] = (start, 3, kind)
        elif lower in ("radius", "radii") and kind == "R" and count == 1:
            used["radius"] = (start, 1, kind)
        elif lower in ("z", "numbers") and kind == "I" and count == 1 and "species" not in used:
            used["Z"] = (start, 1, kind)
        elif kind in "RIL" and count <= 4:
            used["_" + re.sub(r"\W", "_", name).upper()] = (start, count, kind)
        else:
            skipped.add(f"{name}:{kind}:{count}")
        start += count
    if "pos" not in used or not ("species" in used or "Z" in used):
        fail(path, number, "Properties= names no pos:R:3, or neither species:S:1 nor Z:I:1")
    return used, start


def read_xyz(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.read().splitlines()
    frames, types, skipped, at = [], {}, set(), 0
    by_number = {number: symbol for symbol, (number, _, _) in ELEMENTS.items()}
    while at < len(lines):
        if not lines[at].strip():
            at += 1
            continue
        if not re.fullmatch(r"\s*\d+\s*", lines[at]):
            fail(path, at + 1, "expected the number of atoms of a frame")
        count = int(lines[at])
        if at + 1 >= len(lines):
            fail(path, at + 1, "a frame without its comment line")
        properties = xyz_properties(path, at + 2, lines[at + 1])
        columns = None
        if properties:
            columns, width = xyz_columns(path, at + 2, properties, skipped)
        rows = lines[at + 2:at + 2 + count]
        if len(rows) < count:
            fail(path, len(lines), f"{count} atoms announced, {len(rows)} given")
        atoms = Atoms()
        for offset, row in enumerate(rows):
            number = at + 3 + offset
            words = row.split()
            if columns is None:  # plain XYZ: type x y z [more numbers]
                columns = {"species": (0, 1, "S"), "pos": (1, 3, "R")}
                columns.update({f"_COLUMN{c + 1}": (c, 1, "R") for c in range(4, len(words))})
                width = len(words)
            if len(words) != width:
                fail(path, number, f"{len(words)} columns, expected {width}")

            def take(key):
                start, n, kind = columns[key]
                values = [xyz_value(path, number, kind, w) for w in words[start:start + n]]
                return values[0] if n == 1 else values
            if "species" in columns:
                species = words[columns["species"][0]]
            else:
                z = take("Z")
                species = by_number.get(int(z)) or fail(path, number, f"Z = {z}: no such element "
                                                                      "in the table")
            radius = take("radius") if "radius" in columns else None
            values = {k: take(k) for k in columns if k.startswith("_")}
            # An element's symbol, else the type's number in order of appearance.
            atoms.add(take("pos"), element_symbol(species) or types.setdefault(species, len(types)),
                      radius, **values)
        frames.append(atoms)
        at += 2 + count
    if skipped:
        print(f"{PROGRAM}: {path}: not kept (text, or more than 4 numbers): "
              f"{', '.join(sorted(skipped))}", file=sys.stderr)
    return frames


def frame_scene(source, atoms, radius_scale, radius, material):
    particles = []
    for position, species, own_radius in zip(atoms.positions, atoms.species, atoms.radii):
        if isinstance(species, str):
            _, table_radius, srgb = ELEMENTS[species]
            if table_radius is None and radius is None and own_radius is None:
                raise SystemExit(f"{PROGRAM}: {source}: {species} has no van der Waals radius in "
                                 "Alvarez (2013): give --radius")
            r = table_radius * radius_scale if table_radius is not None else None
        else:
            srgb = TYPE_COLOURS[species % len(TYPE_COLOURS)]
            r = TYPE_RADIUS
        # --radius first, then the file's own radius, then the table's.
        r = radius if radius is not None else own_radius if own_radius is not None else r
        particles.append(position + [r] + [srgb_to_linear(c) for c in srgb])
    return particles_to_glb.convert(particles, material, atoms.attributes)


def main():
    args = sys.argv[1:]
    material = particles_to_glb.take_material(args)
    radius_scale = particles_to_glb.take_option(args, "--radius-scale")
    radius = particles_to_glb.take_option(args, "--radius")
    frame = particles_to_glb.take_option(args, "--frame", int)
    if len(args) != 2 or not args[1].endswith(".glb"):
        raise SystemExit(__doc__)
    if radius_scale is not None and not radius_scale > 0:
        raise SystemExit(f"{PROGRAM}: --radius-scale {radius_scale}: not above 0")
    source, output = args
    pdb = source.lower().endswith((".pdb", ".ent"))
    try:
        frames = read_pdb(source) if pdb else read_xyz(source)
    except OSError as e:
        raise SystemExit(f"{PROGRAM}: {source}: {e.strerror}") from None
    frames = [f for f in frames if f.positions]
    if not frames:
        raise SystemExit(f"{PROGRAM}: {source}: no atoms")
    if frame is not None:
        if not 1 <= frame <= len(frames):
            raise SystemExit(f"{PROGRAM}: --frame {frame}: {source} has {len(frames)} frames")
        frames = [frames[frame - 1]]
    # Every frame converted before any file is written.
    scenes = [frame_scene(source, f, radius_scale or 1.0, radius, material) for f in frames]
    stem = output[:-len(".glb")]
    for i, (scene, atoms) in enumerate(zip(scenes, frames)):
        path = output if len(scenes) == 1 else f"{stem}_{i + 1:04d}.glb"
        particles_to_glb.make_scenes.write(*scene, path)
        print(f"{path}: {len(atoms.positions)} spheres")


if __name__ == "__main__":
    main()
