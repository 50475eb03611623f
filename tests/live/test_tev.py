#!/usr/bin/env python3
"""--tev: a stand-in for tev that parses every message exactly as tev's
protocol defines it ([uint32 length, itself included][uint8 type][payload],
little-endian, strings ending in a zero byte; CreateImage = 4: grabFocus,
name, width, height, channel count, channel names; UpdateImage = 3:
grabFocus, name, channel, x, y, width, height, width*height floats) and
rebuilds the image, which must be the EXR ptr writes, float for float.
The stand-in drops the first connection after a few messages, as a tev
that quits and restarts: ptr reconnects and sends the whole image again.
Without any tev listening, the render is the same and takes no longer.
With --denoise, tev gets the layer "denoised" beside the noisy RGB: at the
end, the RGB is the EXR's noisy layer and the layer its denoised colour
(--denoise fast: the preview's network; the same bits on any thread count).

Usage: test_tev.py PTR SOURCE_DIR [SANITIZED]"""
import os
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "support"))
from live_client import Ptr, same_image_bytes, samples, vector_convolution  # noqa: E402

ptr, src = sys.argv[1], sys.argv[2]
scene = os.path.join(src, "scenes", "seed.gltf")
failures = []
WIDTH, HEIGHT = 300, 170  # more than one 128-pixel tile each way, partial tiles at the edges


def check(ok, message):
    if not ok:
        failures.append(message)
        print("FAIL: " + message, file=sys.stderr)
    return ok


class ProtocolError(Exception):
    pass


class Reader:
    def __init__(self, data):
        self.data, self.at = data, 0

    def take(self, n):
        if self.at + n > len(self.data):
            raise ProtocolError("message too short")
        part = self.data[self.at:self.at + n]
        self.at += n
        return part

    def u8(self):
        return self.take(1)[0]

    def boolean(self):
        v = self.u8()
        if v not in (0, 1):
            raise ProtocolError("bool %d" % v)
        return v

    def i32(self):
        return struct.unpack("<i", self.take(4))[0]

    def string(self):
        end = self.data.find(b"\0", self.at)
        if end < 0:
            raise ProtocolError("string without its zero byte")
        s = self.data[self.at:end].decode()
        self.at = end + 1
        return s


class StandIn:
    """tev as far as ptr needs it: images by name, each a dict of channels
    of width*height floats."""

    def __init__(self, drop_first_after=None):
        self.listener = socket.socket()
        self.listener.bind(("127.0.0.1", 0))
        self.listener.listen(4)
        self.port = self.listener.getsockname()[1]
        self.images = {}
        self.connections = 0
        self.messages = {3: 0, 4: 0}
        self.errors = []
        self.drop_first_after = drop_first_after
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        while True:
            try:
                conn, _ = self.listener.accept()
            except OSError:
                return
            self.connections += 1
            try:
                self.receive(conn, self.drop_first_after if self.connections == 1 else None)
            except (ProtocolError, ValueError, UnicodeDecodeError) as e:
                self.errors.append(repr(e))
            conn.close()

    def receive(self, conn, drop_after):
        buffer, count = b"", 0
        while True:
            chunk = conn.recv(1 << 16)
            if not chunk:
                if buffer:
                    raise ProtocolError("connection closed inside a message")
                return
            buffer += chunk
            while len(buffer) >= 4:
                length = struct.unpack("<I", buffer[:4])[0]
                if length < 5:
                    raise ProtocolError("length %d" % length)
                if len(buffer) < length:
                    break
                self.message(buffer[4:length])
                buffer = buffer[length:]
                count += 1
                if drop_after is not None and count >= drop_after:
                    return  # tev quits

    def message(self, payload):
        r = Reader(payload)
        kind = r.u8()
        if kind == 4:
            r.boolean()
            name = r.string()
            width, height, n = r.i32(), r.i32(), r.i32()
            if width <= 0 or height <= 0 or n <= 0:
                raise ProtocolError("CreateImage %dx%d, %d channels" % (width, height, n))
            names = [r.string() for _ in range(n)]
            self.images[name] = {"size": (width, height),
                                 "channels": {c: [float("nan")] * (width * height) for c in names}}
        elif kind == 3:
            r.boolean()
            name, channel = r.string(), r.string()
            x, y, w, h = r.i32(), r.i32(), r.i32(), r.i32()
            image = self.images.get(name)
            if not image or channel not in image["channels"]:
                raise ProtocolError("UpdateImage of %s.%s before CreateImage" % (name, channel))
            width, height = image["size"]
            if w <= 0 or h <= 0 or x < 0 or y < 0 or x + w > width or y + h > height:
                raise ProtocolError("tile %d,%d %dx%d outside %dx%d" % (x, y, w, h, width, height))
            floats = struct.unpack("<%df" % (w * h), r.take(4 * w * h))
            pixels = image["channels"][channel]
            for row in range(h):
                pixels[(y + row) * width + x:(y + row) * width + x + w] = floats[row * w:(row + 1) * w]
        else:
            raise ProtocolError("message type %d" % kind)
        if r.at != len(payload):
            raise ProtocolError("%d bytes left over in a message of type %d" %
                                (len(payload) - r.at, kind))
        self.messages[kind] += 1

    def write_pfm(self, name, path, layer=""):
        image = self.images[name]
        width, height = image["size"]
        c = image["channels"]
        r, g, b = (c[layer + n] for n in "RGB")
        with open(path, "wb") as f:
            f.write(b"PF\n%d %d\n-1.0\n" % (width, height))
            for y in reversed(range(height)):  # PFM rows run bottom to top
                row = []
                for x in range(width):
                    i = y * width + x
                    row += [r[i], g[i], b[i]]
                f.write(struct.pack("<%df" % len(row), *row))

    def close(self):
        self.listener.close()


def render(out, extra):
    return [ptr, scene, "-o", out, "--width", str(WIDTH), "--height", str(HEIGHT),
            "--samples", str(samples(400)), "--threads", "2", *extra]


def same_pixels(a, b):
    """Whether two images hold the same floats (idiff, no tolerance)."""
    r = subprocess.run(["idiff", "-q", "-fail", "0", "-failpercent", "0", "-warn", "0", a, b],
                       capture_output=True, text=True)
    return r.returncode == 0, r.stdout


def denoised_layer(d):
    tev = StandIn()
    out = os.path.join(d, "denoised.exr")
    p = Ptr(render(out, ["--tev", "127.0.0.1:%d" % tev.port, "--denoise", "fast"]))
    code = p.wait()
    time.sleep(0.3)
    tev.close()
    check(code == 0 and not tev.errors, "--tev --denoise: exit %d, %s: %s"
          % (code, tev.errors, p.stderr))
    image = tev.images.get("denoised.exr", {"channels": {}})
    names = list(image["channels"])
    if not vector_convolution(ptr):
        # Below AVX2 the live view has no denoised preview, and says so.
        check(names == ["R", "G", "B"] and "no denoised preview" in p.stderr,
              "--tev --denoise below AVX2: channels %s, stderr %s" % (names, p.stderr))
        return
    if not check(names == ["R", "G", "B", "denoised.R", "denoised.G", "denoised.B"],
                 "--tev --denoise: channels %s" % names):
        return
    # tev's layer against the EXR's, each alone: idiff compares every channel.
    for tev_layer, exr_channels, what in [
            ("denoised.", "R,G,B", "tev's denoised layer is not the EXR's denoised colour"),
            ("", "R=noisy.R,G=noisy.G,B=noisy.B", "tev's RGB is not the EXR's noisy layer")]:
        got, written = os.path.join(d, "tev.pfm"), os.path.join(d, "layer.exr")
        subprocess.run(["oiiotool", out, "--ch", exr_channels, "-o", written], check=True)
        tev.write_pfm("denoised.exr", got, tev_layer)
        same, why = same_pixels(got, written)
        check(same, "%s: %s" % (what, why))


def main():
    with tempfile.TemporaryDirectory() as d:
        tev = StandIn(drop_first_after=5)
        out = os.path.join(d, "tev.exr")
        start = time.time()
        p = Ptr(render(out, ["--tev", "127.0.0.1:%d" % tev.port]))
        code = p.wait()
        took = time.time() - start
        time.sleep(0.3)
        tev.close()
        check(code == 0, "--tev render: exit %d: %s" % (code, p.stderr))
        check(not tev.errors, "tev's messages: %s" % tev.errors)
        check(tev.connections >= 2, "ptr connected %d times, not again after tev quit" %
              tev.connections)
        check(list(tev.images) == ["tev.exr"], "images: %s" % list(tev.images))
        check(tev.messages[3] > 3 * 6, "only %d UpdateImage messages" % tev.messages[3])
        if "tev.exr" in tev.images:
            rebuilt = os.path.join(d, "rebuilt.pfm")
            tev.write_pfm("tev.exr", rebuilt)
            same, why = same_pixels(rebuilt, out)
            check(same, "the image tev got is not the EXR: %s" % why)

        # No tev listening: the same image, no slower than the render above by much.
        closed = socket.socket()
        closed.bind(("127.0.0.1", 0))
        port = closed.getsockname()[1]
        closed.close()
        alone = os.path.join(d, "alone.exr")
        start = time.time()
        p = Ptr(render(alone, ["--tev", str(port)]))
        code = p.wait()
        took_alone = time.time() - start
        check(code == 0 and same_image_bytes(out, alone),
              "without tev: exit %d, image %s" % (code, "same" if code else "?"))
        print("tev: %d connections, %d CreateImage and %d UpdateImage messages; render %.1f s "
              "streaming, %.1f s with no tev" % (tev.connections, tev.messages[4],
                                                 tev.messages[3], took, took_alone))
        denoised_layer(d)
    if failures:
        return 1
    print("tev: passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
