/* What importers use to build a scene: spheres and the camera in
 * double-precision world coordinates, turned into a PtrScene once all are
 * known.
 *
 * The scene's float coordinates are taken relative to the camera
 * (PtrScene.origin), computed in double: single precision is then finest
 * where the image needs it, next to the viewer, whatever the scene's
 * distance from the world origin. A radius-1 sphere 10^7 from the origin
 * cannot even be represented in float world coordinates (their spacing
 * there is 1); seen from a camera beside it, it renders as it does at the
 * origin. */
#ifndef PTR_BUILDER_H
#define PTR_BUILDER_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "base/result.h"
#include "import_options.h"
#include "scene/scene.h"

/* x, y, z, radius of each sphere: floats while every value given is a
 * float exactly (as a file's float coordinates under no transform are),
 * else doubles (wide). Either way they are the doubles given: at 10^8
 * spheres, 1.6 GB where doubles took 3.2. */
typedef struct PtrBuilderSpheres {
    void *data;
    int wide;
} PtrBuilderSpheres;

typedef struct PtrSceneBuilder {
    PtrScene *scene;  /* materials, sky and size go to it directly */
    PtrBuilderSpheres spheres;
    /* A fill in floats met a value that is not one (see ptr_builder_refill). */
    atomic_int lost;
    /* Each sphere's material, material_size bytes an entry: as wide as the
     * scene's entries (PtrSpheres.material: 1 byte while it has at most 256
     * materials) were when spheres were last added, so as wide as every
     * material they may have needs. */
    void *materials;
    size_t material_size;
    /* Those of PTR_SPHERE_ATTRIBUTES (scene.h), as the scene stores them;
     * each NULL while no sphere has one. */
#define PTR_BUILDER_ATTRIBUTE_ARRAY(name, type, per_sphere, none, hashed) type *name;
    PTR_SPHERE_ATTRIBUTES(PTR_BUILDER_ATTRIBUTE_ARRAY)
#undef PTR_BUILDER_ATTRIBUTE_ARRAY
    float *values;    /* each sphere's --color-by value (NaN: none); NULL while none has one */
    size_t count, capacity;
    int has_camera;
    double eye[3], target[3], up[3];
    PtrCamera lens;   /* projection, field of view, aperture, focus, aspect */
    const PtrCameraSpec *override; /* the command line's camera, if any */
    PtrProjection auto_projection;  /* see PtrImportOptions */
    double auto_aspect, orbit_degrees;
} PtrSceneBuilder;

/* options (may be NULL) give the command line's camera, which replaces any
 * the file gives, the automatic camera's projection and aspect, and the
 * turntable's orbit. */
void ptr_builder_init(PtrSceneBuilder *builder, PtrScene *scene, const PtrImportOptions *options);
void ptr_builder_free(PtrSceneBuilder *builder);

/* Makes room for count spheres, for an importer that knows how many it will
 * add: its arrays are then allocated once (the centres once more if they
 * widen to doubles), not doubled as they fill. This and the functions below
 * that add to the builder fail only for memory (PTR_ERR_NOMEM, said in err,
 * which may be NULL). */
PtrResult ptr_builder_reserve(PtrSceneBuilder *builder, size_t count, PtrError *err);

/* material: an index the scene has when the sphere is added, here or by
 * ptr_builder_add_spheres, since the builder's entries are then as wide as
 * the scene's. */
PtrResult ptr_builder_add_sphere(PtrSceneBuilder *builder, const double centre[3],
                                 double radius, uint32_t material, PtrError *err);

/* Adds count spheres at once for an importer that fills them itself, on as
 * many threads as it likes (ptr_builder_fill_sphere, then
 * ptr_builder_refill): for each sphere first + i, the centre and radius,
 * the material, and with with_colors the colour at color[3 * (first + i)]
 * (see ptr_color_quantize). */
PtrResult ptr_builder_add_spheres(PtrSceneBuilder *builder, size_t count, int with_colors,
                                  size_t *first, PtrError *err);

/* Fills sphere n of those ptr_builder_add_spheres added, from any thread:
 * centre, radius, material (one the scene had when they were added) and,
 * where rgb is not NULL (only if they were added with_colors), its
 * colour. The centre and radius may be lost (see ptr_builder_refill). */
void ptr_builder_fill_sphere(PtrSceneBuilder *builder, size_t n, const double centre[3],
                             double radius, uint32_t material, const double *rgb);

/* Where an importer that fills a batch of count spheres on threads ends
 * the block it fills from begin (counted in the batch) before it calls
 * ptr_builder_refill: blocks grow from 4,096 spheres as the batch's filled
 * ones do, so that a refill costs at most the filling so far, up to 2^20
 * (a few milliseconds' work). */
static inline size_t ptr_builder_block_end(size_t begin, size_t count)
{
    enum { BLOCK_MIN = 1 << 12, BLOCK_MAX = 1 << 20 };
    const size_t block = begin < BLOCK_MIN ? BLOCK_MIN : begin > BLOCK_MAX ? BLOCK_MAX : begin;
    return count - begin > block ? begin + block : count;
}

/* Called after spheres were filled, once no thread fills any, with the
 * first sphere that none has filled yet (or the count): where one of them
 * had a coordinate or radius that is not a float exactly while the builder
 * kept floats, the builder now keeps doubles, and *refill is 1: the caller
 * fills the spheres it filled since it last called this again (the
 * others' values are kept). Fails only for memory. */
PtrResult ptr_builder_refill(PtrSceneBuilder *builder, size_t filled, int *refill,
                             PtrError *err);

/* Fills count spheres of a batch that ptr_builder_add_spheres added from
 * first: fill(arg, begin, end), run on threads threads over ranges of
 * 0 .. count - 1 (ptr_parallel_ranges), fills spheres first + begin ..
 * first + end - 1 (ptr_builder_fill_sphere). A block at a time
 * (ptr_builder_block_end), each filled again where ptr_builder_refill asks;
 * after each, done(arg, begin, end), if not NULL, says whether to go on.
 * Fails only for memory (PTR_ERR_NOMEM; the caller says so). */
PtrResult ptr_builder_fill_blocks(PtrSceneBuilder *builder, size_t first, size_t count,
                                  int threads, void (*fill)(void *, size_t, size_t),
                                  int (*done)(void *, size_t, size_t), void *arg);

/* Sphere i's x, y, z and radius, as they were given. Taken by value, so
 * that a loop over many holds the array and its width in locals, and the
 * compiler can make a loop of each width. */
static inline void ptr_builder_sphere(PtrBuilderSpheres spheres, size_t i, double s[4])
{
    if (spheres.wide) {
        const double *d = (const double *)spheres.data + 4 * i;
        for (int k = 0; k < 4; k++)
            s[k] = d[k];
        return;
    }
    const float *f = (const float *)spheres.data + 4 * i;
    for (int k = 0; k < 4; k++)
        s[k] = f[k];
}

/* Gives the sphere added last its own colour (see PtrSpheres.color). */
PtrResult ptr_builder_set_color(PtrSceneBuilder *builder, const double rgb[3], PtrError *err);

/* Gives the sphere added last its value (see PtrSpheres.value). */
PtrResult ptr_builder_set_value(PtrSceneBuilder *builder, double value, PtrError *err);

/* lens gives everything but the position and orientation. Ignored when the
 * builder has an override. */
void ptr_builder_set_camera(PtrSceneBuilder *builder, const double eye[3],
                            const double target[3], const double up[3], const PtrCamera *lens);

/* The lens of a camera the command line gives (its projection, field of
 * view, aperture, focus distance, orthographic height), without its
 * position and orientation. */
PtrCamera ptr_camera_lens(const PtrCameraSpec *spec);

/* How ptr_builder_finish stores the scene. Importers use both; the stability
 * suite measures what leaving either out costs. */
typedef enum PtrBuildFlags {
    /* Coordinates relative to the camera, else to the world origin. */
    PTR_BUILD_RECENTRE = 1,
    /* Spheres far larger than the scene tested in double (accel/huge.h). */
    PTR_BUILD_HUGE_IN_DOUBLE = 2,
    PTR_BUILD_DEFAULT = PTR_BUILD_RECENTRE | PTR_BUILD_HUGE_IN_DOUBLE,
} PtrBuildFlags;

/* Fills the scene's spheres and camera: the camera given, or one that frames
 * the spheres from +Z, looking down -Z (see frame_spheres), then turned by
 * the orbit. Frees the builder's memory. Fails with
 * PTR_ERR_SCENE_INVALID if a sphere is too far from the camera for single
 * precision, PTR_ERR_NOMEM if memory runs out. */
PtrResult ptr_builder_finish(PtrSceneBuilder *builder, unsigned flags, PtrError *err);

/* Makes the builder keep a colour (with colors) and a value (with values)
 * for every sphere, none until one is given: for an importer that gives them
 * to only some of the spheres ptr_builder_add_spheres adds (without
 * with_colors, where colours are kept so), filling those with
 * ptr_builder_fill_sphere and ptr_builder_fill_value. */
PtrResult ptr_builder_keep_attributes(PtrSceneBuilder *builder, int colors, int values,
                                      PtrError *err);

/* Gives sphere n of those ptr_builder_add_spheres added its value (see
 * PtrSpheres.value), from any thread, once the builder keeps values. */
void ptr_builder_fill_value(PtrSceneBuilder *builder, size_t n, double value);

#endif /* PTR_BUILDER_H */
