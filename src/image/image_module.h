/* What the image module (image_oiio.cpp, built as a shared object of its own)
 * gives the loader (image.c): one table holding the functions of image.h, the
 * module's only exported symbol. */
#ifndef PTR_IMAGE_MODULE_H
#define PTR_IMAGE_MODULE_H

#include "image/image.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PTR_IMAGE_MODULE_SYMBOL "ptr_image_module"

typedef struct PtrImageModule {
    /* sizeof(PtrImageModule) and PTR_VERSION as the module was built: the
     * loader refuses a module left over from another build of ptr. */
    size_t size;
    const char *version;

    int (*can_write)(const char *path);
    PtrResult (*write)(const char *path, const PtrImageLayout *layout, const float *rgb,
                       const float *sample_counts, PtrPixelFormat format,
                       const PtrImageAttr *attrs, size_t attr_count, PtrError *err);
    void (*discard_partial)(void);
    PtrImage *(*read)(const char *path, PtrError *err);
    void (*free)(PtrImage *image);
    int (*width)(const PtrImage *image);
    int (*height)(const PtrImage *image);
    PtrImageLayout (*layout)(const PtrImage *image);
    const float *(*pixels)(const PtrImage *image);
    const char *(*attr)(const PtrImage *image, const char *name);
} PtrImageModule;

#ifdef __cplusplus
}
#endif

#endif /* PTR_IMAGE_MODULE_H */
