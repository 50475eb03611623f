/* The spheres of a mesh's surface (gltf_surfaces.h). */
#include "gltf_surfaces.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf_colors.h"
#include "gltf_parts.h"
#include "mesh_spheres.h"

/* A mesh's spheres from its bounds alone: one, unchecked, where its
 * vertices are not there to read: compressed by Draco, which ptr does not
 * decode, or a POSITION accessor with bounds but no buffer view (files
 * written by hand to place a sphere). */
static PtrResult bounds_sphere(Importer *im, const Origin *o, size_t mesh_index,
                               const GltfMesh *mesh, SurfaceSpheres *out)
{
    if (!mesh->has_bounds)
        return ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                             "%s: node %zu ('%s'): mesh %zu has no POSITION min/max bounds",
                             im->path, o->node_index, o->node_name, mesh_index);
    double extent = 0.0;
    for (int k = 0; k < 3; k++) {
        out->spheres[k] = 0.5 * (mesh->min[k] + mesh->max[k]);
        extent = fmax(extent, mesh->max[k] - mesh->min[k]);
    }
    out->spheres[3] = 0.5 * extent;
    for (size_t p = 0; p < mesh->primitive_count; p++) { /* the first surface primitive's */
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, mesh_index, p, &prim);
        if (!prim.points) {
            out->primitives[0] = (int)p;
            break;
        }
    }
    out->count = 1;
    return PTR_OK;
}

/* The components of a mesh's surface primitives, as o first meets them. */
static PtrResult find_surface(Importer *im, const Origin *o, size_t mesh_index,
                              const GltfMesh *mesh, SurfaceSpheres *out)
{
    SurfaceParts s = { malloc((mesh->primitive_count ? mesh->primitive_count : 1) *
                              sizeof *s.parts), 0 };
    if (!s.parts)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    PtrResult res = PTR_OK;
    size_t vertices = 0, triangles = 0, lines = 0;
    for (size_t p = 0; p < mesh->primitive_count && res == PTR_OK; p++) {
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, mesh_index, p, &prim);
        if (prim.points)
            continue;
        SurfacePart *part = &s.parts[s.count];
        res = gltf_surface_part(im, o, mesh_index, p, &prim, part);
        if (res != PTR_OK || !part->triangles) {
            lines += res == PTR_OK;
            continue;
        }
        const size_t count = part->first_vertex;
        part->first_vertex = vertices;
        part->first_triangle = triangles;
        vertices += count;
        triangles += part->triangles;
        s.count++;
    }
    if (res == PTR_OK && vertices >= UINT32_MAX)
        res = ptr_error_set(im->err, PTR_ERR_SCENE_INVALID,
                            "%s: mesh %zu has more vertices than ptr reads (%zu)", im->path,
                            mesh_index, vertices);
    PtrMeshSphere *found = NULL;
    uint32_t *labels = NULL;
    size_t components = 0;
    int colored = 0;
    for (size_t p = 0; p < s.count; p++) {
        GltfPrimitive prim;
        gltf_doc_primitive(im->doc, mesh_index, (size_t)s.parts[p].primitive, &prim);
        colored |= gltf_colored_by_vertices(im, &prim);
    }
    const PtrMeshSource source = {
        .vertex_count = vertices, .triangle_count = triangles, .positions = gltf_mesh_positions,
        .gather = gltf_mesh_gather, .triangles = gltf_mesh_triangles, .user = &s,
    };
    PtrMeshSource quantised = source;
    for (size_t p = 0; p < s.count; p++)
        quantised.quantum = fmax(quantised.quantum, gltf_position_quantum(&s.parts[p].pos));
    if (res == PTR_OK)
        res = ptr_mesh_spheres(&quantised, im->path, &found, &components,
                               colored ? &labels : NULL, im->err);
    if (res == PTR_OK) {
        out->spheres = malloc((components ? components : 1) * 4 * sizeof *out->spheres);
        out->primitives = malloc((components ? components : 1) * sizeof *out->primitives);
        if (!out->spheres || !out->primitives)
            res = ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    }
    out->skipped = lines;
    for (size_t c = 0; res == PTR_OK && c < components; c++) {
        if (!found[c].is_sphere) {
            out->skipped++;
            continue;
        }
        memcpy(&out->spheres[4 * out->count], found[c].centre, sizeof found[c].centre);
        out->spheres[4 * out->count + 3] = found[c].radius;
        out->primitives[out->count++] = gltf_part_of(&s, found[c].first_triangle, 1)->primitive;
    }
    if (res == PTR_OK && colored)
        res = gltf_surface_colors(im, o, mesh_index, &s, found, components, labels, out);
    free(labels);
    free(found);
    free(s.parts);
    return res;
}

/* What the spheres of primitive p of a mesh depend on: whether it is POINTS,
 * else its accessors and mode, and where its vertices colour the spheres,
 * its material, COLOR_0 and first two TEXCOORDs. */
enum { SURFACE_NUMBERS = 9 };
static void surface_numbers(const Importer *im, size_t mesh_index, size_t p,
                            int64_t out[SURFACE_NUMBERS])
{
    GltfPrimitive prim;
    gltf_doc_primitive(im->doc, mesh_index, p, &prim);
    memset(out, 0, SURFACE_NUMBERS * sizeof *out);
    out[0] = prim.points;
    if (prim.points)
        return;
    out[1] = prim.position;
    out[2] = prim.indices;
    out[3] = prim.mode;
    out[4] = prim.draco;
    if (!gltf_colored_by_vertices(im, &prim))
        return;
    out[5] = prim.material;
    out[6] = prim.color;
    out[7] = gltf_doc_primitive_attribute(im->doc, mesh_index, p, "TEXCOORD_0");
    out[8] = gltf_doc_primitive_attribute(im->doc, mesh_index, p, "TEXCOORD_1");
}

/* Whether meshes a and b have the same surface: the same primitives other
 * than POINTS (see surface_numbers), in the same places. */
static int same_surface(const Importer *im, size_t a, size_t b)
{
    GltfMesh ma, mb;
    gltf_doc_mesh(im->doc, a, &ma);
    gltf_doc_mesh(im->doc, b, &mb);
    for (size_t p = 0; p < ma.primitive_count && ma.primitive_count == mb.primitive_count; p++) {
        int64_t na[SURFACE_NUMBERS], nb[SURFACE_NUMBERS];
        surface_numbers(im, a, p, na);
        surface_numbers(im, b, p, nb);
        if (memcmp(na, nb, sizeof na))
            return 0;
    }
    return ma.primitive_count == mb.primitive_count;
}

/* A hash of what same_surface compares. */
static uint64_t surface_key(const Importer *im, size_t mesh_index)
{
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, mesh_index, &mesh);
    uint64_t h = 0xcbf29ce484222325u; /* FNV-1a over the numbers */
    for (size_t p = 0; p < mesh.primitive_count; p++) {
        int64_t part[SURFACE_NUMBERS];
        surface_numbers(im, mesh_index, p, part);
        for (int k = 0; k < SURFACE_NUMBERS; k++)
            h = (h ^ (uint64_t)part[k]) * 0x100000001b3u;
    }
    return h;
}

/* The earlier mesh of the same surface as mesh_index, if one was found,
 * else mesh_index, entered in the table. */
static size_t surface_owner(Importer *im, size_t mesh_index)
{
    const size_t mask = im->surface_slots - 1;
    for (size_t slot = surface_key(im, mesh_index) & mask;; slot = (slot + 1) & mask) {
        const size_t other = im->surface_table[slot];
        if (other == SIZE_MAX) {
            im->surface_table[slot] = mesh_index;
            return mesh_index;
        }
        if (same_surface(im, other, mesh_index))
            return other;
    }
}

PtrResult gltf_surface_spheres(Importer *im, const Origin *o, size_t mesh_index,
                               const SurfaceSpheres **out)
{
    SurfaceSpheres *s = &im->surfaces[mesh_index];
    if (!s->same)
        s->same = &im->surfaces[surface_owner(im, mesh_index)];
    *out = s->same;
    if (s->same != s || s->found)
        return PTR_OK;
    s->found = 1;
    GltfMesh mesh;
    gltf_doc_mesh(im->doc, mesh_index, &mesh);
    if (!mesh.has_surface)
        return PTR_OK;
    int unread = 0;
    for (size_t p = 0; p < mesh.primitive_count; p++) {
        GltfPrimitive prim;
        GltfAccessor a = { .data = NULL };
        gltf_doc_primitive(im->doc, mesh_index, p, &prim);
        if (!prim.points && prim.position >= 0)
            gltf_doc_accessor(im->doc, (size_t)prim.position, &a);
        unread |= !prim.points && (prim.draco || (prim.position >= 0 && !a.data));
    }
    if (!unread)
        return find_surface(im, o, mesh_index, &mesh, s);
    s->spheres = malloc(4 * sizeof *s->spheres);
    s->primitives = malloc(sizeof *s->primitives);
    if (!s->spheres || !s->primitives)
        return ptr_error_set(im->err, PTR_ERR_NOMEM, "%s: out of memory", im->path);
    return bounds_sphere(im, o, mesh_index, &mesh, s);
}

void gltf_note_skipped(Importer *im, const Origin *o, const GltfMesh *mesh, size_t parts)
{
    if (!parts)
        return;
    im->skipped += parts;
    char name[sizeof im->skipped_names];
    const size_t used = strlen(im->skipped_names);
    const int n = snprintf(name, sizeof name, "%snode '%s' (mesh '%s')", used ? ", " : "",
                           o->node_name, label(mesh->name, "unnamed"));
    if (n < 0 || used + (size_t)n >= sizeof im->skipped_names)
        im->skipped_more = 1;
    else
        memcpy(im->skipped_names + used, name, (size_t)n + 1);
}
