#include "cli.h"

#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "color/color.h"
#include "cpu.h"
#include "importer.h"
#include "isect.h"
#include "output.h"
#include "render.h"
#include "scene_json.h"
#include "version.h"

enum {
    DEFAULT_SAMPLES = 100,
    DEFAULT_MAX_DEPTH = 50,
    DEFAULT_WIDTH = 800,
    MAX_SIZE = 1 << 16,
    MAX_THREADS = 1024,
};

typedef struct Options {
    const char *scene_path;
    const char *output_path;
    const char *camera_name;
    uint32_t samples;
    uint64_t seed;
    int width, height; /* 0: from the scene */
    int max_depth;
    int threads;
    int has_sky;
    PtrSky sky;
    PtrKernel kernel;
    PtrDepth depth;
    const char *ocio_config, *display, *view, *look;
    float exposure;
    int bake_view;
    int dither;
    int quiet;
    int dump_scene;
    int list_views;
} Options;

enum {
    OPT_SAMPLES = 256, OPT_WIDTH, OPT_HEIGHT, OPT_THREADS, OPT_SEED, OPT_MAX_DEPTH,
    OPT_SKY, OPT_C, OPT_ASM, OPT_CPUMASK, OPT_PRINT_DISPATCH, OPT_CAMERA, OPT_DEPTH, OPT_DITHER,
    OPT_OCIO_CONFIG, OPT_DISPLAY, OPT_VIEW, OPT_LOOK, OPT_EXPOSURE, OPT_BAKE_VIEW, OPT_LIST_VIEWS,
    OPT_QUIET, OPT_DUMP_SCENE, OPT_HELP, OPT_VERSION,
};

static const struct option long_options[] = {
    { "output", required_argument, NULL, 'o' },
    { "samples", required_argument, NULL, OPT_SAMPLES },
    { "width", required_argument, NULL, OPT_WIDTH },
    { "height", required_argument, NULL, OPT_HEIGHT },
    { "threads", required_argument, NULL, OPT_THREADS },
    { "seed", required_argument, NULL, OPT_SEED },
    { "max-depth", required_argument, NULL, OPT_MAX_DEPTH },
    { "sky", required_argument, NULL, OPT_SKY },
    { "camera", required_argument, NULL, OPT_CAMERA },
    { "c", no_argument, NULL, OPT_C },
    { "asm", no_argument, NULL, OPT_ASM },
    { "cpumask", required_argument, NULL, OPT_CPUMASK },
    { "print-dispatch", no_argument, NULL, OPT_PRINT_DISPATCH },
    { "depth", required_argument, NULL, OPT_DEPTH },
    { "dither", no_argument, NULL, OPT_DITHER },
    { "ocio-config", required_argument, NULL, OPT_OCIO_CONFIG },
    { "display", required_argument, NULL, OPT_DISPLAY },
    { "view", required_argument, NULL, OPT_VIEW },
    { "look", required_argument, NULL, OPT_LOOK },
    { "exposure", required_argument, NULL, OPT_EXPOSURE },
    { "bake-view", no_argument, NULL, OPT_BAKE_VIEW },
    { "list-views", no_argument, NULL, OPT_LIST_VIEWS },
    { "quiet", no_argument, NULL, OPT_QUIET },
    { "dump-scene", no_argument, NULL, OPT_DUMP_SCENE },
    { "help", no_argument, NULL, OPT_HELP },
    { "version", no_argument, NULL, OPT_VERSION },
    { NULL, 0, NULL, 0 },
};

static void print_help(FILE *out)
{
    fprintf(out,
        "Usage: ptr SCENE -o OUTPUT [options]\n"
        "       ptr --dump-scene SCENE [--camera NAME] [--sky SKY]\n"
        "       ptr --list-views [--ocio-config FILE]\n"
        "Renders a scene of spheres (.gltf, .glb) with a path tracer.\n"
        "\n"
        "  -o, --output FILE     image to write; the extension picks the format:\n"
        "                        .exr, .hdr (scene-linear float), .png, .jpg, .tif\n"
        "                        (the display's view of it, 8 bits)\n"
        "      --samples N       samples per pixel (default %d)\n"
        "      --width W         image width; with only one of width/height the other\n"
        "      --height H        follows the camera's aspect ratio (default: the scene's\n"
        "                        resolution, else %d wide)\n"
        "      --threads N       render threads, 0 for one per CPU (default 0)\n"
        "      --seed S          random seed (default 1); the image depends only on it,\n"
        "                        never on the thread count\n"
        "      --max-depth D     rays per path at most (default %d)\n"
        "      --sky SKY         gradient, black or R,G,B (overrides the scene's sky)\n"
        "      --camera NAME     the glTF camera (node or camera name) to render through\n"
        "      --c               use the portable C intersector (the reference)\n"
        "      --asm             use the fastest assembly intersector; an error if none\n"
        "      --cpumask LEVEL   cap the instruction set: none, sse41, avx2 or avx512\n"
        "                        (also $PTR_CPUMASK; default: the best the CPU has)\n"
        "      --print-dispatch  print which intersector each level uses, and exit\n"
        "      --depth D         8, 16, half or float, where the format allows; integer\n"
        "                        depths hold the view, float ones scene-linear light\n"
        "      --dither          dither 8-bit output before rounding\n"
        "\n"
        "Colour (OpenColorIO):\n"
        "      --ocio-config F   config file (default: $OCIO, else ptr's own)\n"
        "      --display NAME    display (default: the config's, sRGB in ptr's own)\n"
        "      --view NAME       view (default: the config's, Standard in ptr's own)\n"
        "      --look NAME       look applied before the view\n"
        "      --exposure STOPS  exposure applied in scene-linear before the view\n"
        "      --bake-view       float outputs too get the view, not scene-linear light\n"
        "      --list-views      print the config's displays, views and looks, and exit\n"
        "      --quiet           no statistics line\n"
        "      --dump-scene      print the imported scene as JSON and render nothing\n"
        "      --help            this text\n"
        "      --version         version and intersector\n"
        "\n"
        "Exit codes:\n",
        DEFAULT_SAMPLES, DEFAULT_WIDTH, DEFAULT_MAX_DEPTH);
    for (int r = PTR_OK; r < PTR_RESULT_COUNT; r++)
        fprintf(out, "  %d  %s\n", ptr_result_exit_code((PtrResult)r),
                ptr_result_description((PtrResult)r));
}

static void print_dispatch(void)
{
    PtrCpuLevel detected = ptr_cpu_detected(), level = ptr_cpu_level();
    for (int l = PTR_CPU_NONE; l < PTR_CPU_LEVEL_COUNT; l++) {
        PtrIsectTable table;
        ptr_isect_init_level(&table, (PtrCpuLevel)l);
        printf("%-7s %-7s%s%s\n", ptr_cpu_level_name((PtrCpuLevel)l), table.name,
               l > (int)detected ? "  (not on this CPU)" : "",
               l == (int)level ? "  <- in use" : "");
    }
}

/* A whole decimal number in [lo, hi], nothing else. */
static int parse_uint(const char *text, uint64_t lo, uint64_t hi, uint64_t *out)
{
    if (*text < '0' || *text > '9')
        return 0;
    errno = 0;
    char *end;
    unsigned long long v = strtoull(text, &end, 10);
    if (errno || *end || v < lo || v > hi)
        return 0;
    *out = v;
    return 1;
}

static int usage_error(const char *option, const char *value, const char *expected)
{
    fprintf(stderr, "ptr: %s: '%s' is not %s (see ptr --help)\n", option, value, expected);
    return ptr_result_exit_code(PTR_ERR_USAGE);
}

/* Returns -1 to go on rendering, else the exit code to return. */
static int parse_options(int argc, char **argv, Options *o)
{
    const char *env_mask = getenv("PTR_CPUMASK");
    PtrCpuLevel env_cap;
    if (env_mask && !ptr_cpu_parse_level(env_mask, &env_cap))
        return usage_error("PTR_CPUMASK", env_mask, "none, sse41, avx2 or avx512");
    *o = (Options){
        .samples = DEFAULT_SAMPLES, .seed = 1, .max_depth = DEFAULT_MAX_DEPTH,
        .kernel = PTR_KERNEL_AUTO,
    };
    optind = 0; /* glibc: restart scanning, so the parser can run more than once */
    opterr = 0;
    int c;
    uint64_t v;
    while ((c = getopt_long(argc, argv, ":o:", long_options, NULL)) != -1) {
        const char *name = long_options[0].name;
        for (const struct option *lo = long_options; lo->name; lo++)
            if (lo->val == c)
                name = lo->name;
        char option[64];
        snprintf(option, sizeof option, "--%s", name);
        switch (c) {
        case 'o': o->output_path = optarg; break;
        case OPT_SAMPLES:
            if (!parse_uint(optarg, 1, 1u << 30, &v))
                return usage_error(option, optarg, "a whole number from 1 to 2^30");
            o->samples = (uint32_t)v;
            break;
        case OPT_WIDTH:
        case OPT_HEIGHT:
            if (!parse_uint(optarg, 1, MAX_SIZE, &v))
                return usage_error(option, optarg, "a whole number from 1 to 65536");
            *(c == OPT_WIDTH ? &o->width : &o->height) = (int)v;
            break;
        case OPT_THREADS:
            if (!parse_uint(optarg, 0, MAX_THREADS, &v))
                return usage_error(option, optarg, "a whole number from 0 to 1024");
            o->threads = (int)v;
            break;
        case OPT_SEED:
            if (!parse_uint(optarg, 0, UINT64_MAX, &v))
                return usage_error(option, optarg, "a whole number from 0 to 2^64-1");
            o->seed = v;
            break;
        case OPT_MAX_DEPTH:
            if (!parse_uint(optarg, 1, 100000, &v))
                return usage_error(option, optarg, "a whole number from 1 to 100000");
            o->max_depth = (int)v;
            break;
        case OPT_SKY:
            if (!ptr_sky_parse(optarg, &o->sky))
                return usage_error(option, optarg, "gradient, black or R,G,B (not negative)");
            o->has_sky = 1;
            break;
        case OPT_CAMERA: o->camera_name = optarg; break;
        case OPT_C: o->kernel = PTR_KERNEL_C; break;
        case OPT_ASM: o->kernel = PTR_KERNEL_ASM; break;
        case OPT_CPUMASK: {
            PtrCpuLevel cap;
            if (!ptr_cpu_parse_level(optarg, &cap))
                return usage_error(option, optarg, "none, sse41, avx2 or avx512");
            ptr_cpu_set_cap(cap);
            break;
        }
        case OPT_PRINT_DISPATCH: print_dispatch(); return 0;
        case OPT_DEPTH:
            if (!ptr_depth_parse(optarg, &o->depth))
                return usage_error(option, optarg, "8, 16, half or float");
            break;
        case OPT_DITHER: o->dither = 1; break;
        case OPT_OCIO_CONFIG: o->ocio_config = optarg; break;
        case OPT_DISPLAY: o->display = optarg; break;
        case OPT_VIEW: o->view = optarg; break;
        case OPT_LOOK: o->look = optarg; break;
        case OPT_EXPOSURE: {
            char *end;
            errno = 0;
            double stops = strtod(optarg, &end);
            if (errno || end == optarg || *end || !(fabs(stops) <= 64))
                return usage_error(option, optarg, "a number of stops from -64 to 64");
            o->exposure = (float)stops;
            break;
        }
        case OPT_BAKE_VIEW: o->bake_view = 1; break;
        case OPT_LIST_VIEWS: o->list_views = 1; break;
        case OPT_QUIET: o->quiet = 1; break;
        case OPT_DUMP_SCENE: o->dump_scene = 1; break;
        case OPT_HELP: print_help(stdout); return 0;
        case OPT_VERSION: {
            PtrIsectTable table;
            ptr_isect_init_level(&table, ptr_cpu_level());
            printf("ptr %s (intersector: %s)\n", PTR_VERSION, table.name);
            return 0;
        }
        case ':':
            fprintf(stderr, "ptr: %s needs a value (see ptr --help)\n", argv[optind - 1]);
            return ptr_result_exit_code(PTR_ERR_USAGE);
        default:
            fprintf(stderr, "ptr: unknown option '%s' (see ptr --help)\n", argv[optind - 1]);
            return ptr_result_exit_code(PTR_ERR_USAGE);
        }
    }
    if (o->list_views)
        return -1;
    if (optind >= argc || (!o->output_path && !o->dump_scene) || argc - optind > 1) {
        fprintf(stderr, "ptr: %s (usage: ptr SCENE -o OUTPUT [options]; see ptr --help)\n",
                optind >= argc ? "no scene file given"
                : !o->output_path ? "no output file given (-o)" : "more than one scene given");
        return ptr_result_exit_code(PTR_ERR_USAGE);
    }
    o->scene_path = argv[optind];
    return -1;
}

/* Width and height: the command line's, else the scene's, filling a missing
 * one from the camera's aspect ratio (else the scene's, else 16:9). */
static void choose_size(const Options *o, const PtrScene *scene, int *width, int *height)
{
    float aspect = scene->camera.aspect > 0.0f ? scene->camera.aspect
                   : scene->width > 0          ? (float)scene->width / (float)scene->height
                                               : 16.0f / 9.0f;
    int w = o->width, h = o->height;
    if (!w && !h && scene->width > 0) {
        w = scene->width;
        h = scene->height;
    }
    if (!w && !h)
        w = DEFAULT_WIDTH;
    if (!h)
        h = (int)lroundf((float)w / aspect);
    if (!w)
        w = (int)lroundf((float)h * aspect);
    *width = w < 1 ? 1 : w > MAX_SIZE ? MAX_SIZE : w;
    *height = h < 1 ? 1 : h > MAX_SIZE ? MAX_SIZE : h;
}

static int fail(const PtrError *err)
{
    fprintf(stderr, "ptr: %s\n", err->message);
    return ptr_result_exit_code(err->code);
}

/* Imports the scene, renders it and writes the image. */
static PtrResult render_scene(const Options *o, const PtrColor *color, PtrIsectTable *isect,
                              PtrError *err)
{
    PtrScene scene;
    PtrWarnings warnings = { 0 };
    PtrImportOptions import_options = { .camera_name = o->camera_name };
    PtrResult res = ptr_import_scene(o->scene_path, &import_options, &scene, &warnings, err);
    for (size_t i = 0; i < warnings.count; i++)
        fprintf(stderr, "ptr: warning: %s\n", warnings.lines[i]);
    if (res == PTR_OK && o->has_sky)
        scene.sky = o->sky;
    if (res == PTR_OK && o->dump_scene)
        ptr_scene_write_json(stdout, o->scene_path, &scene, &warnings);
    ptr_warnings_free(&warnings);
    if (res != PTR_OK || o->dump_scene) {
        ptr_scene_free(&scene);
        return res;
    }
    ptr_isect_init(isect, o->kernel, scene.spheres.count);

    PtrRenderSettings settings = {
        .samples = o->samples, .seed = o->seed, .max_depth = o->max_depth, .threads = o->threads,
    };
    choose_size(o, &scene, &settings.width, &settings.height);
    float *rgb = malloc((size_t)settings.width * (size_t)settings.height * 3 * sizeof *rgb);
    PtrRenderStats stats = { 0 };
    if (!rgb)
        res = ptr_error_set(err, PTR_ERR_NOMEM, "%s: cannot allocate a %dx%d image",
                            o->output_path, settings.width, settings.height);
    else
        res = ptr_render(&scene, isect, &settings, rgb, &stats, err);
    if (res == PTR_ERR_SCENE_INVALID) {
        /* The renderer does not know where the scene came from. */
        char message[sizeof err->message];
        memcpy(message, err->message, sizeof message);
        ptr_error_set(err, res, "%s: %s", o->scene_path, message);
    }
    if (res == PTR_OK) {
        PtrOutputInfo info = {
            .scene_path = o->scene_path, .kernel = isect->name, .samples = o->samples,
            .seed = o->seed, .max_depth = o->max_depth, .render_seconds = stats.seconds,
            .depth = o->depth, .color = color, .exposure = o->exposure,
            .bake_view = o->bake_view, .dither = o->dither,
        };
        res = ptr_output_write(o->output_path, settings.width, settings.height, rgb, &info, err);
    }
    free(rgb);
    ptr_scene_free(&scene);
    if (res == PTR_OK && !o->quiet)
        fprintf(stderr,
                "ptr: %s: %dx%d, %" PRIu32 " spp, %d threads, %s intersector: %.3f s, "
                "%.2f Mrays/s (%" PRIu64 " rays)\n",
                o->output_path, settings.width, settings.height, o->samples, stats.threads,
                isect->name, stats.seconds,
                stats.seconds > 0 ? (double)stats.rays / stats.seconds * 1e-6 : 0.0, stats.rays);
    return res;
}

/* The colour config and the view in force, or an error. */
static PtrColor *open_color(const Options *o, PtrError *err)
{
    char message[sizeof err->message];
    PtrColor *color = ptr_color_open(o->ocio_config, message, sizeof message);
    if (!color) {
        ptr_error_set(err, PTR_ERR_COLOR, "%s", message);
        return NULL;
    }
    int bad = ptr_color_select(color, o->display, o->view, o->look, o->exposure, message,
                               sizeof message);
    if (bad) {
        ptr_error_set(err, bad > 0 ? PTR_ERR_USAGE : PTR_ERR_COLOR, "%s", message);
        ptr_color_close(color);
        return NULL;
    }
    return color;
}

int ptr_cli_main(int argc, char **argv)
{
    Options o;
    int code = parse_options(argc, argv, &o);
    if (code >= 0)
        return code;

    PtrError err = { 0 };
    PtrColor *color = open_color(&o, &err);
    if (!color)
        return fail(&err);
    if (o.list_views) {
        ptr_color_list(color, stdout);
        ptr_color_close(color);
        return 0;
    }

    PtrResult res = PTR_OK;
    PtrIsectTable isect;
    if (!o.dump_scene)
        res = ptr_output_check(o.output_path, o.depth, &err);
    /* Refuse an unavailable kernel before reading the scene; the choice is
     * made again once the scene's size is known. */
    if (res == PTR_OK && !ptr_isect_init(&isect, o.kernel, SIZE_MAX))
        res = ptr_error_set(&err, PTR_ERR_USAGE,
                            "--asm: no assembly intersector at CPU level '%s' (this build %s)",
                            ptr_cpu_level_name(ptr_cpu_level()),
                            ptr_isect_has_asm() ? "has them" : "was built without them");
    if (res == PTR_OK)
        res = render_scene(&o, color, &isect, &err);
    ptr_color_close(color);
    return res == PTR_OK ? 0 : fail(&err);
}
