#include "app/cli_options.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/cpu.h"
#include "base/version.h"

enum {
    DEFAULT_SAMPLES = 100,
    DEFAULT_MAX_DEPTH = 50,
    DEFAULT_MIN_SAMPLES = 32,
    MAX_THREADS = 1024,
};

enum {
    OPT_SAMPLES = 256, OPT_WIDTH, OPT_HEIGHT, OPT_THREADS, OPT_SEED, OPT_MAX_DEPTH,
    OPT_SKY, OPT_C, OPT_ASM, OPT_ACCEL, OPT_CPUMASK, OPT_PRINT_DISPATCH, OPT_CAMERA, OPT_DEPTH, OPT_DITHER,
    OPT_OCIO_CONFIG, OPT_DISPLAY, OPT_VIEW, OPT_LOOK, OPT_EXPOSURE, OPT_BAKE_VIEW, OPT_LIST_VIEWS,
    OPT_QUIET, OPT_DUMP_SCENE, OPT_HELP, OPT_VERSION, OPT_JSON, OPT_TIME, OPT_PREVIEW, OPT_WATCH,
    OPT_SAMPLE_RANGE, OPT_REGION, OPT_LOOKFROM, OPT_LOOKAT, OPT_UP, OPT_VFOV, OPT_APERTURE,
    OPT_FOCUS_DISTANCE, OPT_FIT_ALL, OPT_SAMPLER, OPT_DIRECT_LIGHTING,
    OPT_NOISE_THRESHOLD, OPT_MIN_SAMPLES,
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
    { "sampler", required_argument, NULL, OPT_SAMPLER },
    { "direct-lighting", required_argument, NULL, OPT_DIRECT_LIGHTING },
    { "noise-threshold", required_argument, NULL, OPT_NOISE_THRESHOLD },
    { "min-samples", required_argument, NULL, OPT_MIN_SAMPLES },
    { "camera", required_argument, NULL, OPT_CAMERA },
    { "c", no_argument, NULL, OPT_C },
    { "accel", required_argument, NULL, OPT_ACCEL },
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
    { "json", no_argument, NULL, OPT_JSON },
    { "time", required_argument, NULL, OPT_TIME },
    { "preview", no_argument, NULL, OPT_PREVIEW },
    { "watch", no_argument, NULL, OPT_WATCH },
    { "sample-range", required_argument, NULL, OPT_SAMPLE_RANGE },
    { "region", required_argument, NULL, OPT_REGION },
    { "lookfrom", required_argument, NULL, OPT_LOOKFROM },
    { "lookat", required_argument, NULL, OPT_LOOKAT },
    { "up", required_argument, NULL, OPT_UP },
    { "vfov", required_argument, NULL, OPT_VFOV },
    { "aperture", required_argument, NULL, OPT_APERTURE },
    { "focus-distance", required_argument, NULL, OPT_FOCUS_DISTANCE },
    { "fit-all-objects", no_argument, NULL, OPT_FIT_ALL },
    { "quiet", no_argument, NULL, OPT_QUIET },
    { "dump-scene", no_argument, NULL, OPT_DUMP_SCENE },
    { "help", no_argument, NULL, OPT_HELP },
    { "version", no_argument, NULL, OPT_VERSION },
    { NULL, 0, NULL, 0 },
};

static void print_help(FILE *out)
{
    fprintf(out,
        "Usage: ptr SCENE... -o OUTPUT [options]\n"
        "       ptr merge PART.exr... -o OUTPUT [output options]\n"
        "       ptr --dump-scene SCENE [--camera NAME] [--sky SKY]\n"
        "       ptr --list-views [--ocio-config FILE]\n"
        "Renders scenes of spheres with a path tracer. SCENE is glTF (.gltf, .glb:\n"
        "nodes with meshes, EXT_mesh_gpu_instancing instances, POINTS with _RADIUS)\n"
        "or OBJ (.obj with its .mtl: objects named *sphere*); scripts/particles_to_glb.py\n"
        "turns particle files (CSV, PLY) into .glb.\n"
        "\n"
        "Image:\n"
        "  -o, --output FILE     image to write; the extension picks the format:\n"
        "                        .exr, .hdr (scene-linear float), .png, .jpg, .tif\n"
        "                        (the display's view of it, 8 bits). With several\n"
        "                        scenes: a folder (FOLDER/NAME.exr) or a pattern\n"
        "                        with {name}, e.g. out/{name}.png\n"
        "      --samples N       samples per pixel (default %d)\n"
        "      --width W         image width; with only one of width/height the other\n"
        "      --height H        follows the camera's aspect ratio (default: the scene's\n"
        "                        resolution, else %d wide)\n"
        "      --depth D         8, 16, half or float, where the format allows; integer\n"
        "                        depths hold the view, float ones scene-linear light\n"
        "      --dither          dither 8-bit output before rounding\n"
        "\n"
        "Rendering:\n"
        "      --threads N       render threads, 0 for one per CPU (default 0)\n"
        "      --seed S          random seed (default 1); the image depends only on it,\n"
        "                        never on the thread count\n"
        "      --max-depth D     rays per path at most, shadow rays not counted\n"
        "                        (default %d)\n"
        "      --sampler S       sobol (Owen-scrambled Sobol', the default) or\n"
        "                        independent random numbers\n"
        "      --direct-lighting on|off  sample emissive spheres at diffuse surfaces\n"
        "                        (default on)\n"
        "      --noise-threshold E  adaptive sampling: a pixel stops once its error\n"
        "                        estimate is below E (e.g. 0.01; default off)\n"
        "      --min-samples N   adaptive sampling: samples before the first check\n"
        "                        (default %d; checks every 16 from there)\n"
        "\n"
        "Scene:\n"
        "      --sky SKY         gradient, black or R,G,B (overrides the scene's sky)\n"
        "      --camera NAME     the glTF camera (node or camera name) to render through\n"
        "      --lookfrom X,Y,Z --lookat X,Y,Z --vfov DEG [--up X,Y,Z] [--aperture A]\n"
        "        [--focus-distance D]  a camera in world coordinates, replacing the\n"
        "                        scene's (default up 0,1,0; focus at the look-at point)\n"
        "      --fit-all-objects OBJ: fit every object, not only those named *sphere*\n"
        "      --dump-scene      print the imported scene as JSON and render nothing\n"
        "\n"
        "Intersection:\n"
        "      --accel A         auto, brute or bvh: test every sphere, or build a\n"
        "                        tree over them first (default auto: the tree from\n"
        "                        %d spheres on with --c, %d with SSE4.1, %d with\n"
        "                        AVX2); the image is the same\n"
        "      --c               use the portable C intersector (the reference)\n"
        "      --asm             use the fastest assembly intersector; an error if none\n"
        "      --cpumask LEVEL   cap the instruction set: none, sse41, avx2 or avx512\n"
        "                        (also $PTR_CPUMASK; default: the best the CPU has)\n"
        "      --print-dispatch  print each level's intersector and path tracer, and exit\n"
        "\n"
        "Colour (OpenColorIO):\n"
        "      --ocio-config F   config file (default: $OCIO, else ptr's own)\n"
        "      --display NAME    display (default: the config's, sRGB in ptr's own)\n"
        "      --view NAME       view (default: the config's, Standard in ptr's own)\n"
        "      --look NAME       look applied before the view\n"
        "      --exposure STOPS  exposure applied in scene-linear before the view\n"
        "      --bake-view       float outputs too get the view, not scene-linear light\n"
        "      --list-views      print the config's displays, views and looks, and exit\n"
        "\n"
        "Progress, budgets and parts of a render:\n"
        "      --time SECONDS    stop after the pass that reaches this budget\n"
        "      --preview         a quick look: a quarter of the size, 4 samples\n"
        "      --sample-range A:B  render sample indices A to B-1 of every pixel\n"
        "                        (parts of one render, for `ptr merge`)\n"
        "      --region X0,Y0,X1,Y1  render pixels X0..X1-1, Y0..Y1-1 (an EXR keeps\n"
        "                        them as a data window of the full image)\n"
        "      --watch           render again whenever the scene's files change\n"
        "      --json            one JSON object per render on stdout\n"
        "      --quiet           no progress or statistics\n"
        "\n"
        "      --help            this text\n"
        "      --version         version and intersector\n"
        "\n"
        "Signals: a first SIGINT/SIGTERM finishes the current pass and writes the\n"
        "samples done (exit 8); a second aborts at once, writing nothing (exit 130).\n"
        "\n"
        "Exit codes:\n",
        DEFAULT_SAMPLES, PTR_DEFAULT_WIDTH, DEFAULT_MAX_DEPTH, DEFAULT_MIN_SAMPLES,
        PTR_ACCEL_CROSSOVER_C, PTR_ACCEL_CROSSOVER_SSE41, PTR_ACCEL_CROSSOVER_AVX2);
    for (int r = PTR_OK; r < PTR_RESULT_COUNT; r++)
        fprintf(out, "  %2d  %s\n", ptr_result_exit_code((PtrResult)r),
                ptr_result_description((PtrResult)r));
}

static void print_dispatch(void)
{
    PtrCpuLevel detected = ptr_cpu_detected(), level = ptr_cpu_level();
    for (int l = PTR_CPU_NONE; l < PTR_CPU_LEVEL_COUNT; l++) {
        PtrIsectTable table;
        ptr_isect_init_level(&table, (PtrCpuLevel)l);
        printf("%-7s %-7s %-19s%s%s\n", ptr_cpu_level_name((PtrCpuLevel)l), table.name,
               ptr_render_bundles(&table) ? "bundles of 8 paths" : "paths one at a time",
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

/* Reads a whole string as a number; 0 if it is not one (or overflows). */
static int parse_number(const char *text, double *value)
{
    char *end;
    errno = 0;
    *value = strtod(text, &end);
    return !errno && end != text && !*end;
}

static int usage_error_line(const char *problem)
{
    fprintf(stderr, "ptr: %s (usage: ptr SCENE... -o OUTPUT [options]; see ptr --help)\n", problem);
    return ptr_result_exit_code(PTR_ERR_USAGE);
}

/* Returns -1 to go on rendering, else the exit code to return. */
int ptr_options_parse(int argc, char **argv, PtrOptions *o)
{
    const char *env_mask = getenv("PTR_CPUMASK");
    PtrCpuLevel env_cap;
    if (env_mask && !ptr_cpu_parse_level(env_mask, &env_cap))
        return usage_error("PTR_CPUMASK", env_mask, "none, sse41, avx2 or avx512");
    *o = (PtrOptions){
        .samples = DEFAULT_SAMPLES, .seed = 1, .max_depth = DEFAULT_MAX_DEPTH,
        .min_samples = DEFAULT_MIN_SAMPLES,
        .kernel = PTR_KERNEL_AUTO, .camera = { .up = { 0, 1, 0 } },
    };
    if (argc > 1 && !strcmp(argv[1], "merge")) {
        o->merge = 1;
        argv++;
        argc--;
    }
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
        case 'o': o->output = optarg; break;
        case OPT_SAMPLES:
            if (!parse_uint(optarg, 1, 1u << 30, &v))
                return usage_error(option, optarg, "a whole number from 1 to 2^30");
            o->samples = (uint32_t)v;
            o->sample_first = 0;
            break;
        case OPT_SAMPLE_RANGE: {
            unsigned long long a, b;
            char tail;
            if (sscanf(optarg, "%llu:%llu%c", &a, &b, &tail) != 2 || b <= a || b > (1u << 30) ||
                optarg[0] < '0' || optarg[0] > '9')
                return usage_error(option, optarg, "START:END with 0 <= START < END <= 2^30");
            o->sample_first = (uint32_t)a;
            o->samples = (uint32_t)(b - a);
            break;
        }
        case OPT_REGION: {
            int x0, y0, x1, y1;
            char tail;
            if (sscanf(optarg, "%d,%d,%d,%d%c", &x0, &y0, &x1, &y1, &tail) != 4 || x0 < 0 ||
                y0 < 0 || x1 <= x0 || y1 <= y0)
                return usage_error(option, optarg, "X0,Y0,X1,Y1 with 0 <= X0 < X1 and 0 <= Y0 < Y1");
            o->region = (PtrRegion){ x0, y0, x1, y1 };
            break;
        }
        case OPT_TIME: {
            double t;
            if (!parse_number(optarg, &t) || !(t > 0 && t <= 1e7))
                return usage_error(option, optarg, "a number of seconds above 0");
            o->time_budget = t;
            break;
        }
        case OPT_LOOKFROM:
        case OPT_LOOKAT:
        case OPT_UP: {
            double *xyz = c == OPT_LOOKFROM ? o->camera.lookfrom : c == OPT_LOOKAT ? o->camera.lookat
                                                                                : o->camera.up;
            char tail;
            if (sscanf(optarg, "%lf,%lf,%lf%c", &xyz[0], &xyz[1], &xyz[2], &tail) != 3 ||
                !isfinite(xyz[0]) || !isfinite(xyz[1]) || !isfinite(xyz[2]))
                return usage_error(option, optarg, "X,Y,Z (three finite numbers)");
            o->has_camera |= c == OPT_LOOKFROM ? 1 : c == OPT_LOOKAT ? 2 : 0;
            break;
        }
        case OPT_VFOV:
        case OPT_APERTURE:
        case OPT_FOCUS_DISTANCE: {
            double x;
            int ok = parse_number(optarg, &x) && isfinite(x) &&
                     (c == OPT_VFOV ? x > 0 && x < 180 : c == OPT_APERTURE ? x >= 0 : x > 0);
            if (!ok)
                return usage_error(option, optarg,
                                   c == OPT_VFOV ? "an angle between 0 and 180 degrees"
                                   : c == OPT_APERTURE ? "a diameter, 0 or more"
                                                       : "a distance above 0");
            *(c == OPT_VFOV ? &o->camera.vfov_deg : c == OPT_APERTURE ? &o->camera.aperture
                                                                      : &o->camera.focus_distance) = x;
            o->has_camera |= c == OPT_VFOV ? 4 : 0;
            break;
        }
        case OPT_FIT_ALL: o->fit_all_objects = 1; break;
        case OPT_PREVIEW: o->preview = 1; break;
        case OPT_WATCH: o->watch = 1; break;
        case OPT_JSON: o->json = 1; break;
        case OPT_WIDTH:
        case OPT_HEIGHT:
            if (!parse_uint(optarg, 1, PTR_MAX_IMAGE_SIZE, &v))
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
        case OPT_SAMPLER:
            if (!ptr_sampler_parse(optarg, &o->sampler))
                return usage_error(option, optarg, "sobol or independent");
            break;
        case OPT_DIRECT_LIGHTING:
            if (strcmp(optarg, "on") && strcmp(optarg, "off"))
                return usage_error(option, optarg, "on or off");
            o->direct_lighting = strcmp(optarg, "on") ? PTR_OFF : PTR_ON;
            break;
        case OPT_NOISE_THRESHOLD: {
            double e;
            if (!parse_number(optarg, &e) || !(e > 0 && e <= 1e6))
                return usage_error(option, optarg, "a number above 0");
            o->noise_threshold = (float)e;
            break;
        }
        case OPT_MIN_SAMPLES:
            if (!parse_uint(optarg, 2, 1u << 30, &v))
                return usage_error(option, optarg, "a whole number from 2 to 2^30");
            o->min_samples = (uint32_t)v;
            break;
        case OPT_CAMERA: o->camera_name = optarg; break;
        case OPT_C: o->kernel = PTR_KERNEL_C; break;
        case OPT_ACCEL:
            if (!ptr_accel_parse(optarg, &o->accel))
                return usage_error(option, optarg, "auto, brute or bvh");
            break;
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
            double stops;
            if (!parse_number(optarg, &stops) || !(fabs(stops) <= 64))
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
    o->inputs = argv + optind;
    o->input_count = argc - optind;
    const char *problem = o->has_camera && o->has_camera != 7
                              ? "a camera needs --lookfrom, --lookat and --vfov together"
                          : o->input_count == 0 ? (o->merge ? "no parts given" : "no scene file given")
                          : !o->output && !o->dump_scene ? "no output given (-o)"
                          : o->watch && o->input_count > 1 ? "--watch takes one scene"
                          : o->merge && o->dump_scene ? "--dump-scene is not for merge"
                          /* Stopping decisions need every sample of a pixel from
                           * the first on; a later range cannot know them. */
                          : o->noise_threshold > 0 && o->sample_first > 0
                              ? "--noise-threshold needs samples from 0 (not --sample-range A:B "
                                "with A > 0)"
                                                      : NULL;
    if (problem)
        return usage_error_line(problem);
    return -1;
}

PtrImportOptions ptr_options_import(const PtrOptions *o, PtrStrings *dependencies)
{
    return (PtrImportOptions){
        .camera_name = o->camera_name,
        .camera = o->has_camera ? &o->camera : NULL,
        .fit_all_objects = o->fit_all_objects,
        .dependencies = dependencies,
    };
}
