"""A second implementation of the denoiser, in NumPy and float64, for the tests:
its own reader of tensor archives (.tza), its own U-Net and its own pre- and
post-processing for HDR colour with albedo and normal, written from Open Image
Denoise's description (docs/denoise.md), sharing no code with ptr's.

    denoise_reference.py list FILE.tza
    denoise_reference.py run FILE.tza WIDTH HEIGHT COLOR ALBEDO NORMAL OUT
                             [ALBEDO_FILTER.tza NORMAL_FILTER.tza]

COLOR, ALBEDO and NORMAL are raw little-endian float32 RGB, row by row; OUT
is written the same way (float64 rounded to float32)."""
import os
import struct
import sys

SYSTEM_PYTHON = "/usr/bin/python3"
try:
    import numpy as np
except ImportError:
    # scripts/install-deps.sh installs Debian's python3-numpy, which only
    # Debian's own python3 imports, not one that comes first in PATH (pyenv):
    # the script run (this one or a check importing it) starts again there.
    if os.path.exists(SYSTEM_PYTHON) and not os.path.samefile(sys.executable, SYSTEM_PYTHON):
        os.execv(SYSTEM_PYTHON, [SYSTEM_PYTHON] + sys.argv)
    print("skipped: NumPy is not installed (scripts/install-deps.sh installs python3-numpy)")
    sys.exit(77)


def read_tza(path):
    """The archive's tensors by name, as float64 arrays of their shapes."""
    data = open(path, "rb").read()
    magic, major, _minor, table = struct.unpack_from("<HBBQ", data, 0)
    if magic != 0x41D7 or major != 2:
        raise ValueError(f"{path}: not a version 2 tensor archive")
    (count,) = struct.unpack_from("<I", data, table)
    at = table + 4
    tensors = {}
    for _ in range(count):
        (length,) = struct.unpack_from("<H", data, at)
        name = data[at + 2:at + 2 + length].decode()
        at += 2 + length
        ndims = data[at]
        shape = struct.unpack_from(f"<{ndims}I", data, at + 1)
        at += 1 + 4 * ndims
        layout = data[at:at + ndims].decode()
        at += ndims
        kind = chr(data[at])
        (offset,) = struct.unpack_from("<Q", data, at + 1)
        at += 9
        dtype = {"f": "<f4", "h": "<f2"}[kind]
        values = np.frombuffer(data, dtype=dtype, count=int(np.prod(shape)), offset=offset)
        tensors[name] = (layout, values.astype(np.float64).reshape(shape))
    return tensors


def conv3x3(x, w, b):
    """x: C x H x W; w: O x C x 3 x 3 (OIHW); zero padding of one pixel."""
    c, h, wd = x.shape
    padded = np.zeros((c, h + 2, wd + 2))
    padded[:, 1:-1, 1:-1] = x
    out = np.tensordot(w[:, :, 0, 0], padded[:, 0:h, 0:wd], axes=1)
    for ky in range(3):
        for kx in range(3):
            if ky or kx:
                out += np.tensordot(w[:, :, ky, kx], padded[:, ky:ky + h, kx:kx + wd], axes=1)
    return out + b[:, None, None]


def pool(x):
    c, h, w = x.shape
    return x.reshape(c, h // 2, 2, w // 2, 2).max(axis=(2, 4))


def upsample(x):
    return x.repeat(2, axis=1).repeat(2, axis=2)


def unet(tensors, x):
    """OIDN's UNet (enc_conv0 ..) or UNetLarge (enc_conv1a ..), told apart
    by the names of the tensors."""
    large = "enc_conv1b.weight" in tensors
    encoder = ([["enc_conv1a", "enc_conv1b"], ["enc_conv2a", "enc_conv2b"],
                ["enc_conv3a", "enc_conv3b"], ["enc_conv4a", "enc_conv4b"]] if large else
               [["enc_conv0", "enc_conv1"], ["enc_conv2"], ["enc_conv3"], ["enc_conv4"]])
    decoder = [["dec_conv4a", "dec_conv4b"], ["dec_conv3a", "dec_conv3b"],
               ["dec_conv2a", "dec_conv2b"],
               ["dec_conv1a", "dec_conv1b", "dec_conv1c" if large else "dec_conv0"]]
    last = decoder[-1][-1]

    def conv(name, x):
        y = conv3x3(x, tensors[name + ".weight"][1], tensors[name + ".bias"][1])
        return y if name == last else np.maximum(y, 0.0)

    skips = [x]
    for names in encoder:
        for name in names:
            x = conv(name, x)
        x = pool(x)
        skips.append(x)
    x = conv("enc_conv5b", conv("enc_conv5a", x))
    for names, skip in zip(decoder, reversed(skips[:-1])):
        x = np.concatenate([upsample(x), skip])
        for name in names:
            x = conv(name, x)
    return x


# The PU curve (Aydin et al. 2008) as OIDN fits it, normalised at 65504.
PU = dict(a=1.41283765e+03, b=1.64593172e+00, c=4.31384981e-01, d=-2.94139609e-03,
          e=1.92653254e-01, f=6.26026094e-03, g=9.98620152e-01, y0=1.57945760e-06,
          y1=3.22087631e-02, x0=2.23151711e-03, x1=3.70974749e-01)


def pu_forward(y):
    p = PU
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(y <= p["y0"], p["a"] * y,
                        np.where(y <= p["y1"], p["b"] * np.power(y, p["c"]) + p["d"],
                                 p["e"] * np.log(y + p["f"]) + p["g"]))


def pu_inverse(x):
    p = PU
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        return np.where(x <= p["x0"], x / p["a"],
                        np.where(x <= p["x1"], np.power((x - p["d"]) / p["b"], 1 / p["c"]),
                                 np.exp((x - p["g"]) / p["e"]) - p["f"]))


PU_NORM = 1 / pu_forward(np.float64(65504.0))


def autoexposure(color):
    """0.18 over the geometric mean of the luminance of bins of at most 16x16."""
    lum = color @ np.array([0.212671, 0.715160, 0.072169])
    h, w = lum.shape
    bh, bw = -(-h // 16), -(-w // 16)
    logs = []
    for i in range(bh):
        for j in range(bw):
            mean = lum[i * h // bh:(i + 1) * h // bh, j * w // bw:(j + 1) * w // bw].mean()
            if mean > 1e-8:
                logs.append(np.log2(mean))
    return 0.18 / np.exp2(np.mean(logs)) if logs else 1.0


def srgb_forward(y):
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * np.power(y, 1 / 2.4) - 0.055)


def srgb_inverse(x):
    return np.where(x <= 0.04045, x / 12.92, np.power((x + 0.055) / 1.055, 2.4))


def padded(planes):
    """The planes (H x W x C) padded with zeros at the right and the bottom to
    a multiple of 16, so that every pooling halves exactly."""
    h, w, c = planes.shape
    x = np.zeros((-(-h // 16) * 16, -(-w // 16) * 16, c))
    x[:h, :w] = planes
    return x


def run(tensors, planes):
    """The network on the planes (H x W x C): its 3 output channels,
    H x W x 3, negatives as 0."""
    h, w, _ = planes.shape
    out = unet(tensors, padded(planes).transpose(2, 0, 1))
    return np.maximum(out[:3, :h, :w].transpose(1, 2, 0), 0.0)


def denoise(tensors, color, albedo, normal, guide_filters=None):
    """color, albedo, normal: H x W x 3. The denoised colour, H x W x 3.
    guide_filters: the albedo's and the normal's networks, which filter them
    first (OIDN's way to its best quality), or None."""
    if guide_filters:
        albedo_net, normal_net = guide_filters
        albedo = np.minimum(srgb_inverse(run(albedo_net, srgb_forward(np.clip(albedo, 0, 1)))),
                            1.0)
        normal = np.clip(run(normal_net, np.clip(normal, -1, 1) * 0.5 + 0.5) * 2 - 1, -1, 1)
    planes, scale = color_planes(color, albedo, normal)
    return color_output(run(tensors, planes), scale)


def color_planes(color, albedo, normal):
    """The colour network's input, H x W x 9, and the exposure that scaled
    the colour."""
    scale = autoexposure(np.maximum(np.nan_to_num(color, nan=0.0), 0.0))
    colour_in = pu_forward(np.maximum(np.nan_to_num(color, nan=0.0) * scale, 0.0)) * PU_NORM
    planes = np.concatenate([colour_in, np.clip(albedo, 0.0, 1.0),
                             np.clip(normal, -1.0, 1.0) * 0.5 + 0.5], axis=2)
    return planes, scale


def color_output(out, scale):
    """The colour network's output (H x W x 3, negatives as 0) back to linear
    HDR colour."""
    return pu_inverse(out / PU_NORM) / scale


def test_images(width, height, seed):
    """Noisy HDR colour with a few very bright pixels, albedo in [0, 1],
    unit normals (and one pixel that hit nothing), as float32."""
    rng = np.random.default_rng(seed)
    color = rng.gamma(0.8, 0.6, (height, width, 3))
    for _ in range(3):
        color[rng.integers(height), rng.integers(width)] = rng.uniform(1e2, 3e4, 3)
    albedo = rng.uniform(0.0, 1.0, (height, width, 3))
    normal = rng.normal(size=(height, width, 3))
    normal /= np.linalg.norm(normal, axis=2, keepdims=True)
    normal[0, 0] = 0.0
    return [a.astype("<f4") for a in (color, albedo, normal)]


def main():
    if sys.argv[1] == "list":
        for name, (layout, t) in read_tza(sys.argv[2]).items():
            print(name, layout, "x".join(map(str, t.shape)))
        return
    path, width, height, color, albedo, normal, out = sys.argv[2:9]
    shape = (int(height), int(width), 3)
    load = lambda p: np.fromfile(p, dtype="<f4").astype(np.float64).reshape(shape)
    filters = [read_tza(p) for p in sys.argv[9:11]] or None
    result = denoise(read_tza(path), load(color), load(albedo), load(normal), filters)
    result.astype("<f4").tofile(out)


if __name__ == "__main__":
    main()
