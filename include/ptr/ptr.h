/* ptr: an offline path tracer of sphere sets, as a library.
 *
 * One render: create a context (ptr_context_new), make a scene from a file
 * (ptr_scene_load) or from arrays (ptr_scene_from_arrays), render it
 * (ptr_scene_render) into a frame of scene-linear floats, save the frame
 * (ptr_frame_save) or read its pixels (ptr_frame_pixels), and free each
 * object with its own ptr_*_free. The image ptr_scene_render returns is the
 * one the command line `ptr` writes to EXR for the same scene and options,
 * float for float.
 *
 * Errors: every call that can fail returns a PtrStatus and takes a last
 * parameter PtrErrorInfo *err, which the caller owns (usually on its stack)
 * and may pass as NULL. On failure the call fills err with the same code
 * and one line naming the file (or the option) and the problem; on success
 * it leaves err alone. An object handed through an out-parameter is set
 * only on success.
 *
 * NULL: a call given NULL for an object, a path or an out-parameter it
 * needs fails with PTR_STATUS_USAGE (the options structures and err may be
 * NULL where said); the accessors (ptr_frame_width, ptr_scene_sphere_count,
 * ...) answer 0, or NULL, for a NULL object; the ptr_*_free take NULL.
 *
 * Ownership: no call keeps a pointer the caller passed beyond its return
 * (arrays, strings and structures are copied), except where a comment
 * below says otherwise.
 *
 * Threads: the contexts are independent: several in one process, used from
 * different threads, never see each other's settings. One context, and the
 * scenes made through it, serve one call at a time.
 *
 * Files of ptr's installation: the image module (OpenImageIO, which every
 * format but EXR goes through) is looked for in ../lib/ptr from the folder
 * of the file holding ptr's code, and the denoiser's default weights in
 * ../share/ptr/weights from there, then under the prefix ptr was built for.
 * With libptr.so that file is the library, wherever installed; with the
 * static libptr.a it is the program linked with it, so the module is found
 * only when that program sits in a bin/ beside ptr's lib/ptr (a program
 * elsewhere saves EXR alone: other formats fail with PTR_STATUS_INSTALL),
 * and the weights there or in the prefix (PtrContextOptions.weights_dir
 * names another folder). */
#ifndef PTR_PTR_H
#define PTR_PTR_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Raised whenever a change breaks a program built against an earlier
 * version; the shared library's SONAME carries it (libptr.so.1). */
#define PTR_API_VERSION 1

#if defined(__GNUC__)
#define PTR_PUBLIC __attribute__((visibility("default")))
#else
#define PTR_PUBLIC
#endif

/* The same numbers as the command line's exit codes. */
typedef enum PtrStatus {
    PTR_STATUS_OK = 0,
    PTR_STATUS_INTERNAL = 1,
    PTR_STATUS_USAGE = 2,             /* a bad argument or option value */
    PTR_STATUS_SCENE_UNREADABLE = 3,  /* a scene file cannot be read */
    PTR_STATUS_SCENE_INVALID = 4,     /* a scene is malformed or invalid */
    PTR_STATUS_OUTPUT = 5,            /* an image cannot be written */
    PTR_STATUS_NOMEM = 6,
    PTR_STATUS_COLOR = 7,             /* the OpenColorIO config or view cannot be used */
    PTR_STATUS_CANCELLED = 8,         /* the progress callback asked to stop */
    PTR_STATUS_INSTALL = 10,          /* a module or weight file of ptr cannot be loaded */
} PtrStatus;

typedef struct PtrErrorInfo {
    PtrStatus code;
    char message[512]; /* one line, NUL-terminated */
} PtrErrorInfo;

/* ptr's version, "MAJOR.MINOR.PATCH". */
PTR_PUBLIC const char *ptr_version(void);

/* ---- Contexts ---------------------------------------------------------- */

/* What a context owns: what the command line takes from its process (the
 * CPU level, the threads, the modules and the colour configuration). */
typedef struct PtrContext PtrContext;

typedef struct PtrContextOptions {
    int threads;             /* render threads, at most 1024; 0: one per CPU the process may run on */
    /* The highest CPU level used ("none", "sse41", "avx2", "avx512"), as
     * --cpumask takes it; NULL: the CPU's, capped by $PTR_CPUMASK. */
    const char *cpu_cap;
    /* The denoiser's weights; NULL: $PTR_WEIGHTS_DIR, else the installed. */
    const char *weights_dir;
    /* An OpenColorIO config file for ptr_frame_save's views; NULL: ptr's. */
    const char *ocio_config;
} PtrContextOptions;

/* options may be NULL: all defaults. */
PTR_PUBLIC PtrStatus ptr_context_new(const PtrContextOptions *options, PtrContext **out,
                                     PtrErrorInfo *err);
PTR_PUBLIC void ptr_context_free(PtrContext *context);

/* ---- Scenes ------------------------------------------------------------ */

typedef struct PtrSceneHandle PtrSceneHandle;

/* A camera in world coordinates (--lookfrom, --lookat, ...). */
typedef struct PtrCameraDesc {
    double lookfrom[3], lookat[3], up[3];
    double vfov_deg;       /* vertical field of view */
    double ortho_height;   /* above 0: orthographic, the view this high (vfov unused) */
    double aperture;       /* lens diameter; 0: a pinhole */
    double focus_distance; /* 0: the distance from lookfrom to lookat */
} PtrCameraDesc;

/* How a file is read, as the command line's options of the same names say
 * (README's table); zero for each is the command line's default. */
typedef struct PtrLoadOptions {
    const char *camera_name;      /* --camera */
    const PtrCameraDesc *camera;  /* --lookfrom ...: replaces the file's */
    int orthographic;             /* --auto-camera orthographic */
    int fit_all_objects;          /* --fit-all-objects (OBJ) */
    const char *select;           /* --select (structures) */
    int drop_hydrogens;           /* --hydrogens off */
    const char *assembly;         /* --assembly */
    size_t model;                 /* a structure's model, 1 the first; 0: the first */
    double orbit_degrees;         /* the camera's turn about +Y (a turntable's frame) */
    /* The width and height the image will have, which frame the automatic
     * camera of a scene without one, as --width and --height do; 0: the
     * scene's. */
    int width, height;
    const char *sky;              /* --sky: "gradient", "black" or "R,G,B"; NULL: the file's */
    /* --color-by: a quantity each sphere has, mapped through the colormap
     * onto the colour that replaces its base colour (a glTF instance or
     * point attribute such as _BFACTOR, any case, _ optional; a structure's
     * bfactor or occupancy), or a structure's colour scheme (element,
     * chain, entity, residue, secondary), which takes no colormap or range.
     * NULL: none (a structure's elements). A file without the quantity is
     * PTR_STATUS_SCENE_INVALID. The colour bar (--color-bar) is the command
     * line's alone: ptr_scene_color_range says what range was mapped. */
    const char *color_by;
    /* --colormap: "viridis", "magma", "inferno", "plasma", "cividis" or
     * "coolwarm"; NULL: viridis. */
    const char *colormap;
    /* --color-range MIN,MAX (finite, MIN below MAX): the values mapped to
     * the colormap's ends, others clamped; both 0: the values' own range. */
    double color_range[2];
} PtrLoadOptions;

/* Reads a scene file of any format ptr reads (glTF, OBJ, PDB, mmCIF, ...,
 * by its extension; docs/scenes.md). options may be NULL. The import's
 * warnings (what of the file was left out or guessed), which the command
 * line prints as "ptr: warning: ...", stay with the scene:
 * ptr_scene_warning. */
PTR_PUBLIC PtrStatus ptr_scene_load(PtrContext *context, const char *path,
                                    const PtrLoadOptions *options, PtrSceneHandle **out,
                                    PtrErrorInfo *err);

/* The number of warnings the scene's import gave (0 for a scene of
 * arrays), and warning index (0 first), one line kept by the scene; NULL
 * for an index beyond them. */
PTR_PUBLIC size_t ptr_scene_warning_count(const PtrSceneHandle *scene);
PTR_PUBLIC const char *ptr_scene_warning(const PtrSceneHandle *scene, size_t index);

/* The range a load with color_by mapped onto the colormap's ends
 * (PtrLoadOptions.color_range, or the values' own range, which the
 * command line prints), for a colour bar of the caller's: 1 with *from and
 * *to set; 0, leaving them, for a scene without a quantity mapped (no
 * color_by, or a colour scheme). from and to may be NULL. */
PTR_PUBLIC int ptr_scene_color_range(const PtrSceneHandle *scene, double *from, double *to);

typedef enum PtrMaterialType {
    PTR_MATERIAL_TYPE_DIFFUSE,    /* albedo */
    PTR_MATERIAL_TYPE_METAL,      /* albedo, fuzz (0: a mirror) */
    PTR_MATERIAL_TYPE_DIELECTRIC, /* albedo (the attenuation), ior */
    PTR_MATERIAL_TYPE_EMISSIVE,   /* a diffuse surface that emits: albedo, emission */
} PtrMaterialType;

/* A material as the scene holds it; every type may emit. Its values are
 * finite, the emission is not negative, and a dielectric's ior is above
 * 0. */
typedef struct PtrMaterialDesc {
    PtrMaterialType type;
    float albedo[3];
    float fuzz;
    float ior;
    float emission[3]; /* radiance, seen from both sides */
} PtrMaterialDesc;

/* Spheres as arrays, each of count entries and contiguous. */
typedef struct PtrSceneArrays {
    size_t count;
    /* Centres, x y z each (3 x count), in float or in double: one of the
     * two, the other NULL. */
    const float *centers;
    const double *centers_f64;
    const float *radii;                /* each finite and >= 0 */
    /* Each sphere's index into materials; NULL: 0 for every sphere. */
    const uint32_t *material_indices;
    /* Each sphere's own colour, r g b (3 x count), each clamped to [0, 1],
     * multiplying its material's albedo; NULL: none (white). */
    const float *colors;
    /* NULL with material_count 0: one grey diffuse material (albedo 0.5). */
    const PtrMaterialDesc *materials;
    size_t material_count;
    /* NULL: a camera framing the spheres from +Z, as for a file without
     * one. */
    const PtrCameraDesc *camera;
    int orthographic;      /* the automatic camera's projection */
    int width, height;     /* the image size the scene suggests; 0: none */
    const char *sky;       /* as PtrLoadOptions.sky; NULL: the gradient */
} PtrSceneArrays;

/* Makes a scene of arrays, copied: the scene is the same as a file of the
 * same spheres gives (the same coordinates relative to the camera, the same
 * spheres kept in double). A NaN or infinite coordinate, a negative or NaN
 * radius, a NaN colour or a material index out of the table (index 0 alone
 * without one) is PTR_STATUS_USAGE naming the sphere; a material the file
 * importers would refuse (PtrMaterialDesc) is PTR_STATUS_USAGE naming the
 * material by its index, and a camera whose lookfrom, lookat or up is not
 * finite PTR_STATUS_USAGE too (as for ptr_scene_load). */
PTR_PUBLIC PtrStatus ptr_scene_from_arrays(PtrContext *context, const PtrSceneArrays *arrays,
                                           PtrSceneHandle **out, PtrErrorInfo *err);

/* The number of spheres. */
PTR_PUBLIC size_t ptr_scene_sphere_count(const PtrSceneHandle *scene);

PTR_PUBLIC void ptr_scene_handle_free(PtrSceneHandle *scene);

/* ---- Rendering --------------------------------------------------------- */

/* What a render is asked for, as the command line's options of the same
 * names (README's table). Fill with ptr_render_options_default, then
 * change what differs. The strings are the options' values as the command
 * line takes them; NULL: its default. The numbers have the command line's
 * ranges, a value outside them PTR_STATUS_USAGE: width and height 1 to
 * 65536 (or 0), samples 1 to 2^30 (first_sample + samples at most 2^30),
 * max_depth 1 to 100000, min_samples 2 to 2^30, threads at most 1024,
 * noise_threshold 0 or above 0 up to 10^6, and only with first_sample 0,
 * a region inside the image, time_budget 0 or above 0 up to 10^7. */
typedef struct PtrRenderOptions {
    int width, height;      /* 0: the scene's, else 800 wide (--width, --height) */
    uint32_t samples;       /* per pixel (--samples) */
    uint32_t first_sample;  /* the first sample's index (--sample-range) */
    uint64_t seed;          /* --seed */
    int max_depth;          /* --max-depth */
    int threads;            /* 0: the context's */
    const char *integrator; /* --integrator: "auto", "paths", "bundles" */
    const char *kernel;     /* "c" (--c) or "asm" (--asm); NULL: the fastest */
    const char *cpu_cap;    /* lowers the context's level for this render (--cpumask) */
    const char *accel;      /* --accel: "auto", "brute", "bvh" */
    const char *sampler;    /* --sampler */
    int direct_lighting;    /* --direct-lighting: 1 on (the default), 0 off */
    float noise_threshold;  /* --noise-threshold; 0: off */
    uint32_t min_samples;   /* --min-samples */
    int transparent;        /* --transparent: RGBA, alpha the covered share */
    int passes;             /* --passes albedo,normal: the frame keeps both */
    /* --denoise: "fast", "balanced" or "high"; NULL: no denoising. The
     * frame's colour is then the denoised one (the passes are taken). */
    const char *denoise;
    const char *sky;        /* replaces the scene's sky; NULL: the scene's */
    /* Replaces the scene's camera for this render; NULL: the scene's. The
     * scene's coordinates stay relative to its own camera: the pixels are
     * the command line's for --lookfrom ... only when the camera is given
     * where the scene is made (PtrLoadOptions.camera, PtrSceneArrays.camera),
     * which puts the coordinates relative to it. */
    const PtrCameraDesc *camera;
    /* --region X0,Y0,X1,Y1: the pixels rendered, columns x0 to x1 - 1 and
     * rows y0 to y1 - 1 of the image from its top left (0 <= x0 < x1,
     * 0 <= y0 < y1); all 0: the whole image. The frame holds the region's
     * pixels alone (ptr_frame_width and ptr_frame_height are its size;
     * ptr_frame_placement says where it lies), as the command line's EXR
     * holds them, and saves them as that part of the image. */
    int region[4];
    /* --time: seconds, after which the render stops at the end of the pass
     * under way, with the samples done (ptr_frame_samples); 0: none. */
    double time_budget;
} PtrRenderOptions;

PTR_PUBLIC void ptr_render_options_default(PtrRenderOptions *options);

typedef struct PtrProgressInfo {
    uint32_t samples_done, samples_total;
    double fraction; /* of all samples, counting the pass under way */
    double elapsed;  /* seconds */
} PtrProgressInfo;

/* Called about ten times a second on the thread that called
 * ptr_scene_render: nonzero stops the render after the pass under way,
 * which then fails with PTR_STATUS_CANCELLED. */
typedef int (*PtrProgressCallback)(void *user, const PtrProgressInfo *progress);

/* The image a render made: scene-linear floats, rows top to bottom, with
 * what the command line's EXR of it holds (the samples taken, the scene's
 * name and hash, the import's and the tree's seconds, ...). */
typedef struct PtrFrame PtrFrame;

/* Renders the scene. progress may be NULL. The first render of a scene
 * builds its tree, which later renders reuse (the spheres are then in the
 * tree's order: on exactly equal hit distances, a later render with another
 * accel, kernel or integrator may show the other sphere). */
PTR_PUBLIC PtrStatus ptr_scene_render(PtrContext *context, PtrSceneHandle *scene,
                                      const PtrRenderOptions *options,
                                      PtrProgressCallback progress, void *user, PtrFrame **out,
                                      PtrErrorInfo *err);

PTR_PUBLIC int ptr_frame_width(const PtrFrame *frame);
PTR_PUBLIC int ptr_frame_height(const PtrFrame *frame);
/* 3 (RGB) or 4 (RGBA, with a transparent background: the colour
 * premultiplied by alpha, as EXR stores it). */
PTR_PUBLIC int ptr_frame_channels(const PtrFrame *frame);
/* width x height x channels floats, kept by the frame. */
PTR_PUBLIC const float *ptr_frame_pixels(const PtrFrame *frame);
/* The albedo and normal passes, width x height x 3 floats; NULL unless the
 * render asked for passes or denoising. */
PTR_PUBLIC const float *ptr_frame_albedo(const PtrFrame *frame);
PTR_PUBLIC const float *ptr_frame_normal(const PtrFrame *frame);
/* A denoised frame's colour before denoising, width x height x 3 floats,
 * which an EXR keeps as the layer "noisy"; NULL unless denoised. */
PTR_PUBLIC const float *ptr_frame_noisy(const PtrFrame *frame);
/* The samples per pixel the render took: those asked for, or fewer when
 * its time budget ran out (with adaptive sampling, a pixel may stop
 * earlier still). */
PTR_PUBLIC uint32_t ptr_frame_samples(const PtrFrame *frame);
/* Where the frame's pixels lie in the image rendered: the column and row of
 * their top left corner, and the image's width and height (0, 0 and the
 * frame's own size without a region, or as ptr_frame_set_placement put
 * them). Each pointer may be NULL; all are set to 0 for a NULL frame. */
PTR_PUBLIC void ptr_frame_placement(const PtrFrame *frame, int *x, int *y, int *image_width,
                                    int *image_height);

/* A frame of pixels given (width x height x channels floats, 3: RGB, 4:
 * RGBA with the colour premultiplied), copied: an image made elsewhere, or
 * changed after a render, to save. Its metadata name no scene. */
PTR_PUBLIC PtrStatus ptr_frame_new(int width, int height, int channels, const float *pixels,
                                   PtrFrame **out, PtrErrorInfo *err);

/* Places the frame's pixels in a larger image, as a render of a region is
 * (ptr_frame_placement): their top left corner at column x and row y of an
 * image image_width by image_height, which a saved EXR records (its data window
 * within that display window) as the command line's EXR of --region does;
 * a format without windows, such as PNG, holds the pixels alone. The frame
 * must lie inside the image (0 <= x, x + ptr_frame_width <= image_width,
 * likewise down), of at most 65536 pixels a side: else PTR_STATUS_USAGE. */
PTR_PUBLIC PtrStatus ptr_frame_set_placement(PtrFrame *frame, int x, int y, int image_width,
                                             int image_height, PtrErrorInfo *err);

/* How a frame is stored and shown, as the command line's options of the
 * same names; zero for each (and NULL for the strings) is the command
 * line's default. */
typedef struct PtrSaveOptions {
    /* --depth: "8", "16", "half" or "float", which the format must store;
     * NULL: float for EXR and HDR, else 8 bits. */
    const char *depth;
    int dither;            /* --dither: 8 bits dithered before rounding */
    /* --display, --view, --look: of the context's OpenColorIO config; NULL:
     * its default display, that display's default view, no look. */
    const char *display;
    const char *view;
    const char *look;
    float exposure;        /* --exposure: stops before the view, -64 to 64 */
    int bake_view;         /* --bake-view: float formats too get the view applied */
} PtrSaveOptions;

/* Writes the frame through ptr's writers, by the path's extension: EXR
 * (scene-linear floats, with the passes, the noisy colour of a denoised
 * frame and the render's metadata) directly, any other format through the
 * OpenImageIO module, the view applied (integer formats, and float ones
 * with bake_view). options may be NULL: all defaults; a value outside its
 * range, or a depth the format cannot store, is PTR_STATUS_USAGE, a
 * display, view or look the config lacks too. The file is replaced
 * atomically. */
PTR_PUBLIC PtrStatus ptr_frame_save(PtrContext *context, const char *path,
                                    const PtrFrame *frame, const PtrSaveOptions *options,
                                    PtrErrorInfo *err);

PTR_PUBLIC void ptr_frame_free(PtrFrame *frame);

#ifdef __cplusplus
}
#endif

#endif /* PTR_PTR_H */
