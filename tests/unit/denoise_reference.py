"""A second implementation of the denoiser, in NumPy and float64, for the tests:
its own reader of tensor archives (.tza), its own U-Net and its own pre- and
post-processing for HDR colour with albedo and normal, written from Open Image
Denoise's description (docs/denoise.md), sharing no code with ptr's.

    denoise_reference.py list FILE.tza
    denoise_reference.py run FILE.tza WIDTH HEIGHT COLOR ALBEDO NORMAL OUT

COLOR, ALBEDO and NORMAL are raw little-endian float32 RGB, row by row; OUT
is written the same way (float64 rounded to float32)."""
import struct
import sys

import numpy as np


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
    def conv(name, x, relu=True):
        y = conv3x3(x, tensors[name + ".weight"][1], tensors[name + ".bias"][1])
        return np.maximum(y, 0.0) if relu else y

    inp = x
    x = conv("enc_conv0", x)
    pool1 = x = pool(conv("enc_conv1", x))
    pool2 = x = pool(conv("enc_conv2", x))
    pool3 = x = pool(conv("enc_conv3", x))
    x = pool(conv("enc_conv4", x))
    x = conv("enc_conv5b", conv("enc_conv5a", x))
    x = conv("dec_conv4b", conv("dec_conv4a", np.concatenate([upsample(x), pool3])))
    x = conv("dec_conv3b", conv("dec_conv3a", np.concatenate([upsample(x), pool2])))
    x = conv("dec_conv2b", conv("dec_conv2a", np.concatenate([upsample(x), pool1])))
    x = conv("dec_conv1b", conv("dec_conv1a", np.concatenate([upsample(x), inp])))
    return conv("dec_conv0", x, relu=False)


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


def denoise(tensors, color, albedo, normal):
    """color, albedo, normal: H x W x 3. The denoised colour, H x W x 3."""
    h, w, _ = color.shape
    scale = autoexposure(np.maximum(np.nan_to_num(color, nan=0.0), 0.0))
    colour_in = pu_forward(np.maximum(np.nan_to_num(color, nan=0.0) * scale, 0.0)) * PU_NORM
    albedo_in = np.clip(albedo, 0.0, 1.0)
    normal_in = np.clip(normal, -1.0, 1.0) * 0.5 + 0.5
    # The image padded with zeros at the right and the bottom to a multiple
    # of 16, so that every pooling halves exactly.
    ph, pw = -(-h // 16) * 16, -(-w // 16) * 16
    x = np.zeros((9, ph, pw))
    x[:, :h, :w] = np.concatenate([colour_in, albedo_in, normal_in], axis=2).transpose(2, 0, 1)
    y = unet(tensors, x)[:3, :h, :w].transpose(1, 2, 0)
    return pu_inverse(np.maximum(y, 0.0) / PU_NORM) / scale


def main():
    if sys.argv[1] == "list":
        for name, (layout, t) in read_tza(sys.argv[2]).items():
            print(name, layout, "x".join(map(str, t.shape)))
        return
    _, _, path, width, height, color, albedo, normal, out = sys.argv
    shape = (int(height), int(width), 3)
    load = lambda p: np.fromfile(p, dtype="<f4").astype(np.float64).reshape(shape)
    result = denoise(read_tza(path), load(color), load(albedo), load(normal))
    result.astype("<f4").tofile(out)


if __name__ == "__main__":
    main()
