/* The textures that colour spheres (docs/scenes.md, "Textures"): each
 * decoded once, at the first sphere that reads it, through the decoder the
 * import was given, and read at a texture coordinate as glTF samples it. */
#ifndef PTR_GLTF_TEXTURES_H
#define PTR_GLTF_TEXTURES_H

#include "base/result.h"
#include "gltf_doc.h"
#include "import_options.h"

typedef struct GltfTextures GltfTextures;

/* The textures of doc (read from path, which messages name), decoded by
 * decoder: PTR_OK or PTR_ERR_NOMEM. */
PtrResult gltf_textures_new(const GltfDoc *doc, const char *path,
                            const PtrTextureDecoder *decoder, GltfTextures **out, PtrError *err);
void gltf_textures_free(GltfTextures *textures);

/* What a sample gives: the texel as stored (RGBA, 8-bit values over 255),
 * or its RGB decoded from sRGB to linear (base colour and emissive
 * textures: ptr_srgb_to_linear's values), alpha as stored. */
typedef enum GltfTexelValues { GLTF_TEXELS_STORED, GLTF_TEXELS_LINEAR } GltfTexelValues;

/* The texel ref's texture holds at uv (TEXCOORD_n's value), after its
 * KHR_texture_transform and its sampler's wrap modes: the nearest texel,
 * which a palette's texture coordinates hit exactly, as values says.
 * Fails with PTR_ERR_SCENE_INVALID, naming the texture, for one that does
 * not exist or cannot be decoded (KTX2, broken bytes) and for coordinates
 * that are not finite; PTR_ERR_NOMEM. A texture is decoded at its first
 * sample: threads may sample at once only textures sampled before (err
 * NULL or their own). */
PtrResult gltf_textures_sample(GltfTextures *textures, const GltfTextureRef *ref,
                               const double uv[2], GltfTexelValues values, float rgba[4],
                               PtrError *err);

#endif /* PTR_GLTF_TEXTURES_H */
