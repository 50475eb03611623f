#include "app/cli_help.h"

#include <stdio.h>
#include <string.h>

#include "accel/accel.h"
#include "accel/isect.h"
#include "app/cli_options.h"
#include "base/cpu.h"
#include "base/result.h"
#include "base/version.h"
#include "denoise/conv.h"
#include "importer.h"
#include "render/render.h"

/* A macro's value as a string: SPELLED(PTR_DEFAULT_SAMPLES) is "100". */
#define STRINGIFIED(x) #x
#define SPELLED(macro) STRINGIFIED(macro)

/* The options part of --help: section titles and options, in the table's
 * order. */
static const struct {
    const char *heading;   /* a section's title; NULL for an option */
    char short_name;
    const char *name;
    const char *metavar;
    const char *text;
} help_lines[] = {
#define OPTION(id, short_name, name, has_arg, metavar, text) { NULL, short_name, name, metavar, text },
#define HEADING(title) { title, 0, NULL, NULL, NULL },
#include "app/cli_options.def"
#undef OPTION
#undef HEADING
};

/* The option and its value's name in a column, its text from column 24 on
 * (every line of it, and the first after the column when the option is
 * wider). */
static void print_option(const char *name, char short_name, const char *metavar, const char *text)
{
    char shortcut[8] = "    ", option[64];
    if (short_name)
        snprintf(shortcut, sizeof shortcut, "-%c, ", short_name);
    snprintf(option, sizeof option, "%s--%s%s%s", shortcut, name, metavar ? " " : "",
             metavar ? metavar : "");
    printf("  %-20s  ", option);
    for (; *text; text++) {
        putchar(*text);
        if (*text == '\n')
            printf("%24s", "");
    }
    putchar('\n');
}

static void print_help(void)
{
    fputs("Usage: ptr SCENE... -o OUTPUT [options]\n"
          "       ptr merge PART.exr... -o OUTPUT [output options] [--denoise [QUALITY]]\n"
          "       ptr denoise IMAGE.exr -o OUTPUT [--denoise QUALITY] [--threads N]\n"
          "       ptr --dump-scene SCENE [--camera NAME] [--sky SKY]\n"
          "       ptr --list-views [--ocio-config FILE]\n"
          "Renders scenes of spheres with a path tracer. SCENE is glTF (.gltf, .glb:\n"
          "nodes with meshes, EXT_mesh_gpu_instancing instances, POINTS with _RADIUS)\n"
          "or OBJ (.obj with its .mtl: objects named *sphere*); scripts/particles_to_glb.py\n"
          "turns particle files (CSV, PLY) into .glb.\n",
          stdout);
    /* The list the importer checks files against, filled to 80 columns. */
    size_t column = (size_t)printf("glTF extensions read:");
    for (const char *const *e = ptr_gltf_extensions; *e; e++) {
        size_t width = 1 + strlen(*e) + 1; /* " NAME," */
        if (column + width > 80)
            column = (size_t)printf("\n ");
        column += (size_t)printf(" %s%s", *e, e[1] ? "," : ".\n");
    }
    for (size_t i = 0; i < sizeof help_lines / sizeof help_lines[0]; i++) {
        if (help_lines[i].heading)
            printf("\n%s\n", help_lines[i].heading);
        else
            print_option(help_lines[i].name, help_lines[i].short_name, help_lines[i].metavar,
                         help_lines[i].text);
    }
    fputs("\n"
          "Signals: a first SIGINT/SIGTERM finishes the current pass and writes the\n"
          "samples done (exit 8); a second aborts at once, writing nothing (exit 130).\n"
          "\n"
          "Exit codes:\n",
          stdout);
    for (int r = PTR_OK; r < PTR_RESULT_COUNT; r++)
        printf("  %2d  %s\n", ptr_result_exit_code((PtrResult)r),
               ptr_result_description((PtrResult)r));
}

static void print_version(PtrCpuLevel level)
{
    PtrIsectTable table;
    ptr_isect_init_level(&table, level);
    printf("ptr %s (intersector: %s)\n", PTR_VERSION, table.name);
}

/* Each level: the intersectors, the integrator, the denoiser's convolution,
 * the tree build's binning. */
static void print_dispatch(PtrCpuLevel level)
{
    PtrCpuLevel detected = ptr_cpu_detected();
    for (int l = PTR_CPU_NONE; l < PTR_CPU_LEVEL_COUNT; l++) {
        PtrIsectTable table;
        PtrConvTable conv;
        ptr_isect_init_level(&table, (PtrCpuLevel)l);
        ptr_conv_init_level(&conv, (PtrCpuLevel)l);
        printf("%-7s %-7s %-7s %-7s %-7s%s%s\n", ptr_cpu_level_name((PtrCpuLevel)l), table.name,
               ptr_integrator_name(ptr_integrator_for_level((PtrCpuLevel)l)), conv.name,
               ptr_bvh_bin_name((PtrCpuLevel)l),
               l > (int)detected ? "  (not on this CPU)" : "",
               l == (int)level ? "  <- in use" : "");
    }
}

void ptr_print_requested(const PtrOptions *o)
{
    switch (o->print) {
    case PTR_PRINT_NOTHING: break;
    case PTR_PRINT_HELP: print_help(); break;
    case PTR_PRINT_VERSION: print_version(o->cpu_level); break;
    case PTR_PRINT_DISPATCH: print_dispatch(o->cpu_level); break;
    }
}
