#!/usr/bin/env python3
"""Writes src/scene/colormap_tables.c, the 256-entry tables of --colormap, from
matplotlib (Debian: python3-matplotlib; BSD-compatible licence, data included):

- viridis, magma, inferno, plasma, cividis: matplotlib's listed colormaps
  (matplotlib/_cm_listed.py: van der Walt, Smith and Nunez for the first four,
  Nunez, Anderton and Renslow 2018 for cividis), their 256 entries as stored;
- coolwarm: Kenneth Moreland's diverging map ("Diverging Color Maps for
  Scientific Visualization", ISVC 2009), as matplotlib builds its 256 entries
  from Moreland's CoolWarmFloat33 table (matplotlib/_cm.py).

Entries are sRGB-encoded colours in [0, 1], as matplotlib holds them.
Run at commit time, not at build time; the result is committed:
    /usr/bin/python3 scripts/make_colormaps.py src/scene/colormap_tables.c
"""
import sys

import matplotlib
import numpy as np

NAMES = ["viridis", "magma", "inferno", "plasma", "cividis", "coolwarm"]


def c_float(x):
    text = f"{x:.9g}"
    return (text if "." in text or "e" in text else text + ".0") + "f"


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    out = [f"/* Written by scripts/make_colormaps.py from matplotlib {matplotlib.__version__}\n"
           " * (see there for the sources): 256 sRGB entries a map. */\n",
           '#include "scene/colormap.h"\n']
    for name in NAMES:
        table = matplotlib.colormaps[name](np.arange(256))[:, :3]
        out.append(f"\nstatic const float {name}[256][3] = {{")
        out += ["    { " + ", ".join(c_float(float(x)) for x in entry) + " }," for entry in table]
        out.append("};")
    out.append("\nconst PtrColormap ptr_colormaps[] = {")
    out += [f'    {{ "{name}", {name} }},' for name in NAMES]
    out.append("    { 0, 0 },\n};\n")
    with open(sys.argv[1], "w") as f:
        f.write("\n".join(out))


if __name__ == "__main__":
    main()
