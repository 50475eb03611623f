#!/usr/bin/env python3
"""Writes importers/structure/elements.def, the element data of the structure
importer and (through scripts/element_table.py) of scripts/molecule_to_glb.py,
from the tables the Atomic Simulation Environment ships (Debian: python3-ase):

- van der Waals radii (angstrom): S. Alvarez, "A cartography of the van der Waals
  territories", Dalton Trans. 42 (2013) 8617-8636, doi:10.1039/C3DT50599E
  (ase/data/vdw_alvarez.py); None for the elements the paper gives no radius;
- colours: Jmol's CPK colours (jmol.sourceforge.net/jscolors, ase/data/colors.py,
  whose three decimals are Jmol's 8-bit values over 255, kept as those bytes).

Run at commit time, not at build time; the result is committed:
    /usr/bin/python3 scripts/make_element_table.py importers/structure/elements.def
"""
import math
import sys

from ase.data import chemical_symbols
from ase.data.colors import jmol_colors
from ase.data.vdw_alvarez import vdw_radii


HEADER = """/* The elements ptr knows, in order of atomic number, written by
 * scripts/make_element_table.py (see there for the sources), and read both by
 * the structure importer (structure_import.c) and by scripts/element_table.py
 * for scripts/molecule_to_glb.py: one table for both.
 *
 * PTR_ELEMENT(symbol, atomic number, van der Waals radius in angstrom
 * (Alvarez 2013; 0 where it gives none), Jmol CPK colour as 8-bit sRGB) */
"""


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    rows = []
    for number, symbol in enumerate(chemical_symbols):
        if number == 0 or number >= len(jmol_colors):
            continue
        radius = float(vdw_radii[number]) if number < len(vdw_radii) else math.nan
        rgb = tuple(int(round(float(c) * 255)) for c in jmol_colors[number])
        rows.append(f"PTR_ELEMENT({symbol}, {number}, {0 if math.isnan(radius) else radius!r}, "
                    f"{rgb[0]}, {rgb[1]}, {rgb[2]})")
    with open(sys.argv[1], "w") as f:
        f.write(HEADER + "\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
