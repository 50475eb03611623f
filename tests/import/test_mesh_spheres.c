/* The components of a mesh large enough to be found on all cores are the
 * same whatever the number of CPUs online, even where it changes while they
 * are found (CPUs taken on or off line): ptr_online_cpus is replaced here
 * (the test links with --wrap) by a script of answers. */
#include <stdlib.h>
#include <string.h>

#include "mesh_spheres.h"
#include "test.h"

/* The answers ptr_online_cpus gives, one a call, the last repeated. */
static const int *script;
static size_t script_length, asked;

int __wrap_ptr_online_cpus(void);
int __wrap_ptr_online_cpus(void)
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

static void test_online_cpus(void)
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

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_online_cpus),
        TEST_CASE(test_least_closed),
    };
    TEST_RUN(cases);
    return test_report();
}
