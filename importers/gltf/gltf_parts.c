/* Surface primitives as one mesh (gltf_parts.h). */
#include "gltf_parts.h"

#include <string.h>

#include "base/cpu.h"
#include "base/threads.h"
#include "gltf_accessors.h"

const SurfacePart *gltf_part_of(const SurfaceParts *s, size_t at, int by_triangle)
{
    size_t lo = 0, hi = s->count;
    while (hi - lo > 1) {
        const size_t mid = lo + (hi - lo) / 2;
        const SurfacePart *p = &s->parts[mid];
        if ((by_triangle ? p->first_triangle : p->first_vertex) <= at)
            lo = mid;
        else
            hi = mid;
    }
    return &s->parts[lo];
}

static size_t index_at(const GltfAccessor *a, size_t i)
{
    const unsigned char *p = a->data + i * a->stride;
    uint32_t u32;
    uint16_t u16;
    switch (a->component_type) {
    case GLTF_UNSIGNED_BYTE: return p[0];
    case GLTF_UNSIGNED_SHORT: memcpy(&u16, p, 2); return u16;
    default: memcpy(&u32, p, 4); return u32;
    }
}

/* Vertex j of a part's triangle list, strip or fan (as its mode says). */
static size_t part_vertex(const SurfacePart *p, size_t j)
{
    return p->first_vertex + (p->has_idx ? index_at(&p->idx, j) : j);
}

static void float_position(const unsigned char *at, double out[3])
{
    float f[3];
    memcpy(f, at, sizeof f);
    for (int k = 0; k < 3; k++)
        out[k] = f[k];
}

/* Vertex v of part p (from p's first), as gltf_element reads it. */
static void part_position(const SurfacePart *p, size_t v, double out[3])
{
    if (p->pos.component_type == GLTF_FLOAT) { /* the common case, read at once */
        float_position(p->pos.data + v * p->pos.stride, out);
        return;
    }
    double e[4];
    gltf_element(&p->pos, v, e);
    memcpy(out, e, 3 * sizeof *out);
}

/* Triangles j .. j + count - 1 of part p as mesh vertices. */
static void part_triangles(const SurfacePart *p, size_t j, size_t count, uint32_t (*out)[3])
{
    const uint32_t base = (uint32_t)p->first_vertex;
    if (p->mode == 4 && p->has_idx && p->idx.component_type == GLTF_UNSIGNED_INT &&
        p->idx.stride == 4) { /* the common case of a large mesh, read at once */
        const unsigned char *at = p->idx.data + 12 * j;
        for (size_t i = 0; i < count; i++, at += 12) {
            uint32_t tri[3];
            memcpy(tri, at, sizeof tri);
            for (int k = 0; k < 3; k++)
                out[i][k] = base + tri[k];
        }
        return;
    }
    for (size_t i = 0; i < count; i++, j++) {
        const size_t at[3] = { p->mode == 4 ? 3 * j : p->mode == 6 ? 0 : j,
                               p->mode == 4 ? 3 * j + 1 : j + 1,
                               p->mode == 4 ? 3 * j + 2 : j + 2 };
        for (int k = 0; k < 3; k++)
            out[i][k] = (uint32_t)part_vertex(p, at[k]);
    }
}

void gltf_mesh_positions(const void *user, size_t first, size_t count, double (*out)[3])
{
    const SurfacePart *p = gltf_part_of(user, first, 0);
    for (size_t i = 0; i < count; p++) {
        const size_t v = first + i - p->first_vertex;
        const size_t run = p->pos.count - v < count - i ? p->pos.count - v : count - i;
        if (p->pos.component_type == GLTF_FLOAT) /* the common case, its type asked once */
            for (size_t k = 0; k < run; k++)
                float_position(p->pos.data + (v + k) * p->pos.stride, out[i + k]);
        else
            for (size_t k = 0; k < run; k++)
                part_position(p, v + k, out[i + k]);
        i += run;
    }
}

void gltf_mesh_gather(const void *user, const uint32_t *vertices, size_t count,
                      double (*out)[3])
{
    const SurfacePart *p = gltf_part_of(user, vertices[0], 0);
    for (size_t i = 0; i < count; i++) {
        if (vertices[i] < p->first_vertex || vertices[i] - p->first_vertex >= p->pos.count)
            p = gltf_part_of(user, vertices[i], 0);
        part_position(p, vertices[i] - p->first_vertex, out[i]);
    }
}

void gltf_mesh_triangles(const void *user, size_t first, size_t count, uint32_t (*out)[3])
{
    const SurfacePart *p = gltf_part_of(user, first, 1);
    for (size_t i = 0; i < count; p++) {
        const size_t j = first + i - p->first_triangle;
        const size_t run = p->triangles - j < count - i ? p->triangles - j : count - i;
        part_triangles(p, j, run, out + i);
        i += run;
    }
}

double gltf_position_quantum(const GltfAccessor *a)
{
    if (a->component_type == GLTF_FLOAT)
        return 0.0;
    return a->normalized ? gltf_component_value(a->component_type, 1, 1.0) : 1.0;
}

/* The indices of a primitive, checked on all cores for a large one: the
 * first past the primitive's vertices. */
typedef struct IndexCheck {
    const GltfAccessor *indices;
    size_t vertices;
    atomic_size_t first_past; /* SIZE_MAX: none */
} IndexCheck;

enum { PARALLEL_INDICES = 1 << 18 };

static void check_indices(void *arg, size_t from, size_t to)
{
    IndexCheck *c = arg;
    const GltfAccessor *a = c->indices;
    /* 32-bit indices, the common case of a large mesh: the largest of each
     * chunk first, the chunk searched only if it is past the vertices. */
    for (; a->component_type == GLTF_UNSIGNED_INT && a->stride == 4 && to - from >= 4096;
         from += 4096) {
        uint32_t chunk[4096], largest = 0;
        memcpy(chunk, a->data + 4 * from, sizeof chunk);
        for (size_t i = 0; i < 4096; i++)
            largest = chunk[i] > largest ? chunk[i] : largest;
        if (largest >= c->vertices)
            break;
    }
    for (size_t i = from; i < to; i++)
        if (index_at(a, i) >= c->vertices) {
            gltf_note_failure(&c->first_past, i);
            return;
        }
}

PtrResult gltf_surface_part(Importer *im, const Origin *o, size_t mesh, size_t p,
                            const GltfPrimitive *prim, SurfacePart *part)
{
    char where[160];
    gltf_origin_text(o, where, sizeof where);
    if (prim->position < 0)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: %s: mesh %zu primitive %zu has no POSITION", im->path, where,
                             mesh, p);
    size_t vertices = 0;
    PtrResult res = gltf_attribute_accessor(im, o, "POSITION", prim->position, 3, 3, QUANTIZED,
                                            &vertices, &part->pos);
    if (res != PTR_OK)
        return res;
    part->mode = prim->mode;
    part->primitive = (int)p;
    part->has_idx = prim->indices >= 0;
    size_t n = vertices;
    if (part->has_idx) {
        gltf_doc_accessor(im->doc, (size_t)prim->indices, &part->idx);
        const GltfAccessor *a = &part->idx;
        if (!a->data || a->sparse || a->components != 1 || a->normalized ||
            !(a->component_type == GLTF_UNSIGNED_BYTE || a->component_type == GLTF_UNSIGNED_SHORT ||
              a->component_type == GLTF_UNSIGNED_INT))
            return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                 "%s: %s: mesh %zu primitive %zu has indices that are not "
                                 "unsigned integers in a buffer", im->path, where, mesh, p);
        n = a->count;
        IndexCheck check = { .indices = a, .vertices = vertices };
        atomic_init(&check.first_past, SIZE_MAX);
        ptr_parallel_ranges(n >= PARALLEL_INDICES ? ptr_usable_cpus() : 1, 0, n, check_indices,
                            &check);
        const size_t past = atomic_load(&check.first_past);
        if (past != SIZE_MAX)
            return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                                 "%s: %s: mesh %zu primitive %zu has index %zu past its "
                                 "%zu vertices", im->path, where, mesh, p, index_at(a, past),
                                 vertices);
    }
    part->triangles = prim->mode == 4 ? n / 3 : (prim->mode == 5 || prim->mode == 6) && n >= 3
                                                    ? n - 2 : 0;
    part->first_vertex = vertices;
    return PTR_OK;
}
