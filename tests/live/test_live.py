#!/usr/bin/env python3
"""--live: the server's routes, the address rules (loopback by default, a
warning for any other, a port in use is one line and exit 2), images
byte-identical with and without a page open, the denoised preview (its
toggle, its frames, the image written unchanged by it), the page following a
batch and --watch, a slow request cut off, and a flood of malformed and slow
requests during a render that neither crashes ptr nor stalls it.

Usage: test_live.py PTR SOURCE_DIR [SANITIZED]"""
import os
import random
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "support"))
from live_client import (Ptr, Page, get, read_ppm, same_image_bytes, samples,  # noqa: E402
                         vector_convolution, wait_for)

ptr, src = sys.argv[1], sys.argv[2]
scene = os.path.join(src, "scenes", "seed.gltf")
failures = []


def check(ok, message):
    if not ok:
        failures.append(message)
        print("FAIL: " + message, file=sys.stderr)
    return ok


def render(out, extra=(), n=300, size=160):
    return [ptr, scene, "-o", out, "--width", str(size), "--height", str(size), "--samples",
            str(samples(n)), "--threads", "2", *extra]


def plain(out, **kw):
    p = Ptr(render(out, **kw))
    code = p.wait()
    check(code == 0, "%s without --live: exit %d: %s" % (out, code, p.stderr))


def routes(url):
    status, headers, body = get(url, "/")
    check(status == 200 and headers.get("Content-Type", "").startswith("text/html") and
          b"EventSource" in body, "GET /: %d %s" % (status, headers))
    for path in ["/nope", "/../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/frame.png/../x",
                 "//etc/passwd", "/index.html"]:
        status, _, body = get(url, path)
        check(status == 404 and b"root:" not in body, "GET %s: %d, not 404" % (path, status))
    for query in ["stops=abc", "stops=", "stops=1e9", "stops=nan", ""]:
        status, _, _ = get(url, "/exposure?" + query)
        check(status == 400, "GET /exposure?%s: %d, not 400" % (query, status))
    u = url.split("/")[2].split(":")
    c = socket.create_connection((u[0], int(u[1])), timeout=10)
    c.sendall(b"POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\nhello")
    reply = c.recv(100)
    c.close()
    check(reply.startswith(b"HTTP/1.1 405"), "POST /: %r" % reply[:40])


def identical_with_page(d):
    """The image written is the same bytes with a page open as without."""
    for ext in ["exr", "png"]:
        a, b = os.path.join(d, "plain." + ext), os.path.join(d, "live." + ext)
        plain(a)
        p = Ptr(render(b, ["--live", "0"]))
        url = p.url()
        if not check(url and url.startswith("http://127.0.0.1:"),
                     "--live 0: no address on 127.0.0.1 printed: %s" % p.stderr):
            p.process.kill()
            continue
        page = Page(url)
        if ext == "png":
            routes(url)
        code = p.wait()
        page.close()
        check(code == 0, "--live render to .%s: exit %d: %s" % (ext, code, p.stderr))
        check(page.error is None, "page: %s" % page.error)
        check(len(page.frames) >= 2, "the page saw %d frames, not 2 or more" % len(page.frames))
        check(len(page.states) and page.states[-1]["state"] == "done" and
              page.states[-1]["samples"] == samples(300),
              "the page's last state: %s" % (page.states[-1:] or None))
        check(same_image_bytes(a, b), "%s and %s differ" % (a, b))
        if ext == "png" and page.frames:
            # The last frame the page showed is the output's view: the PNG ptr wrote.
            last = os.path.join(d, "last_frame.png")
            with open(last, "wb") as f:
                f.write(page.frames[-1][1])
            check(os.system("idiff -q -fail 0.0040 -failpercent 0 %s %s >/dev/null" %
                            (last, b)) == 0, "the page's last frame is not the written PNG")


def roughness(d, png):
    """The mean difference between horizontal neighbours over a frame's
    channels, from 0 to 255: what noise raises and denoising lowers."""
    path = os.path.join(d, "roughness.png")
    with open(path, "wb") as f:
        f.write(png)
    subprocess.run(["oiiotool", path, "-o", path + ".ppm"], check=True)
    w, h, rgb = read_ppm(path + ".ppm")
    steps = [abs(rgb[i] - rgb[i + 3])
             for y in range(h) for i in range(3 * w * y, 3 * w * (y + 1) - 3)]
    return sum(steps) / len(steps)


def denoised_preview(d):
    """With the page's toggle on, the frames become the denoised image of a
    pass (the header X-Ptr-Denoised and the state say so, and they are
    smoother than the noisy frames); off, noisy again. The image written is
    the same bytes with the preview on. /denoise takes on=1 or on=0, nothing
    else. With --watch, ptr serves after the render, so the last pass's
    denoised image arrives with nothing left to wait for."""
    a, b = os.path.join(d, "plain_preview.exr"), os.path.join(d, "preview.exr")
    if not vector_convolution(ptr):
        p = Ptr(render(b, ["--live", "0"], n=4))
        code = p.wait()
        check(code == 0 and "no denoised preview: no vector convolution" in p.stderr,
              "--live below AVX2: exit %d, no line saying there is no preview: %s"
              % (code, p.stderr))
        return
    # Few samples, for a frame that is clearly noisy, on more pixels, for a
    # render that lasts beyond its first pass.
    plain(a, n=48, size=320)
    p = Ptr(render(b, ["--live", "0", "--watch"], n=48, size=320))
    url = p.url()
    if not check(url, "--live --watch: no address: %s" % p.stderr):
        p.process.kill()
        return
    for query in ["on=2", "on=", "", "on=true", "on=1x", "on=%00", "off=1", "on=" + "1" * 3000]:
        status = get(url, "/denoise?" + query)[0]
        check(status in (400, 414), "GET /denoise?%s: %d, not 400" % (query[:20], status))
    check(get(url, "/denoise?on=1")[0] == 204, "GET /denoise?on=1: not 204")
    page = Page(url)
    denoised = lambda: [f for f in page.frames if f[2]]  # noqa: E731
    check(wait_for(lambda: denoised() and any(s["state"] == "done" for s in page.states), 120),
          "no denoised frame within 120 s: %d frames, stderr %s" % (len(page.frames), p.stderr))
    check(same_image_bytes(a, b), "the image written with the preview on differs")
    check(any(s["preview"] and s["denoised"] for s in page.states),
          "no state said the frame shown is denoised")
    check(get(url, "/denoise?on=0")[0] == 204, "GET /denoise?on=0: not 204")
    # Off, the page gets the last pass as rendered: the same samples as the
    # last denoised frame.
    if check(wait_for(lambda: page.frames and not page.frames[-1][2], 30),
             "the preview off: the last frame shown is still denoised") and denoised():
        smooth, rough = roughness(d, denoised()[-1][1]), roughness(d, page.frames[-1][1])
        check(smooth < 0.85 * rough, "the denoised frame is not smoother: %.2f against the "
              "noisy frame's %.2f" % (smooth, rough))
        print("preview: %d denoised frames of %d; roughness %.2f denoised, %.2f as rendered"
              % (len(denoised()), len(page.frames), smooth, rough))
    p.process.send_signal(2)
    code = p.wait(30)
    page.close()
    check(code == 0 and "warning" not in p.stderr, "--watch stopped by SIGINT: exit %d: %s"
          % (code, p.stderr))


def addresses(d):
    out = os.path.join(d, "a.exr")
    # A port in use: one line, exit 2, and no render.
    taken = socket.socket()
    taken.bind(("127.0.0.1", 0))
    taken.listen(1)
    port = taken.getsockname()[1]
    p = Ptr(render(out, ["--live", str(port)]))
    code = p.wait()
    taken.close()
    check(code == 2 and len(p.stderr_lines) == 1 and "in use" in p.stderr and
          not os.path.exists(out), "port in use: exit %d, stderr %r" % (code, p.stderr))
    for bad in ["abc", "70000", "host:", ":80", "-1", "1.2.3.4:x"]:
        p = Ptr(render(out, ["--live", bad]))
        code = p.wait()
        check(code == 2 and len(p.stderr_lines) == 1,
              "--live %s: exit %d, stderr %r" % (bad, code, p.stderr))
    p = Ptr(render(out, ["--live", "no-such-host.invalid:0"]))
    check(p.wait() == 2, "--live on an unknown host: not exit 2: %s" % p.stderr)
    # Another address than the loopback: served, with a warning.
    p = Ptr(render(out, ["--live", "0.0.0.0:0"], n=4))
    code = p.wait()
    check(code == 0 and "warning" in p.stderr and "loopback" in p.stderr,
          "--live 0.0.0.0:0: exit %d, stderr %r" % (code, p.stderr))
    p = Ptr(render(out, ["--live", "[::1]:0"], n=4))
    code = p.wait()
    check(code == 0 and "http://[::1]:" in p.stderr and "warning" not in p.stderr,
          "--live [::1]:0: exit %d, stderr %r" % (code, p.stderr))


class Flood:
    """Malformed, oversized and slow requests on many threads until stopped."""

    def __init__(self, host, port):
        self.host, self.port = host, port
        self.stop = False
        self.sent = 0
        self.threads = [threading.Thread(target=f, daemon=True) for f in
                        [self.garbage] * 4 + [self.huge] * 2 + [self.slowloris] * 3 +
                        [self.streams] * 2 + [self.bodies]]
        for t in self.threads:
            t.start()

    def connect(self):
        return socket.create_connection((self.host, self.port), timeout=5)

    def attempt(self, f):
        try:
            s = self.connect()
            try:
                f(s)
            finally:
                s.close()
            self.sent += 1
        except OSError:
            time.sleep(0.01)

    def garbage(self):
        rng = random.Random(1)
        samples = [b"\x00\xff" * 100, b"GET\r\n\r\n", b"GET / HTTP/9.9\r\n\r\n",
                   b"GET " + b"/" * 20000 + b" HTTP/1.1\r\n\r\n", b"\r\n" * 1000,
                   b"GET / HTTP/1.1\r\nHost: x\r\nContent-Length: -5\r\n\r\n",
                   b"GET / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\nzz\r\n",
                   b"GET /events HTTP/1.1\r\nHost: x\r\nRange: bytes=99999-\r\n\r\n",
                   b"GET /frame.png?id=\xff\xfe HTTP/1.1\r\n\r\n",
                   b"GET /denoise?on=1 HTTP/1.1\r\n\r\n", b"GET /denoise?on=\x01 HTTP/1.1\r\n\r\n",
                   b"GET /denoise?on=0&on=1&" + b"x=y&" * 3000 + b" HTTP/1.1\r\n\r\n"]
        while not self.stop:
            data = rng.choice(samples) if rng.random() < 0.7 else rng.randbytes(rng.randrange(1, 3000))
            self.attempt(lambda s: (s.sendall(data), s.recv(1024)))

    def huge(self):
        header = b"GET / HTTP/1.1\r\nHost: x\r\n" + b"X-Big: " + b"a" * 200000 + b"\r\n\r\n"
        while not self.stop:
            self.attempt(lambda s: (s.sendall(header), s.recv(1024)))

    def slowloris(self):
        held = []
        while not self.stop:
            try:
                if len(held) < 20:
                    s = self.connect()
                    s.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n")
                    held.append(s)
                for s in list(held):
                    try:
                        s.sendall(b"X-a: b\r\n")
                    except OSError:
                        held.remove(s)
                        s.close()
            except OSError:
                pass
            time.sleep(0.2)
        for s in held:
            s.close()

    def streams(self):
        """Event streams opened and dropped, and never read."""
        while not self.stop:
            self.attempt(lambda s: (s.sendall(b"GET /events HTTP/1.1\r\nHost: x\r\n\r\n"),
                                    time.sleep(0.3)))

    def bodies(self):
        while not self.stop:
            self.attempt(lambda s: s.sendall(b"PUT /frame.png HTTP/1.1\r\nHost: x\r\n"
                                             b"Content-Length: 100000000\r\n\r\n" + b"x" * 60000))

    def close(self):
        self.stop = True
        for t in self.threads:
            t.join(15)


def flood(d):
    a, b = os.path.join(d, "plain_flood.exr"), os.path.join(d, "flood.exr")
    start = time.time()
    plain(a, n=3000)
    alone = time.time() - start
    start = time.time()
    p = Ptr(render(b, ["--live", "0"], n=3000))
    url = p.url()
    if not check(url, "no address: %s" % p.stderr):
        p.process.kill()
        return
    host, port = url.split("/")[2].rsplit(":", 1)
    page = Page(url)
    f = Flood(host, int(port))
    time.sleep(min(3, alone * 0.6))
    f.close()
    # Once the flood stops, the server answers again before the render ends.
    def answers():
        try:
            return get(url, "/")[0] == 200
        except OSError:
            return p.process.poll() is not None  # ended meanwhile: nothing to ask

    answered = wait_for(answers, 15, 0.2)
    try:
        code = p.wait(timeout=max(60, 10 * alone))
    except Exception:  # noqa: BLE001 - a stalled render is the failure reported
        p.process.kill()
        code = "stalled"
    took = time.time() - start
    page.close()
    check(code == 0, "render under a flood: exit %s: %s" % (code, p.stderr[-2000:]))
    check(answered, "the server did not answer after the flood")
    check(same_image_bytes(a, b), "the image rendered under a flood differs")
    print("flood: %d requests during the render; render %.1f s alone, %.1f s under the flood"
          % (f.sent, alone, took))


def follows(d):
    """In a batch the page follows the scene being rendered; with --watch,
    each re-render after a save."""
    folder = os.path.join(d, "batch")
    os.mkdir(folder)
    second = os.path.join(d, "second.gltf")
    shutil.copy(scene, second)
    # The first render lasts a second or more: the page connects during it.
    p = Ptr([ptr, scene, second, "-o", folder + "/", "--width", "128", "--height", "128",
             "--samples", str(samples(1500)), "--threads", "2", "--live", "0"])
    page = Page(p.url())
    code = p.wait()
    page.close()
    # The page is sent the latest state, a few times a second: the first
    # scene's last state may give way to the second's before it is sent, so
    # the page must have followed the first scene, and seen the second done.
    seen = {s["render"]: s["scene"] for s in page.states}
    last = page.states[-1] if page.states else {}
    check(code == 0 and seen == {1: scene, 2: second} and last.get("state") == "done" and
          last.get("render") == 2,
          "a batch: exit %d, the page saw %s, the last state %s" % (code, seen, last))

    p = Ptr([ptr, second, "-o", os.path.join(d, "watched.exr"), "--width", "32", "--height",
             "32", "--samples", "4", "--threads", "2", "--live", "0", "--watch"])
    page = Page(p.url())
    wait_for(lambda: any(s["state"] == "done" for s in page.states), 30)
    with open(second, "a") as f:
        f.write("\n")  # saved again
    renders = lambda: {s["render"] for s in page.states if s["state"] == "done"}  # noqa: E731
    wait_for(lambda: renders() == {1, 2}, 30)
    p.process.send_signal(2)
    code = p.wait(30)
    page.close()
    check(code == 0 and renders() == {1, 2},
          "--watch: exit %d, the page saw renders %s done, not 1 and 2" % (code, renders()))


def request_deadline(d):
    """A client that sends a header line a second is never idle, yet its
    request is cut off 10 s after it connected; a page's event stream stays.
    With --watch, ptr serves after the render until Ctrl-C."""
    p = Ptr(render(os.path.join(d, "watch.exr"), ["--live", "0", "--watch"], n=4, size=16))
    url = p.url()
    if not check(url, "--watch --live: no address: %s" % p.stderr):
        p.process.kill()
        return
    host, port = url.split("/")[2].rsplit(":", 1)
    page = Page(url)
    slow = socket.create_connection((host, int(port)), timeout=5)
    slow.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n")
    start, cut = time.time(), None
    while time.time() - start < 20:
        try:
            slow.sendall(b"X-a: b\r\n")
            slow.settimeout(1)
            if slow.recv(100) == b"":
                cut = time.time() - start
                break
        except socket.timeout:
            continue
        except OSError:
            cut = time.time() - start
            break
    slow.close()
    check(cut is not None and 8 <= cut <= 13,
          "a request trickling a header a second was cut after %s s, not about 10" % cut)
    check(page.error is None and page.states, "the page's stream: %s, %d states"
          % (page.error, len(page.states)))
    p.process.send_signal(2)
    code = p.wait(30)
    page.close()
    check(code == 0, "--watch stopped by SIGINT: exit %d: %s" % (code, p.stderr))


def main():
    with tempfile.TemporaryDirectory() as d:
        identical_with_page(d)
        denoised_preview(d)
        addresses(d)
        follows(d)
        request_deadline(d)
        flood(d)
    if failures:
        return 1
    print("live: passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
