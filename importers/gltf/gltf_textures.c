/* Textures read at texture coordinates, decoded lazily (gltf_textures.h). */
#include "gltf_textures.h"

#include <math.h>
#include <stdlib.h>

#include "scene/colormap.h"

/* A texture as decoded, or why it cannot be. */
typedef struct Decoded {
    int state; /* UNREAD, READ or FAILED */
    GltfTexture info;
    PtrTexels texels; /* rgba NULL where bytes holds them */
    /* Where the file holds bytes (palettes too): the texels as those bytes,
     * RGBA, read through the tables of GltfTextures; else NULL. */
    unsigned char *bytes;
    PtrError error; /* FAILED: the message, given again at each sample */
} Decoded;

enum { UNREAD, READ, FAILED };

enum { BYTE_VALUES = 256 };

struct GltfTextures {
    const GltfDoc *doc;
    const char *path;
    PtrTextureDecoder decoder;
    Decoded *textures; /* one a texture of the file */
    size_t count;
    /* Byte n's value as the image module decodes it (n times 1 / 255, as
     * OpenImageIO converts), and that value decoded from sRGB: so that the
     * texels of an 8-bit texture are made linear once an import, not
     * through pow at every vertex. */
    float byte_value[BYTE_VALUES], byte_linear[BYTE_VALUES];
};

PtrResult gltf_textures_new(const GltfDoc *doc, const char *path,
                            const PtrTextureDecoder *decoder, GltfTextures **out, PtrError *err)
{
    GltfTextures *t = calloc(1, sizeof *t);
    const size_t count = gltf_doc_texture_count(doc);
    Decoded *textures = t ? calloc(count ? count : 1, sizeof *textures) : NULL;
    if (!textures) {
        free(t);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    }
    *t = (GltfTextures){ doc, path, *decoder, textures, count, { 0 }, { 0 } };
    for (int n = 0; n < BYTE_VALUES; n++) {
        t->byte_value[n] = (float)n * (1.0f / 255.0f);
        t->byte_linear[n] = ptr_srgb_to_linear(t->byte_value[n]);
    }
    *out = t;
    return PTR_OK;
}

void gltf_textures_free(GltfTextures *textures)
{
    if (!textures)
        return;
    for (size_t i = 0; i < textures->count; i++) {
        free(textures->textures[i].texels.rgba);
        free(textures->textures[i].bytes);
    }
    free(textures->textures);
    free(textures);
}

/* An 8-bit texture's texels as bytes (d->bytes), a quarter of the floats'
 * memory, the floats then freed; if memory is short, the floats as they
 * are. */
static void keep_bytes(Decoded *d)
{
    if (d->texels.bits_per_channel != 8)
        return;
    const size_t values = 4 * (size_t)d->texels.width * (size_t)d->texels.height;
    unsigned char *bytes = malloc(values);
    if (!bytes)
        return;
    for (size_t i = 0; i < values; i++) /* n times 1 / 255 back to n */
        bytes[i] = (unsigned char)(d->texels.rgba[i] * 255.0f + 0.5f);
    free(d->texels.rgba);
    d->texels.rgba = NULL;
    d->bytes = bytes;
}

/* Texture index decoded, at its first use. */
static PtrResult decode(GltfTextures *t, int index, const Decoded **out, PtrError *err)
{
    if (index < 0 || (size_t)index >= t->count)
        return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                             "%s: a material refers to texture %d, which does not exist",
                             t->path, index);
    Decoded *d = &t->textures[index];
    if (d->state == UNREAD) {
        gltf_doc_texture(t->doc, index, &d->info);
        PtrError inner = { 0 };
        PtrResult res = PTR_OK;
        if (d->info.fault)
            res = ptr_error_set(&d->error, PTR_ERR_SCENE_INVALID, "%s: texture %d %s", t->path,
                                index, d->info.fault);
        else if ((res = t->decoder.decode(t->decoder.context, d->info.name, d->info.bytes,
                                          d->info.size, &d->texels, &inner)) != PTR_OK)
            res = ptr_error_set(&d->error, res == PTR_ERR_NOMEM ? res : PTR_ERR_SCENE_INVALID,
                                "%s (texture %d)", inner.message, index);
        else if (d->texels.width <= 0 || d->texels.height <= 0)
            res = ptr_error_set(&d->error, PTR_ERR_SCENE_INVALID, "%s: texture %d is empty",
                                t->path, index);
        else
            keep_bytes(d);
        d->state = res == PTR_OK ? READ : FAILED;
    }
    if (d->state == FAILED)
        return ptr_error_set(err, d->error.code, "%s", d->error.message);
    *out = d;
    return PTR_OK;
}

/* A coordinate wrapped into [0, 1] as the sampler's mode says. */
static double wrap(double x, int mode)
{
    if (mode == GLTF_CLAMP)
        return x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x;
    if (mode == GLTF_MIRRORED_REPEAT) {
        const double t = x - 2.0 * floor(0.5 * x);
        return t > 1.0 ? 2.0 - t : t;
    }
    return x - floor(x);
}

/* The texel of a wrapped coordinate among n (the last for 1.0). */
static int texel_of(double x, int n)
{
    const int i = (int)(x * n);
    return i < n ? i : n - 1;
}

PtrResult gltf_textures_sample(GltfTextures *textures, const GltfTextureRef *ref,
                               const double uv[2], GltfTexelValues values, float rgba[4],
                               PtrError *err)
{
    const Decoded *d;
    PtrResult res = decode(textures, ref->texture, &d, err);
    if (res != PTR_OK)
        return res;
    /* KHR_texture_transform: offset + rotation * (scale * uv), the
     * rotation counter-clockwise in the image as glTF's matrix has it. */
    const double c = cos(ref->rotation), s = sin(ref->rotation);
    const double su = ref->scale[0] * uv[0], sv = ref->scale[1] * uv[1];
    const double u = ref->offset[0] + c * su + s * sv, v = ref->offset[1] - s * su + c * sv;
    if (!isfinite(u) || !isfinite(v))
        return ptr_error_set(err, PTR_ERR_SCENE_INVALID,
                             "%s: texture %d is read at a texture coordinate that is not finite",
                             textures->path, ref->texture);
    const PtrTexels *t = &d->texels;
    const size_t x = (size_t)texel_of(wrap(u, d->info.wrap_s), t->width);
    const size_t y = (size_t)texel_of(wrap(v, d->info.wrap_t), t->height);
    const size_t first = 4 * (y * (size_t)t->width + x);
    for (int k = 0; k < 4; k++) {
        const int linear = values == GLTF_TEXELS_LINEAR && k < 3;
        if (d->bytes) {
            const unsigned char n = d->bytes[first + (size_t)k];
            rgba[k] = linear ? textures->byte_linear[n] : textures->byte_value[n];
        } else {
            const float stored = t->rgba[first + (size_t)k];
            rgba[k] = linear ? ptr_srgb_to_linear(stored) : stored;
        }
    }
    return PTR_OK;
}
