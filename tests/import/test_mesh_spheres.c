/* The components of a mesh large enough to be found on all cores are the
 * same whatever the number of CPUs usable, even where it changes while they
 * are found (CPUs taken on or off line, an affinity changed): ptr_usable_cpus is replaced here
 * (the test links with --wrap) by a script of answers. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_runs.h"
#include "mesh_spheres.h"
#include "test.h"

/* The answers ptr_usable_cpus gives, one a call, the last repeated. */
static const int *script;
static size_t script_length, asked;

int __wrap_ptr_usable_cpus(void);
int __wrap_ptr_usable_cpus(void)
{
    const size_t at = asked < script_length ? asked : script_length - 1;
    asked++;
    return script[at];
}

/* Octahedra along x, every other one welded (6 vertices shared by index:
 * closed, so left out of the position matching), the others unwelded
 * (every triangle its own 3 vertices, joined by position): about 10^5
 * vertices and triangles. */
enum { OCTAHEDRA = 4000, WELDED_VERTICES = 6, UNWELDED_VERTICES = 24, FACES = 8 };

typedef struct Mesh {
    double (*v)[3];
    uint32_t (*t)[3];
} Mesh;

static void positions(const void *user, size_t first, size_t count, double (*out)[3])
{
    memcpy(out, &((const Mesh *)user)->v[first], count * sizeof *out);
}

static void gather(const void *user, const uint32_t *vertices, size_t count, double (*out)[3])
{
    for (size_t i = 0; i < count; i++)
        memcpy(out[i], ((const Mesh *)user)->v[vertices[i]], sizeof out[i]);
}

static void triangles(const void *user, size_t first, size_t count, uint32_t (*out)[3])
{
    memcpy(out, &((const Mesh *)user)->t[first], count * sizeof *out);
}

static PtrMeshSource make_mesh(Mesh *m)
{
    static const double corner[6][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 },
                                         { 0, -1, 0 }, { 0, 0, 1 }, { 0, 0, -1 } };
    static const uint32_t face[FACES][3] = { { 0, 2, 4 }, { 2, 1, 4 }, { 1, 3, 4 }, { 3, 0, 4 },
                                             { 2, 0, 5 }, { 1, 2, 5 }, { 3, 1, 5 }, { 0, 3, 5 } };
    m->v = malloc(OCTAHEDRA / 2 * (WELDED_VERTICES + UNWELDED_VERTICES) * sizeof *m->v);
    m->t = malloc(OCTAHEDRA * FACES * sizeof *m->t);
    size_t nv = 0, nt = 0;
    for (int o = 0; o < OCTAHEDRA; o++) {
        const double x = 3.0 * o, radius = 1.0 + (o % 7) * 0.1;
        const size_t first = nv;
        for (int f = 0; f < FACES; f++)
            for (int k = 0; k < 3; k++) {
                const int c = face[f][k];
                if (o % 2) {
                    m->t[nt + (size_t)f][k] = (uint32_t)nv;
                    for (int j = 0; j < 3; j++)
                        m->v[nv][j] = (j == 0 ? x : 0.0) + radius * corner[c][j];
                    nv++;
                } else {
                    m->t[nt + (size_t)f][k] = (uint32_t)(first + (size_t)c);
                }
            }
        if (o % 2 == 0)
            for (int c = 0; c < WELDED_VERTICES; c++, nv++)
                for (int j = 0; j < 3; j++)
                    m->v[nv][j] = (j == 0 ? x : 0.0) + radius * corner[c][j];
        nt += FACES;
    }
    return (PtrMeshSource){ .vertex_count = nv, .triangle_count = nt, .positions = positions,
                            .gather = gather, .triangles = triangles, .user = m };
}

/* Field by field: a sphere's padding is not part of it. */
static int same_sphere(const PtrMeshSphere *a, const PtrMeshSphere *b)
{
    return !memcmp(a->centre, b->centre, sizeof a->centre) && a->radius == b->radius &&
           a->first_triangle == b->first_triangle && a->is_sphere == b->is_sphere;
}

static void test_cpus_changing(void)
{
    Mesh m;
    const PtrMeshSource mesh = make_mesh(&m);
    CHECK(m.v && m.t);
    if (!m.v || !m.t)
        return;
    static const int one[] = { 1 };
    script = one, script_length = 1, asked = 0;
    PtrMeshSphere *expected = NULL;
    uint32_t *expected_labels = NULL;
    size_t expected_count = 0;
    CHECK_INT(ptr_mesh_spheres(&mesh, "octahedra", &expected, &expected_count, &expected_labels,
                               NULL),
              PTR_OK);
    CHECK_INT(expected_count, OCTAHEDRA);
    /* Steady counts, then CPUs coming on line and going off line while the
     * components are found. */
    static const int steady2[] = { 2 }, steady64[] = { 64 }, steady1024[] = { 1024 },
                     coming[] = { 1, 64 }, going[] = { 64, 1 }, rising[] = { 1, 2, 3, 5, 8, 13 };
    static const struct { const int *answers; size_t length; } scripts[] = {
        { steady2, 1 }, { steady64, 1 }, { steady1024, 1 },
        { coming, 2 },  { going, 2 },    { rising, 6 },
    };
    for (size_t i = 0; i < sizeof scripts / sizeof *scripts; i++) {
        script = scripts[i].answers, script_length = scripts[i].length, asked = 0;
        PtrMeshSphere *found = NULL;
        uint32_t *labels = NULL;
        size_t count = 0;
        CHECK_INT(ptr_mesh_spheres(&mesh, "octahedra", &found, &count, &labels, NULL), PTR_OK);
        CHECK_INT(count, expected_count);
        if (count == expected_count) {
            for (size_t c = 0; c < count; c++)
                CHECK(same_sphere(&found[c], &expected[c]));
            CHECK(!memcmp(labels, expected_labels, mesh.vertex_count * sizeof *labels));
        }
        free(found);
        free(labels);
    }
    free(expected);
    free(expected_labels);
    free(m.v);
    free(m.t);
}

/* The least closed set by index: two triangles over the same three vertices
 * (2 vertices a triangle, less 4: balance 4), kept out of the position
 * matching, so a triangle with vertices of its own at the same positions is
 * a component apart; turned open (its second triangle with vertices of its
 * own too), all three are joined by position. */
static void test_least_closed(void)
{
    double v[9][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
    for (int i = 3; i < 9; i++)
        memcpy(v[i], v[i % 3], sizeof v[i]);
    uint32_t closed[3][3] = { { 0, 1, 2 }, { 0, 2, 1 }, { 3, 4, 5 } };
    uint32_t open[3][3] = { { 0, 1, 2 }, { 6, 8, 7 }, { 3, 4, 5 } };
    static const int one[] = { 1 };
    script = one, script_length = 1, asked = 0;
    for (int opened = 0; opened < 2; opened++) {
        Mesh m = { v, opened ? open : closed };
        const PtrMeshSource mesh = { .vertex_count = 9, .triangle_count = 3,
                                     .positions = positions, .gather = gather,
                                     .triangles = triangles, .user = &m };
        PtrMeshSphere *found = NULL;
        size_t count = 0;
        CHECK_INT(ptr_mesh_spheres(&mesh, "triangles", &found, &count, NULL, NULL), PTR_OK);
        CHECK_INT(count, opened ? 1 : 2);
        free(found);
    }
}

/* A joined mesh as the tools write one: welded UV spheres of several sizes,
 * each's triangles in a shuffled order, with closed parts that are not
 * spheres (cubes), vertices no triangle uses between parts, and pairs of
 * spheres whose vertices interleave (two components in one run of
 * vertices). Grown a part at a time. */
typedef struct Joined {
    Mesh m;
    size_t nv, nt, vertex_room, triangle_room;
    size_t components, spheres; /* expected: all, and those that are spheres */
    uint32_t seed;
} Joined;

static uint32_t next_random(Joined *j)
{
    j->seed = j->seed * 1664525u + 1013904223u;
    return j->seed >> 8;
}

static void room_for(Joined *j, size_t vertices, size_t triangles)
{
    if (j->nv + vertices > j->vertex_room) {
        j->vertex_room = 2 * (j->nv + vertices);
        j->m.v = realloc(j->m.v, j->vertex_room * sizeof *j->m.v);
    }
    if (j->nt + triangles > j->triangle_room) {
        j->triangle_room = 2 * (j->nt + triangles);
        j->m.t = realloc(j->m.t, j->triangle_room * sizeof *j->m.t);
    }
}

/* Triangles first .. first + count - 1 in a shuffled order. */
static void shuffle_triangles(Joined *j, size_t first, size_t count)
{
    for (size_t i = count; i > 1; i--) {
        const size_t k = next_random(j) % i;
        uint32_t held[3];
        memcpy(held, j->m.t[first + i - 1], sizeof held);
        memcpy(j->m.t[first + i - 1], j->m.t[first + k], sizeof held);
        memcpy(j->m.t[first + k], held, sizeof held);
    }
}

/* A UV sphere's vertices at first + stride * i (poles, then rings) and its
 * triangles, shuffled. */
static void add_uv_sphere(Joined *j, size_t first, size_t stride, int segments, int rings)
{
    const size_t nv = 2 + (size_t)(rings - 1) * segments, nt = 2 * (size_t)segments * (rings - 1);
    const double centre[3] = { next_random(j) % 1000 * 0.1, next_random(j) % 1000 * 0.1,
                               next_random(j) % 1000 * 0.1 };
    const double radius = 0.5 + next_random(j) % 100 * 0.01, pi = acos(-1.0);
    room_for(j, first + stride * nv - j->nv, nt);
    for (size_t i = 0; i < nv; i++) {
        const int ring = i == 0 ? 0 : i == 1 ? rings : 1 + (int)((i - 2) / segments);
        const int segment = i < 2 ? 0 : (int)((i - 2) % segments);
        const double theta = pi * ring / rings, phi = 2 * pi * segment / segments;
        double *v = j->m.v[first + stride * i];
        v[0] = centre[0] + radius * sin(theta) * cos(phi);
        v[1] = centre[1] + radius * cos(theta);
        v[2] = centre[2] + radius * sin(theta) * sin(phi);
    }
    const size_t t0 = j->nt;
#define AT(ring, s) ((uint32_t)(first + stride * (2 + (size_t)((ring) - 1) * segments + \
                                                  (size_t)((s) % segments))))
    for (int s = 0; s < segments; s++) {
        uint32_t *top = j->m.t[j->nt++], *bottom = j->m.t[j->nt++];
        top[0] = (uint32_t)first, top[1] = AT(1, s + 1), top[2] = AT(1, s);
        bottom[0] = (uint32_t)(first + stride), bottom[1] = AT(rings - 1, s);
        bottom[2] = AT(rings - 1, s + 1);
        for (int ring = 1; ring < rings - 1; ring++) {
            uint32_t *a = j->m.t[j->nt++], *b = j->m.t[j->nt++];
            a[0] = AT(ring, s), a[1] = AT(ring, s + 1), a[2] = AT(ring + 1, s);
            b[0] = AT(ring + 1, s), b[1] = AT(ring, s + 1), b[2] = AT(ring + 1, s + 1);
        }
    }
#undef AT
    shuffle_triangles(j, t0, nt);
}

static void add_cube(Joined *j)
{
    static const uint32_t face[12][3] = { { 0, 2, 1 }, { 1, 2, 3 }, { 4, 5, 6 }, { 5, 7, 6 },
                                          { 0, 1, 4 }, { 1, 5, 4 }, { 2, 6, 3 }, { 3, 6, 7 },
                                          { 0, 4, 2 }, { 2, 4, 6 }, { 1, 3, 5 }, { 3, 7, 5 } };
    room_for(j, 8, 12);
    const size_t first = j->nv;
    for (int c = 0; c < 8; c++)
        for (int k = 0; k < 3; k++)
            j->m.v[first + c][k] = 40.0 + (c >> k & 1);
    for (int f = 0; f < 12; f++)
        for (int k = 0; k < 3; k++)
            j->m.t[j->nt + f][k] = (uint32_t)first + face[f][k];
    shuffle_triangles(j, j->nt, 12);
    j->nv += 8, j->nt += 12;
}

/* A closed flat disc (a fan on either side of one rim): not a sphere, and
 * its bounds in z both zero, of either sign. */
static void add_pillow(Joined *j)
{
    enum { RIM = 12 };
    room_for(j, RIM + 2, 2 * RIM);
    const size_t first = j->nv;
    for (int i = 0; i < RIM + 2; i++) {
        const double angle = 2 * acos(-1.0) * i / RIM;
        j->m.v[first + i][0] = i < RIM ? cos(angle) : 0.0;
        j->m.v[first + i][1] = i < RIM ? sin(angle) : 0.0;
        j->m.v[first + i][2] = i % 2 ? -0.0 : 0.0;
    }
    for (uint32_t i = 0; i < RIM; i++) {
        const uint32_t a = (uint32_t)first + i, b = (uint32_t)first + (i + 1) % RIM;
        uint32_t *top = j->m.t[j->nt++], *bottom = j->m.t[j->nt++];
        top[0] = (uint32_t)first + RIM, top[1] = a, top[2] = b;
        bottom[0] = (uint32_t)first + RIM + 1, bottom[1] = b, bottom[2] = a;
    }
    j->nv += RIM + 2;
}

static void make_joined(Joined *j, int parts)
{
    *j = (Joined){ .seed = 7 };
    for (int p = 0; p < parts; p++) {
        const int segments = 8 + (int)(next_random(j) % 9), rings = 6 + (int)(next_random(j) % 5);
        const size_t nv = 2 + (size_t)(rings - 1) * segments;
        if (p % 17 == 5 || p % 31 == 7) {
            p % 17 == 5 ? add_cube(j) : add_pillow(j);
            j->components++;
            continue;
        }
        /* More triangles than a window, shuffled; one over several slices. */
        if (p % 19 == 2 || p == parts / 2) {
            const int around = p == parts / 2 ? 200 : 40, down = p == parts / 2 ? 150 : 30;
            add_uv_sphere(j, j->nv, 1, around, down);
            j->nv += 2 + (size_t)(down - 1) * around;
            j->components++, j->spheres++;
            continue;
        }
        if (p % 13 == 4) { /* every other vertex one no triangle uses, at the same position */
            add_uv_sphere(j, j->nv, 2, segments, rings);
            for (size_t i = 0; i + 1 < nv; i++)
                memcpy(j->m.v[j->nv + 2 * i + 1], j->m.v[j->nv + 2 * i], sizeof *j->m.v);
            j->nv += 2 * nv - 1;
            j->components++, j->spheres++;
            continue;
        }
        if (p % 37 == 9) { /* a vertex not a number: not a sphere */
            add_uv_sphere(j, j->nv, 1, segments, rings);
            j->m.v[j->nv + 3][1] = NAN;
            j->nv += nv;
            j->components++;
            continue;
        }
        if (p % 29 == 11) { /* two spheres over every other vertex */
            add_uv_sphere(j, j->nv, 2, segments, rings);
            add_uv_sphere(j, j->nv + 1, 2, segments, rings);
            j->nv += 2 * nv;
            j->components += 2, j->spheres += 2;
            continue;
        }
        add_uv_sphere(j, j->nv, 1, segments, rings);
        j->nv += nv;
        j->components++, j->spheres++;
        if (p % 23 == 3) { /* a vertex no triangle uses */
            room_for(j, 1, 0);
            j->m.v[j->nv][0] = j->m.v[j->nv][1] = j->m.v[j->nv][2] = -5.0;
            j->nv++;
        }
    }
}

static PtrMeshSource joined_source(Joined *j)
{
    return (PtrMeshSource){ .vertex_count = j->nv, .triangle_count = j->nt,
                            .positions = positions, .gather = gather,
                            .triangles = triangles, .user = &j->m };
}

/* What a way of finding a mesh's components handed back. */
typedef struct Found {
    PtrMeshSphere *spheres;
    uint32_t *labels;
    size_t count;
} Found;

static void free_found(Found *f)
{
    free(f->spheres);
    free(f->labels);
}

/* Two results the same: spheres field by field, labels word by word. */
static void check_same(const Found *a, const Found *b, size_t vertices)
{
    CHECK_INT(a->count, b->count);
    if (a->count != b->count)
        return;
    size_t differ = 0;
    for (size_t c = 0; c < a->count; c++)
        differ += !same_sphere(&a->spheres[c], &b->spheres[c]);
    CHECK_INT(differ, 0);
    CHECK(!memcmp(a->labels, b->labels, vertices * sizeof *a->labels));
}

/* Found run by run, on any number of threads (slices of 8,192 triangles
 * and more: up to about 70 slices here, with slices' bounds in runs
 * anywhere, and a run over several slices), a joined mesh's components are
 * the union's to the bit. */
static void test_runs_match_union(void)
{
    Joined j;
    make_joined(&j, 4000);
    const PtrMeshSource mesh = joined_source(&j);
    static const int one[] = { 1 };
    script = one, script_length = 1, asked = 0;
    Found expected = { 0 };
    CHECK_INT(ptr_mesh_spheres_by_union(&mesh, "joined", &expected.spheres, &expected.count,
                                        &expected.labels, NULL),
              PTR_OK);
    CHECK_INT(expected.count, j.components);
    size_t spheres = 0;
    for (size_t c = 0; c < expected.count; c++)
        spheres += expected.spheres[c].is_sphere != 0;
    CHECK_INT(spheres, j.spheres);
    static const int threads[] = { 1, 2, 3, 5, 8, 13, 64, 256 };
    for (size_t i = 0; i < sizeof threads / sizeof *threads; i++) {
        Found found = { 0 };
        int by_runs = 0;
        CHECK_INT(ptr_mesh_spheres_by_runs(&mesh, threads[i], "joined", &found.spheres,
                                           &found.count, &found.labels, &by_runs, NULL),
                  PTR_OK);
        CHECK_INT(by_runs, 1);
        if (by_runs)
            check_same(&found, &expected, j.nv);
        free_found(&found);
    }
    free_found(&expected);
    free(j.m.v);
    free(j.m.t);
}

/* Where a mesh is not in runs of closed surfaces, the runs give way, and
 * ptr_mesh_spheres finds what the union finds: a last triangle reaching
 * back into the first sphere (on one thread, and where the slices put it
 * apart from that sphere), a first triangle of one vertex (a run of one),
 * the octahedra of test_cpus_changing (half of them open), and a run larger
 * than a run may be. */
static void test_runs_give_way(void)
{
    Joined back;
    make_joined(&back, 30);
    room_for(&back, 0, 1);
    memcpy(back.m.t[back.nt++], back.m.t[0], sizeof *back.m.t);
    Joined point; /* a vertex of its own first, and a triangle of it alone */
    make_joined(&point, 30);
    room_for(&point, 1, 1);
    memmove(point.m.v + 1, point.m.v, point.nv++ * sizeof *point.m.v);
    memmove(point.m.t + 1, point.m.t, point.nt++ * sizeof *point.m.t);
    for (size_t t = 1; t < point.nt; t++)
        for (int k = 0; k < 3; k++)
            point.m.t[t][k]++;
    memset(point.m.v[0], 0, sizeof *point.m.v);
    memset(point.m.t[0], 0, sizeof *point.m.t);
    Mesh octahedra;
    Joined large = { .seed = 11 };
    add_uv_sphere(&large, 0, 1, 256, 257); /* 65,538 vertices, 131,072 triangles */
    large.nv = 2 + 256 * 256;
    const PtrMeshSource meshes[] = { joined_source(&back), joined_source(&point),
                                     make_mesh(&octahedra), joined_source(&large) };
    static const int one[] = { 1 };
    script = one, script_length = 1, asked = 0;
    for (size_t m = 0; m < sizeof meshes / sizeof *meshes; m++) {
        for (int threads = 1; threads <= 4; threads *= 2) {
            Found none = { 0 };
            int by_runs = 1;
            CHECK_INT(ptr_mesh_spheres_by_runs(&meshes[m], threads, "mesh", &none.spheres,
                                               &none.count, NULL, &by_runs, NULL),
                      PTR_OK);
            CHECK_INT(by_runs, 0);
            CHECK(!none.spheres);
        }
        Found found = { 0 }, expected = { 0 };
        CHECK_INT(ptr_mesh_spheres(&meshes[m], "mesh", &found.spheres, &found.count,
                                   &found.labels, NULL),
                  PTR_OK);
        CHECK_INT(ptr_mesh_spheres_by_union(&meshes[m], "mesh", &expected.spheres,
                                            &expected.count, &expected.labels, NULL),
                  PTR_OK);
        check_same(&found, &expected, meshes[m].vertex_count);
        free_found(&found);
        free_found(&expected);
    }
    free(back.m.v);
    free(back.m.t);
    free(point.m.v);
    free(point.m.t);
    free(octahedra.v);
    free(octahedra.t);
    free(large.m.v);
    free(large.m.t);
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_cpus_changing),
        TEST_CASE(test_least_closed),
        TEST_CASE(test_runs_match_union),
        TEST_CASE(test_runs_give_way),
    };
    TEST_RUN(cases);
    return test_report();
}
