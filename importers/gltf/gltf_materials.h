/* glTF materials as the scene's (docs/scenes.md, "Materials"). */
#ifndef PTR_GLTF_MATERIALS_H
#define PTR_GLTF_MATERIALS_H

#include "gltf_importer.h"

/* What a sphere reads of its material where textures and vertex colours
 * may change it: the factors times their means (docs/scenes.md). */
typedef struct MaterialValues {
    double base[3], emission[3], metallic, roughness;
} MaterialValues;

/* Whether a material takes a value from a texture. */
int gltf_has_color_texture(const GltfMaterial *g);

/* A material's values from its factors alone. */
MaterialValues gltf_factor_values(const GltfMaterial *g);

/* glTF material gltf_index (its values v) as ptr's (docs/scenes.md). */
PtrResult gltf_convert_material(Importer *im, int gltf_index, const GltfMaterial *g,
                                const MaterialValues *v, PtrMaterial *m);

/* The scene material of glTF material gltf_index (-1: none, ptr's default
 * grey), made at its first use. */
PtrResult gltf_map_material(Importer *im, int gltf_index, uint32_t *out);

/* The scene material of value m, made once however many spheres have it:
 * a million spheres of a palette of a hundred colours make a hundred. */
PtrResult gltf_made_material(Importer *im, const PtrMaterial *m, uint32_t *out);

/* A primitive's material, or glTF's stand-in for none: ptr's default grey
 * (docs/scenes.md). */
void gltf_primitive_material(const Importer *im, const GltfPrimitive *prim, GltfMaterial *g);

#endif /* PTR_GLTF_MATERIALS_H */
