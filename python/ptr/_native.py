"""The C API of libptr (include/ptr/ptr.h) through ctypes: the library found,
its structures and its functions' signatures. Nothing here is public."""

import ctypes
import os

PTR_API_VERSION = 1

STATUS_OK = 0
STATUS_USAGE = 2
STATUS_CANCELLED = 8


def _candidates():
    """Where libptr.so is looked for, in order: $PTR_LIBRARY alone if set;
    else the prefix this package was installed into (PREFIX/lib/pythonX.Y/
    site-packages/ptr: PREFIX/lib three folders up), the build trees beside
    python/ in the source tree, /usr/local and /usr; then the system's
    search path."""
    name = "libptr.so.%d" % PTR_API_VERSION
    given = os.environ.get("PTR_LIBRARY")
    if given:
        # A path, even a bare name: ctypes would search the system's path
        # for a name without a slash.
        yield os.path.abspath(given)
        return
    here = os.path.dirname(os.path.abspath(__file__))
    yield os.path.normpath(os.path.join(here, "..", "..", "..", name))
    source = os.path.dirname(os.path.dirname(here))
    for build in ("build", "build-release", "build-debug"):
        yield os.path.join(source, build, "lib", name)
    for prefix in ("/usr/local", "/usr"):
        yield os.path.join(prefix, "lib", name)
    yield name


def _load():
    tried = []
    for path in _candidates():
        if os.sep in path and not os.path.exists(path):
            tried.append(path)
            continue
        try:
            return ctypes.CDLL(path)
        except OSError as error:
            tried.append("%s (%s)" % (path, error))
    raise ImportError("ptr: cannot find libptr.so (set PTR_LIBRARY to its path); tried: "
                      + ", ".join(tried))


class ErrorInfo(ctypes.Structure):
    _fields_ = [("code", ctypes.c_int), ("message", ctypes.c_char * 512)]


class ContextOptions(ctypes.Structure):
    _fields_ = [("threads", ctypes.c_int), ("cpu_cap", ctypes.c_char_p),
                ("weights_dir", ctypes.c_char_p), ("ocio_config", ctypes.c_char_p)]


class CameraDesc(ctypes.Structure):
    _fields_ = [("lookfrom", ctypes.c_double * 3), ("lookat", ctypes.c_double * 3),
                ("up", ctypes.c_double * 3), ("vfov_deg", ctypes.c_double),
                ("ortho_height", ctypes.c_double), ("aperture", ctypes.c_double),
                ("focus_distance", ctypes.c_double)]


class LoadOptions(ctypes.Structure):
    _fields_ = [("camera_name", ctypes.c_char_p), ("camera", ctypes.POINTER(CameraDesc)),
                ("orthographic", ctypes.c_int), ("fit_all_objects", ctypes.c_int),
                ("select", ctypes.c_char_p), ("drop_hydrogens", ctypes.c_int),
                ("assembly", ctypes.c_char_p), ("model", ctypes.c_size_t),
                ("orbit_degrees", ctypes.c_double), ("width", ctypes.c_int),
                ("height", ctypes.c_int), ("sky", ctypes.c_char_p),
                ("color_by", ctypes.c_char_p), ("colormap", ctypes.c_char_p),
                ("color_range", ctypes.c_double * 2)]


class MaterialDesc(ctypes.Structure):
    _fields_ = [("type", ctypes.c_int), ("albedo", ctypes.c_float * 3),
                ("fuzz", ctypes.c_float), ("ior", ctypes.c_float),
                ("emission", ctypes.c_float * 3)]


class SceneArrays(ctypes.Structure):
    _fields_ = [("count", ctypes.c_size_t), ("centers", ctypes.c_void_p),
                ("centers_f64", ctypes.c_void_p), ("radii", ctypes.c_void_p),
                ("material_indices", ctypes.c_void_p), ("colors", ctypes.c_void_p),
                ("materials", ctypes.POINTER(MaterialDesc)), ("material_count", ctypes.c_size_t),
                ("camera", ctypes.POINTER(CameraDesc)), ("orthographic", ctypes.c_int),
                ("width", ctypes.c_int), ("height", ctypes.c_int), ("sky", ctypes.c_char_p)]


class RenderOptions(ctypes.Structure):
    _fields_ = [("width", ctypes.c_int), ("height", ctypes.c_int),
                ("samples", ctypes.c_uint32), ("first_sample", ctypes.c_uint32),
                ("seed", ctypes.c_uint64), ("max_depth", ctypes.c_int),
                ("threads", ctypes.c_int), ("integrator", ctypes.c_char_p),
                ("kernel", ctypes.c_char_p), ("cpu_cap", ctypes.c_char_p),
                ("accel", ctypes.c_char_p), ("sampler", ctypes.c_char_p),
                ("direct_lighting", ctypes.c_int), ("noise_threshold", ctypes.c_float),
                ("min_samples", ctypes.c_uint32), ("transparent", ctypes.c_int),
                ("passes", ctypes.c_int), ("denoise", ctypes.c_char_p),
                ("sky", ctypes.c_char_p), ("camera", ctypes.POINTER(CameraDesc)),
                ("region", ctypes.c_int * 4), ("time_budget", ctypes.c_double)]


class SaveOptions(ctypes.Structure):
    _fields_ = [("depth", ctypes.c_char_p), ("dither", ctypes.c_int),
                ("display", ctypes.c_char_p), ("view", ctypes.c_char_p),
                ("look", ctypes.c_char_p), ("exposure", ctypes.c_float),
                ("bake_view", ctypes.c_int)]


class ProgressInfo(ctypes.Structure):
    _fields_ = [("samples_done", ctypes.c_uint32), ("samples_total", ctypes.c_uint32),
                ("fraction", ctypes.c_double), ("elapsed", ctypes.c_double)]


ProgressCallback = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(ProgressInfo))

lib = _load()

_P = ctypes.c_void_p
_ERR = ctypes.POINTER(ErrorInfo)
_SIGNATURES = {
    "ptr_version": (ctypes.c_char_p, []),
    "ptr_context_new": (ctypes.c_int, [ctypes.POINTER(ContextOptions), ctypes.POINTER(_P), _ERR]),
    "ptr_context_free": (None, [_P]),
    "ptr_scene_load": (ctypes.c_int, [_P, ctypes.c_char_p, ctypes.POINTER(LoadOptions),
                                      ctypes.POINTER(_P), _ERR]),
    "ptr_scene_from_arrays": (ctypes.c_int, [_P, ctypes.POINTER(SceneArrays),
                                             ctypes.POINTER(_P), _ERR]),
    "ptr_scene_sphere_count": (ctypes.c_size_t, [_P]),
    "ptr_scene_warning_count": (ctypes.c_size_t, [_P]),
    "ptr_scene_warning": (ctypes.c_char_p, [_P, ctypes.c_size_t]),
    "ptr_scene_color_range": (ctypes.c_int, [_P, ctypes.POINTER(ctypes.c_double),
                                             ctypes.POINTER(ctypes.c_double)]),
    "ptr_scene_handle_free": (None, [_P]),
    "ptr_render_options_default": (None, [ctypes.POINTER(RenderOptions)]),
    "ptr_scene_render": (ctypes.c_int, [_P, _P, ctypes.POINTER(RenderOptions), ProgressCallback,
                                        _P, ctypes.POINTER(_P), _ERR]),
    "ptr_frame_width": (ctypes.c_int, [_P]),
    "ptr_frame_height": (ctypes.c_int, [_P]),
    "ptr_frame_channels": (ctypes.c_int, [_P]),
    "ptr_frame_pixels": (ctypes.POINTER(ctypes.c_float), [_P]),
    "ptr_frame_albedo": (ctypes.POINTER(ctypes.c_float), [_P]),
    "ptr_frame_normal": (ctypes.POINTER(ctypes.c_float), [_P]),
    "ptr_frame_noisy": (ctypes.POINTER(ctypes.c_float), [_P]),
    "ptr_frame_samples": (ctypes.c_uint32, [_P]),
    "ptr_frame_placement": (None, [_P] + [ctypes.POINTER(ctypes.c_int)] * 4),
    "ptr_frame_new": (ctypes.c_int, [ctypes.c_int, ctypes.c_int, ctypes.c_int, _P,
                                     ctypes.POINTER(_P), _ERR]),
    "ptr_frame_set_placement": (ctypes.c_int, [_P] + [ctypes.c_int] * 4 + [_ERR]),
    "ptr_frame_save": (ctypes.c_int, [_P, ctypes.c_char_p, _P, ctypes.POINTER(SaveOptions),
                                      _ERR]),
    "ptr_frame_free": (None, [_P]),
}
for _name, (_result, _arguments) in _SIGNATURES.items():
    _function = getattr(lib, _name)
    _function.restype = _result
    _function.argtypes = _arguments


def text(value):
    """A str, bytes or path (or None) as the C API takes it: paths in the
    file system's encoding, bytes as they are."""
    return None if value is None else os.fsencode(value)


def set_whole(structure, name, value):
    """Sets an integer field of a ctypes structure, refusing (ValueError) a
    value the field's C type cannot hold rather than letting it wrap."""
    field_type = dict(structure._fields_)[name]
    bits = 8 * ctypes.sizeof(field_type)
    signed = field_type(-1).value < 0
    low, high = (-(1 << (bits - 1)), (1 << (bits - 1)) - 1) if signed else (0, (1 << bits) - 1)
    number = int(value)
    if number != value or not low <= number <= high:
        raise ValueError("%s: %r is not a whole number from %d to %d" % (name, value, low, high))
    setattr(structure, name, number)


def whole_numbers(name, values, count):
    """count whole numbers as a C int array, refusing (ValueError) another
    count or a value a C int cannot hold rather than letting it wrap."""
    numbers = list(values)
    if len(numbers) != count or not all(int(v) == v and -2 ** 31 <= v < 2 ** 31
                                        for v in numbers):
        raise ValueError("%s: %r is not %d whole numbers" % (name, values, count))
    return (ctypes.c_int * count)(*[int(v) for v in numbers])
