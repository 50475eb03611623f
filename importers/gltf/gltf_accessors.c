/* Accessors read as attributes (gltf_accessors.h). */
#include "gltf_accessors.h"

#include <stdio.h>
#include <string.h>

void gltf_origin_text(const Origin *o, char *out, size_t size)
{
    int n = snprintf(out, size, "node %zu ('%s')", o->node_index, o->node_name);
    if (o->part && n >= 0 && (size_t)n < size)
        snprintf(out + n, size - (size_t)n, ", %s %zu", o->part, o->part_index);
}

PtrResult gltf_attribute_accessor(Importer *im, const Origin *o, const char *what, int index,
                                  int min_components, int max_components, Components kinds,
                                  size_t *count, GltfAccessor *a)
{
    gltf_doc_accessor(im->doc, (size_t)index, a);
    const int t = a->component_type;
    int integer = t == GLTF_BYTE || t == GLTF_UNSIGNED_BYTE || t == GLTF_SHORT ||
                  t == GLTF_UNSIGNED_SHORT;
    int kind_ok = (t == GLTF_FLOAT && !a->normalized) || (kinds == QUANTIZED && integer) ||
                  (kinds == FLOATS_OR_SIGNED && a->normalized && (t == GLTF_BYTE || t == GLTF_SHORT)) ||
                  (kinds == FLOATS_OR_UNSIGNED && a->normalized &&
                   (t == GLTF_UNSIGNED_BYTE || t == GLTF_UNSIGNED_SHORT));
    const char *fault = a->sparse ? "is sparse, which ptr does not read"
                        : !a->data ? "has no buffer view"
                        : a->components < min_components || a->components > max_components
                            ? "has the wrong type"
                        : !kind_ok ? "has a component type its attribute does not allow"
                        : *count && a->count != *count ? "has a count that differs from the other attributes'"
                        : a->count == 0 ? "is empty"
                                        : NULL;
    if (fault) {
        char where[160];
        gltf_origin_text(&(Origin){ o->node_index, o->node_name, NULL, 0 }, where, sizeof where);
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID, "%s: %s: %s accessor %d %s",
                             im->path, where, what, index, fault);
    }
    *count = a->count;
    return PTR_OK;
}

void gltf_element_integers(const GltfAccessor *a, size_t i, double out[4])
{
    const unsigned char *p = a->data + i * a->stride;
    for (int c = 0; c < 4; c++) {
        double raw = 0;
        if (c < a->components) {
            switch (a->component_type) {
            case GLTF_UNSIGNED_BYTE: raw = p[c]; break;
            case GLTF_BYTE: raw = (signed char)p[c]; break;
            case GLTF_UNSIGNED_SHORT: { uint16_t u; memcpy(&u, p + 2 * c, 2); raw = u; break; }
            case GLTF_SHORT: { int16_t u; memcpy(&u, p + 2 * c, 2); raw = u; break; }
            }
        }
        out[c] = gltf_component_value(a->component_type, a->normalized, raw);
    }
}
