#include "importer.h"

#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "base/memory.h"
#include "importer_internal.h"

typedef PtrResult (*ImportFn)(const char *, const PtrImportOptions *, PtrScene *,
                              PtrStrings *, PtrError *);

static const struct {
    const char *extension;
    ImportFn import;
} importers[] = {
    { ".gltf", ptr_import_gltf },
    { ".glb", ptr_import_gltf },
    { ".obj", ptr_import_obj },
    { ".pdb", ptr_import_structure }, { ".pdb.gz", ptr_import_structure },
    { ".ent", ptr_import_structure }, { ".ent.gz", ptr_import_structure },
    { ".cif", ptr_import_structure }, { ".cif.gz", ptr_import_structure },
    { ".mmcif", ptr_import_structure }, { ".mmcif.gz", ptr_import_structure },
};

/* Formats that a script turns into an instanced .glb (docs/scenes.md). */
static const struct {
    const char *extension, *script;
} converters[] = {
    { ".xyz", "molecule_to_glb.py" }, { ".extxyz", "molecule_to_glb.py" },
    { ".csv", "particles_to_glb.py" }, { ".ply", "particles_to_glb.py" },
};

/* What the importers table reads, for the message that a file is none of it. */
#define KNOWN ".gltf, .glb, .obj, .pdb, .ent, .cif or .mmcif (those four also .gz)"

/* Whether the file name path ends in extension, in any case. */
static int has_extension(const char *path, const char *extension)
{
    const size_t length = strlen(path), tail = strlen(extension);
    return length > tail && !strcasecmp(path + length - tail, extension);
}

void ptr_warn(PtrStrings *warnings, const char *fmt, ...)
{
    char line[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    char **grown = realloc(warnings->lines, (warnings->count + 1) * sizeof *grown);
    if (!grown)
        return; /* a warning lost to memory exhaustion is not worth failing for */
    warnings->lines = grown;
    grown[warnings->count] = strdup(line);
    if (grown[warnings->count])
        warnings->count++;
}

void ptr_strings_free(PtrStrings *warnings)
{
    for (size_t i = 0; i < warnings->count; i++)
        free(warnings->lines[i]);
    free(warnings->lines);
    warnings->lines = NULL;
    warnings->count = 0;
}

PtrResult ptr_import_finish(PtrSceneBuilder *builder, const char *path, PtrError *err)
{
    PtrError problem;
    PtrResult res = ptr_builder_finish(builder, PTR_BUILD_DEFAULT, &problem);
    return res == PTR_OK ? res : ptr_error_set(err, res, "%s: %s", path, problem.message);
}

PtrResult ptr_import_check_memory(const char *path, uint64_t spheres, PtrError *err)
{
    const uint64_t available = ptr_memory_available();
    if (spheres <= available / PTR_SPHERE_PEAK_BYTES)
        return PTR_OK;
    return ptr_error_set(err, PTR_ERR_NOMEM,
                         "%s: out of memory: %" PRIu64 " spheres need about %.1f GB, and %.1f GB "
                         "is available", path, spheres,
                         (double)spheres * PTR_SPHERE_PEAK_BYTES * 1e-9, (double)available * 1e-9);
}

int ptr_import_is_structure(const char *path)
{
    for (size_t i = 0; i < sizeof importers / sizeof importers[0]; i++)
        if (has_extension(path, importers[i].extension))
            return importers[i].import == ptr_import_structure;
    return 0;
}

PtrResult ptr_import_scene(const char *path, const PtrImportOptions *options,
                           PtrScene *scene, PtrStrings *warnings, PtrError *err)
{
    ptr_scene_init(scene);
    struct stat st;
    if (stat(path, &st) != 0)
        return ptr_error_set(err, PTR_ERR_SCENE_UNREADABLE, "%s: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode))
        return ptr_error_set(err, PTR_ERR_SCENE_UNREADABLE, "%s: is a directory, not a scene file",
                             path);

    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (dot && slash && dot < slash)
        dot = NULL;
    for (size_t i = 0; dot && i < sizeof importers / sizeof importers[0]; i++) {
        if (!has_extension(path, importers[i].extension))
            continue;
        if (S_ISREG(st.st_mode) && st.st_size == 0)
            return ptr_error_set(err, PTR_ERR_SCENE_INVALID, "%s: the file is empty", path);
        PtrResult r = importers[i].import(path, options, scene, warnings, err);
        /* A structure's --color-by may name a colour scheme, which gives
         * colours, not values (structure_import.c checks its own). */
        if (r == PTR_OK && options && options->value_attribute && !scene->spheres.value &&
            importers[i].import != ptr_import_structure)
            r = ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                              "%s: no instance or point attribute '%s' (--color-by)", path,
                              options->value_attribute);
        if (r != PTR_OK)
            ptr_scene_free(scene);
        return r;
    }
    for (size_t i = 0; dot && i < sizeof converters / sizeof converters[0]; i++)
        if (!strcasecmp(dot, converters[i].extension))
            return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                                 "%s: unknown scene format (expected %s); "
                                 "scripts/%s converts this one to .glb", path, KNOWN,
                                 converters[i].script);
    return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                         "%s: unknown scene format (expected %s)", path, KNOWN);
}
