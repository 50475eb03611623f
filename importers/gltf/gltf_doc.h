/* A glTF document as plain C data: the parts of tinygltf's model that ptr
 * maps onto its scene, with indices checked. Everything about the scene
 * conventions lives in gltf_import.c; this layer only reads the file. */
#ifndef PTR_GLTF_DOC_H
#define PTR_GLTF_DOC_H

#include <stddef.h>

#include "base/result.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct GltfDoc GltfDoc;

/* glTF's accessor component types. */
enum {
    GLTF_BYTE = 5120, GLTF_UNSIGNED_BYTE = 5121, GLTF_SHORT = 5122,
    GLTF_UNSIGNED_SHORT = 5123, GLTF_UNSIGNED_INT = 5125, GLTF_FLOAT = 5126,
};

/* A component as glTF reads it: a normalized integer maps to [0, 1]
 * (unsigned) or [-1, 1] (signed, the lowest value clamped), any other number
 * is its value. For the elements and for an accessor's min and max alike
 * (those of a normalized accessor are stored as integers). */
static inline double gltf_component_value(int component_type, int normalized, double raw)
{
    if (!normalized)
        return raw;
    switch (component_type) {
    case GLTF_UNSIGNED_BYTE: return raw / 255.0;
    case GLTF_BYTE: return raw / 127.0 < -1.0 ? -1.0 : raw / 127.0;
    case GLTF_UNSIGNED_SHORT: return raw / 65535.0;
    case GLTF_SHORT: return raw / 32767.0 < -1.0 ? -1.0 : raw / 32767.0;
    default: return raw;
    }
}

/* An accessor's elements as the file stores them. Elements lie inside the
 * buffer (checked when the file loaded); data is NULL where the accessor
 * has no buffer view (glTF's all-zero accessor) or is sparse. */
typedef struct GltfAccessor {
    const unsigned char *data;
    size_t count;
    size_t stride;      /* bytes from one element to the next */
    int component_type; /* GLTF_BYTE ... GLTF_FLOAT */
    int components;     /* 1 (SCALAR) to 4 (VEC4); 0 for matrices */
    int normalized;
    int sparse;
} GltfAccessor;

/* A POINTS primitive's or an EXT_mesh_gpu_instancing node's attributes:
 * accessor indices, -1 where absent (all checked to be in range). */
typedef struct GltfInstancing {
    int translation, rotation, scale, color; /* color: _COLOR_0 */
} GltfInstancing;

typedef struct GltfPrimitive {
    int points;   /* mode 0 (POINTS) */
    int material; /* -1 if none */
    int position, radius, color; /* POSITION, _RADIUS, COLOR_0; -1 if absent */
    int draco;    /* compressed by KHR_draco_mesh_compression: bounds only */
    int mode;     /* glTF's: 0 POINTS ... 4 TRIANGLES, 5 strip, 6 fan */
    int indices;  /* accessor, -1 if absent */
} GltfPrimitive;

typedef struct GltfNode {
    const char *name;
    int mesh;   /* -1 if none */
    int camera; /* -1 if none */
    const int *children;
    size_t child_count;
    int has_matrix;
    double matrix[16]; /* column-major, as glTF stores it */
    double translation[3], rotation[4] /* x, y, z, w */, scale[3];
    int has_radius;    /* extras.radius */
    double radius;
    int instanced;     /* has EXT_mesh_gpu_instancing */
    GltfInstancing instances;
} GltfNode;

/* A mesh's surface is what its primitives other than POINTS cover: a node
 * with the mesh makes a sphere of each of its connected components that is
 * one. */
typedef struct GltfMesh {
    const char *name;
    int has_surface;   /* a primitive other than POINTS */
    int has_bounds;    /* every such primitive has POSITION with min and max */
    double min[3], max[3]; /* union over them */
    int material;      /* the first such primitive's material, -1 if none */
    size_t primitive_count;
    size_t point_primitives; /* of them, POINTS (spheres of their own) */
} GltfMesh;

/* A material's reference to a texture (glTF's textureInfo), with its
 * KHR_texture_transform: uv' = offset + R(rotation) * (scale * uv). */
typedef struct GltfTextureRef {
    int texture;  /* -1 if none; may be out of range (gltf_doc_texture says) */
    int texcoord; /* n of TEXCOORD_n: the transform's texCoord where it gives one */
    double offset[2], rotation, scale[2];
} GltfTextureRef;

/* glTF's sampler wrap modes. */
enum { GLTF_CLAMP = 33071, GLTF_MIRRORED_REPEAT = 33648, GLTF_REPEAT = 10497 };

/* A texture's image, as the file stores it. */
typedef struct GltfTexture {
    const unsigned char *bytes; /* NULL with fault set */
    size_t size;
    const char *name;  /* for the image module: ends in the format's extension */
    int wrap_s, wrap_t;
    const char *fault; /* why the image cannot be read, or NULL */
} GltfTexture;

typedef struct GltfMaterial {
    const char *name;
    double base_color[4];
    double metallic, roughness;
    double emissive[3];
    double emissive_strength;   /* KHR_materials_emissive_strength, default 1 */
    double transmission;        /* KHR_materials_transmission, default 0 */
    double ior;                 /* KHR_materials_ior, default 1.5 */
    GltfTextureRef base_texture, emissive_texture, metal_rough_texture;
} GltfMaterial;

typedef struct GltfCamera {
    const char *name;
    int perspective;     /* else orthographic */
    double yfov;         /* perspective: radians */
    double aspect_ratio; /* perspective: 0 if not given */
    double xmag, ymag, znear, zfar; /* orthographic */
    int has_aperture, has_focus_distance; /* extras */
    double aperture, focus_distance;
} GltfCamera;

/* The default scene (`scene`, else scene 0) and its extras. */
typedef struct GltfScene {
    const int *roots;
    size_t root_count;
    const char *sky_name;   /* extras.sky as a string, or NULL */
    int has_sky_rgb;        /* extras.sky as [r, g, b] */
    double sky_rgb[3];
    int sky_invalid;        /* extras.sky present but neither */
    int has_resolution;     /* extras.resolution: [width, height] */
    int resolution[2];
    int resolution_invalid; /* extras.resolution present but not two integers */
} GltfScene;

/* Loads .gltf or .glb (chosen by the file's first bytes). Returns NULL on
 * failure, with err filled: PTR_ERR_SCENE_UNREADABLE when the file could not
 * be read at all, PTR_ERR_SCENE_INVALID when it was read and found
 * malformed, PTR_ERR_NOMEM. Warnings from the parser are ignored: ptr
 * reports what it drops itself. */
GltfDoc *gltf_doc_load(const char *path, PtrError *err);
void gltf_doc_free(GltfDoc *doc);

/* Files besides the .gltf that were read: external buffers, as paths. */
size_t gltf_doc_file_count(const GltfDoc *doc);
const char *gltf_doc_file(const GltfDoc *doc, size_t index);

size_t gltf_doc_node_count(const GltfDoc *doc);
size_t gltf_doc_mesh_count(const GltfDoc *doc);
size_t gltf_doc_material_count(const GltfDoc *doc);
size_t gltf_doc_texture_count(const GltfDoc *doc);

/* Index arguments must be below the matching count; every index the
 * structures hold has been checked to be in range when the file loaded. */
void gltf_doc_node(const GltfDoc *doc, size_t index, GltfNode *node);
void gltf_doc_mesh(const GltfDoc *doc, size_t index, GltfMesh *mesh);
void gltf_doc_material(const GltfDoc *doc, size_t index, GltfMaterial *material);
void gltf_doc_camera(const GltfDoc *doc, size_t index, GltfCamera *camera);
void gltf_doc_primitive(const GltfDoc *doc, size_t mesh, size_t index, GltfPrimitive *primitive);
void gltf_doc_accessor(const GltfDoc *doc, size_t index, GltfAccessor *accessor);
/* Texture index's image and sampler; out->fault says what is wrong with
 * either (an index out of range, an image in no buffer, KTX2). */
void gltf_doc_texture(const GltfDoc *doc, int index, GltfTexture *out);

/* Gives back the memory of elements first .. end - 1 of an accessor, which
 * the importer has read and will not read again soon: where they lie in a
 * mapped .glb, their pages go (and are read from the file again if need
 * be), so that ten million instances' attributes and the spheres made of
 * them are not all in memory at once. Elsewhere it does nothing. */
void gltf_doc_release(const GltfDoc *doc, const GltfAccessor *accessor, size_t first, size_t end);
/* The accessor of a node's EXT_mesh_gpu_instancing attribute, or of a
 * primitive's attribute, named `name` in any case, its leading underscore
 * optional (docs/scenes.md, --color-by): -1 if there is none, -2 if the
 * node's names no accessor. */
int gltf_doc_instance_attribute(const GltfDoc *doc, size_t node, const char *name);
int gltf_doc_primitive_attribute(const GltfDoc *doc, size_t mesh, size_t index,
                                 const char *name);
/* The names of the file's instance and primitive attributes that start with
 * '_', comma-separated, in out (cut to size); "" if there are none. */
void gltf_doc_custom_attributes(const GltfDoc *doc, char *out, size_t size);
/* Returns 0 if the file has no scene at all. */
int gltf_doc_scene(const GltfDoc *doc, GltfScene *scene);

#ifdef __cplusplus
}
#endif

#endif /* PTR_GLTF_DOC_H */
