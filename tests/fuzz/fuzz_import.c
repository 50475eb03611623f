/* libFuzzer harness for the importers: each input becomes a scene file, which
 * ptr_import_scene must accept or refuse cleanly, never crash on, within
 * bounded time and memory. FUZZ_FORMAT picks the importer: 1 for glTF (a .glb
 * when the input starts with the binary magic, else a .gltf), 2 for OBJ (the
 * input is also its own fuzz.mtl, so that `mtllib fuzz.mtl` lines reach the
 * MTL reader), 3 for structures (an mmCIF when the input starts with data_,
 * else a PDB; gzipped when it starts with gzip's magic). */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "importer.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char dir[64];

static void write_file(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        abort();
    if (size && fwrite(data, 1, size, f) != size)
        abort();
    fclose(f);
}

/* A stand-in for the image module's decoder, so that the fuzzer reaches
 * texture sampling (glTF) without OpenImageIO: an image's first two bytes
 * give its size (1 to 16 texels a side), the bytes after them its texels,
 * cycled; fewer than 3 bytes is a broken image. */
static PtrResult decode_texels(void *context, const char *name, const unsigned char *bytes,
                               size_t size, PtrTexels *out, PtrError *err)
{
    (void)context;
    if (size < 3)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s: not an image", name);
    out->width = 1 + bytes[0] % 16;
    out->height = 1 + bytes[1] % 16;
    const size_t values = 4 * (size_t)out->width * (size_t)out->height;
    out->rgba = malloc(values * sizeof *out->rgba);
    if (!out->rgba)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", name);
    for (size_t i = 0; i < values; i++)
        out->rgba[i] = bytes[2 + i % (size - 2)] * (1.0f / 255.0f);
    out->bits_per_channel = 8;
    return PTR_OK;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "/tmp/ptr-fuzz-%d", (int)getpid());
        char cmd[96];
        snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
        if (system(cmd) != 0)
            abort();
    }
    char path[96];
#if FUZZ_FORMAT == 1
    int binary = size >= 4 && !memcmp(data, "glTF", 4);
    snprintf(path, sizeof path, "%s/fuzz.%s", dir, binary ? "glb" : "gltf");
#elif FUZZ_FORMAT == 3
    const int cif = size >= 5 && !memcmp(data, "data_", 5);
    const int gzipped = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
    snprintf(path, sizeof path, "%s/fuzz.%s%s", dir, cif ? "cif" : "pdb", gzipped ? ".gz" : "");
#else
    snprintf(path, sizeof path, "%s/fuzz.mtl", dir);
    write_file(path, data, size);
    snprintf(path, sizeof path, "%s/fuzz.obj", dir);
#endif
    write_file(path, data, size);

    PtrScene scene;
    PtrStrings warnings = { 0 }, dependencies = { 0 };
    PtrError err = { 0 };
    /* Half the inputs also read a value per sphere (--color-by): COLOR_0
     * names both the points' COLOR_0 and the instances' _COLOR_0, which the
     * seed files have; a structure's B-factor. Structures are read with
     * waters or without, hydrogens or without. Half the glTF files have
     * their textures read. */
    PtrImportOptions options = {
        .dependencies = &dependencies, .fit_all_objects = size & 1,
        .value_attribute = size & 2 ? (FUZZ_FORMAT == 3 ? "bfactor" : "color_0") : NULL,
        .structure_select = size & 4 ? PTR_STRUCTURE_ALL : 0, .drop_hydrogens = size & 8,
        .textures = { size & 16 ? decode_texels : NULL, NULL } };
    PtrResult r = ptr_import_scene(path, &options, &scene, &warnings, &err);
    /* A refusal is one line that names the file. */
    if (r != PTR_OK && (strchr(err.message, '\n') || strncmp(err.message, path, strlen(dir))))
        abort();
    ptr_strings_free(&warnings);
    ptr_strings_free(&dependencies);
    ptr_scene_free(&scene);
    return 0;
}
