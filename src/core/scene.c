#include "core/scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void ptr_scene_init(PtrScene *scene)
{
    memset(scene, 0, sizeof *scene);
    scene->sky.kind = PTR_SKY_GRADIENT;
    scene->camera = (PtrCamera){
        .lookfrom = v3(0, 0, 0), .lookat = v3(0, 0, -1), .up = v3(0, 1, 0),
        .vfov_deg = 90.0f, .aperture = 0.0f, .focus_distance = 1.0f,
    };
}

static void spheres_free(PtrSpheres *s)
{
    free(s->cx);
    free(s->cy);
    free(s->cz);
    free(s->radius);
    free(s->material);
    free(s->id);
    memset(s, 0, sizeof *s);
}

void ptr_scene_free(PtrScene *scene)
{
    spheres_free(&scene->spheres);
    free(scene->huge.centre_radius);
    free(scene->materials);
    ptr_scene_init(scene);
}

static float *aligned_floats(size_t n)
{
    return aligned_alloc(PTR_SPHERE_ALIGN, n * sizeof(float));
}

static PtrResult spheres_grow(PtrSpheres *s)
{
    size_t capacity = s->capacity ? s->capacity * 2 : PTR_SPHERE_BLOCK;
    if (capacity > SIZE_MAX / 2 / sizeof(float))
        return PTR_ERR_NOMEM;

    PtrSpheres grown = { 0 };
    grown.cx = aligned_floats(capacity);
    grown.cy = aligned_floats(capacity);
    grown.cz = aligned_floats(capacity);
    grown.radius = aligned_floats(capacity);
    grown.material = aligned_alloc(PTR_SPHERE_ALIGN, capacity * sizeof(uint32_t));
    grown.id = aligned_alloc(PTR_SPHERE_ALIGN, capacity * sizeof(uint32_t));
    if (!grown.cx || !grown.cy || !grown.cz || !grown.radius || !grown.material || !grown.id) {
        spheres_free(&grown);
        return PTR_ERR_NOMEM;
    }
    grown.count = s->count;
    grown.capacity = capacity;
    for (size_t i = 0; i < capacity; i++) {
        int old = i < s->count;
        grown.cx[i] = old ? s->cx[i] : 0.0f;
        grown.cy[i] = old ? s->cy[i] : 0.0f;
        grown.cz[i] = old ? s->cz[i] : 0.0f;
        grown.radius[i] = old ? s->radius[i] : NAN;
        grown.material[i] = old ? s->material[i] : 0;
        grown.id[i] = old ? s->id[i] : 0;
    }
    spheres_free(s);
    *s = grown;
    return PTR_OK;
}

PtrResult ptr_scene_add_sphere(PtrScene *scene, PtrVec3 centre, float radius,
                               uint32_t material)
{
    PtrSpheres *s = &scene->spheres;
    if (s->count == s->capacity) {
        PtrResult r = spheres_grow(s);
        if (r != PTR_OK)
            return r;
    }
    size_t i = s->count++;
    s->cx[i] = centre.x;
    s->cy[i] = centre.y;
    s->cz[i] = centre.z;
    s->radius[i] = radius;
    s->material[i] = material;
    s->id[i] = (uint32_t)i;
    return PTR_OK;
}

PtrResult ptr_scene_add_material(PtrScene *scene, const PtrMaterial *material,
                                 uint32_t *index)
{
    if (scene->material_count >= UINT32_MAX)
        return PTR_ERR_NOMEM;
    PtrMaterial *grown = realloc(scene->materials,
                                 (scene->material_count + 1) * sizeof *grown);
    if (!grown)
        return PTR_ERR_NOMEM;
    scene->materials = grown;
    grown[scene->material_count] = *material;
    *index = (uint32_t)scene->material_count++;
    return PTR_OK;
}

/* FNV-1a over the bytes of the values, field by field (never over structure
 * padding). */
static uint64_t hash_bytes(uint64_t h, const void *data, size_t size)
{
    const unsigned char *p = data;
    for (size_t i = 0; i < size; i++)
        h = (h ^ p[i]) * UINT64_C(0x100000001b3);
    return h;
}

static uint64_t hash_vec(uint64_t h, PtrVec3 v)
{
    const float f[3] = { v.x, v.y, v.z };
    return hash_bytes(h, f, sizeof f);
}

uint64_t ptr_scene_hash(const PtrScene *scene)
{
    uint64_t h = UINT64_C(0xcbf29ce484222325);
    const PtrSpheres *s = &scene->spheres;
    h = hash_bytes(h, scene->origin, sizeof scene->origin);
    h = hash_bytes(h, &s->count, sizeof s->count);
    h = hash_bytes(h, s->cx, s->count * sizeof *s->cx);
    h = hash_bytes(h, s->cy, s->count * sizeof *s->cy);
    h = hash_bytes(h, s->cz, s->count * sizeof *s->cz);
    h = hash_bytes(h, s->radius, s->count * sizeof *s->radius);
    h = hash_bytes(h, s->material, s->count * sizeof *s->material);
    h = hash_bytes(h, scene->huge.centre_radius, 4 * scene->huge.count * sizeof(double));
    for (size_t i = 0; i < scene->material_count; i++) {
        const PtrMaterial *m = &scene->materials[i];
        const int kind = m->kind;
        const float scalars[2] = { m->fuzz, m->ior };
        h = hash_bytes(h, &kind, sizeof kind);
        h = hash_vec(hash_vec(h, m->albedo), m->emission);
        h = hash_bytes(h, scalars, sizeof scalars);
    }
    const PtrCamera *c = &scene->camera;
    const float lens[4] = { c->vfov_deg, c->aperture, c->focus_distance, c->aspect };
    h = hash_vec(hash_vec(hash_vec(h, c->lookfrom), c->lookat), c->up);
    h = hash_bytes(h, lens, sizeof lens);
    const int sky = scene->sky.kind;
    h = hash_bytes(h, &sky, sizeof sky);
    return hash_vec(h, scene->sky.radiance);
}

PtrVec3 ptr_sky_radiance(const PtrSky *sky, PtrVec3 unit_dir)
{
    switch (sky->kind) {
    case PTR_SKY_GRADIENT: {
        float a = 0.5f * (unit_dir.y + 1.0f);
        return v3_add(v3_splat(1.0f - a), v3_scale(v3(0.5f, 0.7f, 1.0f), a));
    }
    case PTR_SKY_CONSTANT:
        return sky->radiance;
    case PTR_SKY_BLACK:
        break;
    }
    return v3_splat(0.0f);
}

int ptr_sky_parse(const char *text, PtrSky *sky)
{
    if (!strcmp(text, "gradient")) {
        *sky = (PtrSky){ .kind = PTR_SKY_GRADIENT };
        return 1;
    }
    if (!strcmp(text, "black")) {
        *sky = (PtrSky){ .kind = PTR_SKY_BLACK };
        return 1;
    }
    float r, g, b;
    char tail;
    if (sscanf(text, "%f,%f,%f%c", &r, &g, &b, &tail) != 3)
        return 0;
    if (!isfinite(r) || !isfinite(g) || !isfinite(b) || r < 0 || g < 0 || b < 0)
        return 0;
    *sky = (PtrSky){ .kind = PTR_SKY_CONSTANT, .radiance = v3(r, g, b) };
    return 1;
}
