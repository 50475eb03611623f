/* What every importer builds with (importers/builder.h): each sphere keeps
 * its material through the builder's entries, which are as wide as the
 * scene's and widen with it, and its centre and radius through floats that
 * widen to doubles, whether a sphere is added alone or a batch is added and
 * filled; and its colour is quantised (ptr_color_quantize, which the
 * builder calls for every coloured sphere) as the scalar clamp and lrintf
 * would. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "builder.h"
#include "test.h"

static uint32_t add_material(PtrScene *scene)
{
    const PtrMaterial grey = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = { 0.5f, 0.5f, 0.5f } };
    uint32_t index = 0;
    CHECK_INT(ptr_scene_add_material(scene, &grey, &index, NULL), PTR_OK);
    return index;
}

/* 256 spheres of 256 materials, one byte each; then 44 more materials and
 * a batch of 44 spheres filled with them (two bytes: the batch widens);
 * then materials up to 65,537 and a sphere of the last (four bytes). The
 * finished scene gives every sphere its material. */
static void test_material_widths(void)
{
    enum { ONE_BYTE = 256, BATCH = 44, SPHERES = ONE_BYTE + BATCH + 1 };
    PtrScene scene;
    ptr_scene_init(&scene);
    PtrSceneBuilder b;
    ptr_builder_init(&b, &scene, NULL);
    uint32_t expected[SPHERES];
    size_t n = 0;
    for (; n < ONE_BYTE; n++) {
        expected[n] = add_material(&scene);
        const double centre[3] = { (double)n, 0, -10 };
        CHECK_INT(ptr_builder_add_sphere(&b, centre, 0.25, expected[n], NULL), PTR_OK);
    }
    CHECK_INT(b.material_size, 1);
    for (size_t k = 0; k < BATCH; k++)
        expected[ONE_BYTE + k] = add_material(&scene);
    size_t first = 0;
    CHECK_INT(ptr_builder_add_spheres(&b, BATCH, 0, &first, NULL), PTR_OK);
    CHECK_INT(first, ONE_BYTE);
    CHECK_INT(b.material_size, 2);
    for (size_t k = 0; k < BATCH; k++, n++) {
        const double centre[3] = { (double)n, 1, -10 };
        ptr_builder_fill_sphere(&b, first + k, centre, 0.25, expected[n], NULL);
    }
    uint32_t last = 0;
    while (scene.material_count < 65537)
        last = add_material(&scene);
    expected[n] = last;
    const double centre[3] = { (double)n, 2, -10 };
    CHECK_INT(ptr_builder_add_sphere(&b, centre, 0.25, last, NULL), PTR_OK);
    CHECK_INT(b.material_size, 4);
    const double eye[3] = { 150, 0, 100 }, at[3] = { 150, 0, -10 }, up[3] = { 0, 1, 0 };
    const PtrCamera lens = { .vfov_deg = 40.0f, .focus_distance = 1.0f };
    ptr_builder_set_camera(&b, eye, at, up, &lens);
    CHECK_INT(ptr_builder_finish(&b, PTR_BUILD_DEFAULT, NULL), PTR_OK);
    CHECK_INT(scene.spheres.count, SPHERES);
    size_t kept = 0;
    for (size_t i = 0; i < SPHERES; i++)
        kept += ptr_sphere_material(&scene.spheres, i) == expected[i];
    CHECK_INT(kept, SPHERES);
    ptr_scene_free(&scene);
}

/* Each sphere of the finished scene is its centre less the camera's
 * position, worked out in double and then rounded, and its radius rounded:
 * the builder kept them all as they were given, floats or not. */
static void check_kept(const PtrScene *scene, const double (*given)[4], size_t count,
                       const double eye[3])
{
    CHECK_INT(scene->spheres.count, count);
    size_t kept = 0;
    for (size_t i = 0; i < count && i < scene->spheres.count; i++)
        kept += scene->spheres.cx[i] == (float)(given[i][0] - eye[0]) &&
                scene->spheres.cy[i] == (float)(given[i][1] - eye[1]) &&
                scene->spheres.cz[i] == (float)(given[i][2] - eye[2]) &&
                scene->spheres.radius[i] == (float)given[i][3];
    CHECK_INT(kept, count);
}

/* The camera test_float_until_not's spheres are seen from, 2^24 + 1 from
 * the origin, where floats are 2 apart and a value that went through a float
 * would show. */
static void finish_far(PtrSceneBuilder *b, const double eye[3])
{
    const double at[3] = { eye[0], eye[1], -3 }, up[3] = { 0, 1, 0 };
    const PtrCamera lens = { .vfov_deg = 40.0f, .focus_distance = 13.0f };
    ptr_builder_set_camera(b, eye, at, up, &lens);
    CHECK_INT(ptr_builder_finish(b, PTR_BUILD_DEFAULT, NULL), PTR_OK);
}

/* Spheres whose values are all floats are kept as floats; the first value
 * that is not one makes the builder keep doubles. Filled in a batch, once
 * the filling is over: the batch is filled in two blocks, of which the
 * second, which has the value, is filled again (ptr_builder_refill), the
 * first's floats kept through the widening. Added alone, at once: also
 * where the builder is full, so that widening and growing follow each
 * other. Every value comes out as it was given. */
static void test_float_until_not(void)
{
    enum { ALONE = 3, BATCH = 3, SPHERES = ALONE + BATCH + 1 };
    const double given[SPHERES][4] = {
        { 16777216.0, 0.5, -3.0, 0.25 },     /* floats: kept as floats */
        { 16777218.0, -0.75, -3.0, 1.5 },
        { 16777220.0, 1.0, -3.0, 0.125 },
        { 16777222.0, 2.0, -3.0, 0.5 },      /* the batch's first block: floats */
        { 16777217.0, 0.1, -3.0, 0.3 },      /* its second: values that are not */
        { 16777224.0, -2.0, -3.0, 0.75 },
        { 16777219.0, 3.0, -3.0, 0.2 },      /* alone, once wide */
    };
    const double eye[3] = { 16777217.0, 0, 10 };
    PtrScene scene;
    ptr_scene_init(&scene);
    const uint32_t material = add_material(&scene);
    PtrSceneBuilder b;
    ptr_builder_init(&b, &scene, NULL);
    for (size_t i = 0; i < ALONE; i++)
        CHECK_INT(ptr_builder_add_sphere(&b, given[i], given[i][3], material, NULL), PTR_OK);
    CHECK_INT(b.spheres.wide, 0);
    size_t first = 0;
    CHECK_INT(ptr_builder_add_spheres(&b, BATCH, 0, &first, NULL), PTR_OK);
    const size_t blocks[][2] = { { first, first + 1 }, { first + 1, first + BATCH } };
    int fills[2] = { 0, 0 };
    for (size_t k = 0; k < 2; k++) {
        int refill = 1;
        while (refill && fills[k] < 3) {
            for (size_t n = blocks[k][0]; n < blocks[k][1]; n++)
                ptr_builder_fill_sphere(&b, n, given[n], given[n][3], material, NULL);
            fills[k]++;
            CHECK_INT(ptr_builder_refill(&b, blocks[k][1], &refill, NULL), PTR_OK);
        }
        CHECK_INT(b.spheres.wide, (int)k);
    }
    CHECK_INT(fills[0], 1);
    CHECK_INT(fills[1], 2);
    CHECK_INT(ptr_builder_add_sphere(&b, given[SPHERES - 1], given[SPHERES - 1][3], material,
                                     NULL),
              PTR_OK);
    finish_far(&b, eye);
    check_kept(&scene, given, SPHERES, eye);
    ptr_scene_free(&scene);

    /* Alone into a full builder of floats. */
    const double alone[3][4] = { { 16777216.0, 0.5, -3.0, 0.25 },
                                 { 16777218.0, -0.75, -3.0, 1.5 },
                                 { 16777217.0, 0.1, -3.0, 0.3 } };
    ptr_scene_init(&scene);
    const uint32_t grey = add_material(&scene);
    ptr_builder_init(&b, &scene, NULL);
    CHECK_INT(ptr_builder_reserve(&b, 2, NULL), PTR_OK);
    for (size_t i = 0; i < 3; i++) {
        CHECK_INT(b.count == b.capacity, i == 2);
        CHECK_INT(ptr_builder_add_sphere(&b, alone[i], alone[i][3], grey, NULL), PTR_OK);
        CHECK_INT(b.spheres.wide, i == 2);
    }
    finish_far(&b, eye);
    check_kept(&scene, alone, 3, eye);
    ptr_scene_free(&scene);
}

/* Bit patterns for ptr_color_quantize: the ends of [0, 1] and the values
 * either side, zeros, infinities, NaNs and subnormals; every tie (k + 0.5
 * of 65535) and its neighbours; then xorshift's words as floats. */
static const float quantize_edges[] = { 0.0f, -0.0f, 1.0f, -1.0f, 0x1.fffffep-1f, 0x1.000002p0f,
                                        0x1p-149f, -0x1p-149f, 0x1p-126f, 1e30f, -1e30f,
                                        INFINITY, -INFINITY, NAN, -NAN };
enum {
    QUANTIZE_EDGES = sizeof quantize_edges / sizeof quantize_edges[0],
    QUANTIZE_TIES = 3 * 65535,
    QUANTIZE_INPUTS = QUANTIZE_EDGES + QUANTIZE_TIES + (1 << 20),
};

static float quantize_input(uint32_t i, uint32_t *state)
{
    if (i < QUANTIZE_EDGES)
        return quantize_edges[i];
    i -= QUANTIZE_EDGES;
    if (i < QUANTIZE_TIES) {
        const float tie = ((float)(i / 3) + 0.5f) / 65535.0f;
        return i % 3 == 0 ? tie : i % 3 == 1 ? nextafterf(tie, 0.0f) : nextafterf(tie, 2.0f);
    }
    *state ^= *state << 13;
    *state ^= *state >> 17;
    *state ^= *state << 5;
    float f;
    memcpy(&f, state, sizeof f);
    return f;
}

/* ptr_color_quantize, inline in SSE2, gives the scalar clamp and lrintf's
 * rounding (ptr_maxf, ptr_minf: NaN gives 0) for every channel, exact ties
 * among its inputs (each tie's float times 65535 is k + 0.5 exactly). */
static void test_color_quantize(void)
{
    uint32_t state = 0x9e3779b9u;
    size_t wrong = 0, ties = 0;
    for (uint32_t i = 0; i < QUANTIZE_INPUTS; i++) {
        const float c = quantize_input(i, &state);
        const float scaled = c * 65535.0f;
        ties += scaled - floorf(scaled) == 0.5f;
        for (int channel = 0; channel < 3; channel++) {
            float rgb[3] = { 0.25f, 0.5f, 0.75f };
            rgb[channel] = c;
            uint16_t out[3];
            ptr_color_quantize(v3(rgb[0], rgb[1], rgb[2]), out);
            for (int k = 0; k < 3; k++)
                wrong += out[k] != (uint16_t)lrintf(ptr_minf(ptr_maxf(rgb[k], 0.0f), 1.0f) *
                                                    65535.0f);
        }
    }
    CHECK(ties >= 65535);
    CHECK_INT(wrong, 0);
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_material_widths),
        TEST_CASE(test_float_until_not),
        TEST_CASE(test_color_quantize),
    };
    TEST_RUN(cases);
    return test_report();
}
