/* What image.c shares with the two writers and readers behind it: the
 * OpenEXR shim (image_exr.cpp, linked in) and the OpenImageIO module
 * (image_oiio.cpp, a shared object of its own that oiio_loader.c loads, only
 * for other formats). A writer writes the file it is given (image.c writes
 * under a temporary name and renames), naming the final one in messages; a
 * reader fills a PtrImage of malloc'ed parts, which image.c frees. */
#ifndef PTR_IMAGE_BACKEND_H
#define PTR_IMAGE_BACKEND_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"

#ifdef __cplusplus
extern "C" {
#endif

struct PtrImage {
    PtrImageLayout layout;
    float *rgb;          /* layout.width x layout.height RGB, rows top to bottom */
    float *alpha;        /* one float a pixel, or NULL: no alpha channel */
    float *albedo, *normal; /* three floats a pixel each, or NULL: no passes (EXR) */
    float *noisy;        /* three floats a pixel, or NULL: not denoised (EXR) */
    int bits_per_channel; /* see ptr_image_bits_per_channel */
    size_t attr_count;
    char **attr_names;   /* as the file names them */
    char **attr_values;  /* as text: numbers formatted */
};

/* Frees an image and whatever parts it has. */
static inline void ptr_image_release(PtrImage *image)
{
    if (!image)
        return;
    for (size_t i = 0; i < image->attr_count; i++) {
        free(image->attr_names[i]);
        free(image->attr_values[i]);
    }
    free(image->attr_names);
    free(image->attr_values);
    free(image->rgb);
    free(image->alpha);
    free(image->albedo);
    free(image->normal);
    free(image->noisy);
    free(image);
}

/* An image of the given pixels and attribute slots (names and values NULL),
 * or NULL if memory runs out. Inline: the module cannot call into ptr. */
static inline PtrImage *ptr_image_alloc(size_t pixels, size_t attr_count)
{
    PtrImage *image = (PtrImage *)calloc(1, sizeof *image);
    if (!image || pixels > SIZE_MAX / (3 * sizeof(float))) {
        free(image);
        return NULL;
    }
    image->rgb = (float *)malloc((pixels ? pixels : 1) * 3 * sizeof(float));
    image->attr_names = (char **)calloc(attr_count ? attr_count : 1, sizeof(char *));
    image->attr_values = (char **)calloc(attr_count ? attr_count : 1, sizeof(char *));
    image->attr_count = attr_count;
    if (!image->rgb || !image->attr_names || !image->attr_values) {
        image->attr_count = 0;
        ptr_image_release(image);
        return NULL;
    }
    return image;
}

/* Gives the image an alpha channel (uninitialised): 0 if memory runs out. */
static inline int ptr_image_alloc_alpha(PtrImage *image)
{
    size_t pixels = (size_t)image->layout.width * (size_t)image->layout.height;
    image->alpha = (float *)malloc((pixels ? pixels : 1) * sizeof(float));
    return image->alpha != NULL;
}

/* Sets attribute slot i to copies of name and value: 0 if memory runs out. */
static inline int ptr_image_set_attr(PtrImage *image, size_t i, const char *name,
                                     const char *value)
{
    image->attr_names[i] = strdup(name);
    image->attr_values[i] = strdup(value);
    return image->attr_names[i] && image->attr_values[i];
}

/* The writers write file, whose format is that of name's extension (the
 * name messages give). OpenEXR (image_exr.cpp): errors are PTR_ERR_OUTPUT
 * when writing, PTR_ERR_USAGE when reading, PTR_ERR_NOMEM either way. */
PtrResult ptr_exr_write(const char *file, const char *name, const PtrImageLayout *layout,
                        const float *rgb, const float *alpha, const PtrImageExtras *extras,
                        PtrPixelFormat format,
                        const PtrImageAttr *attrs, size_t attr_count, PtrError *err);
PtrResult ptr_exr_read(const char *path, PtrImage **out, PtrError *err);
PtrResult ptr_exr_set_threads(int threads, PtrError *err);

#define PTR_IMAGE_MODULE_SYMBOL "ptr_image_module"

/* The OpenImageIO module's one exported symbol. */
typedef struct PtrImageModule {
    /* sizeof(PtrImageModule) and PTR_VERSION as the module was built: the
     * loader refuses a module left over from another build of ptr. */
    size_t size;
    const char *version;

    int (*can_write)(const char *path);
    PtrResult (*write)(const char *file, const char *name, const PtrImageLayout *layout,
                       const float *rgb, const float *alpha, PtrPixelFormat format,
                       const PtrImageAttr *attrs, size_t attr_count, PtrError *err);
    /* Reads the file path, or, where bytes is not NULL, the size bytes
     * given, in the format path's extension names. */
    PtrResult (*read)(const char *path, const unsigned char *bytes, size_t size, PtrImage **out,
                      PtrError *err);
} PtrImageModule;

/* The loader's module into *out, loaded now if its thread has not (see
 * ptr_image_preload): PTR_OK, else what ptr_image_ready says, or
 * PTR_ERR_USAGE naming path without a loader. */
PtrResult ptr_oiio_module(PtrImageLoader *loader, const char *path, const PtrImageModule **out,
                          PtrError *err);

#ifdef __cplusplus
}
#endif

#endif /* PTR_IMAGE_BACKEND_H */
