/* The command line's options, parsed. */
#ifndef PTR_CLI_OPTIONS_H
#define PTR_CLI_OPTIONS_H

#include <stdint.h>

#include "accel/accel.h"
#include "accel/isect.h"
#include "api/output.h"
#include "api/pipeline.h"
#include "base/cpu.h"
#include "base/result.h"
#include "denoise/denoise.h"
#include "importer.h"
#include "render/render.h"
#include "scene/colormap.h"
#include "scene/scene.h"

/* At most this many frames in one sequence. */
enum { PTR_MAX_FRAMES = 1000000 };

/* What the command line asks printed instead of a render. */
typedef enum PtrPrintRequest {
    PTR_PRINT_NOTHING,
    PTR_PRINT_HELP,
    PTR_PRINT_VERSION,
    PTR_PRINT_DISPATCH,
} PtrPrintRequest;

/* The live view (app/live_view.h). */
typedef struct PtrLiveView PtrLiveView;

typedef struct PtrOptions {
    char **inputs;          /* scenes; for `ptr merge`, the parts */
    int input_count;
    int merge;              /* `ptr merge PART... -o OUT`, and `ptr denoise` */
    int denoise_command;    /* `ptr denoise IN.exr -o OUT`: a merge of one part, denoised */
    const char *output;     /* a file, a folder, or a pattern with {name} */
    const char *camera_name;
    PtrCameraSpec camera;   /* --lookfrom ... */
    int has_camera;
    PtrProjection auto_camera; /* the projection of a scene without a camera */
    int fit_all_objects;
    unsigned structure_select; /* PtrImportOptions.structure_select */
    PtrSwitch hydrogens;
    const char *structure_assembly; /* PtrImportOptions.structure_assembly */
    const char *color_by;   /* --color-by: the attribute; NULL: none */
    const PtrColormap *colormap;
    int has_color_range;
    double color_range[2];  /* --color-range MIN,MAX */
    const char *color_bar;  /* --color-bar FILE */
    uint32_t samples;
    uint32_t sample_first;  /* --sample-range START:END sets both */
    uint64_t seed;
    int width, height;      /* 0: from the scene */
    int transparent;        /* alpha 0 where camera rays meet no sphere */
    int passes;             /* --passes albedo,normal: EXR layers of both passes */
    const char *denoise;    /* --denoise's quality as given; NULL: no denoising */
    PtrDenoiseQuality denoise_quality;
    PtrRegion region;       /* all zero: the whole image */
    int max_depth;
    PtrSamplerKind sampler;
    PtrSwitch direct_lighting;
    float noise_threshold;  /* adaptive sampling; 0: off */
    uint32_t min_samples;
    int threads;
    int has_sky;
    PtrSky sky;
    PtrKernel kernel;
    PtrCpuLevel cpu_level;  /* the CPU's, capped by $PTR_CPUMASK, then by --cpumask */
    PtrIntegrator integrator; /* --integrator, else $PTR_INTEGRATOR, else auto */
    PtrAccelChoice accel;
    PtrDepth depth;
    const char *ocio_config, *display, *view, *look;
    float exposure;
    int bake_view;
    int dither;
    double time_budget;     /* seconds; 0: none */
    int preview;
    int watch;
    const char *live, *tev; /* [HOST:]PORT of the live view, of tev */
    int has_frames;         /* --frames A:B:STEP */
    long frame_first, frame_last, frame_step;
    int turntable;          /* frames in a full turn; 0: none */
    int skip_existing;
    double orbit_degrees;   /* the camera's turn in the frame being rendered */
    size_t structure_model; /* the structure's model the frame renders (1 the first); 0: none */
    /* Not an option: the structure whose models the frames render, parsed
     * once for all of them; NULL: none, or each import reads its scene. */
    const PtrStructureFile *structure_file;
    int json;
    int quiet;
    int dump_scene;
    int list_views;
    PtrPrintRequest print;  /* --help, --version, --print-dispatch: options after it are not read */
    /* Not an option: the image module's loader of the run, which
     * ptr_cli_main owns (NULL from ptr_options_parse). */
    PtrImageLoader *images;
    /* Not an option either: the denoiser of the run, with --denoise, which
     * ptr_cli_main owns too (NULL from ptr_options_parse). */
    PtrDenoiser *denoiser;
    /* Not an option either: the live view of the renders, with --live or
     * --tev, which the run that renders owns (NULL otherwise). */
    PtrLiveView *live_view;
} PtrOptions;

/* What the importers need of the options. */
PtrImportOptions ptr_options_import(const PtrOptions *options, PtrStrings *dependencies);

/* The output's settings the options give, color being the run's
 * configuration with their display, view, look and exposure selected. */
PtrOutputSettings ptr_options_output(const PtrOptions *options, const PtrColor *color);

/* Parses argv: PTR_OK, with options->print saying whether to print something
 * instead of rendering, else PTR_ERR_USAGE with err saying what is wrong. */
PtrResult ptr_options_parse(int argc, char **argv, PtrOptions *options, PtrError *err);

#endif /* PTR_CLI_OPTIONS_H */
