"""The Python module against the command line and on bad input: shapes and
dtypes, errors as ValueError, the CLI's EXR pixels float for float (with
--color-by, and a region's frame saved in place), import warnings,
contexts rendering at once, cancellation by callback and by SIGINT.

Run by ctest (python_tests) with PTR_LIBRARY, PTR_EXECUTABLE and
PTR_SOURCE_DIR set; by hand: PTR_LIBRARY=build/lib/libptr.so.1
PTR_EXECUTABLE=build/src/ptr python3 -m pytest python/tests."""

import ctypes
import math
import os
import pathlib
import shutil
import signal
import subprocess
import threading
import weakref

import numpy as np
import pytest

import ptr

SOURCE = os.environ.get("PTR_SOURCE_DIR",
                        os.path.join(os.path.dirname(__file__), "..", ".."))
SEED = os.path.join(SOURCE, "scenes", "seed.gltf")
FINAL = os.path.join(SOURCE, "scenes", "final.gltf")
MOLECULE = os.path.join(SOURCE, "scenes", "1tii.pdb")


def spheres(count=50, seed=3):
    rng = np.random.default_rng(seed)
    centers = rng.uniform(-1, 1, (count, 3)).astype(np.float32)
    radii = rng.uniform(0.05, 0.2, count).astype(np.float32)
    return centers, radii


def same_pixels(a, b):
    """Whether two EXR files hold the same pixels, bit for bit (through
    OpenImageIO's idiff: the test is skipped without it)."""
    if shutil.which("idiff") is None:
        pytest.skip("idiff (OpenImageIO's tools) is missing")
    return subprocess.run(["idiff", "-q", "-a", "-fail", "0", "-failpercent", "0", a, b],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode == 0


def test_shapes_and_dtypes():
    centers, radii = spheres()
    scene = ptr.Scene.from_arrays(centers, radii)
    assert len(scene) == 50
    image = scene.render(40, 30, samples=2)
    assert image.shape == (30, 40, 3) and image.dtype == np.float32
    assert np.isfinite(image).all() and image.max() > 0
    assert scene.render(40, 30, samples=2, transparent=True).shape == (30, 40, 4)
    image, albedo, normal = scene.render(16, 8, samples=1, passes=True)
    assert image.shape == albedo.shape == normal.shape == (8, 16, 3)
    # Width alone: the height from the camera's aspect ratio (16:9 here).
    assert scene.render(64, samples=1).shape == (36, 64, 3)


def test_dtypes_converted_and_exact():
    centers, radii = spheres()
    reference = ptr.Scene.from_arrays(centers, radii).render(24, 24, samples=2)
    # float64 holding the same values, a strided view and a list: the same image.
    wide = np.zeros((50, 6), np.float32)
    wide[:, ::2] = centers
    for variant in (centers.astype(np.float64), wide[:, ::2], centers.tolist()):
        image = ptr.Scene.from_arrays(variant, radii.astype(np.float64)).render(
            24, 24, samples=2)
        assert np.array_equal(image, reference)
    # float32 and C-contiguous: read where it is.
    assert ptr._contiguous(centers, np.float32) is centers
    integers = np.array([[0, 0, -3], [1, 0, -3]], np.int32)
    assert len(ptr.Scene.from_arrays(integers, [0.5, 0.5])) == 2


def test_bad_input():
    centers, radii = spheres(4)
    with pytest.raises(ValueError, match="shape"):
        ptr.Scene.from_arrays(centers[:, :2], radii)
    with pytest.raises(ValueError, match="radii"):
        ptr.Scene.from_arrays(centers, radii[:3])
    bad = centers.copy()
    bad[2, 1] = np.nan
    with pytest.raises(ValueError, match="sphere 2"):
        ptr.Scene.from_arrays(bad, radii)
    negative = radii.copy()
    negative[1] = -0.5
    with pytest.raises(ValueError, match="sphere 1"):
        ptr.Scene.from_arrays(centers, negative)
    with pytest.raises(ValueError, match="material_indices"):
        ptr.Scene.from_arrays(centers, radii, material_indices=[0, 0, 1, 0])
    with pytest.raises(ValueError, match="numbers"):
        ptr.Scene.from_arrays(np.array([["a", "b", "c"]]), [1.0])
    with pytest.raises(ValueError, match="kind"):
        ptr.Material("velvet")
    scene = ptr.Scene.from_arrays(centers, radii)
    with pytest.raises(ValueError, match="integrator"):
        scene.render(8, 8, samples=1, integrator="sideways")
    with pytest.raises(ValueError):
        ptr.Scene.from_arrays(centers, radii, sky="purple")
    with pytest.raises(ValueError, match="cpu_cap: 'avx9000' is not"):
        ptr.Context(cpu_cap="avx9000")
    with pytest.raises(ptr.Error, match="^arrays: "):
        ptr.Scene.from_arrays([[0, 0, 0]], [0.0])  # nothing to frame
    with pytest.raises(ptr.Error) as failure:
        ptr.load("/nonexistent/scene.gltf")
    assert failure.value.code == 3 and "/nonexistent/scene.gltf" in str(failure.value)
    with pytest.raises(ValueError, match="shape"):
        ptr.save("/tmp/never.exr", np.zeros((4, 4)))


@pytest.mark.parametrize("scene,extra,kwargs", [
    (FINAL, [], {}),
    (SEED, ["--transparent"], {"transparent": True}),
    (MOLECULE, [], {}),
])
def test_same_pixels_as_command_line(tmp_path, scene, extra, kwargs):
    cli = str(tmp_path / "cli.exr")
    subprocess.run([os.environ["PTR_EXECUTABLE"], scene, "-o", cli, "--width", "80",
                    "--samples", "4", "--quiet"] + extra, check=True)
    image = ptr.load(scene).render(80, samples=4, **kwargs)
    ours = str(tmp_path / "ours.exr")
    ptr.save(ours, image)
    assert same_pixels(cli, ours)


def test_materials_and_save(tmp_path):
    centers = np.array([[0, 0, -3], [1.2, 0, -3], [0, -101, -3]], np.float32)
    radii = np.array([0.5, 0.5, 100], np.float32)
    materials = [ptr.Material("metal", (0.8, 0.8, 0.8), fuzz=0.1),
                 ptr.Material("emissive", (0, 0, 0), emission=(4, 4, 4)),
                 ptr.Material("diffuse", (0.5, 0.5, 0.5))]
    camera = ptr.Camera((0, 0, 0), (0, 0, -1), vfov=60)
    scene = ptr.Scene.from_arrays(centers, radii, colors=[[1, 0, 0], [1, 1, 1], [1, 1, 1]],
                                  materials=materials, material_indices=[0, 1, 2],
                                  camera=camera, sky="black")
    image = scene.render(32, 24, samples=4)
    assert image.max() > 1  # the emitter
    png = tmp_path / "image.png"
    ptr.save(png, image, view="Raw")
    assert png.stat().st_size > 0
    # Another camera for one render: the scene read again with it.
    turned = scene.render(32, 24, samples=4, camera=ptr.Camera((0, 3, 0), (0, 0, -3)))
    assert not np.array_equal(turned, image)


def test_colors_beside_many_materials():
    """Colours in a scene of more than 65,536 materials, whose tree build
    cannot pack a sphere's material and colour together and gathers them
    from its place instead (src/accel/bvh_prims.h), give the image of the
    same colours folded into the materials, which the build packs: white
    times a colour is the colour, bit for bit."""
    rng = np.random.default_rng(3)
    count, kinds = 4000, 70001
    centers = rng.uniform(-10, 10, (count, 3)).astype(np.float32)
    radii = rng.uniform(0.2, 0.8, count).astype(np.float32)
    channels = rng.integers(0, 65536, (count, 3))
    indices = np.arange(count) * 7919 % kinds
    white = ptr.Material("diffuse", (1.0, 1.0, 1.0))
    colored = ptr.Scene.from_arrays(centers, radii, colors=channels / 65535.0,
                                    materials=[white] * kinds, material_indices=indices)
    # The renderer's colour: each channel as a float times 1/65535 in float.
    folded = channels.astype(np.float32) * (np.float32(1) / np.float32(65535))
    materials = [white] * kinds
    for i in range(count):
        materials[indices[i]] = ptr.Material("diffuse", tuple(float(v) for v in folded[i]))
    plain = ptr.Scene.from_arrays(centers, radii, materials=materials, material_indices=indices)
    image = colored.render(48, 32, samples=4, seed=1)
    assert np.array_equal(image, plain.render(48, 32, samples=4, seed=1))
    assert image.std() > 0.01  # spheres in view, in many colours


def test_contexts_at_once():
    jobs = [(SEED, "none"), (FINAL, None)]
    alone = [ptr.load(path, context=ptr.Context(1, cap)).render(48, samples=2)
             for path, cap in jobs]
    results = [None, None]

    def run(i):
        path, cap = jobs[i]
        results[i] = ptr.load(path, context=ptr.Context(1, cap)).render(48, samples=2)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(2)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for i in range(2):
        assert np.array_equal(results[i], alone[i])


def test_cancel_by_callback():
    calls = []

    def progress(done, total):
        calls.append((done, total))
        return True

    with pytest.raises(ptr.Cancelled):
        ptr.load(FINAL).render(400, samples=100000, progress=progress)
    assert calls and calls[0][1] == 100000


def test_ctrl_c_cancels():
    def interrupt(done, total):
        os.kill(os.getpid(), signal.SIGINT)

    handler = signal.getsignal(signal.SIGINT)
    with pytest.raises(KeyboardInterrupt):
        ptr.load(FINAL).render(400, samples=100000, progress=interrupt)
    assert signal.getsignal(signal.SIGINT) is handler


def test_progress_exception_raised():
    def broken(done, total):
        raise RuntimeError("from the callback")

    with pytest.raises(RuntimeError, match="from the callback"):
        ptr.load(SEED).render(64, samples=4, progress=broken)


def test_help_reads():
    assert "numpy in, numpy out" in ptr.__doc__
    for name in ptr.__all__:
        assert getattr(ptr, name).__doc__
    assert ptr.version().count(".") == 2


def test_material_values_refused():
    centers, radii = spheres(2)
    good = ptr.Material("dielectric", (1, 1, 1), ior=1.5)
    assert len(ptr.Scene.from_arrays(centers, radii, materials=[good],
                                     material_indices=[0, 0])) == 2
    for bad in (ptr.Material("diffuse", (math.nan, 0.5, 0.5)),
                ptr.Material("emissive", (0, 0, 0), emission=(1, -1, 1)),
                ptr.Material("dielectric", (1, 1, 1), ior=0.0)):
        with pytest.raises(ValueError, match="material 1"):
            ptr.Scene.from_arrays(centers, radii, materials=[good, bad],
                                  material_indices=[0, 1])


def test_whole_numbers_do_not_wrap():
    centers, radii = spheres(4)
    scene = ptr.Scene.from_arrays(centers, radii)
    # 2^32 + 1 would be 1 in the C field; 2^30 + 1 fits it but not ptr's limit.
    for options in ({"samples": 2 ** 32 + 1}, {"samples": 2 ** 30 + 1}, {"height": 2 ** 31},
                    {"seed": -1}, {"max_depth": 0}, {"min_samples": 1}, {"samples": 2.5},
                    {"threads": 1025}, {"first_sample": 1, "noise_threshold": 0.1}):
        with pytest.raises(ValueError):
            scene.render(**{"width": 8, "height": 8, **options})
    for threads in (10 ** 6, 2 ** 40):
        with pytest.raises(ValueError, match="threads"):
            ptr.Context(threads=threads)


def test_defaults_are_the_libraries(monkeypatch):
    """Options not given keep ptr_render_options_default's values."""
    centers, radii = spheres(8)
    scene = ptr.Scene.from_arrays(centers, radii)
    real = ptr.lib.ptr_render_options_default

    def two_samples(reference):
        real(reference)
        reference._obj.samples, reference._obj.max_depth = 2, 3  # ctypes.byref's object

    monkeypatch.setattr(ptr.lib, "ptr_render_options_default", two_samples)
    image = scene.render(16, 16)
    monkeypatch.undo()
    assert np.array_equal(image, scene.render(16, 16, samples=2, max_depth=3))
    assert not np.array_equal(image, scene.render(16, 16, samples=100, max_depth=50))


def test_paths_and_library(monkeypatch):
    assert ptr._native.text("scenes/a.gltf") == b"scenes/a.gltf"
    assert ptr._native.text(b"scenes/\xff.gltf") == b"scenes/\xff.gltf"
    assert ptr._native.text(pathlib.Path("a") / "b.gltf") == b"a/b.gltf"
    assert ptr._native.text(None) is None
    monkeypatch.setenv("PTR_LIBRARY", "build/libptr.so.1")
    assert list(ptr._native._candidates()) == [os.path.abspath("build/libptr.so.1")]
    with pytest.raises(ptr.Error) as failure:
        ptr.load(b"/nonexistent/scene.gltf")
    assert failure.value.code == 3


def test_interrupted_load_frees_the_scene(monkeypatch):
    """Ctrl-C as the import returns: the scene is freed, then the
    KeyboardInterrupt raised."""
    freed = []
    real_free = ptr.lib.ptr_scene_handle_free

    def free(handle):
        freed.append(handle)
        real_free(handle)

    def interrupted(status, err):
        raise KeyboardInterrupt

    monkeypatch.setattr(ptr.lib, "ptr_scene_handle_free", free)
    monkeypatch.setattr(ptr, "_check", interrupted)
    with pytest.raises(KeyboardInterrupt):
        ptr.load(SEED)
    assert len(freed) == 1


def test_structures_agree_with_header():
    """Every structure's ctypes copy has the header's fields at the
    compiler's offsets, and its size (PTR_API_LAYOUT: tests/api's
    print_api_layout, which prints them)."""
    program = os.environ.get("PTR_API_LAYOUT")
    if not program:
        pytest.skip("PTR_API_LAYOUT (the build's print_api_layout) is not set")
    header = {}
    for line in subprocess.run([program], check=True, capture_output=True,
                               text=True).stdout.splitlines():
        words = line.split()
        entry = header.setdefault(words[0], {"fields": {}})
        if len(words) == 2:
            entry["size"] = int(words[1])
        else:
            entry["fields"][words[1]] = int(words[2])
    assert len(header) == 9
    for name, entry in header.items():
        copy = getattr(ptr._native, name[len("Ptr"):])
        assert ctypes.sizeof(copy) == entry["size"], name
        assert [field for field, _ in copy._fields_] == list(entry["fields"]), name
        for field, offset in entry["fields"].items():
            assert getattr(copy, field).offset == offset, (name, field)


def test_region_and_time_budget():
    scene = ptr.load(SEED)
    full = scene.render(80, 60, samples=4)
    part = scene.render(80, 60, samples=4, region=(10, 5, 50, 30))
    assert part.shape == (25, 40, 3)
    assert np.array_equal(part, full[5:30, 10:50])
    # Time enough for every sample: the same image; too little for all
    # 2^30: what was done, without an error.
    assert np.array_equal(scene.render(80, 60, samples=4, time_budget=600), full)
    assert scene.render(16, 16, samples=2 ** 30, time_budget=0.1).shape == (16, 16, 3)
    for bad in ({"region": (1, 2, 3)}, {"region": (5, 0, 5, 4)}, {"region": (0, 0, 81, 4)},
                {"region": (0, 0, 2 ** 40, 4)}, {"time_budget": -1}, {"time_budget": 1e8}):
        with pytest.raises(ValueError):
            scene.render(80, 60, samples=1, **bad)


def test_save_options_as_command_line(tmp_path):
    cli = str(tmp_path / "cli.exr")
    options = ["--depth", "half", "--exposure", "1.5", "--view", "Raw", "--bake-view"]
    subprocess.run([os.environ["PTR_EXECUTABLE"], FINAL, "-o", cli, "--width", "80",
                    "--samples", "4", "--quiet"] + options, check=True)
    image = ptr.load(FINAL).render(80, samples=4)
    ours = str(tmp_path / "ours.exr")
    ptr.save(ours, image, depth="half", exposure=1.5, view="Raw", bake_view=True)
    assert same_pixels(cli, ours)
    png = tmp_path / "deep.png"
    ptr.save(png, image, depth="16", dither=True, look=None, display=None)
    assert png.stat().st_size > 0
    for bad in ({"depth": "12"}, {"depth": "16"}, {"exposure": 65}, {"look": "no such look"}):
        with pytest.raises(ValueError):
            ptr.save(ours, image, **bad)


STRUCTURE = os.path.join(SOURCE, "tests", "fixtures", "structures", "1tii.cif")


@pytest.mark.parametrize("options, kwargs", [
    (["--color-by", "chain"], {"color_by": "chain"}),
    (["--color-by", "bfactor", "--colormap", "magma", "--color-range", "10,60"],
     {"color_by": "bfactor", "colormap": "magma", "color_range": (10, 60)}),
])
def test_color_by_as_command_line(tmp_path, options, kwargs):
    cli = str(tmp_path / "cli.exr")
    subprocess.run([os.environ["PTR_EXECUTABLE"], STRUCTURE, "-o", cli, "--width", "80",
                    "--samples", "4", "--quiet"] + options, check=True)
    ours = str(tmp_path / "ours.exr")
    ptr.save(ours, ptr.load(STRUCTURE, **kwargs).render(80, samples=4))
    assert same_pixels(cli, ours)


def test_color_range_and_bad_colors():
    assert ptr.load(STRUCTURE, color_by="bfactor", color_range=(10, 60)).color_range == (10, 60)
    low, high = ptr.load(STRUCTURE, color_by="bfactor").color_range
    assert 0 < low < high
    assert ptr.load(STRUCTURE, color_by="chain").color_range is None
    assert ptr.load(STRUCTURE).color_range is None
    for bad in ({"colormap": "magma"}, {"color_by": "bfactor", "colormap": "jet"},
                {"color_by": "bfactor", "color_range": (2, 1)},
                {"color_by": "bfactor", "color_range": (0, 0)},
                {"color_by": "bfactor", "color_range": (1, 2, 3)},
                {"color_by": "bfactor", "color_range": (0, math.inf)},
                {"color_by": "chain", "colormap": "magma"}, {"color_by": ""},
                {"color_by": "bfactor", "color_range": 5},
                {"color_by": "bfactor", "color_range": "1,2"}):
        with pytest.raises(ValueError):
            ptr.load(STRUCTURE, **bad)
    with pytest.raises(ptr.Error) as error:
        ptr.load(STRUCTURE, color_by="temperature")
    assert error.value.code == 4


def test_import_warnings():
    path = os.path.join(SOURCE, "tests", "fixtures", "orthographic.gltf")
    with pytest.warns(ptr.SceneWarning) as issued:
        scene = ptr.load(path)
    assert len(scene.warnings) == 2
    assert [str(w.message) for w in issued] == scene.warnings
    assert "extras.aperture is ignored" in scene.warnings[0]
    assert ptr.Scene.from_arrays(*spheres()).warnings == []
    assert ptr.load(SEED).warnings == []


def test_full_frame_and_placed_save(tmp_path):
    scene = ptr.load(SEED)
    whole = scene.render(80, 60, samples=4)
    frame = scene.render(80, 60, samples=4, region=(10, 5, 50, 30), full=True)
    assert isinstance(frame, ptr.Frame)
    assert frame.image.shape == (25, 40, 3) and frame.image.dtype == np.float32
    assert np.array_equal(frame.image, whole[5:30, 10:50])
    assert frame.placement == ptr.Placement(10, 5, 80, 60)
    assert frame.samples == 4
    assert frame.albedo is None and frame.normal is None and frame.noisy is None
    with pytest.raises(ValueError):
        frame.image[0, 0, 0] = 1  # read in place: the frame's own
    for name in ("image", "placement", "samples"):
        with pytest.raises(AttributeError):  # saved as rendered: not to be changed
            setattr(frame, name, None)
    with pytest.raises(TypeError):
        ptr.Frame(0x1000)  # only a render makes one
    # The frame, or its pixels placed where it says, save as the command
    # line's EXR of the region; without the placement, as an image of their
    # own, they do not.
    cli = str(tmp_path / "cli.exr")
    subprocess.run([os.environ["PTR_EXECUTABLE"], SEED, "-o", cli, "--width", "80", "--height",
                    "60", "--samples", "4", "--quiet", "--region", "10,5,50,30"], check=True)
    saved, placed, alone = (str(tmp_path / name) for name in ("saved.exr", "placed.exr",
                                                              "alone.exr"))
    ptr.save(saved, frame)
    ptr.save(placed, frame.image.copy(), placement=frame.placement)
    ptr.save(alone, frame.image)
    assert same_pixels(cli, saved) and same_pixels(cli, placed)
    assert not same_pixels(cli, alone)
    for bad in ((41, 5, 80, 60), (10, 5, 80), (-1, 0, 80, 60), (0, 0, 70000, 60)):
        with pytest.raises(ValueError):
            ptr.save(placed, frame.image, placement=bad)
    with pytest.raises(ValueError):
        ptr.save(saved, frame, placement=(0, 0, 40, 25))
    # The arrays keep the frame they read alive, and it is freed with the
    # last of them, not later by the garbage collector.
    image, memory = frame.image, weakref.ref(frame._memory)
    del frame
    assert np.array_equal(image, whole[5:30, 10:50])
    del image
    assert memory() is None
    whole_frame = scene.render(80, 60, samples=4, full=True, passes=True)
    assert whole_frame.placement == (0, 0, 80, 60)
    assert whole_frame.albedo.shape == whole_frame.normal.shape == (60, 80, 3)


def test_full_frame_denoised():
    frame = ptr.load(SEED).render(32, 24, samples=2, denoise="fast", full=True)
    assert frame.noisy.shape == frame.image.shape == (24, 32, 3)
    assert frame.albedo is not None
    assert not np.array_equal(frame.noisy, frame.image)
