#include "app/cli_options.h"

#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Which of --lookfrom, --lookat, --vfov and --ortho were given: a camera
 * needs the first two and one of the others. */
enum {
    CAMERA_LOOKFROM = 1, CAMERA_LOOKAT = 2, CAMERA_VFOV = 4, CAMERA_ORTHO = 8,
    CAMERA_PLACED = CAMERA_LOOKFROM | CAMERA_LOOKAT,
};

/* The table's headings are --help's alone. */
#define HEADING(title)

/* The options of cli_options.def, in its order. */
typedef enum OptionId {
#define OPTION(id, short_name, name, has_arg, metavar, text) OPT_##id,
#include "app/cli_options.def"
#undef OPTION
} OptionId;

/* Counted apart from OptionId, so that a switch over the options needs no
 * case for the count. */
enum {
    OPTION_COUNT = 0
#define OPTION(id, short_name, name, has_arg, metavar, text) + 1
#include "app/cli_options.def"
#undef OPTION
};

/* getopt_long answers a short option with its character, a long one with
 * LONG_OPTION_BASE plus its identifier: above every character. */
enum { LONG_OPTION_BASE = 256 };

static const struct option long_options[OPTION_COUNT + 1] = {
#define OPTION(id, short_name, name, has_arg, metavar, text) \
    { name, has_arg, NULL, LONG_OPTION_BASE + OPT_##id },
#include "app/cli_options.def"
#undef OPTION
    { NULL, 0, NULL, 0 },
};

static const char short_names[OPTION_COUNT] = {
#define OPTION(id, short_name, name, has_arg, metavar, text) short_name,
#include "app/cli_options.def"
#undef OPTION
};

/* getopt's string of short options. It starts with ':' so that a missing
 * value is told apart from an unknown option. */
static void short_options(char text[2 * OPTION_COUNT + 2])
{
    size_t n = 0;
    text[n++] = ':';
    for (int id = 0; id < OPTION_COUNT; id++) {
        if (!short_names[id])
            continue;
        text[n++] = short_names[id];
        if (long_options[id].has_arg == required_argument)
            text[n++] = ':';
    }
    text[n] = '\0';
}

/* The option getopt_long answered c for, or -1 for an unknown one. */
static int option_id(int c)
{
    if (c >= LONG_OPTION_BASE)
        return c - LONG_OPTION_BASE;
    for (int id = 0; id < OPTION_COUNT; id++)
        if (short_names[id] == c)
            return id;
    return -1;
}

/* A value's problem as the command line reports it, naming where the value
 * came from: an option or a variable of the environment. */
static PtrResult value_error(const char *source, const PtrError *problem, PtrError *err)
{
    return ptr_error_set(err, problem->code, "%s: %s (see ptr --help)", source, problem->message);
}

/* Errors name an option by its long name, whichever name was typed. */
static PtrResult option_error(OptionId id, const PtrError *problem, PtrError *err)
{
    char option[64];
    snprintf(option, sizeof option, "--%s", long_options[id].name);
    return value_error(option, problem, err);
}

static PtrResult bad_value(OptionId id, const char *value, const char *expected, PtrError *err)
{
    PtrError problem;
    ptr_error_set(&problem, PTR_ERR_USAGE, "'%s' is not %s", value, expected);
    return option_error(id, &problem, err);
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

/* Reads a whole string as a number; 0 if it is not one (or overflows). */
static int parse_number(const char *text, double *value)
{
    char *end;
    errno = 0;
    *value = strtod(text, &end);
    return !errno && end != text && !*end;
}

/* The set_ helpers take an option's value into o: PTR_OK, else
 * PTR_ERR_USAGE with err saying what is wrong. */
static PtrResult set_switch(OptionId id, const char *value, PtrSwitch *out, PtrError *err)
{
    if (strcmp(value, "on") && strcmp(value, "off"))
        return bad_value(id, value, "on or off", err);
    *out = strcmp(value, "on") ? PTR_OFF : PTR_ON;
    return PTR_OK;
}

static PtrResult set_int(OptionId id, const char *value, int lo, int hi, int *out, PtrError *err)
{
    uint64_t v;
    if (!parse_uint(value, (uint64_t)lo, (uint64_t)hi, &v)) {
        char expected[64];
        snprintf(expected, sizeof expected, "a whole number from %d to %d", lo, hi);
        return bad_value(id, value, expected, err);
    }
    *out = (int)v;
    return PTR_OK;
}

/* A render's number (pipeline.h), in its range. */
static PtrResult set_number(OptionId id, const char *value, PtrRenderNumber number,
                            uint64_t *out, PtrError *err)
{
    if (!parse_uint(value, 0, UINT64_MAX, out) || !ptr_render_number_ok(number, *out))
        return bad_value(id, value, ptr_render_number_range(number), err);
    return PTR_OK;
}

static PtrResult set_count(OptionId id, const char *value, PtrRenderNumber number, int *out,
                           PtrError *err)
{
    uint64_t v;
    PtrResult res = set_number(id, value, number, &v, err);
    if (res == PTR_OK)
        *out = (int)v;
    return res;
}

static PtrResult set_point(OptionId id, const char *value, double xyz[3], PtrError *err)
{
    char tail;
    if (sscanf(value, "%lf,%lf,%lf%c", &xyz[0], &xyz[1], &xyz[2], &tail) != 3 ||
        !isfinite(xyz[0]) || !isfinite(xyz[1]) || !isfinite(xyz[2]))
        return bad_value(id, value, "X,Y,Z (three finite numbers)", err);
    return PTR_OK;
}

static PtrResult set_sample_range(OptionId id, const char *value, PtrOptions *o, PtrError *err)
{
    unsigned long long a, b;
    char tail;
    /* %llu alone would take spaces and a sign. */
    if (sscanf(value, "%llu:%llu%c", &a, &b, &tail) != 2 || b <= a ||
        !ptr_render_number_ok(PTR_NUMBER_SAMPLES, b) || value[0] < '0' || value[0] > '9')
        return bad_value(id, value, "START:END with 0 <= START < END <= 2^30", err);
    o->sample_first = (uint32_t)a;
    o->samples = (uint32_t)(b - a);
    return PTR_OK;
}

static PtrResult set_region(OptionId id, const char *value, PtrOptions *o, PtrError *err)
{
    int x0, y0, x1, y1;
    char tail;
    if (sscanf(value, "%d,%d,%d,%d%c", &x0, &y0, &x1, &y1, &tail) != 4 ||
        !ptr_region_ok((PtrRegion){ x0, y0, x1, y1 }))
        return bad_value(id, value, PTR_REGION_WORDS, err);
    o->region = (PtrRegion){ x0, y0, x1, y1 };
    return PTR_OK;
}

static PtrResult set_frames(OptionId id, const char *value, PtrOptions *o, PtrError *err)
{
    long a, b, step = 1;
    int end = 0, with_step = 0;
    /* %n after each form: the whole text must be A:B or A:B:STEP. */
    int n = sscanf(value, "%ld:%ld%n:%ld%n", &a, &b, &end, &step, &with_step);
    if (n == 3)
        end = with_step;
    if (n < 2 || value[end] || value[0] < '0' || value[0] > '9' || a < 0 || b < a ||
        b > 1000000000L || step < 1)
        return bad_value(id, value, "A:B or A:B:STEP with 0 <= A <= B <= 10^9, STEP >= 1", err);
    o->has_frames = 1;
    o->frame_first = a;
    o->frame_last = b;
    o->frame_step = step;
    return PTR_OK;
}

/* Takes one option (and its value, if it has one) into o: PTR_OK, else
 * PTR_ERR_USAGE with err saying what is wrong. The cases follow the table;
 * the switch has no default, so that the compiler names an option left
 * without one. */
static PtrResult apply_option(OptionId id, const char *value, PtrOptions *o, PtrError *err)
{
    uint64_t v;
    double x;
    PtrError problem; /* a parser's, which err then gets with the option's name */
    switch (id) {
    case OPT_output: o->output = value; break;
    case OPT_samples:
        if (set_number(id, value, PTR_NUMBER_SAMPLES, &v, err) != PTR_OK)
            return PTR_ERR_USAGE;
        o->samples = (uint32_t)v;
        o->sample_first = 0; /* the last of --samples and --sample-range counts */
        break;
    case OPT_width: return set_count(id, value, PTR_NUMBER_SIZE, &o->width, err);
    case OPT_height: return set_count(id, value, PTR_NUMBER_SIZE, &o->height, err);
    case OPT_transparent: o->transparent = 1; break;
    case OPT_passes:
        /* Both or none: a denoiser takes the albedo and normal together. */
        if (strcmp(value, "albedo,normal"))
            return bad_value(id, value, "albedo,normal", err);
        o->passes = 1;
        break;
    case OPT_denoise:
        o->denoise = value ? value : PTR_DEFAULT_DENOISE;
        if (ptr_denoise_quality_parse(o->denoise, &o->denoise_quality, &problem) != PTR_OK)
            return option_error(id, &problem, err);
        break;
    case OPT_threads: return set_count(id, value, PTR_NUMBER_THREADS, &o->threads, err);
    case OPT_seed:
        if (!parse_uint(value, 0, UINT64_MAX, &o->seed))
            return bad_value(id, value, "a whole number from 0 to 2^64-1", err);
        break;
    case OPT_max_depth: return set_count(id, value, PTR_NUMBER_MAX_DEPTH, &o->max_depth, err);
    case OPT_sampler:
        if (ptr_sampler_parse(value, &o->sampler, &problem) != PTR_OK)
            return option_error(id, &problem, err);
        break;
    case OPT_direct_lighting: return set_switch(id, value, &o->direct_lighting, err);
    case OPT_noise_threshold:
        if (!parse_number(value, &x) || !ptr_noise_threshold_ok(x))
            return bad_value(id, value, "a number above 0", err);
        o->noise_threshold = (float)x;
        break;
    case OPT_min_samples:
        if (set_number(id, value, PTR_NUMBER_MIN_SAMPLES, &v, err) != PTR_OK)
            return PTR_ERR_USAGE;
        o->min_samples = (uint32_t)v;
        break;
    case OPT_sky:
        if (ptr_sky_parse(value, &o->sky, &problem) != PTR_OK)
            return option_error(id, &problem, err);
        o->has_sky = 1;
        break;
    case OPT_camera: o->camera_name = value; break;
    case OPT_lookfrom:
        o->has_camera |= CAMERA_LOOKFROM;
        return set_point(id, value, o->camera.lookfrom, err);
    case OPT_lookat:
        o->has_camera |= CAMERA_LOOKAT;
        return set_point(id, value, o->camera.lookat, err);
    case OPT_vfov:
        if (!parse_number(value, &x) || !(x > 0 && x < 180))
            return bad_value(id, value, "an angle between 0 and 180 degrees", err);
        o->camera.vfov_deg = x;
        o->has_camera |= CAMERA_VFOV;
        break;
    case OPT_ortho:
        if (!parse_number(value, &x) || !(isfinite(x) && x > 0))
            return bad_value(id, value, "a height above 0", err);
        o->camera.ortho_height = x;
        o->has_camera |= CAMERA_ORTHO;
        break;
    case OPT_up: return set_point(id, value, o->camera.up, err);
    case OPT_aperture:
        if (!parse_number(value, &x) || !(isfinite(x) && x >= 0))
            return bad_value(id, value, "a diameter, 0 or more", err);
        o->camera.aperture = x;
        break;
    case OPT_focus_distance:
        if (!parse_number(value, &x) || !(isfinite(x) && x > 0))
            return bad_value(id, value, "a distance above 0", err);
        o->camera.focus_distance = x;
        break;
    case OPT_auto_camera:
        if (strcmp(value, "perspective") && strcmp(value, "orthographic"))
            return bad_value(id, value, "perspective or orthographic", err);
        o->auto_camera = strcmp(value, "perspective") ? PTR_PROJECTION_ORTHOGRAPHIC
                                                      : PTR_PROJECTION_PERSPECTIVE;
        break;
    case OPT_fit_all_objects: o->fit_all_objects = 1; break;
    case OPT_select:
        if (ptr_structure_select_parse(value, &o->structure_select, &problem) != PTR_OK)
            return option_error(id, &problem, err);
        break;
    case OPT_hydrogens: return set_switch(id, value, &o->hydrogens, err);
    case OPT_assembly:
        if (!*value)
            return bad_value(id, value, "an assembly's name or none", err);
        o->structure_assembly = value;
        break;
    case OPT_color_by:
        if (!*value)
            return bad_value(id, value, "an attribute name", err);
        o->color_by = value;
        break;
    case OPT_colormap:
        o->colormap = ptr_colormap_find(value);
        if (!o->colormap)
            return bad_value(id, value, PTR_COLORMAP_NAMES, err);
        break;
    case OPT_color_range: {
        char tail;
        double *r = o->color_range;
        if (sscanf(value, "%lf,%lf%c", &r[0], &r[1], &tail) != 2 || !ptr_color_range_ok(r))
            return bad_value(id, value, "MIN,MAX (finite numbers, MIN below MAX)", err);
        o->has_color_range = 1;
        break;
    }
    case OPT_color_bar: o->color_bar = value; break;
    case OPT_accel:
        if (ptr_accel_parse(value, &o->accel, &problem) != PTR_OK)
            return option_error(id, &problem, err);
        break;
    case OPT_c: o->kernel = PTR_KERNEL_C; break;
    case OPT_asm: o->kernel = PTR_KERNEL_ASM; break;
    case OPT_integrator:
        if (ptr_integrator_parse(value, &o->integrator, &problem) != PTR_OK)
            return option_error(id, &problem, err);
        break;
    case OPT_cpumask: {
        PtrCpuLevel cap;
        if (ptr_cpu_parse_level(value, &cap, &problem) != PTR_OK)
            return option_error(id, &problem, err);
        /* The last --cpumask counts, as the environment lets it. */
        o->cpu_level = cap < ptr_cpu_level() ? cap : ptr_cpu_level();
        break;
    }
    case OPT_print_dispatch: o->print = PTR_PRINT_DISPATCH; break;
    case OPT_depth:
        if (ptr_depth_parse(value, &o->depth, &problem) != PTR_OK)
            return option_error(id, &problem, err);
        break;
    case OPT_dither: o->dither = 1; break;
    case OPT_ocio_config: o->ocio_config = value; break;
    case OPT_display: o->display = value; break;
    case OPT_view: o->view = value; break;
    case OPT_look: o->look = value; break;
    case OPT_exposure:
        if (!parse_number(value, &x) || !ptr_exposure_ok(x))
            return bad_value(id, value, "a number of stops from -64 to 64", err);
        o->exposure = (float)x;
        break;
    case OPT_bake_view: o->bake_view = 1; break;
    case OPT_list_views: o->list_views = 1; break;
    case OPT_time:
        if (!parse_number(value, &x) || !ptr_time_budget_ok(x))
            return bad_value(id, value, "a number of seconds above 0", err);
        o->time_budget = x;
        break;
    case OPT_preview: o->preview = 1; break;
    case OPT_sample_range: return set_sample_range(id, value, o, err);
    case OPT_region: return set_region(id, value, o, err);
    case OPT_watch: o->watch = 1; break;
    case OPT_live: o->live = value; break;
    case OPT_tev: o->tev = value; break;
    case OPT_frames: return set_frames(id, value, o, err);
    case OPT_turntable: return set_int(id, value, 1, PTR_MAX_FRAMES, &o->turntable, err);
    case OPT_skip_existing: o->skip_existing = 1; break;
    case OPT_json: o->json = 1; break;
    case OPT_quiet: o->quiet = 1; break;
    case OPT_dump_scene: o->dump_scene = 1; break;
    case OPT_help: o->print = PTR_PRINT_HELP; break;
    case OPT_version: o->print = PTR_PRINT_VERSION; break;
    }
    return PTR_OK;
}

/* Whether text, the argument after an option whose value is optional and
 * not given with '=', is that value (getopt_long takes only --denoise=fast):
 * it is if it is one of the option's values, else it is an operand. */
static int is_optional_value(OptionId id, const char *text)
{
    PtrDenoiseQuality quality;
    return id == OPT_denoise && ptr_denoise_quality_parse(text, &quality, NULL) == PTR_OK;
}

/* Takes argv's options into o, leaving optind at the first operand, up to
 * the first that asks for something printed instead of a render. */
static PtrResult read_options(int argc, char **argv, PtrOptions *o, PtrError *err)
{
    char shorts[2 * OPTION_COUNT + 2];
    short_options(shorts);
    optind = 0; /* glibc: restart scanning, so the parser can run more than once */
    opterr = 0;
    for (int c; (c = getopt_long(argc, argv, shorts, long_options, NULL)) != -1;) {
        if (c == ':')
            return ptr_error_set(err, PTR_ERR_USAGE, "%s needs a value (see ptr --help)",
                                 argv[optind - 1]);
        int id = option_id(c);
        if (id < 0)
            return ptr_error_set(err, PTR_ERR_USAGE, "unknown option '%s' (see ptr --help)",
                                 argv[optind - 1]);
        const char *value = optarg;
        if (long_options[id].has_arg == optional_argument && !value && optind < argc &&
            is_optional_value((OptionId)id, argv[optind]))
            value = argv[optind++];
        PtrResult res = apply_option((OptionId)id, value, o, err);
        if (res != PTR_OK || o->print != PTR_PRINT_NOTHING)
            return res;
    }
    return PTR_OK;
}

/* What is wrong with the options taken together, or NULL. */
static const char *usage_problem(const PtrOptions *o)
{
    if ((o->has_camera & CAMERA_VFOV) && (o->has_camera & CAMERA_ORTHO))
        return "--vfov and --ortho exclude each other: a camera has one projection";
    if (o->has_camera && ((o->has_camera & CAMERA_PLACED) != CAMERA_PLACED ||
                          !(o->has_camera & (CAMERA_VFOV | CAMERA_ORTHO))))
        return "a camera needs --lookfrom, --lookat and --vfov (or --ortho) together";
    /* Parallel rays have no lens: rather than ignore a lens asked for, say so. */
    if ((o->has_camera & CAMERA_ORTHO) && o->camera.aperture > 0)
        return "--ortho has no depth of field: leave out --aperture";
    if (!o->color_by && (o->colormap || o->has_color_range || o->color_bar))
        return "--colormap, --color-range and --color-bar need --color-by";
    if (o->input_count == 0)
        return o->denoise_command ? "no image given"
               : o->merge         ? "no parts given"
                                  : "no scene file given";
    if (o->denoise_command && o->input_count > 1)
        return "ptr denoise takes one image";
    if (!o->output && !o->dump_scene)
        return "no output given (-o)";
    if (o->watch && o->input_count > 1)
        return "--watch takes one scene";
    if (o->watch && (o->turntable || o->has_frames || o->skip_existing ||
                     strchr(o->inputs[0], '#')))
        return "--watch takes one scene, not a sequence (# patterns, --frames, --turntable, "
               "--skip-existing)";
    if (o->merge && o->dump_scene)
        return "--dump-scene is not for merge";
    return ptr_sample_range_problem(o->noise_threshold, o->sample_first, o->samples);
}

PtrResult ptr_options_parse(int argc, char **argv, PtrOptions *o, PtrError *err)
{
    PtrError problem;
    const char *env_mask = getenv("PTR_CPUMASK");
    PtrCpuLevel env_cap;
    if (env_mask && ptr_cpu_parse_level(env_mask, &env_cap, &problem) != PTR_OK)
        return value_error("PTR_CPUMASK", &problem, err);
    *o = (PtrOptions){
        .samples = PTR_DEFAULT_SAMPLES, .seed = PTR_DEFAULT_SEED, .max_depth = PTR_DEFAULT_MAX_DEPTH,
        .min_samples = PTR_DEFAULT_MIN_SAMPLES,
        .kernel = PTR_KERNEL_AUTO, .cpu_level = ptr_cpu_level(), .camera = { .up = { 0, 1, 0 } },
    };
    const char *env_integrator = getenv("PTR_INTEGRATOR");
    if (env_integrator && ptr_integrator_parse(env_integrator, &o->integrator, &problem) != PTR_OK)
        return value_error("PTR_INTEGRATOR", &problem, err);
    /* ptr denoise is ptr merge of one image with --denoise: its default
     * quality, unless the options give another. */
    o->denoise_command = argc > 1 && !strcmp(argv[1], "denoise");
    PtrResult res = o->denoise_command ? apply_option(OPT_denoise, NULL, o, err) : PTR_OK;
    if (res != PTR_OK)
        return res;
    if (argc > 1 && (o->denoise_command || !strcmp(argv[1], "merge"))) {
        o->merge = 1;
        argv++;
        argc--;
    }
    res = read_options(argc, argv, o, err);
    if (res != PTR_OK || o->print != PTR_PRINT_NOTHING || o->list_views)
        return res;
    o->inputs = argv + optind;
    o->input_count = argc - optind;
    const char *wrong = usage_problem(o);
    return wrong ? ptr_error_set(err, PTR_ERR_USAGE,
                                 "%s (usage: ptr SCENE... -o OUTPUT [options]; see ptr --help)",
                                 wrong)
                 : PTR_OK;
}

PtrImportOptions ptr_options_import(const PtrOptions *o, PtrStrings *dependencies)
{
    return (PtrImportOptions){
        .camera_name = o->camera_name,
        .camera = o->has_camera ? &o->camera : NULL,
        .fit_all_objects = o->fit_all_objects,
        .structure_select = o->structure_select,
        .drop_hydrogens = o->hydrogens == PTR_OFF,
        .structure_assembly = o->structure_assembly,
        .value_attribute = o->color_by,
        .auto_projection = o->auto_camera,
        .auto_aspect = o->width && o->height ? (double)o->width / o->height : 0,
        .orbit_degrees = o->orbit_degrees,
        .structure_model = o->structure_model,
        .structure_file = o->structure_file,
        .dependencies = dependencies,
        .textures = ptr_texture_decoder(o->images),
    };
}

PtrOutputSettings ptr_options_output(const PtrOptions *o, const PtrColor *color)
{
    return (PtrOutputSettings){ o->depth, color, o->exposure, o->bake_view, o->dither };
}
