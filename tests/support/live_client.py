"""What the live view's tests and bench/live.sh share: starting ptr with
--live and reading the address it prints, and a page as a script (the
event stream, and each new frame fetched as the page fetches it)."""
import http.client
import json
import re
import subprocess
import threading
import time
import urllib.parse


def samples(n):
    """n samples, or an eighth under the sanitizers (a third argument of 1,
    after PTR and SOURCE_DIR)."""
    import sys
    return max(8, n // 8) if len(sys.argv) > 3 and sys.argv[3] == "1" else n


class Ptr:
    """A ptr process whose stderr is read on a thread; url is the live
    view's address once ptr printed it."""

    def __init__(self, args, **kwargs):
        self.process = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        text=True, **kwargs)
        self.stderr_lines = []
        self._url = None
        self._have_url = threading.Event()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self._out = []
        self._out_reader = threading.Thread(target=lambda: self._out.append(
            self.process.stdout.read()), daemon=True)
        self._out_reader.start()

    def _read(self):
        for line in self.process.stderr:
            self.stderr_lines.append(line.rstrip("\n"))
            m = re.search(r"live view at (http://\S+)", line)
            if m and not self._url:
                self._url = m.group(1)
                self._have_url.set()
        self._have_url.set()

    def url(self, timeout=30):
        self._have_url.wait(timeout)
        return self._url

    def wait(self, timeout=300):
        code = self.process.wait(timeout)
        self._reader.join(5)
        self._out_reader.join(5)
        return code

    @property
    def stdout(self):
        return "".join(self._out)

    @property
    def stderr(self):
        return "\n".join(self.stderr_lines)


def get(url, path, timeout=10):
    """(status, headers, body) of one GET."""
    u = urllib.parse.urlsplit(url)
    c = http.client.HTTPConnection(u.hostname, u.port, timeout=timeout)
    try:
        c.request("GET", path)
        r = c.getresponse()
        return r.status, dict(r.getheaders()), r.read()
    finally:
        c.close()


class Page:
    """What the page does, as a script: follows /events, and fetches
    /frame.png whenever the state names a new frame. states and frames
    (id, PNG bytes, whether ptr said it is denoised) collect what it saw."""

    def __init__(self, url):
        self.url = url
        self.states = []
        self.frames = []
        self.error = None
        self._stop = False
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self):
        u = urllib.parse.urlsplit(self.url)
        try:
            c = http.client.HTTPConnection(u.hostname, u.port, timeout=30)
            c.request("GET", "/events")
            r = c.getresponse()
            shown = 0
            while not self._stop:
                line = r.fp.readline()
                if not line:
                    break
                if not line.startswith(b"data: "):
                    continue
                state = json.loads(line[6:])
                self.states.append(state)
                if state["frame"] and state["frame"] != shown:
                    status, headers, body = get(self.url, "/frame.png?id=%d" % state["frame"])
                    if status == 200:
                        shown = state["frame"]
                        self.frames.append((shown, body, headers.get("X-Ptr-Denoised") == "1"))
            c.close()
        except (OSError, http.client.HTTPException, ValueError) as e:
            if not self._stop:
                self.error = repr(e)

    def close(self, timeout=10):
        self._stop = True
        self._thread.join(timeout)


def wait_for(predicate, timeout, step=0.05):
    end = time.time() + timeout
    while time.time() < end:
        if predicate():
            return True
        time.sleep(step)
    return predicate()


# What differs between any two renders: when, and how long.
TIMINGS = {b"ptr:render_seconds", b"ptr:import_seconds", b"ptr:build_seconds", b"capDate"}


def exr_without_timings(path):
    """An EXR file's bytes with the values of the attributes that hold
    timings zeroed: the header is magic, version, then attributes (name,
    type, size, value) up to an empty name."""
    data = bytearray(open(path, "rb").read())
    if data[:4] != b"\x76\x2f\x31\x01":
        raise ValueError(path + ": not an EXR file")
    at = 8
    while data[at] != 0:
        name_end = data.index(0, at)
        name = bytes(data[at:name_end])
        type_end = data.index(0, name_end + 1)
        size = int.from_bytes(data[type_end + 1:type_end + 5], "little")
        value = type_end + 5
        if name in TIMINGS:
            data[value:value + size] = bytes(size)
        at = value + size
    return bytes(data)


def same_image_bytes(a, b):
    """Whether two images are the same bytes (EXR: apart from timings)."""
    if a.endswith(".exr"):
        return exr_without_timings(a) == exr_without_timings(b)
    return open(a, "rb").read() == open(b, "rb").read()


def read_ppm(path):
    """(width, height, RGB bytes) of an 8-bit binary PPM (oiiotool's)."""
    data = open(path, "rb").read()
    parts = data.split(maxsplit=4)
    if parts[0] != b"P6" or parts[3] != b"255":
        raise ValueError(path + ": not an 8-bit PPM")
    return int(parts[1]), int(parts[2]), parts[4]


def vector_convolution(ptr):
    """Whether the CPU level in use has the denoiser's vector convolution
    (the fourth column of --print-dispatch's row "<- in use"): below it the
    live view has no denoised preview."""
    out = subprocess.run([ptr, "--print-dispatch"], capture_output=True, text=True).stdout
    row = next(line.split() for line in out.splitlines() if "<- in use" in line)
    return row[3] != "c"
