#!/usr/bin/env python3
"""glTF files of spheres coloured by textures and vertex colours
(docs/scenes.md, "Textures"), for tests/import/check_textures.py: each
function writes one file and returns what ptr must make of it.

Run as a script, writes the hostile files of texture reading into DIR
(tests/fixtures/hostile): broken PNG bytes, a texture index out of range,
texture coordinates that are not numbers.

Usage: texture_files.py DIR"""
import base64
import json
import math
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import mesh_files as mf  # noqa: E402

CLAMP, REPEAT = 33071, 10497


def png(texels, width, bits=8):
    """An RGBA PNG of texels (lists of 4 values of bits, 8 or 16), rows top
    to bottom."""
    height = len(texels) // width
    sample = ">" + ("B" if bits == 8 else "H")

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    rows = b"".join(b"\0" + b"".join(struct.pack(sample, c)
                                     for t in texels[y * width:(y + 1) * width] for c in t)
                    for y in range(height))
    return (b"\x89PNG\r\n\x1a\n"
            + chunk(b"IHDR", struct.pack(">2I5B", width, height, bits, 6, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def linear(value, top=255):
    """An sRGB texel value (an 8-bit one, or of top at most) made linear."""
    x = value / top
    return x / 12.92 if x <= 0.04045 else ((x + 0.055) / 1.055) ** 2.4


class Writer(mf.Writer):
    """mesh_files' writer with vertex attributes, images and textures."""

    def attribute(self, mesh, primitive, name, values, component=mf.FLOAT, normalized=False):
        fmt = {mf.FLOAT: "f", mf.UBYTE: "B", mf.USHORT: "H"}[component]
        element = struct.Struct("<" + fmt * len(values[0]))
        stride = (element.size + 3) // 4 * 4  # vertex attributes are aligned to 4 bytes
        data = b"".join(element.pack(*v) + b"\0" * (stride - element.size) for v in values)
        index = self.accessor(data, component, len(values), f"VEC{len(values[0])}")
        if stride != element.size:
            self.doc["bufferViews"][-1]["byteStride"] = stride
        if normalized:
            self.doc["accessors"][index]["normalized"] = True
        self.doc["meshes"][mesh]["primitives"][primitive]["attributes"][name] = index

    def image(self, data, mime="image/png"):
        self.doc.setdefault("images", []).append({"bufferView": self.view(data),
                                                  "mimeType": mime})
        return len(self.doc["images"]) - 1

    def texture(self, image, wrap=None):
        texture = {"source": image}
        if wrap:
            self.doc.setdefault("samplers", []).append({"wrapS": wrap[0], "wrapT": wrap[1]})
            texture["sampler"] = len(self.doc["samplers"]) - 1
        self.doc.setdefault("textures", []).append(texture)
        return len(self.doc["textures"]) - 1

    def material(self, **material):
        self.doc["materials"].append(material)
        return len(self.doc["materials"]) - 1


def constant(uv, count):
    return [uv] * count


PALETTE = [[200, 30, 40, 255], [20, 180, 60, 255], [10, 40, 230, 255], [255, 255, 255, 255]]
# Metallic-roughness texels: G roughness, B metallic.
METAL_ROUGH = [[0, 64, 0, 255], [0, 32, 255, 255], [0, 128, 255, 255], [0, 255, 0, 255]]


def palette(path):
    """Five spheres joined in one primitive, each of one constant texcoord at
    a texel's centre of a 4 x 1 base colour and metallic-roughness palette;
    two spheres share texel 1. Returns the spheres' (colour, kind, fuzz) and
    the number of materials."""
    w = Writer()
    texels = [0, 1, 2, 3, 1]
    spheres = [mf.uv_sphere((3 * i, 0, 0), 1) for i in range(len(texels))]
    shape = mf.combine(*spheres)
    m = w.material(pbrMetallicRoughness={
        "baseColorTexture": {"index": w.texture(w.image(png(PALETTE, 4)))},
        "metallicRoughnessTexture": {"index": w.texture(w.image(png(METAL_ROUGH, 4)))}})
    mesh = w.mesh("palette", [(shape, m)])
    uv = [((t + 0.5) / 4, 0.5) for t in texels for _ in spheres[0][0]]
    w.attribute(mesh, 0, "TEXCOORD_0", uv)
    w.node("Palette", mesh)
    w.write(path)
    want = []
    for t in texels:
        metal = METAL_ROUGH[t][2] >= 128
        want.append(([linear(c) for c in PALETTE[t][:3]], "metal" if metal else "diffuse",
                     METAL_ROUGH[t][1] / 255 if metal else 0))
    return want, 4


def transform(path):
    """KHR_texture_transform: offset (0.5, 0) and scale 0.5 move texcoord
    (0.5, 0.5) of TEXCOORD_1 (which the transform's texCoord names over the
    textureInfo's 0) to (0.75, 0.25): texel (1, 0) of a 2 x 2 texture; the
    sphere's TEXCOORD_0 would read texel (0, 1). Returns the colour."""
    w = Writer()
    grid = [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [255, 255, 0, 255]]
    sphere = mf.uv_sphere((0, 0, 0), 1)
    m = w.material(pbrMetallicRoughness={"metallicFactor": 0, "baseColorTexture": {
        "index": w.texture(w.image(png(grid, 2))), "texCoord": 0,
        "extensions": {"KHR_texture_transform": {"offset": [0.5, 0], "scale": [0.5, 0.5],
                                                 "texCoord": 1}}}})
    mesh = w.mesh("transformed", [(sphere, m)])
    w.attribute(mesh, 0, "TEXCOORD_0", constant((0.25, 0.75), len(sphere[0])))
    w.attribute(mesh, 0, "TEXCOORD_1", constant((0.5, 0.5), len(sphere[0])))
    w.node("Transformed", mesh)
    w.doc["extensionsUsed"] = ["KHR_texture_transform"]
    w.write(path)
    return [linear(c) for c in grid[1][:3]]


def wrap(path):
    """Texcoord (1.25, 0.25) of a 2 x 2 texture: clamped, texel (1, 0);
    repeated, texel (0, 0); mirrored, (0.75, 0.25): texel (1, 0) too, so
    the third sphere reads (-0.25, 1.25): mirrored (0.25, 0.75), texel
    (0, 1). Returns the three colours."""
    w = Writer()
    grid = [[255, 0, 0, 255], [0, 255, 0, 255], [0, 0, 255, 255], [255, 255, 0, 255]]
    image = w.image(png(grid, 2))
    for i, (mode, uv) in enumerate([(CLAMP, (1.25, 0.25)), (REPEAT, (1.25, 0.25)),
                                    (33648, (-0.25, 1.25))]):
        sphere = mf.uv_sphere((3 * i, 0, 0), 1)
        m = w.material(pbrMetallicRoughness={"metallicFactor": 0, "baseColorTexture": {
            "index": w.texture(image, (mode, mode))}})
        mesh = w.mesh(f"wrap{i}", [(sphere, m)])
        w.attribute(mesh, 0, "TEXCOORD_0", constant(uv, len(sphere[0])))
        w.node(f"Wrap{i}", mesh)
    w.write(path)
    return [[linear(c) for c in grid[t][:3]] for t in (1, 0, 2)]


def vertex_colors(path):
    """COLOR_0 of three spheres joined in one primitive of no material
    (ptr's grey 0.8), as float VEC3, and of two more primitives as
    normalised unsigned byte and short VEC4 under a material of base colour
    0.5. Returns the five colours."""
    w = Writer()
    spheres = [mf.uv_sphere((3 * i, 0, 0), 1) for i in range(5)]
    colours = [[1.0, 0.5, 0.25], [0.2, 0.4, 0.6], [0.0, 1.0, 0.0]]
    half = w.material(pbrMetallicRoughness={"baseColorFactor": [0.5, 0.5, 0.5, 1],
                                            "metallicFactor": 0})
    shape = mf.combine(*spheres[:3])
    mesh = w.mesh("colours", [(shape, None), (spheres[3], half), (spheres[4], half)])
    del w.doc["meshes"][mesh]["primitives"][0]["material"]
    n = len(spheres[0][0])
    w.attribute(mesh, 0, "COLOR_0", [c for c in colours for _ in range(n)])
    w.attribute(mesh, 1, "COLOR_0", constant((255, 51, 102, 255), n), mf.UBYTE, True)
    w.attribute(mesh, 2, "COLOR_0", constant((65535, 0, 32768, 65535), n), mf.USHORT, True)
    w.node("Colours", mesh)
    w.write(path)
    return ([[0.8 * x for x in c] for c in colours] +
            [[0.5, 0.5 * 51 / 255, 0.5 * 102 / 255], [0.5, 0.0, 0.5 * 32768 / 65535]])


def emissive(path):
    """An emissive texture times emissiveFactor (0.5, 1, 1) and strength 4,
    the texel (255, 128, 0) in sRGB. Returns the emission."""
    w = Writer()
    sphere = mf.uv_sphere((0, 0, 0), 1)
    m = w.material(pbrMetallicRoughness={"metallicFactor": 0},
                   emissiveFactor=[0.5, 1, 1],
                   emissiveTexture={"index": w.texture(w.image(png([[255, 128, 0, 255]], 1)))},
                   extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 4}})
    mesh = w.mesh("lamp", [(sphere, m)])
    w.attribute(mesh, 0, "TEXCOORD_0", constant((0.5, 0.5), len(sphere[0])))
    w.node("Lamp", mesh)
    w.doc["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    w.write(path)
    return [4 * 0.5 * linear(255), 4 * linear(128), 0.0]


def deep(path):
    """A 16-bit base colour and metallic-roughness texture, whose values are
    no byte's: the colour (30000, 1000, 65535) / 65535 in sRGB, metallic 1
    and roughness 20000 / 65535. Returns the colour and the fuzz."""
    w = Writer()
    sphere = mf.uv_sphere((0, 0, 0), 1)
    m = w.material(pbrMetallicRoughness={
        "baseColorTexture": {"index": w.texture(w.image(png([[30000, 1000, 65535, 65535]], 1,
                                                             16)))},
        "metallicRoughnessTexture": {"index": w.texture(w.image(png([[0, 20000, 65535, 65535]],
                                                                    1, 16)))}})
    mesh = w.mesh("deep", [(sphere, m)])
    w.attribute(mesh, 0, "TEXCOORD_0", constant((0.5, 0.5), len(sphere[0])))
    w.node("Deep", mesh)
    w.write(path)
    return [linear(c, 65535) for c in (30000, 1000, 65535)], 20000 / 65535


def varying(path):
    """Two spheres whose texcoords cross a 2 x 1 texture (the upper half of
    their vertices on texel 0, the rest on texel 1), and one constant.
    Returns the colours (the mean of the texels under the vertices) and the
    count of varying spheres."""
    w = Writer()
    texels = [[255, 0, 0, 255], [0, 0, 255, 255]]
    spheres = [mf.uv_sphere((3 * i, 0, 0), 1) for i in range(3)]
    m = w.material(pbrMetallicRoughness={"metallicFactor": 0, "baseColorTexture": {
        "index": w.texture(w.image(png(texels, 2)))}})
    mesh = w.mesh("varying", [(mf.combine(*spheres), m)])
    uv, want = [], []
    for i, (verts, _) in enumerate(spheres):
        sides = [0 if i == 2 or v[1] >= 0 else 1 for v in verts]
        uv += [((s + 0.5) / 2, 0.5) for s in sides]
        want.append([sum(linear(texels[s][k]) for s in sides) / len(sides) for k in range(3)])
    w.attribute(mesh, 0, "TEXCOORD_0", uv)
    w.node("Varying", mesh)
    w.write(path)
    return want, 2


def ktx2(path, required):
    """A texture in KHR_texture_basisu alone (gltfpack -tc), the extension
    required or only used."""
    w = Writer()
    sphere = mf.uv_sphere((0, 0, 0), 1)
    image = w.image(b"\xabKTX 20\xbb\r\n\x1a\n" + b"\0" * 64, "image/ktx2")
    w.doc["textures"] = [{"extensions": {"KHR_texture_basisu": {"source": image}}}]
    m = w.material(pbrMetallicRoughness={"baseColorTexture": {"index": 0}})
    mesh = w.mesh("basis", [(sphere, m)])
    w.attribute(mesh, 0, "TEXCOORD_0", constant((0.5, 0.5), len(sphere[0])))
    w.node("Basis", mesh)
    w.doc["extensionsUsed"] = ["KHR_texture_basisu"]
    if required:
        w.doc["extensionsRequired"] = ["KHR_texture_basisu"]
    w.write(path)


def uri_images(folder):
    """A .gltf whose two spheres read a PNG file beside it and one in a
    data: URI. Returns the path and the two colours."""
    w = Writer()
    red, blue = [[250, 10, 10, 255]], [[10, 10, 250, 255]]
    with open(os.path.join(folder, "red.png"), "wb") as f:
        f.write(png(red, 1))
    w.doc["images"] = [{"uri": "red.png"},
                       {"uri": "data:image/png;base64," + base64.b64encode(png(blue, 1)).decode()}]
    w.doc["textures"] = [{"source": 0}, {"source": 1}]
    for i in range(2):
        sphere = mf.uv_sphere((3 * i, 0, 0), 1)
        m = w.material(pbrMetallicRoughness={"metallicFactor": 0,
                                             "baseColorTexture": {"index": i}})
        mesh = w.mesh(f"uri{i}", [(sphere, m)])
        w.attribute(mesh, 0, "TEXCOORD_0", constant((0.5, 0.5), len(sphere[0])))
        w.node(f"Uri{i}", mesh)
    w.doc["buffers"] = [{"byteLength": len(w.blob),
                         "uri": "data:application/octet-stream;base64," +
                                base64.b64encode(bytes(w.blob)).decode()}]
    path = os.path.join(folder, "uri_images.gltf")
    with open(path, "w") as f:
        json.dump(w.doc, f)
    return path, [[linear(c) for c in t[0][:3]] for t in (red, blue)]


def one_textured_sphere(path, change):
    """A sphere of a 1 x 1 base colour texture, with change(writer, mesh)
    applied before it is written."""
    w = Writer()
    sphere = mf.uv_sphere((0, 0, 0), 1)
    m = w.material(pbrMetallicRoughness={"baseColorTexture": {
        "index": w.texture(w.image(png([[128, 128, 128, 255]], 1)))}})
    mesh = w.mesh("textured", [(sphere, m)])
    w.attribute(mesh, 0, "TEXCOORD_0", constant((0.5, 0.5), len(sphere[0])))
    w.node("Textured", mesh)
    change(w, mesh)
    w.write(path)


def write_hostile(folder):
    def broken_png(w, mesh):
        view = w.doc["bufferViews"][w.doc["images"][0]["bufferView"]]
        start = view["byteOffset"] + 16
        w.blob[start:start + 16] = b"\xff" * 16  # the header's size and the IDAT garbled

    def texture_out_of_range(w, mesh):
        w.doc["materials"][-1]["pbrMetallicRoughness"]["baseColorTexture"]["index"] = 7

    def texcoord_nan(w, mesh):
        uv = w.doc["meshes"][mesh]["primitives"][0]["attributes"]["TEXCOORD_0"]
        view = w.doc["bufferViews"][w.doc["accessors"][uv]["bufferView"]]
        w.blob[view["byteOffset"]:view["byteOffset"] + 4] = struct.pack("<f", math.nan)

    for name, change in [("texture_png_broken.glb", broken_png),
                         ("texture_index_out_of_range.glb", texture_out_of_range),
                         ("texture_texcoord_nan.glb", texcoord_nan)]:
        one_textured_sphere(os.path.join(folder, name), change)


if __name__ == "__main__":
    write_hostile(sys.argv[1])
