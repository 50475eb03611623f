/* Image files behind a C interface: EXR through OpenEXR, linked in; every
 * other format through OpenImageIO, in a module loaded at run time, so that a
 * process which writes or reads no such image never loads it (260 shared
 * libraries); the functions here load it on first use. */
#ifndef PTR_IMAGE_H
#define PTR_IMAGE_H

#include <stddef.h>

#include "base/result.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum PtrPixelFormat {
    PTR_PIXEL_UINT8,
    PTR_PIXEL_UINT16,
    PTR_PIXEL_HALF,
    PTR_PIXEL_FLOAT,
} PtrPixelFormat;

typedef enum PtrAttrType { PTR_ATTR_INT, PTR_ATTR_FLOAT, PTR_ATTR_STRING } PtrAttrType;

/* One metadata entry of an image file's header. */
typedef struct PtrImageAttr {
    const char *name;
    PtrAttrType type;
    int int_value;
    float float_value;
    const char *string_value;
} PtrImageAttr;

/* Where the stored pixels sit in the full image: a crop is a data window
 * inside a larger display window (formats that have no such notion store the
 * crop alone). */
typedef struct PtrImageLayout {
    int width, height;           /* pixels stored */
    int x, y;                    /* their top-left corner in the full image */
    int full_width, full_height; /* the full image */
} PtrImageLayout;

/* How many threads compress and decompress EXR files (default 1). Zip
 * compression is slow: a 1000x1000 render at 1 sample on two cores took
 * 0.61-0.67 s with one thread compressing, 0.46-0.49 s with two.
 * PTR_ERR_NOMEM if they cannot be started. */
PtrResult ptr_image_set_threads(int threads, PtrError *err);

/* Whether a file of this name is EXR, written and read through OpenEXR; every
 * other format goes through the OpenImageIO module. */
int ptr_image_is_exr(const char *path);

/* The OpenImageIO module as one owner loads it, once, at first use or
 * early (ptr_image_preload). The functions below that take a loader need it
 * for formats other than EXR only, and take NULL from a caller that reads
 * and writes EXR alone (any other format is then PTR_ERR_USAGE). */
typedef struct PtrImageLoader PtrImageLoader;

/* A loader that has loaded nothing yet, into *out: PTR_OK or PTR_ERR_NOMEM. */
PtrResult ptr_image_loader_new(PtrImageLoader **out, PtrError *err);

/* Waits for the loader's thread, if it runs (exiting while it runs the
 * libraries' constructors would race their destructors), and frees the
 * loader; the module stays loaded for the process. Takes NULL. */
void ptr_image_loader_free(PtrImageLoader *loader);

/* If writing output needs the module, starts loading it on a thread of its
 * own and returns at once: PTR_OK, or PTR_ERR_INSTALL with one line in err if
 * the module file is missing (a broken installation). */
PtrResult ptr_image_preload(PtrImageLoader *loader, const char *output, PtrError *err);

/* Loads the module, or waits for ptr_image_preload's thread: PTR_OK once it
 * works, else (and the formats it serves then fail alike) PTR_ERR_NOMEM if
 * the module or a library it needs could not be mapped for want of memory,
 * PTR_ERR_INSTALL if it cannot be loaded otherwise, with one line in err. */
PtrResult ptr_image_ready(PtrImageLoader *loader, PtrError *err);

/* Whether a writer exists for the file's extension. */
int ptr_image_can_write(PtrImageLoader *loader, const char *path);

/* What an EXR holds beside the colour and alpha, in float channels of their
 * own, each where it is not NULL: how many samples each pixel took (one
 * float a pixel: "samples"), the albedo and normal passes, and the noisy
 * colour of a denoised image (three floats a pixel each: "albedo.R/G/B",
 * "normal.X/Y/Z", "noisy.R/G/B"). */
typedef struct PtrImageExtras {
    const float *sample_counts;
    const float *albedo, *normal;
    const float *noisy;
} PtrImageExtras;

/* Writes RGB float pixels (rows top to bottom), stored in the file as format,
 * with an alpha channel (A) from alpha if it is not NULL, and for EXR, whose
 * channels have names, the extras if they are not NULL (other formats
 * ignore them). The pixels are written as given:
 * the caller premultiplies them or not, as the format expects.
 * The file is created under a temporary name in the same directory and
 * renamed over path only once complete, so an existing file is replaced by a
 * whole new one or not at all. Returns PTR_OK; otherwise fills err with one
 * line and returns its code: PTR_ERR_OUTPUT, PTR_ERR_NOMEM, or what
 * ptr_image_ready says. */
PtrResult ptr_image_write(PtrImageLoader *loader, const char *path, const PtrImageLayout *layout,
                          const float *rgb, const float *alpha, const PtrImageExtras *extras,
                          PtrPixelFormat format, const PtrImageAttr *attrs, size_t attr_count,
                          PtrError *err);

/* Removes the temporary file of a write under way, if any. Safe to call from
 * a signal handler: for a process that is about to _exit mid-write. */
void ptr_image_discard_partial(void);

/* An image read back as float RGB (grey replicated) and its alpha channel,
 * if it has one, and an EXR's albedo and normal passes and noisy colour, if
 * it has them; other channels are dropped. */
typedef struct PtrImage PtrImage;

/* The image into *out (for ptr_image_free): PTR_OK, else PTR_ERR_USAGE for a
 * file that is not an image the module can read (images are read only as
 * files the command line names), PTR_ERR_NOMEM, or what ptr_image_ready
 * says. */
PtrResult ptr_image_read(PtrImageLoader *loader, const char *path, PtrImage **out,
                         PtrError *err);
/* An image file's size bytes, held in memory (a texture a glTF embeds),
 * decoded through the module in the format name's extension gives (PNG,
 * JPEG, WebP, ...), into *out; errors as ptr_image_read's, naming name. */
PtrResult ptr_image_decode(PtrImageLoader *loader, const char *name, const unsigned char *bytes,
                           size_t size, PtrImage **out, PtrError *err);
void ptr_image_free(PtrImage *image);
int ptr_image_width(const PtrImage *image);
int ptr_image_height(const PtrImage *image);
PtrImageLayout ptr_image_layout(const PtrImage *image);
const float *ptr_image_pixels(const PtrImage *image);
/* One float a pixel, as stored; NULL if the image has no alpha channel. */
const float *ptr_image_alpha(const PtrImage *image);
/* Three floats a pixel each, as stored; NULL if the image has no passes. */
const float *ptr_image_albedo(const PtrImage *image);
const float *ptr_image_normal(const PtrImage *image);
/* Three floats a pixel, as stored; NULL unless the image was denoised. */
const float *ptr_image_noisy(const PtrImage *image);
/* The bits of each channel where the file stores unsigned integers, all of
 * one size (8 for a PNG, JPEG or WebP of bytes, palettes' too: every value
 * is then a byte n read as n / 255; 16: n / 65535); 0 for floats (EXR) and
 * any other types. */
int ptr_image_bits_per_channel(const PtrImage *image);

/* A header attribute as text (numbers formatted), or NULL if absent. The
 * string lives as long as the image. */
const char *ptr_image_attr(const PtrImage *image, const char *name);

#ifdef __cplusplus
}
#endif

#endif /* PTR_IMAGE_H */
