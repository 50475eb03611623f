/* The C side of image.h: EXR goes to OpenEXR (image_exr.cpp), every other
 * format to the OpenImageIO module (oiio_loader.c). Writes go to a
 * temporary file renamed into place, whichever library writes them. */
#include "image/image_backend.h"

#include <errno.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

enum { PATH_SIZE = 4096 };

/* The temporary file of a write under way, for ptr_image_discard_partial:
 * plain storage a signal handler may read. Writes may run on several
 * threads at once (the library's): the one that claims it keeps it until
 * done, and the others write without it. */
static char partial_path[PATH_SIZE];
static volatile sig_atomic_t partial_active;
static atomic_flag partial_claimed = ATOMIC_FLAG_INIT;

/* The writes of this process so far: each temporary name is its own. */
static atomic_ulong writes_started;

int ptr_image_is_exr(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot && !strcasecmp(dot, ".exr");
}

PtrResult ptr_image_set_threads(int threads, PtrError *err)
{
    return ptr_exr_set_threads(threads, err);
}

PtrResult ptr_image_ready(PtrImageLoader *loader, PtrError *err)
{
    const PtrImageModule *m;
    return ptr_oiio_module(loader, "the image module", &m, err);
}

int ptr_image_can_write(PtrImageLoader *loader, const char *path)
{
    const PtrImageModule *m;
    return ptr_image_is_exr(path) ||
           (ptr_oiio_module(loader, path, &m, NULL) == PTR_OK && m->can_write(path));
}

/* "dir/name.ext" -> "dir/.name.ptr-PID-N.ext", N counting this process's
 * writes: hidden, unique to this write even when threads write the same
 * path, and keeping the extension for tools that look at it. Returns 0 if
 * it does not fit. */
static int temporary_name(const char *path, char *tmp, size_t size)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    int stem = (int)(dot ? dot - base : (ptrdiff_t)strlen(base));
    int n = snprintf(tmp, size, "%.*s.%.*s.ptr-%ld-%lu%s", (int)(base - path), path, stem,
                     base, (long)getpid(), atomic_fetch_add(&writes_started, 1),
                     dot ? dot : "");
    return n > 0 && (size_t)n < size;
}

PtrResult ptr_image_write(PtrImageLoader *loader, const char *path, const PtrImageLayout *layout,
                          const float *rgb, const float *alpha, const PtrImageExtras *extras,
                          PtrPixelFormat format, const PtrImageAttr *attrs, size_t attr_count,
                          PtrError *err)
{
    const int exr = ptr_image_is_exr(path);
    const PtrImageModule *m = NULL;
    PtrResult loaded = exr ? PTR_OK : ptr_oiio_module(loader, path, &m, err);
    if (loaded != PTR_OK)
        return loaded;
    char tmp[PATH_SIZE];
    if (!temporary_name(path, tmp, sizeof tmp))
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: path too long", path);
    const int tracked = !atomic_flag_test_and_set(&partial_claimed);
    if (tracked) {
        memcpy(partial_path, tmp, sizeof tmp);
        partial_active = 1;
    }
    PtrResult res = exr ? ptr_exr_write(tmp, path, layout, rgb, alpha, extras, format,
                                        attrs, attr_count, err)
                        : m->write(tmp, path, layout, rgb, alpha, format, attrs, attr_count, err);
    if (res == PTR_OK && rename(tmp, path) != 0)
        res = ptr_error_set(err, PTR_ERR_OUTPUT, "%s: cannot replace file: %s", path,
                            strerror(errno));
    if (res != PTR_OK)
        unlink(tmp);
    if (tracked) {
        partial_active = 0;
        atomic_flag_clear(&partial_claimed);
    }
    return res;
}

void ptr_image_discard_partial(void)
{
    if (partial_active)
        unlink(partial_path);
}

PtrResult ptr_image_read(PtrImageLoader *loader, const char *path, PtrImage **out,
                         PtrError *err)
{
    if (ptr_image_is_exr(path))
        return ptr_exr_read(path, out, err);
    const PtrImageModule *m;
    PtrResult loaded = ptr_oiio_module(loader, path, &m, err);
    return loaded == PTR_OK ? m->read(path, NULL, 0, out, err) : loaded;
}

PtrResult ptr_image_decode(PtrImageLoader *loader, const char *name, const unsigned char *bytes,
                           size_t size, PtrImage **out, PtrError *err)
{
    const PtrImageModule *m;
    PtrResult loaded = ptr_oiio_module(loader, name, &m, err);
    return loaded == PTR_OK ? m->read(name, bytes, size, out, err) : loaded;
}

void ptr_image_free(PtrImage *image)
{
    ptr_image_release(image);
}

int ptr_image_width(const PtrImage *image) { return image->layout.width; }
int ptr_image_height(const PtrImage *image) { return image->layout.height; }
PtrImageLayout ptr_image_layout(const PtrImage *image) { return image->layout; }
const float *ptr_image_pixels(const PtrImage *image) { return image->rgb; }
const float *ptr_image_alpha(const PtrImage *image) { return image->alpha; }
const float *ptr_image_albedo(const PtrImage *image) { return image->albedo; }
const float *ptr_image_normal(const PtrImage *image) { return image->normal; }
const float *ptr_image_noisy(const PtrImage *image) { return image->noisy; }
int ptr_image_bits_per_channel(const PtrImage *image) { return image->bits_per_channel; }

const char *ptr_image_attr(const PtrImage *image, const char *name)
{
    for (size_t i = 0; i < image->attr_count; i++)
        if (!strcmp(image->attr_names[i], name))
            return image->attr_values[i];
    return NULL;
}
