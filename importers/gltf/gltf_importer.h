/* What the parts of the glTF importer share: the import under way
 * (Importer), the spheres found of each mesh's surface and where a sphere
 * comes from, for messages. Each gltf_*.c includes it; it has no .c of its
 * own. */
#ifndef PTR_GLTF_IMPORTER_H
#define PTR_GLTF_IMPORTER_H

#include <math.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "builder.h"
#include "gltf_doc.h"
#include "gltf_textures.h"
#include "importer_internal.h"

/* A mesh's surface spheres (docs/scenes.md, "What becomes a sphere"), found once however
 * many nodes use the mesh, and once for meshes of the same surface. */
typedef struct SurfaceSpheres {
    int found;
    const struct SurfaceSpheres *same; /* where the spheres are: itself, or
                                        * an earlier mesh's; NULL until found */
    size_t count;
    double *spheres;  /* 4 a sphere: the centre and radius in the mesh's frame */
    int *primitives;  /* each one's primitive in its mesh (which gives its material) */
    uint32_t *materials; /* each one's scene material, where textures or vertex
                          * colours give it one of its own; else NULL */
    size_t skipped;   /* the parts that are not spheres */
} SurfaceSpheres;

typedef struct Importer {
    const char *path;
    const GltfDoc *doc;
    PtrScene *scene;
    PtrSceneBuilder builder;
    PtrStrings *warnings;
    PtrError *err;
    const char *camera_name;
    int camera_found;
    const char *ortho_name; /* the orthographic camera taken, if one was */
    double zfar;            /* its far plane */
    uint32_t *material_index; /* glTF material -> scene material, UINT32_MAX unset */
    uint32_t default_material;
    int warned_texture;
    GltfTextures *textures;   /* NULL where the import reads none */
    uint32_t *made;           /* the materials textures gave, by value
                               * (made_slots, a power of two), UINT32_MAX: none */
    size_t made_slots, made_count;
    size_t varying;           /* spheres a texture or COLOR_0 varies over */
    const char *value_name; /* the attribute --color-by asks for, or NULL */
    SurfaceSpheres *surfaces; /* one a mesh */
    size_t *surface_table;    /* meshes by their surface (surface_key), SIZE_MAX: none */
    size_t surface_slots;     /* a power of two */
    size_t skipped;           /* mesh parts not drawn, for the one warning */
    char skipped_names[256];  /* where they are, as many as fit */
    int skipped_more;         /* whether more did not fit */
} Importer;

/* What a sphere is made for, for messages: "node 3 ('Cloud')", with
 * ", instance 17" or ", point 5" after it. */
typedef struct Origin {
    size_t node_index;
    const char *node_name;
    const char *part;  /* "instance", "point" or NULL */
    size_t part_index;
} Origin;

static inline int all_finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

static inline PtrVec3 vec_from(const double v[3])
{
    return v3((float)v[0], (float)v[1], (float)v[2]);
}

static inline const char *label(const char *name, const char *fallback)
{
    return name && *name ? name : fallback;
}

/* Keeps in *failed the least slot that fails: the one a serial import
 * reports, whichever thread meets it first. */
static inline void gltf_note_failure(atomic_size_t *failed, size_t slot)
{
    size_t seen = atomic_load(failed);
    while (slot < seen && !atomic_compare_exchange_weak(failed, &seen, slot))
        ;
}

#endif /* PTR_GLTF_IMPORTER_H */
