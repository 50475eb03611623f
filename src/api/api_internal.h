/* What the objects of the public API (include/ptr/ptr.h) hold, shared by
 * the files that implement it, and the entries that its renders and saves
 * are thin wrappers over, which the command line (app/job.c) renders and
 * writes through: one path from a loaded scene to a file for both. */
#ifndef PTR_API_INTERNAL_H
#define PTR_API_INTERNAL_H

#include <signal.h>

#include "api/output.h"
#include "api/pipeline.h"
#include "color/color.h"
#include "denoise/denoise.h"
#include "image/image.h"
#include "import_options.h"
#include "ptr/ptr.h"

struct PtrContext {
    int threads;           /* 0: one per CPU it may run on */
    PtrCpuLevel cpu_level; /* the CPU's, capped by $PTR_CPUMASK, then by the options */
    char *weights_dir;     /* NULL: the denoiser's default */
    PtrImageLoader *images;
    PtrColor *color;
    /* Loaded on the first render that asks for each quality. */
    PtrDenoiser *denoisers[PTR_DENOISE_HIGH + 1];
};

/* The choices a scene's tree was built for: a render asking for others
 * builds again. */
typedef struct PtrPreparedFor {
    PtrKernel kernel;
    PtrCpuLevel level;
    PtrIntegrator integrator;
    PtrAccelChoice accel;
} PtrPreparedFor;

struct PtrSceneHandle {
    PtrScene scene;
    char *name;            /* the file, or "arrays": what messages and metadata name */
    double import_seconds;
    PtrStrings warnings;   /* the import's, for the caller to read */
    /* Whether a quantity was mapped onto a colormap, and from what to what. */
    int color_mapped;
    double color_from, color_to;
    /* The hash of the first build, taken in the file's order: later builds
     * see the tree's, even after one that failed. */
    int hash_valid;
    uint64_t scene_hash;
    int prepared_valid;
    PtrPreparedFor prepared_for;
    PtrPrepared prepared;
};

/* A scene adopted by a new handle named name (the file, or "arrays"),
 * which frees it; on failure the scene is freed. */
PtrResult ptr_api_scene_adopt(PtrScene *scene, const char *name, double import_seconds,
                              PtrSceneHandle **out, PtrError *err);

/* A render as asked, its options read and checked: what ptr_scene_render
 * takes of PtrRenderOptions and the context, and the command line of its
 * options. */
typedef struct PtrRenderRequest {
    int width, height;     /* asked; 0: the scene's (ptr_choose_size) */
    int divisor;           /* the size divided by this (--preview); 1: none */
    PtrRegion region;      /* all zero: the whole image */
    uint32_t first_sample, samples;
    double time_budget;    /* seconds; 0: none */
    uint64_t seed;
    int max_depth;
    int threads;           /* 0: one per CPU it may run on */
    PtrKernel kernel;
    PtrCpuLevel level;
    PtrIntegrator integrator;
    PtrAccelChoice accel;
    PtrSamplerKind sampler;
    PtrSwitch direct_lighting;
    float noise_threshold; /* 0: off */
    uint32_t min_samples;
    int transparent, passes;
    const PtrDenoiser *denoiser; /* NULL: no denoising (the passes are then recorded) */
    const char *denoise_quality; /* its name, for the metadata */
    const PtrSky *sky;           /* this render's; NULL: the scene's */
    const PtrCamera *camera;     /* this render's; NULL: the scene's */
} PtrRenderRequest;

/* What the caller of a render adds to it, each NULL if not wanted. */
typedef struct PtrRenderHooks {
    const volatile sig_atomic_t *stop; /* set: stop after the pass under way */
    void (*report)(void *user, const PtrProgress *progress); /* about ten times a second */
    void *user;
    /* Called once the tree is ready, before the first pass, with the
     * render's settings: may set passes->pass_done (the live view). */
    void (*begin)(void *begin_user, const PtrScene *scene, const PtrAccel *accel,
                  const PtrRenderSettings *settings, PtrProgressiveOptions *passes);
    void *begin_user;
} PtrRenderHooks;

struct PtrFrame {
    PtrImageLayout layout; /* the pixels' size and place in the image */
    int channels;
    /* rgb: the colour shown, denoised once the frame is finished. */
    PtrFrameBuffers buffers;
    float *noisy;          /* the colour before denoising; NULL unless denoised */
    float *rgba;           /* the colour with alpha, with a transparent background; else NULL */
    char *scene_name;      /* info.scene_path */
    PtrProgressiveResult done; /* the samples taken, whether stopped, the statistics */
    /* The metadata of a saved image, without the pixels and the output's
     * settings; info.denoiser until the frame is finished. */
    PtrOutputInfo info;
};

/* Renders the scene as asked into a new frame (the scene's kernels and tree
 * built for the request unless already): a render stopped by hooks->stop
 * is a frame too, with done.stopped set. The image's size chosen
 * (ptr_choose_size) goes to *width and *height first, so that a caller can
 * report it whatever fails. PTR_ERR_USAGE for a region outside the image. */
PtrResult ptr_api_render(PtrSceneHandle *scene, const PtrRenderRequest *request,
                         const PtrRenderHooks *hooks, int *width, int *height, PtrFrame **out,
                         PtrError *err);
/* Denoises the frame's colour if its render asked for it, keeping the
 * noisy one; name: what a message names (the output, or the scene). */
PtrResult ptr_api_frame_finish(PtrFrame *frame, const char *name, PtrError *err);
/* Writes the frame to path as output says; an EXR keeps the passes, the
 * noisy colour and the samples counts the frame has. */
PtrResult ptr_api_frame_write(PtrImageLoader *images, const char *path, const PtrFrame *frame,
                              const PtrOutputSettings *output, PtrError *err);

/* A public camera as the command line's (the importers' PtrCameraSpec);
 * PTR_ERR_USAGE if lookfrom, lookat or up is not finite. */
PtrResult ptr_api_camera_spec(const PtrCameraDesc *desc, PtrCameraSpec *spec, PtrError *err);

/* Copies an internal error into the caller's (which may be NULL) and
 * returns its code as a status. */
PtrStatus ptr_api_fail(PtrErrorInfo *err, const PtrError *error);
/* PTR_STATUS_USAGE with message, into the caller's err (which may be NULL). */
PtrStatus ptr_api_usage(PtrErrorInfo *err, const char *message);

/* PTR_ERR_USAGE naming the field name if value is outside number's range. */
PtrResult ptr_api_check_number(const char *name, PtrRenderNumber number, long long value,
                               PtrError *err);

#endif /* PTR_API_INTERNAL_H */
