/* PNG through libpng, into memory: the page's image. Stored, not
 * compressed (zlib level 0, no filter): a frame is shown once and replaced
 * within a second, mostly over the loopback, where bytes cost nothing and
 * compression would cost the render's CPU (level 1 took ten times the
 * encoding's time: 10 to 15 ms of CPU for 500x500 pixels against 1 to 2). */
#include "live/live_module.h"

#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>

typedef struct Buffer {
    unsigned char *data;
    size_t size, capacity;
    int failed;
} Buffer;

static void write_bytes(png_structp png, png_bytep bytes, png_size_t n)
{
    Buffer *b = png_get_io_ptr(png);
    if (b->failed)
        return;
    if (b->size + n > b->capacity) {
        size_t capacity = (b->size + n) * 2;
        unsigned char *data = realloc(b->data, capacity);
        if (!data) {
            b->failed = 1;
            return;
        }
        b->data = data;
        b->capacity = capacity;
    }
    memcpy(b->data + b->size, bytes, n);
    b->size += n;
}

static void flush_nothing(png_structp png)
{
    (void)png;
}

unsigned char *ptr_live_png_encode(const unsigned char *rgb, int width, int height, size_t *size)
{
    Buffer buffer = { 0 };
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, NULL, NULL, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    png_bytep *rows = malloc((size_t)height * sizeof *rows);
    if (!png || !info || !rows || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        free(rows);
        free(buffer.data);
        return NULL;
    }
    for (int y = 0; y < height; y++)
        rows[y] = (png_bytep)(rgb + (size_t)y * (size_t)width * 3);
    png_set_write_fn(png, &buffer, write_bytes, flush_nothing);
    png_set_IHDR(png, info, (png_uint_32)width, (png_uint_32)height, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    /* No colour chunk: the pixels are the view's already, and a browser
     * shows an untagged image as it is. */
    png_set_compression_level(png, 0);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_rows(png, info, rows);
    png_write_png(png, info, PNG_TRANSFORM_IDENTITY, NULL);
    png_destroy_write_struct(&png, &info);
    free(rows);
    if (buffer.failed) {
        free(buffer.data);
        return NULL;
    }
    *size = buffer.size;
    return buffer.data;
}
