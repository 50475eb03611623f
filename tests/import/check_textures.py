#!/usr/bin/env python3
"""Spheres take their colours from textures and vertex colours
(docs/scenes.md, "Textures"): files from tests/support/texture_files.py,
each imported with --dump-scene.

- palette: five spheres joined in one primitive, each reading one texel of a
  base colour and a metallic-roughness palette: each its texel's colour
  (sRGB made linear), kind (metallic >= 0.5: metal) and fuzz (roughness),
  within 1e-6; the two of the same texel share a material (4 in all).
- transform: KHR_texture_transform's offset, scale and texCoord (TEXCOORD_1).
- wrap: the sampler's clamp, repeat and mirrored repeat.
- vertex colours: COLOR_0 as float, normalised byte and short, times the
  base colour (ptr's grey 0.8 without a material).
- emissive: the emissive texture times emissiveFactor and the strength.
- deep: 16-bit textures, whose values are no byte's, made linear (colour)
  or not (roughness) alike.
- varying: spheres whose texels differ take the mean over their vertices,
  and one warning counts them.
- uri images: a PNG file beside the .gltf and one in a data: URI.
- KTX2 (KHR_texture_basisu): refused, exit 4 and one line naming the
  extension, whether the file requires it or only uses it.
Usage: check_textures.py PTR"""
import json
import os
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../support"))
import texture_files as tf  # noqa: E402

ptr = sys.argv[1]
TOL = 1e-6
failures = []


def run(path):
    return subprocess.run([ptr, "--dump-scene", path], capture_output=True, text=True,
                          timeout=60)


def dump(path):
    done = run(path)
    if done.returncode != 0:
        failures.append(f"{os.path.basename(path)}: exit {done.returncode}: "
                        f"{done.stderr.strip()}")
        return None
    return json.loads(done.stdout)


def near(a, b):
    return all(abs(x - y) <= TOL for x, y in zip(a, b))


def check_colours(name, scene, want, key="albedo"):
    got = [scene["materials"][s["material"]][key] for s in scene["spheres"]]
    if len(got) != len(want):
        failures.append(f"{name}: {len(got)} spheres, not {len(want)}")
        return
    for i, (g, w) in enumerate(zip(got, want)):
        if not near(g, w):
            failures.append(f"{name}: sphere {i} {key} {g}, not {w}")


def main():
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "palette.glb")
        want, materials = tf.palette(path)
        scene = dump(path)
        if scene:
            check_colours("palette", scene, [c for c, _, _ in want])
            for i, (s, (_, kind, fuzz)) in enumerate(zip(scene["spheres"], want)):
                m = scene["materials"][s["material"]]
                if m["kind"] != kind or abs(m.get("fuzz", 0) - fuzz) > TOL:
                    failures.append(f"palette: sphere {i} {m}, not {kind} of fuzz {fuzz}")
            if len(scene["materials"]) != materials:
                failures.append(f"palette: {len(scene['materials'])} materials, not {materials}")
            if scene["warnings"]:
                failures.append(f"palette: warnings {scene['warnings']}")

        for name, make in [("transform", tf.transform), ("emissive", tf.emissive)]:
            path = os.path.join(d, name + ".glb")
            want = make(path)
            scene = dump(path)
            if scene:
                check_colours(name, scene, [want], "emission" if name == "emissive" else "albedo")

        path = os.path.join(d, "deep.glb")
        want, fuzz = tf.deep(path)
        scene = dump(path)
        if scene:
            check_colours("deep", scene, [want])
            m = scene["materials"][scene["spheres"][0]["material"]]
            if m["kind"] != "metal" or abs(m["fuzz"] - fuzz) > TOL:
                failures.append(f"deep: {m}, not metal of fuzz {fuzz}")

        for name, make in [("wrap", tf.wrap), ("vertex_colors", tf.vertex_colors)]:
            path = os.path.join(d, name + ".glb")
            want = make(path)
            scene = dump(path)
            if scene:
                check_colours(name, scene, want)

        path = os.path.join(d, "varying.glb")
        want, varying = tf.varying(path)
        scene = dump(path)
        if scene:
            check_colours("varying", scene, want)
            told = [w for w in scene["warnings"] if "vary" in w]
            if len(told) != 1 or f"{varying} spheres" not in told[0]:
                failures.append(f"varying: warnings {scene['warnings']}, not one naming "
                                f"{varying} spheres")

        path, want = tf.uri_images(d)
        scene = dump(path)
        if scene:
            check_colours("uri_images", scene, want)

        for required in (True, False):
            path = os.path.join(d, f"ktx2_{'required' if required else 'used'}.glb")
            tf.ktx2(path, required)
            done = run(path)
            lines = done.stderr.strip().splitlines()
            if (done.returncode != 4 or len(lines) != 1 or "KHR_texture_basisu" not in lines[0]
                    or os.path.basename(path) not in lines[0]):
                failures.append(f"{os.path.basename(path)}: exit {done.returncode}, stderr "
                                f"{done.stderr.strip()!r}: not exit 4 and one line naming "
                                f"the file and KHR_texture_basisu")

    for f in failures:
        print("FAIL", f)
    print("PASS" if not failures else f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
