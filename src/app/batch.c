#include "app/batch.h"

#include <glob.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "api/output.h"
#include "importer.h"

/* The last run of '#' in text: its offset and width; 0 if there is none. */
static int find_run(const char *text, size_t *at, int *width)
{
    const char *end = strrchr(text, '#');
    if (!end)
        return 0;
    const char *start = end;
    while (start > text && start[-1] == '#')
        start--;
    *at = (size_t)(start - text);
    *width = (int)(end - start + 1);
    return 1;
}

int ptr_batch_is_pattern(const char *text)
{
    size_t at = 0;
    int width = 0;
    return find_run(text, &at, &width);
}

/* pattern with its last run of '#' replaced by frame, zero-padded to the
 * run's width. */
static PtrResult substitute(const char *pattern, long frame, char *out, PtrError *err)
{
    size_t at = 0;
    int width = 0;
    find_run(pattern, &at, &width);
    int n = snprintf(out, PTR_PATH_SIZE, "%.*s%0*ld%s", (int)at, pattern, width, frame,
                     pattern + at + (size_t)width);
    if (n < 0 || n >= PTR_PATH_SIZE)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s: the path is too long", pattern);
    return PTR_OK;
}

/* Whether -o names a folder: one that exists, or written with a trailing /. */
static int is_folder(const char *output)
{
    struct stat st;
    size_t len = strlen(output);
    return (len > 0 && output[len - 1] == '/') || (stat(output, &st) == 0 && S_ISDIR(st.st_mode));
}

PtrResult ptr_batch_output(const PtrOptions *o, const char *scene, char *out, PtrError *err)
{
    const char *base = strrchr(scene, '/') ? strrchr(scene, '/') + 1 : scene;
    const char *dot = strrchr(base, '.');
    int name_len = (int)(dot && dot != base ? (size_t)(dot - base) : strlen(base));
    size_t len = strlen(o->output);
    int folder = is_folder(o->output);
    int n;
    if (strstr(o->output, "{name}")) {
        const char *at = o->output, *hit;
        out[0] = '\0';
        n = 0;
        while ((hit = strstr(at, "{name}")) && n < PTR_PATH_SIZE) {
            n += snprintf(out + n, (size_t)(PTR_PATH_SIZE - n), "%.*s%.*s", (int)(hit - at), at,
                          name_len, base);
            at = hit + 6;
        }
        if (n < PTR_PATH_SIZE)
            n += snprintf(out + n, (size_t)(PTR_PATH_SIZE - n), "%s", at);
    } else if (folder) {
        n = snprintf(out, PTR_PATH_SIZE, "%s%s%.*s.exr", o->output,
                     o->output[len - 1] == '/' ? "" : "/", name_len, base);
    } else if (o->input_count > 1) {
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "-o %s: with several scenes, -o must be a folder or a pattern with {name}",
                             o->output);
    } else {
        n = snprintf(out, PTR_PATH_SIZE, "%s", o->output);
    }
    if (n >= PTR_PATH_SIZE)
        return ptr_error_set(err, PTR_ERR_USAGE, "-o %s: the output path is too long", o->output);
    return PTR_OK;
}

/* The frame numbers of the files matching pattern (its run of '#' standing
 * for that many digits), in increasing order, in a new array. */
static PtrResult find_frames(const char *pattern, long **frames, int *count, PtrError *err)
{
    size_t at = 0;
    int width = 0;
    find_run(pattern, &at, &width);
    /* The rest of the name is taken literally: glob's special characters
     * escaped, the run a digit class per '#'. */
    char glob_pattern[3 * PTR_PATH_SIZE];
    size_t n = 0;
    for (size_t i = 0; pattern[i] && n + 8 < sizeof glob_pattern; i++) {
        if (i >= at && i < at + (size_t)width) {
            memcpy(glob_pattern + n, "[0-9]", 5);
            n += 5;
            continue;
        }
        if (strchr("*?[]\\", pattern[i]))
            glob_pattern[n++] = '\\';
        glob_pattern[n++] = pattern[i];
    }
    glob_pattern[n] = '\0';
    glob_t found;
    int res = glob(glob_pattern, 0, NULL, &found);
    if (res == GLOB_NOSPACE)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", pattern);
    if (res != 0 || found.gl_pathc == 0) {
        if (res == 0)
            globfree(&found);
        return ptr_error_set(err, PTR_ERR_SCENE_UNREADABLE,
                             "%s: no file matches (# stands for one digit of the frame number)",
                             pattern);
    }
    if (found.gl_pathc > PTR_MAX_FRAMES) {
        ptr_error_set(err, PTR_ERR_USAGE, "%s: %zu frames; at most %d", pattern,
                      (size_t)found.gl_pathc, PTR_MAX_FRAMES);
        globfree(&found);
        return PTR_ERR_USAGE;
    }
    *frames = malloc(found.gl_pathc * sizeof **frames);
    if (!*frames) {
        globfree(&found);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", pattern);
    }
    /* glob sorts the names, and names of one width sort as their numbers. */
    for (size_t i = 0; i < found.gl_pathc; i++)
        (*frames)[i] = strtol(found.gl_pathv[i] + at, NULL, 10);
    *count = (int)found.gl_pathc;
    globfree(&found);
    return PTR_OK;
}

/* The frames --frames A:B:STEP names, in a new array. */
static PtrResult listed_frames(const PtrOptions *o, long **frames, int *count, PtrError *err)
{
    long n = (o->frame_last - o->frame_first) / o->frame_step + 1;
    if (n > PTR_MAX_FRAMES)
        return ptr_error_set(err, PTR_ERR_USAGE, "--frames: %ld frames; at most %d", n,
                             PTR_MAX_FRAMES);
    *frames = malloc((size_t)n * sizeof **frames);
    if (!*frames)
        return ptr_error_set(err, PTR_ERR_NOMEM, "--frames: out of memory");
    for (long i = 0; i < n; i++)
        (*frames)[i] = o->frame_first + i * o->frame_step;
    *count = (int)n;
    return PTR_OK;
}

/* Gives item copies of its scene and output: PTR_ERR_NOMEM if memory runs
 * out. */
static PtrResult set_item(PtrBatchItem *item, const char *scene, const char *output,
                          PtrError *err)
{
    item->scene = strdup(scene);
    item->output = strdup(output);
    if (!item->scene || !item->output)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", scene);
    return PTR_OK;
}

/* Whether the options ask for a structure's models as frames: one structure
 * (not a pattern) and # in -o. */
static int renders_models(const PtrOptions *o)
{
    return o->input_count == 1 && !o->turntable && !ptr_batch_is_pattern(o->inputs[0]) &&
           ptr_import_is_structure(o->inputs[0]) && ptr_batch_is_pattern(o->output);
}

/* The items of a sequence: frames of a scene pattern, of a turntable, or a
 * structure's models (frame k: model k, from 1; *structure the file, parsed
 * once for them). */
static PtrResult plan_frames(const PtrOptions *o, PtrBatchItem **items, int *count,
                             PtrStructureFile **structure, PtrError *err)
{
    const char *scene = o->inputs[0];
    const int models = renders_models(o);
    long *frames = NULL;
    int n = 0;
    size_t model_count = 0;
    PtrResult res =
        models ? ptr_structure_open(scene, o->structure_assembly, structure, err) : PTR_OK;
    if (res == PTR_OK && models)
        model_count = ptr_structure_models(*structure);
    if (res == PTR_OK)
        res = o->has_frames ? listed_frames(o, &frames, &n, err)
              : o->turntable || models ? PTR_OK
                                       : find_frames(scene, &frames, &n, err);
    if (res != PTR_OK)
        return res;
    if (models && !o->has_frames && model_count > PTR_MAX_FRAMES)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s: %zu models; at most %d frames", scene,
                             model_count, PTR_MAX_FRAMES);
    if (o->turntable && !o->has_frames)
        n = o->turntable;
    if (models && !o->has_frames)
        n = (int)model_count;
    *items = calloc((size_t)n, sizeof **items);
    if (!*items) {
        free(frames);
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for %d frames", n);
    }
    *count = n;
    char frame_scene[PTR_PATH_SIZE], output[PTR_PATH_SIZE];
    for (int i = 0; res == PTR_OK && i < n; i++) {
        long frame = frames ? frames[i] : models ? i + 1 : i;
        if (o->turntable && frame >= o->turntable) {
            res = ptr_error_set(err, PTR_ERR_USAGE,
                                "--frames: frame %ld is beyond --turntable %d (frames 0 to %d)",
                                frame, o->turntable, o->turntable - 1);
            break;
        }
        if (models && (frame < 1 || (size_t)frame > model_count)) {
            res = ptr_error_set(err, PTR_ERR_USAGE,
                                "--frames: %s has no model %ld (frames 1 to %zu)", scene, frame,
                                model_count);
            break;
        }
        if (!o->turntable && !models)
            res = substitute(scene, frame, frame_scene, err);
        const char *this_scene = o->turntable || models ? scene : frame_scene;
        if (res == PTR_OK)
            res = ptr_batch_is_pattern(o->output) ? substitute(o->output, frame, output, err)
                                                  : ptr_batch_output(o, this_scene, output, err);
        if (res == PTR_OK)
            res = set_item(&(*items)[i], this_scene, output, err);
        /* Frame k of N turns the camera k/N of a full turn: frame 0 is the
         * scene's own view. */
        (*items)[i].orbit_degrees = o->turntable ? 360.0 * (double)frame / o->turntable : 0.0;
        (*items)[i].model = models ? (size_t)frame : 0;
    }
    free(frames);
    return res;
}

/* What is wrong with a sequence's options, or NULL. */
static const char *sequence_problem(const PtrOptions *o)
{
    int pattern = ptr_batch_is_pattern(o->inputs[0]);
    if (o->input_count > 1 && pattern)
        return "a scene pattern with # stands for every frame: give it alone";
    if (o->turntable && pattern)
        return "--turntable turns one scene: give a scene, not a pattern with #";
    if (o->turntable && !ptr_batch_is_pattern(o->output))
        return "--turntable needs # in -o for the frame number, e.g. -o out/turn_####.png";
    if (pattern && !ptr_batch_is_pattern(o->output) && !strstr(o->output, "{name}") &&
        !is_folder(o->output))
        return "a sequence needs # (the frame number), {name} or a folder in -o, "
               "e.g. -o out/f_####.png";
    if (o->has_frames && !pattern && !o->turntable && !renders_models(o))
        return "--frames needs a scene pattern with #, --turntable, or a structure with # in "
               "-o";
    return NULL;
}

PtrResult ptr_batch_plan(const PtrOptions *o, PtrBatchItem **items, int *count,
                         PtrStructureFile **structure, PtrError *err)
{
    *items = NULL;
    *count = 0;
    *structure = NULL;
    const char *problem = sequence_problem(o);
    if (problem)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s", problem);
    int sequence = o->turntable || ptr_batch_is_pattern(o->inputs[0]) || renders_models(o);
    PtrResult res = PTR_OK;
    if (sequence) {
        res = plan_frames(o, items, count, structure, err);
    } else {
        *items = calloc((size_t)o->input_count, sizeof **items);
        if (!*items)
            return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory");
        *count = o->input_count;
        char output[PTR_PATH_SIZE];
        for (int i = 0; res == PTR_OK && i < o->input_count; i++) {
            res = ptr_batch_output(o, o->inputs[i], output, err);
            if (res == PTR_OK)
                res = set_item(&(*items)[i], o->inputs[i], output, err);
        }
    }
    /* Every output is settled before anything renders. A sequence's differ
     * (by their numbers, or the names of its numbered scenes); a list of
     * scenes' may not. */
    for (int i = 0; res == PTR_OK && i < *count; i++) {
        res = ptr_output_check(o->images, (*items)[i].output, o->depth, o->transparent,
                               o->passes, err);
        for (int j = 0; res == PTR_OK && !sequence && j < i; j++)
            if (!strcmp((*items)[i].output, (*items)[j].output))
                res = ptr_error_set(err, PTR_ERR_USAGE, "%s and %s would both be written to %s",
                                    (*items)[j].scene, (*items)[i].scene, (*items)[i].output);
    }
    if (res != PTR_OK) {
        ptr_batch_free(*items, *count);
        *items = NULL;
        *count = 0;
        ptr_structure_close(*structure);
        *structure = NULL;
    }
    return res;
}

void ptr_batch_free(PtrBatchItem *items, int count)
{
    for (int i = 0; items && i < count; i++) {
        free(items[i].scene);
        free(items[i].output);
    }
    free(items);
}
