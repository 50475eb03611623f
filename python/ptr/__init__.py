"""ptr: render sets of spheres with ptr's path tracer, numpy in, numpy out.

    import numpy as np, ptr

    scene = ptr.load("molecule.pdb")              # any file ptr reads
    image = scene.render(640, 480, samples=64)    # (480, 640, 3) float32
    ptr.save("molecule.png", image)               # through ptr's writers

    chains = ptr.load("molecule.cif", color_by="chain")   # as --color-by chain
    frame = chains.render(640, 480, region=(0, 0, 320, 240), full=True)
    ptr.save("corner.exr", frame)                 # the region, placed in the image

    centers = np.random.rand(1000, 3).astype(np.float32)
    radii = np.full(1000, 0.02, np.float32)
    image = ptr.Scene.from_arrays(centers, radii).render(320, 240)

Images are scene-linear floats (the command line's EXR pixels, float for
float, for the same scene and options); with transparent=True they have a
fourth channel, alpha, the colour premultiplied by it. ptr.save applies an
OpenColorIO view for the integer formats (PNG, JPEG, ...).

What an import warns of (a part of the file left out or guessed) is each
scene's `warnings`, and ptr.load also issues each line through Python's
warnings module as a ptr.SceneWarning, which warnings.simplefilter("ignore",
ptr.SceneWarning) silences.

Each scene belongs to a Context, which holds the CPU level, the threads,
the loaded modules and the colour configuration; one is made for the
process unless given. A context serves one call at a time (its calls wait
for each other); scenes of different contexts render at the same time on
different threads.

The library is libptr.so (ptr's C API, include/ptr/ptr.h), found through
$PTR_LIBRARY, else where this package was installed beside it, the build
tree, /usr/local/lib or /usr/lib.
"""

import collections
import ctypes
import math
import signal
import threading
import warnings

import numpy as np

from . import _native
from ._native import lib

__all__ = ["Camera", "Material", "Context", "Scene", "Frame", "Placement", "Error", "Cancelled",
           "SceneWarning", "load", "save", "version"]


class Error(Exception):
    """A failure of ptr, with the command line's exit code as `code` and its
    one-line message."""

    def __init__(self, code, message):
        super().__init__(message)
        self.code = code


class UsageError(Error, ValueError):
    """A bad argument or option value (ptr's exit code 2)."""


class Cancelled(Error):
    """A render stopped because its progress callback returned True."""


class SceneWarning(UserWarning):
    """A warning of a scene's import, which the command line prints as
    "ptr: warning: ..." (ptr.load issues one a line)."""


def _check(status, err):
    if status == _native.STATUS_OK:
        return
    message = err.message.decode(errors="replace")
    kind = UsageError if status == _native.STATUS_USAGE else \
        Cancelled if status == _native.STATUS_CANCELLED else Error
    raise kind(status, message)


def version():
    """ptr's version, "MAJOR.MINOR.PATCH"."""
    return lib.ptr_version().decode()


class Camera:
    """A camera in world coordinates, as the command line's --lookfrom,
    --lookat, --up, --vfov, --ortho-height, --aperture and --focus-distance
    give it. ortho_height above 0 makes it orthographic."""

    def __init__(self, lookfrom, lookat, up=(0.0, 1.0, 0.0), vfov=40.0, ortho_height=0.0,
                 aperture=0.0, focus_distance=0.0):
        self.lookfrom, self.lookat, self.up = lookfrom, lookat, up
        self.vfov, self.ortho_height = vfov, ortho_height
        self.aperture, self.focus_distance = aperture, focus_distance

    def _desc(self):
        values = [self.lookfrom, self.lookat, self.up, self.vfov, self.ortho_height,
                  self.aperture, self.focus_distance]
        if not all(math.isfinite(v) for v in np.ravel(np.array(values[:3], dtype=np.float64))):
            raise ValueError("camera: lookfrom, lookat and up are three finite numbers each")
        return _native.CameraDesc(
            (ctypes.c_double * 3)(*self.lookfrom), (ctypes.c_double * 3)(*self.lookat),
            (ctypes.c_double * 3)(*self.up), self.vfov, self.ortho_height, self.aperture,
            self.focus_distance)


class Material:
    """A material as ptr's scenes hold them: kind "diffuse" (albedo),
    "metal" (albedo, fuzz: 0 a mirror), "dielectric" (albedo as its
    attenuation, ior) or "emissive" (a diffuse surface that emits); every
    kind may have an emission (radiance)."""

    KINDS = ("diffuse", "metal", "dielectric", "emissive")

    def __init__(self, kind="diffuse", albedo=(0.5, 0.5, 0.5), fuzz=0.0, ior=1.5,
                 emission=(0.0, 0.0, 0.0)):
        if kind not in self.KINDS:
            raise ValueError("material: kind %r is not one of %s" % (kind, ", ".join(self.KINDS)))
        self.kind, self.albedo, self.fuzz, self.ior, self.emission = \
            kind, albedo, fuzz, ior, emission

    def _desc(self):
        return _native.MaterialDesc(self.KINDS.index(self.kind),
                                    (ctypes.c_float * 3)(*self.albedo), self.fuzz, self.ior,
                                    (ctypes.c_float * 3)(*self.emission))


class Context:
    """What renders share: threads (0: one per CPU the process may run on; at most 1024), the
    highest CPU level used (cpu_cap: "none", "sse41", "avx2", "avx512";
    None: the CPU's, capped by $PTR_CPUMASK), the denoiser's weights folder
    and an OpenColorIO config (None: ptr's). Its calls run one at a time."""

    def __init__(self, threads=0, cpu_cap=None, weights_dir=None, ocio_config=None):
        options = _native.ContextOptions(0, _native.text(cpu_cap), _native.text(weights_dir),
                                         _native.text(ocio_config))
        _native.set_whole(options, "threads", threads)
        handle = ctypes.c_void_p()
        err = _native.ErrorInfo()
        _check(lib.ptr_context_new(ctypes.byref(options), ctypes.byref(handle),
                                   ctypes.byref(err)), err)
        self._handle = handle
        self._lock = threading.Lock()

    def __del__(self):
        if getattr(self, "_handle", None):
            lib.ptr_context_free(self._handle)
            self._handle = None


_default_context = None
_default_lock = threading.Lock()


def _context(context):
    global _default_context
    if context is not None:
        return context
    with _default_lock:
        if _default_context is None:
            _default_context = Context()
        return _default_context


def load(path, context=None, **options):
    """Reads a scene file of any format ptr reads (glTF, OBJ, PDB, mmCIF,
    ...) into a Scene. options are the command line's, by name: camera
    (a Camera, replacing the file's), camera_name, orthographic,
    fit_all_objects, select, drop_hydrogens, assembly, model, orbit_degrees,
    width and height (framing the automatic camera), sky ("gradient",
    "black" or "R,G,B"), and the colours of --color-by: color_by (a
    quantity such as a glTF attribute "_BFACTOR" or a structure's
    "bfactor" or "occupancy", mapped through the colormap; or a structure's
    colour scheme: "element", "chain", "entity", "residue", "secondary"),
    colormap ("viridis", the default, "magma", "inferno", "plasma",
    "cividis" or "coolwarm") and color_range ((min, max), the values mapped
    to its ends; None: the values' own range, which Scene.color_range then
    gives). The pixels are the command line's for the same options; its
    colour bar (--color-bar) is not drawn here: matplotlib's colormaps of
    the same names draw it from Scene.color_range.

    Each warning of the import (Scene.warnings) is issued as a
    ptr.SceneWarning."""
    context = _context(context)
    scene = Scene._load(context, path, options)
    for line in scene.warnings:
        warnings.warn(line, SceneWarning, stacklevel=2)
    return scene


def _load_options(options):
    known = {"camera", "camera_name", "orthographic", "fit_all_objects", "select",
             "drop_hydrogens", "assembly", "model", "orbit_degrees", "width", "height", "sky",
             "color_by", "colormap", "color_range"}
    unknown = set(options) - known
    if unknown:
        raise TypeError("load: unknown options %s" % ", ".join(sorted(unknown)))
    camera = options.get("camera")
    desc = camera._desc() if camera is not None else None
    load_options = _native.LoadOptions(
        _native.text(options.get("camera_name")),
        ctypes.pointer(desc) if desc is not None else None,
        int(bool(options.get("orthographic"))), int(bool(options.get("fit_all_objects"))),
        _native.text(options.get("select")), int(bool(options.get("drop_hydrogens"))),
        _native.text(options.get("assembly")), int(options.get("model", 0)),
        float(options.get("orbit_degrees", 0.0)), int(options.get("width", 0)),
        int(options.get("height", 0)), _native.text(options.get("sky")),
        _native.text(options.get("color_by")), _native.text(options.get("colormap")))
    color_range = options.get("color_range")
    if color_range is not None:
        wrong = ValueError("color_range: %r is not (min, max), min below max" % (color_range,))
        try:
            values = [float(v) for v in color_range]
        except (TypeError, ValueError):
            raise wrong from None
        # (0, 0) is the C API's "the values' own range": refused as the
        # empty range it is.
        if len(values) != 2 or not values[0] < values[1]:
            raise wrong
        load_options.color_range[:] = values
    return load_options, desc


def _float_array(name, values, shape_text, columns):
    """values as an array of numbers, checked for shape (N, columns), or
    (N,) when columns is 0; shape_text says the shape in messages."""
    array = np.asarray(values)
    if array.dtype.kind not in "fiub":
        raise ValueError("%s: numbers are needed, not %s" % (name, array.dtype))
    expected = 2 if columns else 1
    if array.ndim != expected or (columns and array.shape[1] != columns):
        raise ValueError("%s: shape %s, not %s" % (name, array.shape, shape_text))
    return array


def _contiguous(array, dtype):
    """array as a C-contiguous array of dtype: itself (no copy) if it is one."""
    return np.ascontiguousarray(array, dtype=dtype)


class Scene:
    """Spheres, their materials, a camera and a sky: from a file (ptr.load)
    or from arrays (Scene.from_arrays); rendered by render()."""

    def __init__(self, *args, **kwargs):
        raise TypeError("make a Scene with ptr.load or Scene.from_arrays")

    @classmethod
    def _made(cls, context, make, remake):
        """The Scene of the handle make(handle, err) hands, under the
        context's lock. The Scene holds the handle from the call on, and an
        exception (Ctrl-C as the call returns) frees it before it is raised."""
        scene = object.__new__(cls)
        scene._context, scene._remake = context, remake
        scene._handle = ctypes.c_void_p()
        err = _native.ErrorInfo()
        try:
            with context._lock:
                status = make(ctypes.byref(scene._handle), ctypes.byref(err))
            _check(status, err)
        except BaseException:
            scene._free()
            raise
        return scene

    def _free(self):
        if getattr(self, "_handle", None):
            lib.ptr_scene_handle_free(self._handle)
            self._handle = None

    @classmethod
    def _load(cls, context, path, options):
        load_options, _ = _load_options(options)
        def remake(camera):
            return cls._load(context, path, dict(options, camera=camera))

        def make(handle, err):
            return lib.ptr_scene_load(context._handle, _native.text(path),
                                      ctypes.byref(load_options), handle, err)
        return cls._made(context, make, remake)

    @classmethod
    def from_arrays(cls, centers, radii, colors=None, materials=None, material_indices=None,
                    camera=None, sky=None, orthographic=False, width=0, height=0, context=None):
        """A scene of spheres from numpy arrays, copied by ptr (a render
        with another camera reads them again).

        centers: (N, 3), float32 read in place if C-contiguous, float64 read
        in place too (its precision kept), any other numbers converted;
        radii: (N,), each finite and >= 0; colors: (N, 3) in [0, 1]
        (clamped), multiplying the material's albedo; materials: a list of
        Material (default: one grey diffuse); material_indices: (N,)
        integers into materials; camera: a Camera (default: framing the
        spheres from +Z); sky: "gradient" (default), "black" or "R,G,B";
        width, height: the image size the scene suggests.

        Wrong shapes, NaN or infinite centres, negative or NaN radii and
        indices outside materials raise ValueError."""
        context = _context(context)
        centers = _float_array("centers", centers, "(N, 3)", 3)
        count = centers.shape[0]
        centers = _contiguous(centers, np.float64 if centers.dtype == np.float64 else np.float32)
        radii = _contiguous(_float_array("radii", radii, "(N,)", 0), np.float32)
        if radii.shape[0] != count:
            raise ValueError("radii: %d of them for %d centers" % (radii.shape[0], count))
        if not np.isfinite(centers).all():
            raise ValueError("centers: sphere %d is not finite"
                             % int(np.argmin(np.isfinite(centers).all(axis=1))))
        bad = ~(np.isfinite(radii) & (radii >= 0))
        if bad.any():
            raise ValueError("radii: sphere %d has radius %g, not finite and >= 0"
                             % (int(np.argmax(bad)), radii[np.argmax(bad)]))
        if colors is not None:
            colors = _contiguous(_float_array("colors", colors, "(N, 3)", 3), np.float32)
            if colors.shape[0] != count:
                raise ValueError("colors: %d of them for %d centers" % (colors.shape[0], count))
            if np.isnan(colors).any():
                raise ValueError("colors: NaN")
        table = list(materials) if materials is not None else []
        if material_indices is not None:
            indices = np.asarray(material_indices)
            if indices.shape != (count,) or indices.dtype.kind not in "iu":
                raise ValueError("material_indices: integers of shape (%d,), not %s %s"
                                 % (count, indices.dtype, indices.shape))
            if count and (indices.min() < 0 or indices.max() >= max(len(table), 1)):
                raise ValueError("material_indices: outside the %d materials"
                                 % max(len(table), 1))
            material_indices = _contiguous(indices, np.uint32)
        descs = (_native.MaterialDesc * len(table))(*[m._desc() for m in table]) \
            if table else None
        camera_desc = camera._desc() if camera is not None else None
        arrays = _native.SceneArrays(
            count=count,
            centers=centers.ctypes.data if centers.dtype == np.float32 else None,
            centers_f64=centers.ctypes.data if centers.dtype == np.float64 else None,
            radii=radii.ctypes.data,
            material_indices=material_indices.ctypes.data if material_indices is not None
            else None,
            colors=colors.ctypes.data if colors is not None else None,
            materials=descs, material_count=len(table),
            camera=ctypes.pointer(camera_desc) if camera_desc is not None else None,
            orthographic=int(bool(orthographic)), width=width, height=height,
            sky=_native.text(sky))
        def remake(new_camera):
            return cls.from_arrays(centers, radii, colors, table, material_indices, new_camera,
                                   sky, orthographic, width, height, context)

        def make(handle, err):
            return lib.ptr_scene_from_arrays(context._handle, ctypes.byref(arrays), handle, err)
        return cls._made(context, make, remake)

    def __len__(self):
        """The number of spheres."""
        return lib.ptr_scene_sphere_count(self._handle)

    @property
    def warnings(self):
        """The warnings of the scene's import, a list of str, one a line
        (empty for a scene of arrays)."""
        return [lib.ptr_scene_warning(self._handle, i).decode(errors="replace")
                for i in range(lib.ptr_scene_warning_count(self._handle))]

    @property
    def color_range(self):
        """(min, max), the range of values a load with color_by mapped onto
        the colormap's ends (color_range, else the values' own); None
        without a quantity mapped (no color_by, or a colour scheme)."""
        low, high = ctypes.c_double(), ctypes.c_double()
        if not lib.ptr_scene_color_range(self._handle, ctypes.byref(low), ctypes.byref(high)):
            return None
        return low.value, high.value

    def __del__(self):
        self._free()

    def render(self, width=0, height=0, samples=None, seed=None, camera=None, threads=0,
               denoise=None, progress=None, transparent=False, passes=False, max_depth=None,
               integrator=None, kernel=None, cpu_cap=None, accel=None, sampler=None,
               direct_lighting=True, noise_threshold=0.0, min_samples=None, first_sample=0,
               sky=None, region=None, time_budget=0.0, full=False):
        """Renders the scene into a numpy array of shape (height, width, 3),
        or (height, width, 4) with transparent=True, float32, scene-linear.

        width, height: 0 takes the scene's (else 800 wide); camera: a Camera
        for this render (the scene is read again with it); threads: 0 for
        the context's; samples, seed, max_depth, min_samples: None for
        ptr's defaults (the command line's); denoise: "fast", "balanced" or "high"; progress: a
        function of (samples_done, samples_total), called about ten times a
        second, that returns True to cancel (then ptr.Cancelled is raised);
        passes=True returns (image, albedo, normal), each pass (H, W, 3);
        region: (x0, y0, x1, y1), the pixels rendered (columns x0 to x1 - 1,
        rows y0 to y1 - 1 of the image), returned alone as an array of
        shape (y1 - y0, x1 - x0, 3); time_budget: seconds after which the
        render stops at the end of the pass under way (0: none);
        full=True returns a ptr.Frame instead: the image with its passes,
        its colour before denoising, the samples taken and where a region
        lies, which ptr.save writes as the command line writes its EXR.
        The other options are the command line's of the same names.

        Ctrl-C (SIGINT) stops the render after the pass under way and raises
        KeyboardInterrupt."""
        if camera is not None:
            return self._remake(camera).render(
                width, height, samples, seed, None, threads, denoise, progress, transparent,
                passes, max_depth, integrator, kernel, cpu_cap, accel, sampler,
                direct_lighting, noise_threshold, min_samples, first_sample, sky, region,
                time_budget, full)
        options = _native.RenderOptions()
        lib.ptr_render_options_default(ctypes.byref(options))
        for name, value in (("width", width), ("height", height), ("samples", samples),
                            ("seed", seed), ("threads", threads), ("max_depth", max_depth),
                            ("min_samples", min_samples), ("first_sample", first_sample)):
            if value is not None:
                _native.set_whole(options, name, value)
        options.transparent, options.passes = int(bool(transparent)), int(bool(passes))
        options.direct_lighting = int(bool(direct_lighting))
        options.noise_threshold = float(noise_threshold)
        options.time_budget = float(time_budget)
        if region is not None:
            options.region = _native.whole_numbers("region", region, 4)
        for name, value in (("integrator", integrator), ("kernel", kernel),
                            ("cpu_cap", cpu_cap), ("accel", accel), ("sampler", sampler),
                            ("denoise", denoise), ("sky", sky)):
            setattr(options, name, _native.text(value))
        frame = self._render_frame(options, progress)
        if full:
            return Frame._of(frame)
        try:
            image = _frame_array(lib.ptr_frame_pixels(frame), frame)
            if not passes:
                return image
            return (image, _frame_array(lib.ptr_frame_albedo(frame), frame, 3),
                    _frame_array(lib.ptr_frame_normal(frame), frame, 3))
        finally:
            lib.ptr_frame_free(frame)

    def _render_frame(self, options, progress):
        """The frame of a render, cancelled by progress or by SIGINT."""
        interrupted = []

        def on_progress(user, info):
            if interrupted:
                return 1
            try:
                return 1 if progress and progress(info.contents.samples_done,
                                                  info.contents.samples_total) else 0
            except BaseException as error:  # noqa: B902 - raised again after the render
                interrupted.append(error)
                return 1

        callback = _native.ProgressCallback(on_progress)
        # Python runs signal handlers between the callback's bytecodes, on the
        # main thread: the handler asks the render to stop.
        in_main = threading.current_thread() is threading.main_thread()
        previous = None
        if in_main:
            previous = signal.signal(signal.SIGINT,
                                     lambda number, stack: interrupted.append(KeyboardInterrupt()))
        frame = ctypes.c_void_p()
        err = _native.ErrorInfo()
        try:
            with self._context._lock:
                status = lib.ptr_scene_render(self._context._handle, self._handle,
                                              ctypes.byref(options), callback, None,
                                              ctypes.byref(frame), ctypes.byref(err))
        finally:
            if in_main:
                signal.signal(signal.SIGINT, previous)
        # Ctrl-C, or an exception of the progress callback: raised, whether
        # the render stopped for it or had just finished.
        if interrupted:
            if status == _native.STATUS_OK:
                lib.ptr_frame_free(frame)
            raise interrupted[0]
        _check(status, err)
        return frame


Placement = collections.namedtuple("Placement", "x y image_width image_height")
Placement.__doc__ = """Where a frame's pixels lie in the image rendered: the column and
row of their top left corner, and the whole image's width and height."""


class _FrameMemory:
    """A C frame, freed when nothing holds it: neither its Frame nor an
    array of its buffers (a Frame and its arrays hold this, not each other,
    so that no cycle waits for the garbage collector to free the pixels)."""

    def __init__(self, handle):
        self.handle = handle

    def __del__(self):
        if getattr(self, "handle", None):
            lib.ptr_frame_free(self.handle)
            self.handle = None


class _Buffer:
    """A frame's buffer as numpy reads it, in place and read-only: it keeps
    the frame's memory alive while an array uses it."""

    def __init__(self, memory, pointer, channels):
        self.memory = memory
        self.__array_interface__ = {
            "shape": (lib.ptr_frame_height(memory.handle), lib.ptr_frame_width(memory.handle),
                      channels),
            "typestr": np.dtype(np.float32).str,
            "data": (ctypes.cast(pointer, ctypes.c_void_p).value, True),
            "version": 3,
        }


class Frame:
    """A render's result, from Scene.render(..., full=True). Its arrays are
    float32, scene-linear, read in place (read-only: copy one to change it):

    image: (H, W, 3), or (H, W, 4) with transparent=True (premultiplied);
    albedo, normal: the passes, (H, W, 3), with passes=True or a denoise;
    else None;
    noisy: a denoised image's colour before denoising, (H, W, 3); else None;
    samples: the samples per pixel taken (fewer than asked when a
    time_budget ran out);
    placement: a ptr.Placement, where the pixels lie in the image (with a
    region, its corner and the whole image's size; else 0, 0 and their own).

    ptr.save(path, frame) writes it as the command line writes the same
    render: an EXR keeps the passes, the noisy colour, the metadata and the
    region's place in the image."""

    def __init__(self, *args, **kwargs):
        raise TypeError("a ptr.Frame comes from Scene.render(..., full=True)")

    @classmethod
    def _of(cls, handle):
        """The Frame that owns the C frame handle (freed with its last array)."""
        self = object.__new__(cls)
        self._memory = memory = _FrameMemory(handle)
        buffer = lib.ptr_frame_pixels(handle)
        self._image = np.asarray(_Buffer(memory, buffer, lib.ptr_frame_channels(handle)))
        self._albedo, self._normal, self._noisy = (
            np.asarray(_Buffer(memory, pointer, 3)) if pointer else None
            for pointer in (lib.ptr_frame_albedo(handle), lib.ptr_frame_normal(handle),
                            lib.ptr_frame_noisy(handle)))
        self._samples = lib.ptr_frame_samples(handle)
        corner = [ctypes.c_int() for _ in range(4)]
        lib.ptr_frame_placement(handle, *[ctypes.byref(c) for c in corner])
        self._placement = Placement(*[c.value for c in corner])
        return self

    # Read-only: ptr.save(path, frame) writes the frame as rendered, which
    # an assignment here would not change.
    image = property(lambda self: self._image)
    albedo = property(lambda self: self._albedo)
    normal = property(lambda self: self._normal)
    noisy = property(lambda self: self._noisy)
    samples = property(lambda self: self._samples)
    placement = property(lambda self: self._placement)


def _frame_array(pointer, frame, channels=None):
    """A copy of a frame's buffer as an (H, W, channels) float32 array."""
    height, width = lib.ptr_frame_height(frame), lib.ptr_frame_width(frame)
    channels = channels or lib.ptr_frame_channels(frame)
    return np.ctypeslib.as_array(pointer, shape=(height, width, channels)).copy()


def save(path, image, view=None, context=None, depth=None, dither=False, display=None,
         look=None, exposure=0.0, bake_view=False, placement=None):
    """Writes an image (an array (H, W, 3) or (H, W, 4), scene-linear, RGBA
    premultiplied, or a ptr.Frame) through ptr's writers, by the path's
    extension: EXR as floats; other formats (PNG, JPEG, TIFF, ...) through
    OpenImageIO with the OpenColorIO view applied. The options are the
    command line's of the same names: depth ("8", "16", "half" or "float";
    None: the format's default), dither (8 bits), display, view (such as
    "Standard" or "Raw") and look of the context's OpenColorIO config
    (None: its defaults, no look), exposure (stops before the view, -64 to
    64) and bake_view (the view applied to a float format too).

    A Frame is written as the command line writes the same render: its
    passes, noisy colour and metadata in an EXR, a region as its part of
    the image. An array is the pixels alone, placed by placement (a
    ptr.Placement or (x, y, image_width, image_height): the array as that
    part of a larger image, as a Frame's placement says; an EXR records it,
    a PNG holds the pixels alone); None: the whole image."""
    context = _context(context)
    options = _native.SaveOptions(_native.text(depth), int(bool(dither)), _native.text(display),
                                  _native.text(view), _native.text(look), float(exposure),
                                  int(bool(bake_view)))
    err = _native.ErrorInfo()
    if isinstance(image, Frame):
        if placement is not None:
            raise ValueError("placement: a Frame keeps its own")
        _write(context, path, image._memory.handle, options, err)
        return
    image = np.asarray(image)
    if image.ndim != 3 or image.shape[2] not in (3, 4):
        raise ValueError("image: shape %s, not (H, W, 3) or (H, W, 4)" % (image.shape,))
    pixels = _contiguous(image, np.float32)
    corner = _native.whole_numbers("placement", placement, 4) if placement is not None else None
    frame = ctypes.c_void_p()
    _check(lib.ptr_frame_new(pixels.shape[1], pixels.shape[0], pixels.shape[2],
                             pixels.ctypes.data, ctypes.byref(frame), ctypes.byref(err)), err)
    try:
        if corner is not None:
            _check(lib.ptr_frame_set_placement(frame, *corner, ctypes.byref(err)), err)
        _write(context, path, frame, options, err)
    finally:
        lib.ptr_frame_free(frame)


def _write(context, path, frame, options, err):
    """Saves a C frame through the context, one call of it at a time."""
    with context._lock:
        status = lib.ptr_frame_save(context._handle, _native.text(path), frame,
                                    ctypes.byref(options), ctypes.byref(err))
    _check(status, err)
