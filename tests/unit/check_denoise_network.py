"""ptr's denoiser (through denoise_raw) against the NumPy reference
(denoise_reference.py) on small images that are not multiples of 16: random
HDR colour with a few very bright pixels, albedo and unit normals, to 1e-4
relative, with the default and the small network, and the large ones that
filter albedo and normal first. Then the same output, byte
for byte, at every CPU level ($PTR_CPUMASK: none, sse41, avx2, or only the
one the environment sets), with 1 and 2 threads, and cut into tiles across
and down. Skipped (77) when the weights are not installed, or NumPy is not."""
import os
import shutil
import subprocess
import sys
import tempfile

# The reference first: without NumPy it runs this script again under
# Debian's python3, or skips it.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import denoise_reference  # noqa: E402
import numpy as np  # noqa: E402

# Each quality's networks: the colour's, then those filtering albedo and normal.
WEIGHTS = {"balanced": ["rt_hdr_alb_nrm.tza"], "fast": ["rt_hdr_alb_nrm_small.tza"],
           "high": ["rt_hdr_calb_cnrm_large.tza", "rt_alb_large.tza", "rt_nrm_large.tza"]}
TOLERANCE = 1e-4

denoise_raw = sys.argv[2]
weights_dir = os.environ.get("PTR_WEIGHTS_DIR", "")
if not all(os.path.isfile(os.path.join(weights_dir, f)) for fs in WEIGHTS.values() for f in fs):
    print(f"skipped: the denoiser's weights are not in '{weights_dir}' "
          "(scripts/install-deps.sh installs them)")
    sys.exit(77)

failures = []
work = tempfile.mkdtemp(prefix="ptr_denoise_")


def run_ptr(quality, images, threads=1, tile=0, level=None):
    """ptr's denoised image, as raw bytes."""
    height, width, _ = images[0].shape
    paths = [os.path.join(work, name) for name in ("color", "albedo", "normal", "out")]
    for image, path in zip(images, paths):
        image.tofile(path)
    env = dict(os.environ)
    if level:
        env["PTR_CPUMASK"] = level
    done = subprocess.run([denoise_raw, quality, str(width), str(height), str(threads),
                           str(tile)] + paths, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        shutil.rmtree(work)
        print(done.stderr.strip())
        sys.exit(77 if done.returncode == 77 else 1)
    return open(paths[3], "rb").read()


def compare_with_reference(quality, width, height, seed):
    images = denoise_reference.test_images(width, height, seed)
    color_net, *guide_nets = [denoise_reference.read_tza(os.path.join(weights_dir, f))
                              for f in WEIGHTS[quality]]
    expected = denoise_reference.denoise(color_net, *(a.astype(np.float64) for a in images),
                                         guide_nets)
    got = np.frombuffer(run_ptr(quality, images), dtype="<f4").reshape(height, width, 3)
    relative = np.abs(got - expected) / np.abs(expected)
    worst = np.unravel_index(np.argmax(relative), relative.shape)
    print(f"{quality} {width}x{height}: largest relative difference {relative.max():.3g} "
          f"at {worst} (ptr {got[worst]:.9g}, NumPy {expected[worst]:.9g})")
    if not relative.max() <= TOLERANCE:
        failures.append(f"{quality} {width}x{height}: {relative.max():.3g} > {TOLERANCE}")


def check_same(what, outputs):
    """outputs: (label, bytes); all must be the first's."""
    first_label, first = outputs[0]
    differ = [label for label, data in outputs[1:] if data != first]
    failures.extend(f"{what}: {label} differs from {first_label}" for label in differ)
    print(f"{what}: {'; '.join(label for label, _ in outputs)}: "
          f"{'differ' if differ else 'identical'}")


compare_with_reference("balanced", 40, 24, 1)
compare_with_reference("balanced", 70, 50, 2)
compare_with_reference("fast", 70, 50, 3)
compare_with_reference("high", 40, 24, 5)

levels = [os.environ["PTR_CPUMASK"]] if os.environ.get("PTR_CPUMASK") else ["none", "sse41",
                                                                            "avx2"]
images = denoise_reference.test_images(40, 24, 1)
check_same("levels and threads",
           [(f"{level} with {threads} thread(s)", run_ptr("balanced", images, threads, 0, level))
            for level in levels for threads in (1, 2)])

# Tiles across a side a little longer than one tile make two; each pixel is
# the untiled image's, bit for bit. UNet's (fast) overlap by 80: tiles of 240
# across 256 pixels, and across 250, whose last tile is padded to a multiple
# of 16 as the whole image is. UNetLarge's (high) overlap by 96: tiles of 208
# across 224 pixels, one size on one thread, as high's three large networks
# cost the most (minutes at CPU level none under the sanitizers).
for quality, tile, sizes, threads in (("fast", 240, ((256, 24), (24, 256), (250, 24)), (1, 2)),
                                      ("high", 208, ((224, 16),), (1,))):
    for width, height in sizes:
        images = denoise_reference.test_images(width, height, 4)
        check_same(f"{quality}, tiles of {tile} on {width}x{height}",
                   [("one tile", run_ptr(quality, images))] +
                   [(f"tiles of {tile}, {t} thread(s)", run_ptr(quality, images, t, tile))
                    for t in threads])

shutil.rmtree(work)
for failure in failures:
    print("FAILED:", failure)
sys.exit(1 if failures else 0)
