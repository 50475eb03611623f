"""Element data for scripts/molecule_to_glb.py, read from the table the
structure importer compiles (importers/structure/elements.def, written by
scripts/make_element_table.py: see there for the sources): symbol ->
(atomic number, van der Waals radius in angstrom (Alvarez 2013; None where
it gives none), Jmol CPK colour as 8-bit sRGB)."""
import os
import re

TABLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "importers",
                     "structure", "elements.def")


def read(path=TABLE):
    rows = {}
    with open(path, encoding="ascii") as f:
        for symbol, number, radius, r, g, b in re.findall(
                r"^PTR_ELEMENT\((\w+), (\d+), ([\d.]+), (\d+), (\d+), (\d+)\)$", f.read(), re.M):
            rows[symbol] = (int(number), float(radius) or None, (int(r), int(g), int(b)))
    return rows


ELEMENTS = read()
