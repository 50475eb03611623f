/* Accessors read as attributes: checked for what an attribute allows, and
 * their elements read as numbers. */
#ifndef PTR_GLTF_ACCESSORS_H
#define PTR_GLTF_ACCESSORS_H

#include <string.h>

#include "gltf_importer.h"

/* What kinds of stored numbers an attribute accepts. */
typedef enum Components {
    FLOATS,              /* float only */
    FLOATS_OR_SIGNED,    /* float, normalized byte or short */
    FLOATS_OR_UNSIGNED,  /* float, normalized unsigned byte or short */
    QUANTIZED,           /* float, or any byte or short, normalized or not
                          * (KHR_mesh_quantization) */
} Components;

/* o as text for messages, as far as size allows. */
void gltf_origin_text(const Origin *o, char *out, size_t size);

/* Checks accessor index as attribute `what` of o's node: its type (between
 * min_components and max_components numbers an element), its stored numbers,
 * and, unless *count is 0, that it has *count elements (else sets *count). The
 * accessor's bounds within its buffer were checked when the file loaded. */
PtrResult gltf_attribute_accessor(Importer *im, const Origin *o, const char *what, int index,
                                  int min_components, int max_components, Components kinds,
                                  size_t *count, GltfAccessor *a);

/* gltf_element of an accessor of bytes or shorts. */
void gltf_element_integers(const GltfAccessor *a, size_t i, double out[4]);

/* Element i of an accessor checked by gltf_attribute_accessor, each component
 * as gltf_component_value reads it. Missing components are 0. Inline for
 * floats, the common case, read once an instance or a point: called, its
 * results went through memory, and the caller's reads of them as pairs
 * waited on the stores of each. */
static inline void gltf_element(const GltfAccessor *a, size_t i, double out[4])
{
    if (a->component_type != GLTF_FLOAT) {
        gltf_element_integers(a, i, out);
        return;
    }
    const unsigned char *p = a->data + i * a->stride;
    for (int c = 0; c < 4; c++) {
        float f = 0.0f;
        if (c < a->components)
            memcpy(&f, p + c * sizeof f, sizeof f);
        out[c] = f;
    }
}

#endif /* PTR_GLTF_ACCESSORS_H */
