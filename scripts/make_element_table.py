#!/usr/bin/env python3
"""Writes scripts/element_table.py, the element data of scripts/molecule_to_glb.py,
from the tables the Atomic Simulation Environment ships (Debian: python3-ase):

- van der Waals radii (angstrom): S. Alvarez, "A cartography of the van der Waals
  territories", Dalton Trans. 42 (2013) 8617-8636, doi:10.1039/C3DT50599E
  (ase/data/vdw_alvarez.py); None for the elements the paper gives no radius;
- colours: Jmol's CPK colours (jmol.sourceforge.net/jscolors, ase/data/colors.py,
  whose three decimals are Jmol's 8-bit values over 255, kept as those bytes).

Run at commit time, not at build time; the result is committed beside this script:
    /usr/bin/python3 scripts/make_element_table.py scripts/element_table.py
"""
import math
import sys

from ase.data import chemical_symbols
from ase.data.colors import jmol_colors
from ase.data.vdw_alvarez import vdw_radii


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    rows = []
    for number, symbol in enumerate(chemical_symbols):
        if number == 0 or number >= len(jmol_colors):
            continue
        radius = float(vdw_radii[number]) if number < len(vdw_radii) else math.nan
        rgb = tuple(int(round(float(c) * 255)) for c in jmol_colors[number])
        rows.append(f"    {symbol!r}: ({number}, {None if math.isnan(radius) else radius!r}, "
                    f"{rgb!r}),")
    with open(sys.argv[1], "w") as f:
        f.write('"""Element data for scripts/molecule_to_glb.py, written by\n'
                "scripts/make_element_table.py (see there for the sources): symbol ->\n"
                "(atomic number, van der Waals radius in angstrom (Alvarez 2013; None where\n"
                'it gives none), Jmol CPK colour as 8-bit sRGB)."""\n\nELEMENTS = {\n')
        f.write("\n".join(rows) + "\n}\n")


if __name__ == "__main__":
    main()
