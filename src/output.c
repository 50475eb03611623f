#include "output.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image/image.h"
#include "version.h"

static int is_float_format(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot && (!strcasecmp(dot, ".exr") || !strcasecmp(dot, ".hdr"));
}

PtrResult ptr_output_check(const char *path, PtrError *err)
{
    if (!ptr_image_can_write(path))
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "%s: no image format for this extension (try .exr or .png)", path);
    /* The file is written beside its final name and renamed, so the folder
     * must take new files. */
    char dir[4096];
    const char *slash = strrchr(path, '/');
    size_t len = slash ? (size_t)(slash - path) : 1;
    if (len >= sizeof dir)
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: path too long", path);
    memcpy(dir, slash ? path : ".", len);
    dir[len] = '\0';
    if (slash && len == 0)
        strcpy(dir, "/");
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: folder %s does not exist", path, dir);
    if (access(dir, W_OK | X_OK) != 0)
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: cannot create files in %s: %s", path, dir,
                             strerror(errno));
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s: is a directory", path);
    return PTR_OK;
}

float ptr_srgb_encode(float linear)
{
    float x = fminf(fmaxf(linear, 0.0f), 1.0f);
    return x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
}

PtrResult ptr_output_write(const char *path, int width, int height, const float *rgb,
                           const PtrOutputInfo *info, PtrError *err)
{
    int linear = is_float_format(path);
    size_t values = (size_t)width * (size_t)height * 3;
    float *encoded = NULL;
    if (!linear) {
        encoded = malloc(values * sizeof *encoded);
        if (!encoded)
            return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
        for (size_t i = 0; i < values; i++)
            encoded[i] = ptr_srgb_encode(rgb[i]);
    }

    char seed[24];
    snprintf(seed, sizeof seed, "%" PRIu64, info->seed);
    const PtrImageAttr attrs[] = {
        { .name = "Software", .type = PTR_ATTR_STRING, .string_value = "ptr " PTR_VERSION },
        { .name = "oiio:ColorSpace", .type = PTR_ATTR_STRING,
          .string_value = linear ? "lin_rec709" : "sRGB" },
        { .name = "ptr:scene", .type = PTR_ATTR_STRING, .string_value = info->scene_path },
        { .name = "ptr:samples", .type = PTR_ATTR_INT, .int_value = (int)info->samples },
        { .name = "ptr:seed", .type = PTR_ATTR_STRING, .string_value = seed },
        { .name = "ptr:max_depth", .type = PTR_ATTR_INT, .int_value = info->max_depth },
        { .name = "ptr:kernel", .type = PTR_ATTR_STRING, .string_value = info->kernel },
        { .name = "ptr:render_seconds", .type = PTR_ATTR_FLOAT,
          .float_value = (float)info->render_seconds },
    };
    PtrPixelFormat format = !linear ? PTR_PIXEL_UINT8 : info->half ? PTR_PIXEL_HALF
                                                                     : PTR_PIXEL_FLOAT;
    char message[sizeof err->message];
    int failed = ptr_image_write(path, width, height, linear ? rgb : encoded, format, attrs,
                                 sizeof attrs / sizeof attrs[0], message, sizeof message);
    free(encoded);
    if (failed)
        return ptr_error_set(err, PTR_ERR_OUTPUT, "%s", message);
    return PTR_OK;
}
