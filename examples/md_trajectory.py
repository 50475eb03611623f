#!/usr/bin/env python3
"""Renders the frames of a molecular-dynamics-like trajectory from numpy
arrays with ptr's Python module: one scene per frame, made from the frame's
positions, coloured by each atom's speed, saved as numbered PNGs.

    PTR_LIBRARY=build/lib/libptr.so.1 PYTHONPATH=python \\
        python3 examples/md_trajectory.py frames/ --atoms 2000 --frames 24

The trajectory here is made up (atoms of a cubic lattice vibrating about
their sites, with a slow drift): replace `trajectory` with your reader, such
as MDAnalysis's `universe.trajectory` (`ts.positions`) or ASE's
`read(..., index=":")` (`atoms.positions`), to render a real one."""

import argparse
import os

import numpy as np

import ptr


def trajectory(atoms, frames, seed=7):
    """Yields (positions (atoms, 3) float32, speeds (atoms,)) per frame."""
    rng = np.random.default_rng(seed)
    side = int(np.ceil(atoms ** (1 / 3)))
    grid = np.stack(np.meshgrid(*[np.arange(side)] * 3, indexing="ij"), -1).reshape(-1, 3)
    sites = (grid[:atoms] - (side - 1) / 2).astype(np.float32)
    phase = rng.uniform(0, 2 * np.pi, (atoms, 3))
    amplitude = rng.uniform(0.05, 0.25, (atoms, 1))
    drift = rng.normal(0, 0.01, (atoms, 3))
    for t in range(frames):
        angle = phase + 0.6 * t
        positions = sites + amplitude * np.sin(angle) + drift * t
        velocities = amplitude * np.cos(angle) + drift
        yield positions.astype(np.float32), np.linalg.norm(velocities, axis=1)


def colours(speeds):
    """Slow atoms blue, fast ones orange."""
    s = (speeds - speeds.min()) / max(np.ptp(speeds), 1e-9)
    return np.stack([0.1 + 0.9 * s, 0.3 + 0.3 * s, 1.0 - 0.8 * s], axis=1).astype(np.float32)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folder", help="where frame_0000.png, ... go")
    parser.add_argument("--atoms", type=int, default=2000)
    parser.add_argument("--frames", type=int, default=12)
    parser.add_argument("--size", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    parser.add_argument("--samples", type=int, default=16)
    args = parser.parse_args()
    os.makedirs(args.folder, exist_ok=True)

    side = args.atoms ** (1 / 3)
    camera = ptr.Camera(lookfrom=(1.6 * side, 1.1 * side, 2.2 * side), lookat=(0, 0, 0), vfov=35)
    materials = [ptr.Material("diffuse", (0.9, 0.9, 0.9))]
    radii = np.full(args.atoms, 0.35, np.float32)
    for frame, (positions, speeds) in enumerate(trajectory(args.atoms, args.frames)):
        scene = ptr.Scene.from_arrays(positions, radii, colors=colours(speeds),
                                      materials=materials, camera=camera)
        image = scene.render(*args.size, samples=args.samples, seed=1)
        path = os.path.join(args.folder, "frame_%04d.png" % frame)
        ptr.save(path, image)
        print("%s: %d atoms, mean %.3f" % (path, len(scene), float(image.mean())))


if __name__ == "__main__":
    main()
