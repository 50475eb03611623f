#!/usr/bin/env python3
"""A mesh gives one sphere per connected component that is a sphere
(docs/scenes.md, "What becomes a sphere"), and what is not one is skipped with one warning
that counts and names it, never drawn as its bounding sphere.

Files from tests/support/mesh_files.py, each imported with --dump-scene:
- joined: spheres in one primitive (welded, one turned so its bounds are not
  its sphere's), and two more in a second primitive of another material;
- unwelded: every triangle its own vertices (components by position), and
  a sphere whose hemispheres meet at y = +0 on one side, -0 on the other;
- touching: two welded (closed) spheres meeting at a pole's position, and a
  welded one meeting an unwelded one there: two spheres each (a closed part
  is not matched by position);
- seam and hemispheres: a sphere whose seam's vertices are split (open by
  index), and one of two welded hemispheres sharing the equator's positions
  (each open): one sphere each;
- many: 300 unwelded spheres and two cubes over two primitives, one sphere
  split across them, enough for the components to be found on all cores;
- quantised: normalised 16-bit and plain 8-bit positions, scaled back by the
  node, within the tolerance;
- cube, torus, plane, cylinder, each alone: no sphere, the warning;
- mixed: spheres, a cube and a torus joined, with a degenerate triangle of
  its own: the spheres, and one warning counting 3 parts and naming the node;
- nan: a sphere and 200,001 vertices whose positions are NaN, unwelded in
  one primitive: the sphere, and each NaN triangle a part not drawn (a NaN
  position equals nothing, so matching positions stays linear: kept, they
  would all probe one chain of the table, minutes of import);
- a cube mesh under 40 nodes beside a sphere: 40 parts, the names cut with
  ", ..." to fit the line;
- OBJ: an object of two joined spheres, each under its own usemtl, and a
  cube named like a sphere: the two spheres, each with its material, and the
  warning; with --fit-all-objects one sphere an object, unchecked, no
  warning;
- OBJ at the tolerance: spheres each with one vertex moved out to within a
  few units in the last place of the vertex check's limit, in doubles: the
  ones the check as written passes, and one warning counting the others
  (the check first passes distances by their squares, far enough inside the
  limit; these must take the check itself).
Usage: check_mesh_spheres.py PTR"""
import json
import math
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../support"))
import mesh_files as mf  # noqa: E402

ptr = sys.argv[1]
WARNING = "mesh part"
failures = []


def dump(path):
    run = subprocess.run([ptr, "--dump-scene", path], capture_output=True, text=True, timeout=60)
    if run.returncode != 0:
        failures.append(f"{os.path.basename(path)}: exit {run.returncode}: {run.stderr.strip()}")
        return None, run.stderr
    return json.loads(run.stdout), run.stderr


def expect(path, spheres, skipped, names=(), tol=1e-5):
    """spheres: (centre, radius, material index, -1 for the default grey) in
    the file's order."""
    name = os.path.basename(path)
    scene, stderr = dump(path)
    if scene is None:
        return
    got = [(s["center"], s["radius"], scene["materials"][s["material"]]["albedo"][0])
           for s in scene["spheres"]]
    if len(got) != len(spheres):
        failures.append(f"{name}: {len(got)} spheres, not {len(spheres)}: {got}")
    for (gc, gr, ga), (wc, wr, wm) in zip(got, spheres):
        off = max(abs(a - b) for a, b in zip(gc, wc))
        if off > tol * wr or abs(gr - wr) > tol * wr:
            failures.append(f"{name}: sphere {gc} r {gr}, not {wc} r {wr}")
        if abs(ga - (0.8 if wm < 0 else 0.25 * (wm + 1))) > 1e-6:
            failures.append(f"{name}: sphere at {wc} has material albedo {ga}, not material {wm}'s")
    lines = [line for line in stderr.splitlines() if WARNING in line]
    if not skipped:
        if lines:
            failures.append(f"{name}: unexpected warning {lines}")
        return
    if len(lines) != 1:
        failures.append(f"{name}: {len(lines)} warnings about skipped parts, not 1: {stderr}")
        return
    counted = f"{skipped} {WARNING}{'s' if skipped > 1 else ''} not drawn"
    if counted not in lines[0]:
        failures.append(f"{name}: warning does not say '{counted}': {lines[0]}")
    for n in names:
        if n not in lines[0]:
            failures.append(f"{name}: warning does not name {n}: {lines[0]}")


def single(folder, name, shape, skipped=1):
    w = mf.Writer()
    w.node(name, w.mesh(name + "_mesh", [(shape, 0)]))
    path = os.path.join(folder, name + ".glb")
    w.write(path)
    expect(path, [], skipped, [f"node '{name}' (mesh '{name}_mesh')"])


def passes_check(verts, tris):
    """Whether a component passes mesh_spheres.c's checks, computed as it
    computes them in doubles (quantum 0)."""
    lo = [min(v[k] for v in verts) for k in range(3)]
    hi = [max(v[k] for v in verts) for k in range(3)]
    centre = [0.5 * (lo[k] + hi[k]) for k in range(3)]
    extent = max(hi[k] - lo[k] for k in range(3))
    r = 0.5 * extent
    if not (extent > 0 and min(hi[k] - lo[k] for k in range(3)) >= 0.75 * extent):
        return False

    def dist(a, b):
        return math.sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                         (a[2] - b[2]) * (a[2] - b[2]))

    if not all(abs(dist(v, centre) - r) <= 0.1 * r + 0.0 for v in verts):
        return False
    thrice = [3 * x for x in centre]
    for t in tris:
        total = [0.0, 0.0, 0.0]
        for i in t:
            total = [total[k] + verts[i][k] for k in range(3)]
        if not dist(total, thrice) + 0.0 >= 3 * 0.88 * r:
            return False
    return True


def at_tolerance(folder):
    path = os.path.join(folder, "tolerance.obj")
    want, skipped = [], 0
    with open(path, "w") as f:
        first = 1
        for k, ulps in enumerate(range(-4, 5)):
            verts, tris = mf.uv_sphere((0, 0, 0), 1)
            t = 1.1
            for _ in range(abs(ulps)):
                t = math.nextafter(t, math.inf if ulps > 0 else -math.inf)
            verts[18] = [0.6 * t, 0.0, 0.8 * t]  # on the equator, inside the bounds
            verts = [[x + 3 * k for x in v] for v in verts]
            if passes_check(verts, tris):
                want.append(([3 * k] * 3, 1, -1))
            else:
                skipped += 1
            f.write(f"o Sphere{k}\n")
            f.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in verts)
            f.writelines(f"f {a + first} {b + first} {c + first}\n" for a, b, c in tris)
            first += len(verts)
    if not want or not skipped:
        failures.append(f"tolerance.obj: {len(want)} spheres pass, {skipped} fail: "
                        "the limit was not straddled")
    expect(path, want, skipped)


def cut_open(shape, axis, cut):
    """The shape with the triangles whose centroid lies below 0 along axis
    given their own copies of the vertices cut selects (a seam, or a cut
    into pieces, welded each)."""
    verts, tris = shape
    verts = [list(v) for v in verts]
    copies = {}
    out = []
    for t in tris:
        if sum(verts[i][axis] for i in t) < 0:
            t = tuple(copies.setdefault(i, len(verts) + len(copies)) if cut(verts[i]) else i
                      for i in t)
        out.append(t)
    return verts + [list(verts[i]) for i in sorted(copies, key=copies.get)], out


def main():
    with tempfile.TemporaryDirectory() as folder:
        # Joined, over two primitives of materials 1 and 2.
        first = [((0, 0, 0), 1.0, 0.0), ((3, 0, 0), 0.5, 0.4), ((0, 4, 1), 2.0, 0.0)]
        second = [((-5, 1, 0), 0.25, 0.0), ((-5, 3, 0), 0.75, 0.0)]
        w = mf.Writer()
        w.node("joined", w.mesh("joined", [
            (mf.combine(*[mf.uv_sphere(c, r, turn=t) for c, r, t in first]), 1),
            (mf.combine(*[mf.uv_sphere(c, r, 16, 8) for c, r, _ in second]), 2)]))
        path = os.path.join(folder, "joined.glb")
        w.write(path)
        # The turned sphere's fit is its bounds': centre and radius within 10%.
        want = [(c, r, 1) for c, r, _ in first] + [(c, r, 2) for c, r, _ in second]
        expect(path, want, 0, tol=0.1)

        # Unwelded: the triangles share positions, not indices.
        w = mf.Writer()
        w.node("flat", w.mesh("flat", [(mf.unweld(mf.combine(
            mf.uv_sphere((1, 2, 3), 1.5), mf.uv_sphere((6, 2, 3), 0.5))), 0)]))
        path = os.path.join(folder, "unwelded.glb")
        w.write(path)
        expect(path, [((1, 2, 3), 1.5, 0), ((6, 2, 3), 0.5, 0)], 0)

        # Unwelded with signed zeros: -0 and +0 are one position (they
        # compare equal). The hemispheres meet only at the equator, y = +0
        # in the northern's triangles and -0 in the southern's: one sphere.
        verts, tris = mf.unweld(mf.uv_sphere((0, 0, 0), 1))
        verts = [[x, 0.0 if abs(y) < 1e-9 else y, z] for x, y, z in verts]
        for t in range(0, len(verts), 3):
            if min(v[1] for v in verts[t:t + 3]) < 0:
                for v in verts[t:t + 3]:
                    v[1] = -0.0 if v[1] == 0 else v[1]
        w = mf.Writer()
        w.node("zeros", w.mesh("zeros", [((verts, tris), 0)]))
        path = os.path.join(folder, "signed_zeros.glb")
        w.write(path)
        expect(path, [((0, 0, 0), 1, 0)], 0)

        # Touching at one position (the first's north pole, the second's
        # south pole): a welded sphere is closed by index, so it is not
        # matched by position, neither with another closed one nor with an
        # unwelded one; each is its own sphere.
        for name, second in (("touching_closed", mf.uv_sphere((0, 2, 0), 1)),
                             ("touching_open", mf.unweld(mf.uv_sphere((0, 2, 0), 1)))):
            w = mf.Writer()
            w.node(name, w.mesh(name, [(mf.combine(mf.uv_sphere((0, 0, 0), 1), second), 0)]))
            path = os.path.join(folder, name + ".glb")
            w.write(path)
            expect(path, [((0, 0, 0), 1, 0), ((0, 2, 0), 1, 0)], 0)

        # Open by index, so still matched by position: the seam's vertices
        # split (one part with a border), and two welded hemispheres sharing
        # the equator's positions (two parts): one sphere each.
        seam = cut_open(mf.uv_sphere((0, 0, 0), 1), 2, lambda v: v[2] == 0 and v[0] > 0)
        halves = cut_open(mf.uv_sphere((0, 0, 0), 1), 1, lambda v: v[1] == 0)
        for name, shape in (("seam", seam), ("hemispheres", halves)):
            w = mf.Writer()
            w.node(name, w.mesh(name, [(shape, 0)]))
            path = os.path.join(folder, name + ".glb")
            w.write(path)
            expect(path, [((0, 0, 0), 1, 0)], 0)

        # Many: enough vertices and triangles that the components are found
        # on all cores; unwelded, over two primitives, with a cube among the
        # spheres of each and a sphere split across them (joined by position,
        # of the material of its first triangle's primitive).
        many = [((3 * (i % 20), 3 * (i // 20), 0), 0.5 + 0.001 * i) for i in range(300)]
        split = mf.uv_sphere((0, -5, 0), 1)
        half = len(split[1]) // 2
        parts = []
        for spheres, piece, at in ((many[:150], split[1][:half], 151),
                                   (many[150:], split[1][half:], 0)):
            shapes = [mf.uv_sphere(c, r) for c, r in spheres]
            shapes.insert(75, mf.cube((at, 100, 0), 1))
            shapes.insert(at, (split[0], piece))
            parts.append(mf.unweld(mf.combine(*shapes)))
        w = mf.Writer()
        w.node("Many", w.mesh("ManyMesh", [(parts[0], 1), (parts[1], 2)]))
        path = os.path.join(folder, "many.glb")
        w.write(path)
        expect(path, [(c, r, 1) for c, r in many[:150]] + [((0, -5, 0), 1, 1)] +
               [(c, r, 2) for c, r in many[150:]], 2, ["node 'Many' (mesh 'ManyMesh')"])

        # Quantised: 16-bit normalised over [0, 1], and 8-bit integers; the
        # node's scale and translation map them back to (10, 0, 0) radius 2.
        for kind, top in (("short", 1.0), ("byte", 255.0)):
            w = mf.Writer()
            sphere = mf.uv_sphere((top / 2,) * 3, top / 2, 32, 16)
            w.node("q", w.mesh("q", [(sphere, 0)], quantise=kind), scale=[4 / top] * 3,
                   translation=[8, -2, -2])
            path = os.path.join(folder, f"quantised_{kind}.glb")
            w.write(path)
            expect(path, [((10, 0, 0), 2, 0)], 0, tol=0.02)

        single(folder, "cube", mf.cube((0, 0, 0), 1))
        single(folder, "torus", mf.torus((0, 0, 0), 1, 0.3))
        single(folder, "fat_torus", mf.torus((0, 0, 0), 1, 0.9))
        single(folder, "plane", mf.plane((0, 0, 0), 1))
        single(folder, "cylinder", mf.cylinder((0, 0, 0), 1, 2))
        single(folder, "tall_cylinder", mf.cylinder((0, 0, 0), 1, 2.5))

        # Mixed: two spheres, a cube, a torus and a degenerate triangle.
        verts, tris = mf.combine(mf.uv_sphere((0, 0, 0), 1), mf.cube((4, 0, 0), 1),
                                 mf.uv_sphere((8, 0, 0), 1), mf.torus((12, 0, 0), 1, 0.3))
        verts.append([20, 0, 0])
        tris.append((len(verts) - 1,) * 3)
        w = mf.Writer()
        w.node("Mixed", w.mesh("MixedMesh", [((verts, tris), 0)]))
        path = os.path.join(folder, "mixed.glb")
        w.write(path)
        expect(path, [((0, 0, 0), 1, 0), ((8, 0, 0), 1, 0)], 3, ["node 'Mixed' (mesh 'MixedMesh')"])

        # NaN positions, unwelded: each triangle its own part, not drawn.
        nan = float("nan")
        count = 66667
        bad = ([[nan] * 3] * (3 * count), [(3 * k, 3 * k + 1, 3 * k + 2) for k in range(count)])
        w = mf.Writer()
        w.node("Nan", w.mesh("NanMesh", [(mf.combine(mf.unweld(mf.uv_sphere((1, 2, 3), 1.5)),
                                                     bad), 0)]))
        positions = w.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        for bound in ("min", "max"):  # NaN is not JSON
            del w.doc["accessors"][positions][bound]
        path = os.path.join(folder, "nan.glb")
        w.write(path)
        expect(path, [((1, 2, 3), 1.5, 0)], count, ["node 'Nan' (mesh 'NanMesh')"])

        # One mesh, a cube, under 40 nodes: 40 parts, the names cut with "...".
        w = mf.Writer()
        box = w.mesh("Box", [(mf.cube((0, 0, 0), 1), 0)])
        for i in range(40):
            w.node(f"Cube{i}", box, translation=[3 * i, 0, 0])
        w.node("Ball", w.mesh("Ball", [(mf.uv_sphere((0, -5, 0), 1), 0)]))
        path = os.path.join(folder, "cubes.glb")
        w.write(path)
        expect(path, [((0, -5, 0), 1, 0)], 40, ["node 'Cube0' (mesh 'Box')", ", ..."])

        # OBJ, under its naming rule: an object of two joined spheres of
        # materials 0 and 1 (usemtl is state: the second holds for the cube),
        # a cube named like a sphere; --fit-all-objects fits each object,
        # unchecked.
        first = mf.uv_sphere((0, 0, 0), 1)
        verts, tris = mf.combine(first, mf.uv_sphere((5, 0, 0), 2))
        cube_verts, cube_tris = mf.cube((0, 9, 0), 1)
        with open(os.path.join(folder, "joined.mtl"), "w") as f:
            f.write("newmtl M0\nKd 0.25 0.25 0.25\nnewmtl M1\nKd 0.5 0.5 0.5\n")
        path = os.path.join(folder, "joined.obj")
        with open(path, "w") as f:
            f.write("mtllib joined.mtl\no TwoSpheres\n")
            f.writelines(f"v {x} {y} {z}\n" for x, y, z in verts)
            for t, (a, b, c) in enumerate(tris):
                if t in (0, len(first[1])):
                    f.write(f"usemtl M{0 if t == 0 else 1}\n")
                f.write(f"f {a + 1} {b + 1} {c + 1}\n")
            f.write("o CubeSphere\n")
            f.writelines(f"v {x} {y} {z}\n" for x, y, z in cube_verts)
            f.writelines(f"f {a + 1 + len(verts)} {b + 1 + len(verts)} {c + 1 + len(verts)}\n"
                         for a, b, c in cube_tris)
        expect(path, [((0, 0, 0), 1, 0), ((5, 0, 0), 2, 1)], 1, ["object 'CubeSphere' (line"])
        run = subprocess.run([ptr, "--dump-scene", "--fit-all-objects", path], capture_output=True,
                             text=True, timeout=60)
        fitted = [(s["center"], s["radius"]) for s in json.loads(run.stdout)["spheres"]]
        want = [((3, 0, 0), 4), ((0, 9, 0), 1)]  # the objects' bounds
        if len(fitted) != 2 or WARNING in run.stderr or any(
                abs(gr - wr) > 1e-5 or max(abs(a - b) for a, b in zip(gc, wc)) > 1e-5
                for (gc, gr), (wc, wr) in zip(fitted, want)):
            failures.append(f"joined.obj --fit-all-objects: {fitted} {run.stderr}")

        at_tolerance(folder)

    for f in failures:
        print("FAIL " + f)
    print("PASS" if not failures else f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
