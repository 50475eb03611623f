#!/usr/bin/env python3
"""Writes scenes/droplet.extxyz: one frame of a spinning argon droplet, the
particle example of the README, as extended XYZ (the format ASE and OVITO
write). Atoms sit on argon's face-centred cubic lattice (a = 5.26 angstrom)
inside a sphere of radius 30, shaken by thermal noise; the droplet turns
about +Z, so each atom's velocity (vel, angstrom/ps) is the rotation's plus
noise, and its speed (the scalar `speed`) grows with the distance from the
axis: seen from +Z, in rings. The same file every run (a fixed seed).

Usage: make_particle_frame.py OUTPUT.extxyz
"""
import math
import random
import sys

LATTICE = 5.26      # angstrom, solid argon near its triple point
RADIUS = 30.0       # of the droplet
OMEGA = 0.25        # rad/ps about +Z
THERMAL = 0.5       # angstrom/ps, the spread of each velocity component
JITTER = 0.15       # angstrom, the spread of each position about its site


def sites():
    basis = [(0, 0, 0), (0.5, 0.5, 0), (0.5, 0, 0.5), (0, 0.5, 0.5)]
    cells = int(RADIUS / LATTICE) + 1
    for i in range(-cells, cells + 1):
        for j in range(-cells, cells + 1):
            for k in range(-cells, cells + 1):
                for b in basis:
                    p = [(i + b[0]) * LATTICE, (j + b[1]) * LATTICE, (k + b[2]) * LATTICE]
                    if sum(c * c for c in p) <= RADIUS * RADIUS:
                        yield p


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    rng = random.Random(24)
    rows = []
    for site in sites():
        x, y, z = (c + rng.gauss(0, JITTER) for c in site)
        v = [-OMEGA * y + rng.gauss(0, THERMAL), OMEGA * x + rng.gauss(0, THERMAL),
             rng.gauss(0, THERMAL)]
        speed = math.sqrt(sum(c * c for c in v))
        rows.append(f"Ar {x:.4f} {y:.4f} {z:.4f} {v[0]:.4f} {v[1]:.4f} {v[2]:.4f} {speed:.4f}")
    with open(sys.argv[1], "w") as f:
        f.write(f"{len(rows)}\n")
        f.write('Properties=species:S:1:pos:R:3:vel:R:3:speed:R:1 '
                'comment="spinning argon droplet, scripts/make_particle_frame.py"\n')
        f.write("\n".join(rows) + "\n")
    print(f"{sys.argv[1]}: {len(rows)} atoms")


if __name__ == "__main__":
    main()
