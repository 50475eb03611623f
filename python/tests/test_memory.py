"""Memory: 10^7 spheres from numpy render with no more memory than the arrays
themselves and the renderer's own bytes a sphere, plus a fixed allowance
(issue 38's criterion). The peak is measured in a process of its own (this
file run as a script), whose high-water mark (VmHWM) no other test raised.

The renderer's own bytes a sphere are its peak, the tree's build: a prim
(BvhPrim, src/accel/bvh_prims.h) is the whole sphere, 24 bytes, and the
tree's nodes (256 bytes each) come to about 5 bytes a sphere
(docs/intersectors.md, "Memory"; 4.5 here), so 8 is allowed. The scene's
own arrays (16 bytes of centre and radius, 1 of material) do not add to that
peak: the build gives them back a million spheres at a time as it fills the
prims (docs/intersectors.md), so a million spheres of them (17 MB) are in the
fixed allowance. Copies kept besides (float64 centres, a Python-side copy of
the arrays) would exceed the budget at 10^7 spheres.

The test is skipped where the machine has less memory available than twice
its budget."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

SPHERES = 10**7
PRIM_BYTES = 24
NODE_BYTES = 8
ALLOWANCE = 48 << 20  # a million spheres of the scene's arrays, the allocator's slack
WIDTH, HEIGHT = 64, 36


def budget(count, array_bytes):
    """Bytes the process may grow by, from before the arrays are made."""
    return array_bytes + count * (PRIM_BYTES + NODE_BYTES) + ALLOWANCE


def status(field):
    """A field of /proc/self/status in bytes (VmRSS, VmHWM)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) * 1024
    raise KeyError(field)


def available():
    """Bytes of memory the machine has available (0 if it does not say)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def measure(count):
    """In this process: the resident bytes before the arrays are made, the
    peak after a render of count spheres made from them, and the arrays'
    bytes, as JSON on stdout."""
    import ptr
    # Two threads on any machine: each thread of the tree's build has a
    # scratch of 1/64 of the prims (half a byte a sphere), which the
    # allowance counts for two.
    context = ptr.Context(threads=2)
    # What does not grow with the spheres first (the modules, the kept
    # threads, a render's buffers), so that it is in the baseline.
    ptr.Scene.from_arrays(np.zeros((1, 3), np.float32), np.ones(1, np.float32),
                          context=context).render(WIDTH, HEIGHT, samples=1)
    before = status("VmRSS")
    # Made in place: a temporary would raise the peak by its own size.
    centers = np.empty((count, 3), np.float32)
    np.random.default_rng(1).random(out=centers, dtype=np.float32)
    centers *= np.float32(count ** (1 / 3))
    radii = np.full(count, 0.3, np.float32)
    image = ptr.Scene.from_arrays(centers, radii, context=context).render(WIDTH, HEIGHT,
                                                                          samples=1)
    assert image.shape == (HEIGHT, WIDTH, 3) and image.max() > 0
    json.dump({"before": before, "peak": status("VmHWM"),
               "arrays": centers.nbytes + radii.nbytes}, sys.stdout)


@pytest.mark.skipif(not os.path.exists("/proc/self/status"),
                    reason="the peak is read from /proc/self/status (Linux)")
@pytest.mark.skipif(available() < 2 * budget(SPHERES, 16 * SPHERES),
                    reason="less memory available than twice the test's budget")
def test_spheres_from_numpy_add_only_the_renderers_bytes():
    run = subprocess.run([sys.executable, __file__, str(SPHERES)], capture_output=True,
                         text=True, check=True)
    m = json.loads(run.stdout)
    grown = m["peak"] - m["before"]
    assert grown <= budget(SPHERES, m["arrays"]), \
        "grew %.1f MB, budget %.1f MB (%.1f bytes a sphere beyond the arrays)" % (
            grown / 1e6, budget(SPHERES, m["arrays"]) / 1e6,
            (grown - m["arrays"]) / SPHERES)


if __name__ == "__main__":
    measure(int(sys.argv[1]))
