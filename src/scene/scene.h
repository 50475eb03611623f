/* The scene: the only thing importers hand to the renderer.
 *
 * Spheres are stored as a structure of arrays so that SIMD kernels can test
 * 4, 8 or 16 of them per instruction. Each array is 64-byte aligned and
 * padded to a multiple of PTR_SPHERE_BLOCK entries, at least
 * PTR_SPHERE_BLOCK of them after the last sphere, so SIMD code may read 16
 * lanes from any sphere on; padding entries have a NaN radius, which fails
 * every ordered comparison and so can never be hit.
 *
 * The tree's build (accel/bvh.h) puts the spheres in its own order, every
 * array moving with them but value, and from then on a sphere is its
 * position in that order: on equal hit distances the lowest position wins,
 * whether the tree or brute force found the hits (both search the spheres
 * in the build's order). What reads the file's order (the hash, the scene
 * dump, --color-by) reads the arrays before the build. */
#ifndef PTR_SCENE_H
#define PTR_SCENE_H

#include <stddef.h>
#include <stdint.h>
#include <emmintrin.h> /* SSE2, which every x86-64 CPU has */

#include "base/memory.h"
#include "base/result.h"
#include "base/vec.h"

enum { PTR_SPHERE_BLOCK = 16, PTR_SPHERE_ALIGN = 64 };

/* The attributes a sphere may have besides its centre, radius and
 * material: the one list of them, from which the scene's arrays, the
 * builder's (importers/builder.h), the tree's prims (accel/bvh_prims.h) and
 * the hash are all made, so that a new attribute is a line here (and a way
 * for importers to set it). Each is an array of PtrSpheres, NULL while no
 * sphere has one, that moves with its sphere:
 *
 *   X(name, type of an element, elements a sphere, bits of each 4-byte
 *     word of the entry of a sphere that has none (bytes all alike where
 *     an entry is not whole words), elements the hash takes: the sphere's,
 *     then none's)
 *
 * color: the sphere's own colour, multiplying its material's base colour
 * (albedo or attenuation): r, g, b in units of 1/65535, 6 bytes a sphere;
 * none is white. So a million colours are a million of these, never a
 * million materials. The hash takes a fourth element, 65535, as the
 * entries had when they were 8 bytes, so that a recorded hash keeps its
 * value. */
#define PTR_SPHERE_ATTRIBUTES(X) X(color, uint16_t, 3, UINT32_MAX, 4)

typedef struct PtrSpheres {
    /* Kernels depend on this field order (see isect.h). */
    float *cx, *cy, *cz, *radius;
    /* Each sphere's index into PtrScene.materials, material_size bytes an
     * entry: 1 while the scene has at most 256 materials, 2 up to 65,536,
     * else 4 (ptr_scene_add_material widens it), so that most scenes spend
     * 1 byte a sphere on it. Read through ptr_sphere_material, written
     * through ptr_sphere_set_material. */
    void *material;
    /* The sphere's position in the scene file's order (the importer puts
     * the huge ones last, the others staying in that order, ascending),
     * until the tree's build, which keeps the arrays' order, so the file's,
     * within a leaf (coincident spheres sharing one show the first in the
     * file) and frees the array: the renderer needs no ids. NULL: the arrays
     * are in the file's order. */
    uint32_t *id;
    /* Those of PTR_SPHERE_ATTRIBUTES, in its order. */
#define PTR_SPHERE_ATTRIBUTE_ARRAY(name, type, per_sphere, none, hashed) type *name;
    PTR_SPHERE_ATTRIBUTES(PTR_SPHERE_ATTRIBUTE_ARRAY)
#undef PTR_SPHERE_ATTRIBUTE_ARRAY
    /* The value of the quantity --color-by names of the sphere of id i (NaN:
     * none) at entry i, in the file's order whatever the order of the other
     * arrays; 4 bytes a sphere, NULL unless asked for (see scene/colormap.h),
     * and read before the build. */
    float *value;
    size_t count;        /* spheres in use */
    size_t capacity;     /* allocated, a multiple of PTR_SPHERE_BLOCK */
    size_t material_size; /* 1, 2 or 4 (see material) */
} PtrSpheres;

typedef enum PtrMaterialKind {
    PTR_MATERIAL_DIFFUSE,
    PTR_MATERIAL_METAL,
    PTR_MATERIAL_DIELECTRIC,
} PtrMaterialKind;

typedef struct PtrMaterial {
    PtrMaterialKind kind;
    PtrVec3 albedo;   /* diffuse and metal reflectance; dielectric attenuation */
    float fuzz;       /* metal only: 0 is a perfect mirror */
    float ior;        /* dielectric only */
    PtrVec3 emission; /* emitted radiance, seen from both sides */
} PtrMaterial;

typedef enum PtrProjection {
    PTR_PROJECTION_PERSPECTIVE, /* rays from lookfrom through a lens */
    PTR_PROJECTION_ORTHOGRAPHIC, /* parallel rays along the view direction */
} PtrProjection;

typedef struct PtrCamera {
    PtrVec3 lookfrom, lookat, up;
    PtrProjection projection;
    float vfov_deg;       /* perspective: vertical field of view */
    float aperture;       /* perspective: lens diameter; 0 is a pinhole */
    float focus_distance; /* perspective: distance to the plane in focus */
    /* Orthographic: half the view's height in world units (glTF's ymag; the
     * width follows the image's aspect ratio), and how far ahead of lookfrom
     * the rays start (glTF's znear): nothing nearer is seen. */
    float ymag, znear;
    /* Width / height the scene suggests (glTF's aspectRatio, or xmag / ymag
     * of an orthographic camera); 0 if none. */
    float aspect;
} PtrCamera;

typedef enum PtrSkyKind {
    PTR_SKY_GRADIENT, /* white at the horizon to (0.5, 0.7, 1.0) overhead */
    PTR_SKY_CONSTANT,
    PTR_SKY_BLACK,
} PtrSkyKind;

typedef struct PtrSky {
    PtrSkyKind kind;
    PtrVec3 radiance; /* PTR_SKY_CONSTANT only */
} PtrSky;

/* Spheres far larger than the region the rays live in (see accel/huge.h):
 * the last count entries of PtrScene.spheres, kept here too in double
 * precision (relative to PtrScene.origin), where every ray tests them. The
 * float kernels and acceleration structures leave them out. */
typedef struct PtrHugeSpheres {
    double *centre_radius; /* x, y, z, radius of each */
    size_t count;
} PtrHugeSpheres;

enum { PTR_HUGE_MAX = 16 };

/* The one rule for spheres much larger than the rest, "huge": of the
 * spheres whose radius exceeds a limit, the PTR_HUGE_MAX largest (every ray
 * tests them all), on equal radii the first in the file. Its two users set
 * the limit their question asks for: the builder, which keeps the huge
 * spheres in double (PtrHugeSpheres; importers/builder.c says why its limit
 * decides pixels), and the tree's build, which keeps the huge ones among
 * the rest out of its boxes (accel/bvh_prims.c; speed only). Offer every
 * sphere, then put the choice in the file's order. */
typedef struct PtrHugeCandidate {
    double radius;
    size_t index;         /* in the caller's arrays */
    size_t file_position; /* decides between equal radii, and the final order */
} PtrHugeCandidate;

typedef struct PtrHugeChoice {
    double limit;
    size_t count;
    PtrHugeCandidate sphere[PTR_HUGE_MAX];
} PtrHugeChoice;

/* How many of indices[0 .. count - 1] (ascending: a choice's, in the
 * file's order) lie below i: the huge spheres before sphere i, which a stage
 * that moves the others forward past them skips. */
static inline size_t ptr_huge_before(const size_t *indices, size_t count, size_t i)
{
    size_t k = 0;
    while (k < count && indices[k] < i)
        k++;
    return k;
}

/* Adds a sphere above the limit to the choice if among the largest. */
void ptr_huge_insert(PtrHugeChoice *choice, size_t index, size_t file_position, double radius);

static inline void ptr_huge_offer(PtrHugeChoice *choice, size_t index, size_t file_position,
                                  double radius)
{
    if (radius > choice->limit)
        ptr_huge_insert(choice, index, file_position, radius);
}

/* Offers choice the spheres of count choices, each made over a piece of
 * the spheres with choice's limit: the choice keeps the largest by one
 * order, so this gives the choice of all the pieces' spheres together, for
 * choices made on several threads. */
void ptr_huge_merge(PtrHugeChoice *choice, const PtrHugeChoice *pieces, size_t count);

/* Sorts the choice by file position. */
void ptr_huge_file_order(PtrHugeChoice *choice);

typedef struct PtrScene {
    /* World position of the point every coordinate below is relative to:
     * importers put it at the camera (see importers/builder.h). */
    double origin[3];
    PtrSpheres spheres;
    PtrHugeSpheres huge;
    PtrMaterial *materials;
    size_t material_count, material_capacity; /* see ptr_scene_add_material */
    PtrCamera camera;
    PtrSky sky;
    /* Image size the scene asks for (glTF scene extras.resolution); 0 if none. */
    int width, height;
} PtrScene;

/* An empty scene: no spheres, no materials, gradient sky, default camera. */
void ptr_scene_init(PtrScene *scene);
void ptr_scene_free(PtrScene *scene);

/* Appends a sphere; PTR_ERR_NOMEM if the arrays cannot grow. These
 * functions fail only for memory, and say so in err (which may be NULL). */
PtrResult ptr_scene_add_sphere(PtrScene *scene, PtrVec3 centre, float radius,
                               uint32_t material, PtrError *err);

/* Sets the sphere count, making room as needed, for an importer that knows
 * how many spheres it has: the arrays are allocated once (not doubled as
 * they fill), and memory is only used as they are written. Entries from the
 * old count on hold no sphere until the caller writes every array's entry
 * (colour and value through their functions). PTR_ERR_NOMEM (arrays
 * unchanged) if they cannot grow. */
PtrResult ptr_spheres_resize(PtrSpheres *spheres, size_t count, PtrError *err);

/* Gives up the memory of the entries of spheres begin .. end - 1 in every
 * array but value, page by page, to bank (NULL: to the machine; see
 * ptr_pages_put), for a caller that has copied them and writes them back in
 * a new order (the tree's build: at 10^8 spheres, 3 GB it then has for
 * itself). Called as the copy grows, each begin the last call's end; the
 * entries read as zero until written again. */
void ptr_spheres_release(PtrSpheres *spheres, PtrPageBank *bank, size_t begin, size_t end);

/* Puts pages from bank under the entries of spheres begin .. end - 1 in the
 * arrays every store of a sphere writes (all but id and value; see
 * ptr_pages_take), for a caller that then writes each of those spheres.
 * Returns 0 where the kernel lost a range (see ptr_pages_take): then the
 * caller fails for memory. */
int ptr_spheres_take_pages(PtrSpheres *spheres, PtrPageBank *bank, size_t begin, size_t end);

/* Fills entries from .. to - 1 of an array of entries of size bytes with
 * bits (as PTR_SPHERE_ATTRIBUTES gives none's): word by word where an entry
 * is whole 4-byte words, else byte by byte, bits' bytes being alike. */
void ptr_entries_fill(void *array, size_t size, uint32_t bits, size_t from, size_t to);

/* Gives sphere i its own colour (each channel in [0, 1]); the first call
 * creates the colour array, white for every other sphere. */
PtrResult ptr_scene_set_sphere_color(PtrScene *scene, size_t i, PtrVec3 color,
                                     PtrError *err);

/* The same with r, g and b as PtrSpheres.color stores them. */
PtrResult ptr_scene_set_sphere_color16(PtrScene *scene, size_t i, const uint16_t rgb[3],
                                       PtrError *err);

/* Creates array, one of the arrays of spheres that may be NULL (an
 * attribute's, the values or the ids; or the materials, which the tree's
 * build sets aside), if absent, for a caller that writes every sphere's
 * entry: only the padding is set, so at 10^8 spheres memory is used as the
 * entries are written (600 MB of colours), not at once. */
PtrResult ptr_spheres_make(PtrSpheres *spheres, void **array, PtrError *err);

/* ptr_spheres_make for the ids (PtrSpheres.id), for an importer that puts
 * spheres out of the file's order. */
PtrResult ptr_spheres_make_ids(PtrSpheres *spheres, PtrError *err);

/* A colour, each channel clamped to [0, 1], as PtrSpheres.color stores it.
 * Inline and in SSE2, since an import with colours calls it for every
 * sphere: as a call whose clamps were branches it took a quarter of perf's
 * samples in the conversion of an instanced cloud. _mm_max_ps(c, 0) and
 * _mm_min_ps(c, 1) are ptr_maxf(c, 0) and ptr_minf(c, 1) lane by lane
 * because each returns its second operand where the compare fails: so NaN
 * gives 0 and -0 gives +0, which the operands the other way round would
 * not. _mm_cvtps_epi32 rounds to nearest even, as lrintf does. */
static inline void ptr_color_quantize(PtrVec3 color, uint16_t out[3])
{
    const __m128 c = _mm_min_ps(_mm_max_ps(_mm_setr_ps(color.x, color.y, color.z, 0.0f),
                                           _mm_setzero_ps()),
                                _mm_set1_ps(1.0f));
    const __m128i q = _mm_cvtps_epi32(_mm_mul_ps(c, _mm_set1_ps(65535.0f)));
    out[0] = (uint16_t)_mm_extract_epi16(q, 0);
    out[1] = (uint16_t)_mm_extract_epi16(q, 2);
    out[2] = (uint16_t)_mm_extract_epi16(q, 4);
}

/* Gives the sphere of id i a value (see PtrSpheres.value); the first call
 * creates the array, NaN for every other sphere. */
PtrResult ptr_scene_set_sphere_value(PtrScene *scene, size_t i, float value, PtrError *err);

static inline uint32_t ptr_sphere_material(const PtrSpheres *s, size_t i)
{
    switch (s->material_size) {
    case 1: return ((const uint8_t *)s->material)[i];
    case 2: return ((const uint16_t *)s->material)[i];
    default: return ((const uint32_t *)s->material)[i];
    }
}

/* Copies the material indices of spheres 0 .. count - 1 from one array to
 * another, each of its own width (material_size): for an array widening. */
void ptr_spheres_copy_materials(PtrSpheres *to, const PtrSpheres *from, size_t count);

/* Gives sphere i material m, an index the scene has (so one that fits). */
static inline void ptr_sphere_set_material(PtrSpheres *s, size_t i, uint32_t m)
{
    switch (s->material_size) {
    case 1: ((uint8_t *)s->material)[i] = (uint8_t)m; break;
    case 2: ((uint16_t *)s->material)[i] = (uint16_t)m; break;
    default: ((uint32_t *)s->material)[i] = m; break;
    }
}

static inline PtrVec3 ptr_sphere_color(const PtrSpheres *s, size_t i)
{
    const float unit = 1.0f / 65535.0f;
    const uint16_t *c = &s->color[3 * i];
    return v3((float)c[0] * unit, (float)c[1] * unit, (float)c[2] * unit);
}

/* What makes a material unrenderable, as every importer and the library's
 * arrays refuse it: a value that is not finite, a dielectric's ior not above
 * 0, a negative emission; NULL if nothing does. */
const char *ptr_material_problem(const PtrMaterial *material);

/* Appends a material and stores its index in *index; the spheres' material
 * array widens if the count needs it (PtrSpheres.material). */
PtrResult ptr_scene_add_material(PtrScene *scene, const PtrMaterial *material,
                                 uint32_t *index, PtrError *err);

/* The position in the file of sphere i (see PtrSpheres.id). */
static inline uint32_t ptr_sphere_id(const PtrSpheres *s, size_t i)
{
    return s->id ? s->id[i] : (uint32_t)i;
}

static inline PtrVec3 ptr_sphere_centre(const PtrSpheres *s, size_t i)
{
    return v3(s->cx[i], s->cy[i], s->cz[i]);
}

/* In *hash, a 64-bit fingerprint of everything in the scene that shapes an
 * image (spheres, materials, camera, sky, origin), the spheres taken in the
 * file's order: parts of one render match, parts of different scenes almost
 * surely do not. XXH3 (64 bits) of those values' bytes, recorded in images
 * as ptr:scene_xxh3 (docs/distributed.md says what came before). Taken
 * before the tree's build (as the renderer does), whose order it does not
 * know. PTR_ERR_NOMEM if the file's order, where the arrays are not in it,
 * cannot be held: never another fingerprint. */
PtrResult ptr_scene_hash(const PtrScene *scene, uint64_t *hash, PtrError *err);

/* The gradient sky's radiance along a unit direction. */
static inline PtrVec3 ptr_sky_gradient(PtrVec3 unit_dir)
{
    float a = 0.5f * (unit_dir.y + 1.0f);
    return v3_add(v3_splat(1.0f - a), v3_scale(v3(0.5f, 0.7f, 1.0f), a));
}

/* Radiance arriving from the sky along a unit direction. */
static inline PtrVec3 ptr_sky_radiance(const PtrSky *sky, PtrVec3 unit_dir)
{
    switch (sky->kind) {
    case PTR_SKY_GRADIENT:
        return ptr_sky_gradient(unit_dir);
    case PTR_SKY_CONSTANT:
        return sky->radiance;
    case PTR_SKY_BLACK:
        break;
    }
    return v3_splat(0.0f);
}

/* "gradient", "black" or "R,G,B" (as --sky takes it); PTR_ERR_USAGE for
 * anything else. */
PtrResult ptr_sky_parse(const char *text, PtrSky *sky, PtrError *err);

#endif /* PTR_SCENE_H */
