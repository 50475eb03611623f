/* What the objects of the public API (include/ptr/ptr.h) hold, shared by
 * the files that implement it. */
#ifndef PTR_API_INTERNAL_H
#define PTR_API_INTERNAL_H

#include "api/pipeline.h"
#include "color/color.h"
#include "denoise/denoise.h"
#include "image/image.h"
#include "import_options.h"
#include "ptr/ptr.h"

struct PtrContext {
    int threads;           /* 0: one per online CPU */
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
    /* The hash of the first build, taken in the file's order: later builds
     * see the tree's, even after one that failed. */
    int hash_valid;
    uint64_t scene_hash;
    int prepared_valid;
    PtrPreparedFor prepared_for;
    PtrPrepared prepared;
};

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
