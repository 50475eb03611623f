/* Spheres far larger than the scene (accel/huge.h), as smallpt builds a room:
 * six radius-1e5 walls closing a 100 x 80 x 170 box, lit by a small emitter
 * inside, the camera inside looking into a corner.
 *
 * The walls overlap outside the box, so no path can leave it: rendered under
 * a black sky and under a sky of 1000, every pixel must come out the same bit
 * for bit (same seed, so the same paths). A ray that slipped out at a corner
 * or through a wall, or started behind one, would see the bright sky. The
 * tree (over the lamp alone: the walls are huge) gives the same image as
 * brute force, and every intersector level the C reference's. */
#include <stdlib.h>
#include <string.h>

#include "accel/accel.h"
#include "builder.h"
#include "lit_ground.h"
#include "methods.h"
#include "render/render.h"
#include "test.h"

enum { SIZE = 32, SAMPLES = 32 };

static PtrScene room(unsigned build_flags, PtrSky sky)
{
    const PtrMaterial wall = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3(0.75f, 0.7f, 0.65f) };
    const PtrMaterial light = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.0f),
                                .emission = v3_splat(12.0f) };
    PtrScene s;
    uint32_t w, l;
    ptr_scene_init(&s);
    CHECK_INT(ptr_scene_add_material(&s, &wall, &w, NULL), PTR_OK);
    CHECK_INT(ptr_scene_add_material(&s, &light, &l, NULL), PTR_OK);
    PtrSceneBuilder b;
    ptr_builder_init(&b, &s, NULL);
    const double big = 1e5;
    const double walls[6][3] = {
        { -big, 40, 85 }, { 100 + big, 40, 85 }, { 50, -big, 85 },
        { 50, 80 + big, 85 }, { 50, 40, -big }, { 50, 40, 170 + big },
    };
    for (int i = 0; i < 6; i++)
        CHECK_INT(ptr_builder_add_sphere(&b, walls[i], big, w, NULL), PTR_OK);
    const double lamp[3] = { 50, 75, 85 };
    CHECK_INT(ptr_builder_add_sphere(&b, lamp, 4.0, l, NULL), PTR_OK);
    const double eye[3] = { 70, 50, 160 }, corner[3] = { 0, 0, 0 }, up[3] = { 0, 1, 0 };
    const PtrCamera lens = { .vfov_deg = 50.0f, .focus_distance = 1.0f };
    ptr_builder_set_camera(&b, eye, corner, up, &lens);
    CHECK_INT(ptr_builder_finish(&b, build_flags, NULL), PTR_OK);
    s.sky = sky;
    return s;
}

static float *render(const Method *m, PtrSky sky, PtrAccelChoice choice)
{
    PtrScene s = room(m->build_flags, sky);
    PtrRenderSettings settings = { .width = SIZE, .height = SIZE, .samples = SAMPLES, .seed = 3,
                                   .max_depth = 50, .threads = 2, .fixed_tmin = m->fixed_tmin };
    float *rgb = malloc(SIZE * SIZE * 3 * sizeof *rgb);
    PtrError err = { 0 };
    PtrAccel accel;
    CHECK_INT(ptr_accel_init(&accel, choice, &m->isect, 0, &s, 0, NULL), PTR_OK);
    CHECK_INT(ptr_render(&s, &accel, &settings, rgb, NULL, &err), PTR_OK);
    ptr_accel_free(&accel);
    ptr_scene_free(&s);
    return rgb;
}

/* The closed form of lit_ground.h on a radius-1e5 ground at 256 spp: each
 * pixel within 1.5% and the image's mean within 0.5% (measured: 0.13% and
 * 0.04%). Light sampling takes the direction and distance to the emitter
 * from the point on the surface, so the float ground's lift moves only the
 * shadow rays' origins and passes too (printed, not asserted). */
static void lit_ground_table(const Method *methods, int n)
{
    PtrRenderSettings settings = { .samples = 256, .seed = 1, .max_depth = 50, .threads = 2 };
    printf("\nradius-1e5 ground lit by a small emitter, 256 spp: relative error\n"
           "%-20s %10s %10s\n", "", "worst px", "mean");
    int ptr_rows = 0;
    for (int i = 0; i < n; i++) {
        if (methods[i].fixed_tmin > 0.0f || !(methods[i].build_flags & PTR_BUILD_RECENTRE))
            continue;
        LitGroundErrors e = lit_ground_errors(1e5, methods[i].build_flags, &methods[i].isect,
                                              settings);
        printf("%-20s %10.4f %10.4f\n", methods[i].name, e.worst, e.mean);
        if (methods[i].is_ptr) {
            CHECK(e.worst <= 0.015);
            CHECK(e.mean <= 0.005);
            ptr_rows++;
        }
    }
    CHECK_INT(ptr_rows, stability_ptr_levels());
}

static Method methods[MAX_METHODS];
static int method_count;

static void test_walls_are_huge(void)
{
    const PtrSky black = { .kind = PTR_SKY_BLACK };
    PtrScene probe = room(PTR_BUILD_DEFAULT, black);
    CHECK_INT((int)probe.huge.count, 6); /* the walls, not the lamp */
    ptr_scene_free(&probe);
}

/* The builder's choice of huge spheres when more than PTR_HUGE_MAX are
 * (scene.h's rule), made on all cores: 3,000 radius-1 spheres in a
 * 60 x 50 grid with 40 huge ones among them, radii 1e6 to 4e6 with ties,
 * spread through the file. The scene keeps the 16 largest, on equal radii
 * the first in the file, in the file's order, each in double. (The builder
 * makes a piece a CPU: on one CPU this checks the serial choice alone.) */
static void test_many_huge(void)
{
    enum { SMALL = 3000, HUGE = 40, STEP = (SMALL + HUGE) / HUGE };
    const PtrMaterial grey = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.5f) };
    PtrScene s;
    uint32_t m;
    ptr_scene_init(&s);
    CHECK_INT(ptr_scene_add_material(&s, &grey, &m, NULL), PTR_OK);
    PtrSceneBuilder b;
    ptr_builder_init(&b, &s, NULL);
    PtrHugeChoice rule = { .limit = 1e5 };
    for (int i = 0, small = 0, huge = 0; i < SMALL + HUGE; i++) {
        const int is_huge = i % STEP == STEP - 1 && huge < HUGE;
        /* A huge sphere's x is its place in the file, to find it by. */
        const double centre[3] = { is_huge ? i : small % 60 * 2.0, small / 60 * 2.0, -100.0 };
        const double radius = is_huge ? 1e6 * (1 + huge % 4) : 1.0;
        CHECK_INT(ptr_builder_add_sphere(&b, centre, radius, m, NULL), PTR_OK);
        ptr_huge_offer(&rule, (size_t)i, (size_t)i, radius);
        huge += is_huge;
        small += !is_huge;
    }
    ptr_huge_file_order(&rule);
    const double eye[3] = { 60, 50, 200 }, at[3] = { 60, 50, 0 }, up[3] = { 0, 1, 0 };
    const PtrCamera lens = { .vfov_deg = 50.0f, .focus_distance = 1.0f };
    ptr_builder_set_camera(&b, eye, at, up, &lens);
    CHECK_INT(ptr_builder_finish(&b, PTR_BUILD_DEFAULT, NULL), PTR_OK);
    CHECK_INT((int)s.huge.count, PTR_HUGE_MAX);
    int wrong = 0;
    for (size_t k = 0; k < s.huge.count; k++)
        wrong += s.huge.centre_radius[4 * k] + s.origin[0] != (double)rule.sphere[k].file_position ||
                 s.huge.centre_radius[4 * k + 3] != rule.sphere[k].radius;
    CHECK_INT(wrong, 0);
    ptr_scene_free(&s);
}

static void test_closed_room(void)
{
    const PtrSky black = { .kind = PTR_SKY_BLACK };
    const PtrSky bright = { .kind = PTR_SKY_CONSTANT, .radiance = v3_splat(1000.0f) };
    printf("radius-1e5 walls closing a room: pixels that see the sky outside (of %d)\n",
           SIZE * SIZE);
    float *reference = NULL;
    for (int i = 0; i < method_count; i++) {
        float *closed = render(&methods[i], black, PTR_ACCEL_BRUTE);
        float *open = render(&methods[i], bright, PTR_ACCEL_BRUTE);
        int leaking = 0;
        double mean = 0;
        for (int p = 0; p < SIZE * SIZE; p++) {
            leaking += memcmp(&closed[3 * p], &open[3 * p], 3 * sizeof *closed) != 0;
            mean += closed[3 * p];
        }
        printf("%-20s %5d   (mean red %.4f)\n", methods[i].name, leaking, mean / (SIZE * SIZE));
        if (methods[i].is_ptr) {
            CHECK_INT(leaking, 0);
            float *tree = render(&methods[i], black, PTR_ACCEL_BVH);
            CHECK(!memcmp(tree, closed, SIZE * SIZE * 3 * sizeof *tree));
            free(tree);
            /* Every intersector level gives the C reference's image. */
            if (!reference)
                reference = closed;
            else
                CHECK(!memcmp(reference, closed, SIZE * SIZE * 3 * sizeof *closed));
        }
        if (closed != reference)
            free(closed);
        free(open);
    }
    free(reference);
}

static void test_lit_ground(void)
{
    lit_ground_table(methods, method_count);
}

int main(void)
{
    method_count = stability_methods(methods, MAX_METHODS);
    CHECK_INT(stability_ptr_methods(methods, method_count), stability_ptr_levels());
    const TestCase cases[] = {
        TEST_CASE(test_walls_are_huge),
        TEST_CASE(test_many_huge),
        TEST_CASE(test_closed_room),
        TEST_CASE(test_lit_ground),
    };
    TEST_RUN(cases);
    return test_report();
}
