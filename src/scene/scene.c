#include "scene/scene.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* xxHash's functions compiled here from its header (libxxhash-dev), as its
 * documentation offers: nothing to link, in libptr.a too. */
#define XXH_INLINE_ALL
#include <xxhash.h>
#if XXH_VERSION_NUMBER < 800
#error "ptr needs xxHash 0.8 or later: XXH3's values are fixed from 0.8 on"
#endif

#include "base/grow.h"
#include "base/memory.h"

void ptr_scene_init(PtrScene *scene)
{
    memset(scene, 0, sizeof *scene);
    scene->spheres.material_size = 1;
    scene->sky.kind = PTR_SKY_GRADIENT;
    scene->camera = (PtrCamera){
        .lookfrom = v3(0, 0, 0), .lookat = v3(0, 0, -1), .up = v3(0, 1, 0),
        .vfov_deg = 90.0f, .aperture = 0.0f, .focus_distance = 1.0f,
    };
}

/* Every per-sphere array, with the value its padding entries hold: growing,
 * freeing and releasing go through this list, so a new array is one line. */
typedef struct SphereArray {
    void **data;
    size_t size;     /* of one entry */
    uint32_t padding; /* bits of a padding entry */
    int optional;     /* may be NULL: then it stays so */
    int moves;        /* with the spheres when reordered: all but value */
    int stored;       /* written by every store of a sphere: all but id and value */
} SphereArray;

enum { SPHERE_ARRAYS_MAX = 16 };

#define PADDED(name, type, per_sphere, none, hashed)                                       \
    static_assert(((per_sphere) * sizeof(type) % sizeof(uint32_t) == 0 &&                  \
                   (hashed) == (per_sphere)) ||                                            \
                      (uint32_t)(none) == ((none) & 0xffu) * 0x01010101u,                  \
                  #name ": an entry is whole 4-byte words, as the hash takes it, or "      \
                        "none's bytes are alike (see pad_array, hash_in_file_order)");
PTR_SPHERE_ATTRIBUTES(PADDED)
#undef PADDED

/* Fills a with s's arrays; returns how many there are. */
static int sphere_arrays(PtrSpheres *s, SphereArray a[SPHERE_ARRAYS_MAX])
{
    union { float f; uint32_t u; } nan_bits = { .f = NAN }, zero = { .f = 0.0f };
    /* Entries are whole 4-byte words, or others whose padding's bytes are
     * alike (see pad_array). */
    SphereArray list[] = {
        { (void **)&s->cx, sizeof *s->cx, zero.u, 0, 1, 1 },
        { (void **)&s->cy, sizeof *s->cy, zero.u, 0, 1, 1 },
        { (void **)&s->cz, sizeof *s->cz, zero.u, 0, 1, 1 },
        { (void **)&s->radius, sizeof *s->radius, nan_bits.u, 0, 1, 1 }, /* never hit */
        { (void **)&s->material, s->material_size, 0, 0, 1, 1 },
        { (void **)&s->id, sizeof *s->id, UINT32_MAX, 1, 1, 0 },
#define ATTRIBUTE_ARRAY(name, type, per_sphere, none, hashed)                              \
    { (void **)&s->name, (per_sphere) * sizeof(type), (none), 1, 1, 1 },
        PTR_SPHERE_ATTRIBUTES(ATTRIBUTE_ARRAY)
#undef ATTRIBUTE_ARRAY
        { (void **)&s->value, sizeof *s->value, nan_bits.u, 1, 0, 0 }, /* none */
    };
    static_assert(sizeof list / sizeof list[0] <= SPHERE_ARRAYS_MAX, "room for the list");
    memcpy(a, list, sizeof list);
    return (int)(sizeof list / sizeof list[0]);
}

static void spheres_free(PtrSpheres *s)
{
    SphereArray a[SPHERE_ARRAYS_MAX];
    int arrays = sphere_arrays(s, a);
    for (int k = 0; k < arrays; k++)
        free(*a[k].data);
    *s = (PtrSpheres){ .material_size = s->material_size };
}

/* An array of capacity entries of size bytes, 64-byte aligned (its size a
 * multiple of that, as aligned_alloc asks). */
static void *array_alloc(size_t capacity, size_t size)
{
    size_t bytes = capacity * size;
    return aligned_alloc(PTR_SPHERE_ALIGN, (bytes + PTR_SPHERE_ALIGN - 1) / PTR_SPHERE_ALIGN *
                                               PTR_SPHERE_ALIGN);
}

void ptr_scene_free(PtrScene *scene)
{
    spheres_free(&scene->spheres);
    free(scene->huge.centre_radius);
    free(scene->materials);
    ptr_scene_init(scene);
}

void ptr_entries_fill(void *array, size_t size, uint32_t bits, size_t from, size_t to)
{
    if (size % sizeof(uint32_t)) {
        memset((char *)array + from * size, (int)(bits & 0xff), (to - from) * size);
        return;
    }
    uint32_t *words = array;
    const size_t per_entry = size / sizeof *words;
    for (size_t i = from * per_entry; i < to * per_entry; i++)
        words[i] = bits;
}

/* Fills entries from .. to - 1 of array a with its padding (a material
 * index's 0, a colour's 0xff bytes). */
static void pad_array(const SphereArray *a, size_t from, size_t to)
{
    ptr_entries_fill(*a->data, a->size, a->padding, from, to);
}

/* Fails for the memory of count spheres. */
static PtrResult no_room(size_t count, PtrError *err)
{
    return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for %zu spheres", count);
}

/* Arrays like s's with room for capacity entries, the first s->count copied
 * from s and those from pad_from on padding (those between are left for the
 * caller to write). An optional array s does not have (the colour) stays
 * absent. */
static PtrResult spheres_copy(const PtrSpheres *s, size_t capacity, size_t pad_from,
                              PtrSpheres *out, PtrError *err)
{
    PtrSpheres copy = { .count = s->count, .capacity = capacity,
                        .material_size = s->material_size };
    SphereArray from[SPHERE_ARRAYS_MAX], to[SPHERE_ARRAYS_MAX];
    sphere_arrays((PtrSpheres *)s, from);
    int arrays = sphere_arrays(&copy, to);
    for (int k = 0; k < arrays; k++) {
        if (to[k].optional && !*from[k].data)
            continue;
        *to[k].data = array_alloc(capacity, to[k].size);
        if (!*to[k].data) {
            spheres_free(&copy);
            return no_room(capacity, err);
        }
        if (s->count)
            memcpy(*to[k].data, *from[k].data, s->count * to[k].size);
        pad_array(&to[k], pad_from, capacity);
    }
    *out = copy;
    return PTR_OK;
}

/* The capacity that holds count spheres and the PTR_SPHERE_BLOCK padding
 * entries that always follow the last (see scene.h). */
static size_t capacity_for(size_t count)
{
    return (count / PTR_SPHERE_BLOCK + 2) * PTR_SPHERE_BLOCK;
}

/* Gives s room for count spheres, entries from pad_from on padding. */
static PtrResult spheres_grow(PtrSpheres *s, size_t count, size_t pad_from, PtrError *err)
{
    if (count > SIZE_MAX / 128)
        return no_room(count, err);
    PtrSpheres grown;
    PtrResult r = spheres_copy(s, capacity_for(count), pad_from, &grown, err);
    if (r != PTR_OK)
        return r;
    spheres_free(s);
    *s = grown;
    return PTR_OK;
}

PtrResult ptr_spheres_resize(PtrSpheres *s, size_t count, PtrError *err)
{
    if (capacity_for(count) > s->capacity) {
        PtrResult r = spheres_grow(s, count, count, err);
        if (r != PTR_OK)
            return r;
    } else if (count < s->count) {
        SphereArray a[SPHERE_ARRAYS_MAX] = { 0 }; /* all set; the compiler cannot tell */
        const int arrays = sphere_arrays(s, a);
        for (int k = 0; k < arrays; k++)
            if (*a[k].data)
                pad_array(&a[k], count, s->count);
    }
    s->count = count;
    return PTR_OK;
}

void ptr_spheres_release(PtrSpheres *s, PtrPageBank *bank, size_t begin, size_t end)
{
    SphereArray a[SPHERE_ARRAYS_MAX] = { 0 }; /* all set; the compiler cannot tell */
    const int arrays = sphere_arrays(s, a);
    for (int k = 0; k < arrays; k++)
        if (a[k].moves && *a[k].data)
            ptr_pages_put(bank, *a[k].data, begin * a[k].size, end * a[k].size);
}

int ptr_spheres_take_pages(PtrSpheres *s, PtrPageBank *bank, size_t begin, size_t end)
{
    SphereArray a[SPHERE_ARRAYS_MAX] = { 0 }; /* all set; the compiler cannot tell */
    const int arrays = sphere_arrays(s, a);
    for (int k = 0; k < arrays; k++)
        if (a[k].stored && *a[k].data &&
            !ptr_pages_take(bank, *a[k].data, begin * a[k].size, end * a[k].size))
            return 0;
    return 1;
}

PtrResult ptr_scene_add_sphere(PtrScene *scene, PtrVec3 centre, float radius,
                               uint32_t material, PtrError *err)
{
    PtrSpheres *s = &scene->spheres;
    if (capacity_for(s->count) > s->capacity) {
        PtrResult r = spheres_grow(s, 2 * s->count, s->count, err);
        if (r != PTR_OK)
            return r;
    }
    size_t i = s->count++;
    s->cx[i] = centre.x;
    s->cy[i] = centre.y;
    s->cz[i] = centre.z;
    s->radius[i] = radius;
    ptr_sphere_set_material(s, i, material);
    if (s->id)
        s->id[i] = (uint32_t)i;
    return PTR_OK;
}

/* Creates the optional array at data (one of s's) if absent, entries from
 * pad_from on holding its value for none. */
static PtrResult create_optional(PtrSpheres *s, void **data, size_t pad_from, PtrError *err)
{
    if (*data)
        return PTR_OK;
    SphereArray a[SPHERE_ARRAYS_MAX] = { 0 }; /* all set; the compiler cannot tell */
    const int arrays = sphere_arrays(s, a);
    int k = 0;
    while (k < arrays - 1 && a[k].data != data)
        k++;
    *data = array_alloc(s->capacity, a[k].size);
    if (!*data)
        return no_room(s->capacity, err);
    pad_array(&a[k], pad_from, s->capacity);
    return PTR_OK;
}

PtrResult ptr_spheres_make(PtrSpheres *s, void **array, PtrError *err)
{
    return create_optional(s, array, s->count, err);
}

PtrResult ptr_spheres_make_ids(PtrSpheres *s, PtrError *err)
{
    return ptr_spheres_make(s, (void **)&s->id, err);
}

PtrResult ptr_scene_set_sphere_color16(PtrScene *scene, size_t i, const uint16_t rgb[3],
                                       PtrError *err)
{
    PtrSpheres *s = &scene->spheres;
    PtrResult res = create_optional(s, (void **)&s->color, 0, err);
    if (res == PTR_OK)
        memcpy(&s->color[3 * i], rgb, 3 * sizeof *rgb);
    return res;
}

PtrResult ptr_scene_set_sphere_color(PtrScene *scene, size_t i, PtrVec3 color, PtrError *err)
{
    uint16_t quantized[3];
    ptr_color_quantize(color, quantized);
    return ptr_scene_set_sphere_color16(scene, i, quantized, err);
}

PtrResult ptr_scene_set_sphere_value(PtrScene *scene, size_t i, float value, PtrError *err)
{
    PtrSpheres *s = &scene->spheres;
    PtrResult res = create_optional(s, (void **)&s->value, 0, err);
    if (res == PTR_OK)
        s->value[i] = value;
    return res;
}

void ptr_spheres_copy_materials(PtrSpheres *to, const PtrSpheres *from, size_t count)
{
    for (size_t i = 0; i < count; i++)
        ptr_sphere_set_material(to, i, ptr_sphere_material(from, i));
}

/* Gives the spheres' material array entries of size bytes, the indices
 * kept. */
static PtrResult widen_materials(PtrSpheres *s, size_t size, PtrError *err)
{
    void *wide = NULL;
    if (s->material) {
        wide = array_alloc(s->capacity, size);
        if (!wide)
            return no_room(s->capacity, err);
        PtrSpheres to = { .material = wide, .material_size = size };
        ptr_spheres_copy_materials(&to, s, s->capacity);
        free(s->material);
    }
    s->material = wide;
    s->material_size = size;
    return PTR_OK;
}

const char *ptr_material_problem(const PtrMaterial *m)
{
    const float values[] = { m->albedo.x, m->albedo.y, m->albedo.z, m->fuzz, m->ior,
                             m->emission.x, m->emission.y, m->emission.z };
    for (size_t k = 0; k < sizeof values / sizeof values[0]; k++)
        if (!isfinite(values[k]))
            return "a value is not finite";
    if (m->kind == PTR_MATERIAL_DIELECTRIC && !(m->ior > 0.0f))
        return "it refracts with an ior not above 0";
    if (m->emission.x < 0.0f || m->emission.y < 0.0f || m->emission.z < 0.0f)
        return "its emission is negative";
    return NULL;
}

PtrResult ptr_scene_add_material(PtrScene *scene, const PtrMaterial *material,
                                 uint32_t *index, PtrError *err)
{
    const size_t count = scene->material_count + 1;
    if (scene->material_count >= UINT32_MAX)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for %zu materials", count);
    const size_t size = count > 65536 ? 4 : count > 256 ? 2 : 1;
    if (size > scene->spheres.material_size) {
        PtrResult r = widen_materials(&scene->spheres, size, err);
        if (r != PTR_OK)
            return r;
    }
    /* Grown by doubling, so that a file of 10^5 materials is not copied
     * 10^5 times (realloc copies where it cannot grow in place, as under
     * AddressSanitizer it always does). */
    if (ptr_grow((void **)&scene->materials, &scene->material_capacity, count,
                 sizeof *scene->materials) != PTR_OK)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for %zu materials", count);
    scene->materials[scene->material_count] = *material;
    *index = (uint32_t)scene->material_count++;
    return PTR_OK;
}

/* Whether a comes before b among the huge: larger, or as large and first
 * in the file. */
static int huge_before(double radius_a, size_t file_a, double radius_b, size_t file_b)
{
    return radius_a != radius_b ? radius_a > radius_b : file_a < file_b;
}

void ptr_huge_insert(PtrHugeChoice *c, size_t index, size_t file_position, double radius)
{
    size_t at = c->count < PTR_HUGE_MAX ? c->count++ : PTR_HUGE_MAX;
    for (; at > 0 && huge_before(radius, file_position, c->sphere[at - 1].radius,
                                 c->sphere[at - 1].file_position); at--)
        if (at < PTR_HUGE_MAX)
            c->sphere[at] = c->sphere[at - 1];
    if (at < PTR_HUGE_MAX)
        c->sphere[at] = (PtrHugeCandidate){ radius, index, file_position };
}

void ptr_huge_merge(PtrHugeChoice *c, const PtrHugeChoice *pieces, size_t count)
{
    for (size_t k = 0; k < count; k++)
        for (size_t j = 0; j < pieces[k].count; j++) {
            const PtrHugeCandidate *h = &pieces[k].sphere[j];
            ptr_huge_offer(c, h->index, h->file_position, h->radius);
        }
}

void ptr_huge_file_order(PtrHugeChoice *c)
{
    for (size_t k = 1; k < c->count; k++) {
        const PtrHugeCandidate chosen = c->sphere[k];
        size_t at = k;
        for (; at > 0 && c->sphere[at - 1].file_position > chosen.file_position; at--)
            c->sphere[at] = c->sphere[at - 1];
        c->sphere[at] = chosen;
    }
}

/* The scene's bytes, value by value (never structure padding), through
 * XXH3 (64 bits) as one stream: how the updates cut the stream changes
 * nothing. */
static void hash_bytes(XXH3_state_t *h, const void *data, size_t size)
{
    (void)XXH3_64bits_update(h, data, size);
}

static void hash_vec(XXH3_state_t *h, PtrVec3 v)
{
    const float f[3] = { v.x, v.y, v.z };
    hash_bytes(h, f, sizeof f);
}

/* Entries gathered into the stream at a time, of at most GATHER_ENTRY
 * bytes each (PTR_SPHERE_ATTRIBUTES' are checked below): one update a
 * block, not one an entry, in 8 KB of the caller's stack. */
enum { GATHER = 1024, GATHER_ENTRY = 8 };

/* The entries (stored bytes each) of a per-sphere array in file order:
 * by_id[k] is the position of the sphere whose id is k (NULL: the arrays
 * are in file order). Each entry is hashed as hashed bytes, those past the
 * stored ones fill's (an attribute's none: see PTR_SPHERE_ATTRIBUTES).
 * Inlined, so that the copies' sizes are constants. */
static inline __attribute__((always_inline)) void
hash_in_file_order(XXH3_state_t *h, const void *array, size_t stored, size_t hashed,
                   unsigned char fill, const uint32_t *by_id, size_t count)
{
    assert(stored <= hashed && hashed <= GATHER_ENTRY);
    const unsigned char *a = array;
    if (!by_id && stored == hashed) {
        hash_bytes(h, a, count * stored);
        return;
    }
    unsigned char block[GATHER * GATHER_ENTRY];
    memset(block, fill, sizeof block);
    for (size_t k = 0; k < count; k += GATHER) {
        const size_t n = count - k < GATHER ? count - k : GATHER;
        for (size_t j = 0; j < n; j++)
            memcpy(&block[j * hashed], a + (by_id ? by_id[k + j] : k + j) * stored, stored);
        hash_bytes(h, block, n * hashed);
    }
}

/* Each sphere's material in file order, as a 4-byte index whatever its
 * size in the arrays. */
static void hash_materials(XXH3_state_t *h, const PtrSpheres *s, const uint32_t *by_id)
{
    uint32_t block[GATHER];
    for (size_t k = 0; k < s->count; k += GATHER) {
        const size_t n = s->count - k < GATHER ? s->count - k : GATHER;
        for (size_t j = 0; j < n; j++)
            block[j] = ptr_sphere_material(s, by_id ? by_id[k + j] : k + j);
        hash_bytes(h, block, n * sizeof *block);
    }
}

PtrResult ptr_scene_hash(const PtrScene *scene, uint64_t *hash, PtrError *err)
{
    const PtrSpheres *s = &scene->spheres;
    /* In the file's order, through the ids where the importer put the huge
     * spheres last (the renderer hashes before the build, while nothing
     * else holds memory). */
    size_t reordered = s->id ? 0 : s->count; /* no ids: in the file's order */
    while (reordered < s->count && s->id[reordered] == reordered)
        reordered++;
    uint32_t *by_id = NULL;
    if (reordered < s->count) {
        by_id = malloc(s->count * sizeof *by_id);
        if (!by_id)
            return ptr_error_set(err, PTR_ERR_NOMEM,
                                 "out of memory for the file's order of %zu spheres", s->count);
    }
    for (size_t j = 0; by_id && j < s->count; j++)
        by_id[s->id[j]] = (uint32_t)j;
    XXH3_state_t h;
    (void)XXH3_64bits_reset(&h);
    hash_bytes(&h, scene->origin, sizeof scene->origin);
    hash_bytes(&h, &s->count, sizeof s->count);
    hash_in_file_order(&h, s->cx, sizeof *s->cx, sizeof *s->cx, 0, by_id, s->count);
    hash_in_file_order(&h, s->cy, sizeof *s->cy, sizeof *s->cy, 0, by_id, s->count);
    hash_in_file_order(&h, s->cz, sizeof *s->cz, sizeof *s->cz, 0, by_id, s->count);
    hash_in_file_order(&h, s->radius, sizeof *s->radius, sizeof *s->radius, 0, by_id, s->count);
    hash_materials(&h, s, by_id);
#define HASH_ATTRIBUTE(name, type, per_sphere, none, hashed)                               \
    _Static_assert((hashed) * sizeof(type) <= GATHER_ENTRY, #name " is gathered whole");   \
    if (s->name)                                                                           \
        hash_in_file_order(&h, s->name, (per_sphere) * sizeof(type), (hashed) * sizeof(type), \
                           (unsigned char)(none), by_id, s->count);
    PTR_SPHERE_ATTRIBUTES(HASH_ATTRIBUTE)
#undef HASH_ATTRIBUTE
    free(by_id);
    hash_bytes(&h, scene->huge.centre_radius, 4 * scene->huge.count * sizeof(double));
    for (size_t i = 0; i < scene->material_count; i++) {
        const PtrMaterial *m = &scene->materials[i];
        const int kind = m->kind;
        const float scalars[2] = { m->fuzz, m->ior };
        hash_bytes(&h, &kind, sizeof kind);
        hash_vec(&h, m->albedo);
        hash_vec(&h, m->emission);
        hash_bytes(&h, scalars, sizeof scalars);
    }
    const PtrCamera *c = &scene->camera;
    const float lens[4] = { c->vfov_deg, c->aperture, c->focus_distance, c->aspect };
    hash_vec(&h, c->lookfrom);
    hash_vec(&h, c->lookat);
    hash_vec(&h, c->up);
    hash_bytes(&h, lens, sizeof lens);
    const int projection = c->projection;
    hash_bytes(&h, &projection, sizeof projection);
    if (c->projection == PTR_PROJECTION_ORTHOGRAPHIC) {
        const float ortho[2] = { c->ymag, c->znear };
        hash_bytes(&h, ortho, sizeof ortho);
    }
    const int sky = scene->sky.kind;
    hash_bytes(&h, &sky, sizeof sky);
    hash_vec(&h, scene->sky.radiance);
    *hash = XXH3_64bits_digest(&h);
    return PTR_OK;
}

PtrResult ptr_sky_parse(const char *text, PtrSky *sky, PtrError *err)
{
    if (!strcmp(text, "gradient")) {
        *sky = (PtrSky){ .kind = PTR_SKY_GRADIENT };
        return PTR_OK;
    }
    if (!strcmp(text, "black")) {
        *sky = (PtrSky){ .kind = PTR_SKY_BLACK };
        return PTR_OK;
    }
    float r, g, b;
    char tail;
    if (sscanf(text, "%f,%f,%f%c", &r, &g, &b, &tail) != 3 || !isfinite(r) || !isfinite(g) ||
        !isfinite(b) || r < 0 || g < 0 || b < 0)
        return ptr_error_set(err, PTR_ERR_USAGE,
                             "'%s' is not gradient, black or R,G,B (not negative)", text);
    *sky = (PtrSky){ .kind = PTR_SKY_CONSTANT, .radiance = v3(r, g, b) };
    return PTR_OK;
}
