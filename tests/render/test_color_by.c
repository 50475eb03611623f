/* Colour by a quantity (scene/colormap.h): the mapped colour replaces the
 * base colour, and a render shows it in closed form. A diffuse sphere alone
 * under a uniform sky of radiance L: every path off a convex sphere's
 * outside leaves for the sky, so every sample of a pixel on the sphere is L
 * times its albedo, with no noise: the albedo being the map's colour, L
 * times map(value). */
#include <math.h>
#include <string.h>

#include "importer.h"
#include "render/render.h"
#include "scene/colormap.h"
#include "test.h"

enum { SIZE = 16 };

/* Entries of matplotlib's tables (matplotlib/_cm_listed.py, _cm.py), as
 * published: the generated tables must hold them. */
static const struct {
    const char *map;
    int index;
    float srgb[3];
} published[] = {
    { "viridis", 0, { 0.267004f, 0.004874f, 0.329415f } },
    { "viridis", 128, { 0.127568f, 0.566949f, 0.550556f } },
    { "viridis", 255, { 0.993248f, 0.906157f, 0.143936f } },
    { "coolwarm", 0, { 0.2298057f, 0.29871797f, 0.75368315f } },
    { "coolwarm", 255, { 0.70567316f, 0.01555616f, 0.15023281f } },
};

static double srgb_decode(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

/* The value whose colour is entry `index` with the range [0, 256). */
static double value_of(int index)
{
    return index + 0.5;
}

static void test_published_entries(void)
{
    for (size_t i = 0; i < sizeof published / sizeof published[0]; i++) {
        const PtrColormap *map = ptr_colormap_find(published[i].map);
        CHECK(map != NULL);
        PtrVec3 c = ptr_colormap_srgb(map, value_of(published[i].index), 0.0, 256.0);
        CHECK_FLOAT_EQ(c.x, published[i].srgb[0]);
        CHECK_FLOAT_EQ(c.y, published[i].srgb[1]);
        CHECK_FLOAT_EQ(c.z, published[i].srgb[2]);
    }
    CHECK(ptr_colormap_find("jet") == NULL);
    const char *names[] = { "viridis", "magma", "inferno", "plasma", "cividis", "coolwarm" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        CHECK(ptr_colormap_find(names[i]) != NULL);
}

/* matplotlib's bins: 256 equal ones, the top of the range in the last,
 * values beyond it clamped to the ends. */
static void test_bins_and_clamping(void)
{
    const PtrColormap *map = ptr_colormap_find("viridis");
    const float *first = map->srgb[0], *last = map->srgb[255];
    PtrVec3 c = ptr_colormap_srgb(map, -5.0, 10.0, 20.0);
    CHECK(c.x == first[0] && c.y == first[1] && c.z == first[2]);
    c = ptr_colormap_srgb(map, 20.0, 10.0, 20.0);
    CHECK(c.x == last[0] && c.y == last[1] && c.z == last[2]);
    c = ptr_colormap_srgb(map, 1e9, 10.0, 20.0);
    CHECK(c.x == last[0] && c.y == last[1] && c.z == last[2]);
    /* 10 + 10 * 100 / 256 starts bin 100; a hair below is still bin 99. */
    c = ptr_colormap_srgb(map, 10.0 + 1000.0 / 256.0, 10.0, 20.0);
    CHECK_FLOAT_EQ(c.x, map->srgb[100][0]);
    c = ptr_colormap_srgb(map, 10.0 + 999.9 / 256.0, 10.0, 20.0);
    CHECK_FLOAT_EQ(c.x, map->srgb[99][0]);
    /* An empty range: the first entry. */
    c = ptr_colormap_srgb(map, 3.0, 3.0, 3.0);
    CHECK_FLOAT_EQ(c.x, first[0]);
}

/* One sphere of `material` with a grey colour of its own and `value`, seen
 * from distance 5 through a 20 degree field of view under a sky of radiance
 * sky. */
static PtrScene valued_sphere(PtrMaterial material, float value, float sky)
{
    PtrScene s;
    uint32_t m;
    ptr_scene_init(&s);
    CHECK_INT(ptr_scene_add_material(&s, &material, &m, NULL), PTR_OK);
    CHECK_INT(ptr_scene_add_sphere(&s, v3(0, 0, 0), 1.0f, m, NULL), PTR_OK);
    CHECK_INT(ptr_scene_set_sphere_color(&s, 0, v3_splat(0.5f), NULL), PTR_OK);
    CHECK_INT(ptr_scene_set_sphere_value(&s, 0, value, NULL), PTR_OK);
    s.sky = (PtrSky){ .kind = PTR_SKY_CONSTANT, .radiance = v3_splat(sky) };
    s.camera = (PtrCamera){ .lookfrom = v3(0, 0, 5), .lookat = v3(0, 0, 0),
                            .up = v3(0, 1, 0), .vfov_deg = 20.0f, .focus_distance = 5.0f };
    return s;
}

/* The central 8x8 pixels (on the sphere's disc) against expected: the
 * colour stored in 1/65535 steps, the sum of 16 equal samples over 16. */
static void check_centre(const PtrScene *s, const double expected[3], const char *what)
{
    PtrIsectTable isect;
    ptr_isect_init(&isect, PTR_KERNEL_AUTO, ptr_cpu_level(), s->spheres.count, NULL);
    const PtrAccel accel = ptr_accel_brute(&isect, s);
    const PtrRenderSettings settings = { .width = SIZE, .height = SIZE, .samples = 16,
                                         .seed = 1, .max_depth = 50, .threads = 2 };
    float *rgb = malloc(SIZE * SIZE * 3 * sizeof *rgb);
    PtrError err = { 0 };
    CHECK_INT(ptr_render(s, &accel, &settings, rgb, NULL, &err), PTR_OK);
    int wrong = 0;
    for (int y = 4; y < 12; y++)
        for (int x = 4; x < 12; x++)
            for (int c = 0; c < 3; c++) {
                float got = rgb[3 * (y * SIZE + x) + c];
                if (fabs(got - expected[c]) > 1.0 / 65535 + 1e-6 * expected[c]) {
                    if (!wrong)
                        fprintf(stderr, "%s: pixel (%d, %d) channel %d is %.9g, not %.9g\n",
                                what, x, y, c, got, expected[c]);
                    wrong++;
                }
            }
    CHECK_INT(wrong, 0);
    free(rgb);
}

/* A diffuse sphere of albedo 0.3 and colour 0.5, whose value is mapped:
 * under a sky of 0.8 it shows 0.8 x map(value), the map's colour in place
 * of 0.3 x 0.5, and so for every published entry. */
static void test_furnace_shows_the_map(void)
{
    const PtrMaterial grey = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.3f) };
    for (size_t i = 0; i < sizeof published / sizeof published[0]; i++) {
        PtrScene s = valued_sphere(grey, (float)value_of(published[i].index), 0.8f);
        CHECK_INT(ptr_scene_color_by_value(&s, ptr_colormap_find(published[i].map), 0.0, 256.0,
                                           NULL),
                  PTR_OK);
        double expected[3];
        for (int c = 0; c < 3; c++)
            expected[c] = 0.8 * srgb_decode(published[i].srgb[c]);
        check_centre(&s, expected, published[i].map);
        ptr_scene_free(&s);
    }
}

/* --color-range: a value beyond it shows the end's colour. */
static void test_furnace_clamps(void)
{
    const PtrMaterial grey = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.3f) };
    PtrScene s = valued_sphere(grey, 500.0f, 1.0f);
    CHECK_INT(ptr_scene_color_by_value(&s, ptr_colormap_find("viridis"), 0.0, 256.0, NULL), PTR_OK);
    double expected[3];
    for (int c = 0; c < 3; c++)
        expected[c] = srgb_decode(published[2].srgb[c]); /* viridis[255] */
    check_centre(&s, expected, "above the range");
    ptr_scene_free(&s);
}

/* Spheres without a value keep material and colour; those with one get a
 * white copy of theirs, its other properties kept, shared among them. */
static void test_materials(void)
{
    PtrScene s;
    ptr_scene_init(&s);
    const PtrMaterial gold = { .kind = PTR_MATERIAL_METAL, .albedo = v3(0.9f, 0.7f, 0.2f),
                               .fuzz = 0.25f, .emission = v3_splat(0.5f) };
    uint32_t m;
    CHECK_INT(ptr_scene_add_material(&s, &gold, &m, NULL), PTR_OK);
    for (int i = 0; i < 3; i++)
        CHECK_INT(ptr_scene_add_sphere(&s, v3((float)i, 0, 0), 0.4f, m, NULL), PTR_OK);
    CHECK_INT(ptr_scene_set_sphere_value(&s, 0, 1.0f, NULL), PTR_OK);
    CHECK_INT(ptr_scene_set_sphere_value(&s, 2, 2.0f, NULL), PTR_OK);
    CHECK(isnan(s.spheres.value[1]));
    CHECK_INT(ptr_scene_color_by_value(&s, ptr_colormap_find("magma"), 1.0, 2.0, NULL), PTR_OK);
    CHECK_INT((int)s.material_count, 2);
    CHECK_INT((int)ptr_sphere_material(&s.spheres, 1), 0);
    CHECK_INT((int)ptr_sphere_material(&s.spheres, 0), 1);
    CHECK_INT((int)ptr_sphere_material(&s.spheres, 2), 1);
    const PtrMaterial *white = &s.materials[1];
    CHECK(white->kind == PTR_MATERIAL_METAL && white->fuzz == 0.25f);
    CHECK(white->albedo.x == 1.0f && white->albedo.y == 1.0f && white->albedo.z == 1.0f);
    CHECK(white->emission.x == 0.5f);
    PtrVec3 unmapped = ptr_sphere_color(&s.spheres, 1);
    CHECK(unmapped.x == 1.0f && unmapped.y == 1.0f && unmapped.z == 1.0f);
    PtrVec3 top = ptr_sphere_color(&s.spheres, 2);
    const float *magma_top = ptr_colormap_find("magma")->srgb[255];
    CHECK_NEAR(top.x, srgb_decode(magma_top[0]), 1.0 / 65535);
    ptr_scene_free(&s);
}

/* The range mapped: the values' own without one given (spheres without a
 * value left out), viridis without a map; a range given is the one mapped.
 * And which ranges --color-range takes. */
static void test_range_mapped(void)
{
    for (int given = 0; given < 2; given++) {
        PtrScene s;
        ptr_scene_init(&s);
        const PtrMaterial grey = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.5f) };
        uint32_t m;
        CHECK_INT(ptr_scene_add_material(&s, &grey, &m, NULL), PTR_OK);
        for (int i = 0; i < 3; i++)
            CHECK_INT(ptr_scene_add_sphere(&s, v3((float)i, 0, 0), 0.4f, m, NULL), PTR_OK);
        CHECK_INT(ptr_scene_set_sphere_value(&s, 0, 4.0f, NULL), PTR_OK);
        CHECK_INT(ptr_scene_set_sphere_value(&s, 2, -2.0f, NULL), PTR_OK);
        const double range[2] = { 0.0, 8.0 };
        PtrColorMapping mapping;
        CHECK_INT(ptr_scene_color_by_range(&s, given ? ptr_colormap_find("magma") : NULL,
                                           given ? range : NULL, &mapping, NULL),
                  PTR_OK);
        CHECK(!strcmp(mapping.map->name, given ? "magma" : "viridis"));
        CHECK_INT((int)mapping.valued, 2);
        CHECK(mapping.lo == -2.0 && mapping.hi == 4.0);
        CHECK(given ? mapping.from == 0.0 && mapping.to == 8.0
                    : mapping.from == -2.0 && mapping.to == 4.0);
        /* The highest value, 4: the top of its own range, the middle of 0 to 8. */
        const PtrVec3 high = ptr_sphere_color(&s.spheres, 0);
        const PtrVec3 expected = ptr_colormap_linear(mapping.map, given ? 0.5 : 1.0, 0.0, 1.0);
        CHECK_NEAR(high.x, expected.x, 1.0 / 65535); /* colours are kept in 16 bits */
        CHECK_NEAR(high.y, expected.y, 1.0 / 65535);
        CHECK_NEAR(high.z, expected.z, 1.0 / 65535);
        ptr_scene_free(&s);
    }
    const double ok[2] = { -1.0, 1.0 }, empty[2] = { 1.0, 1.0 }, reversed[2] = { 2.0, 1.0 },
                 infinite[2] = { 0.0, INFINITY }, nan[2] = { NAN, 1.0 };
    CHECK(ptr_color_range_ok(ok));
    CHECK(!ptr_color_range_ok(empty) && !ptr_color_range_ok(reversed));
    CHECK(!ptr_color_range_ok(infinite) && !ptr_color_range_ok(nan));
}

/* The values take memory only when asked for: a file with instance
 * attributes imports without a value array unless --color-by names one. */
static void test_values_only_when_asked(void)
{
    const char *path = PTR_SOURCE_DIR "/tests/fixtures/instancing/instances.gltf";
    for (int asked = 0; asked < 2; asked++) {
        PtrImportOptions options = { .value_attribute = asked ? "color_0" : NULL };
        PtrScene s;
        PtrStrings warnings = { 0 };
        PtrError err = { 0 };
        CHECK_INT(ptr_import_scene(path, &options, &s, &warnings, &err), PTR_OK);
        CHECK(s.spheres.count > 0);
        CHECK(asked ? s.spheres.value != NULL : s.spheres.value == NULL);
        ptr_strings_free(&warnings);
        ptr_scene_free(&s);
    }
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_values_only_when_asked),
        TEST_CASE(test_published_entries),
        TEST_CASE(test_bins_and_clamping),
        TEST_CASE(test_furnace_shows_the_map),
        TEST_CASE(test_furnace_clamps),
        TEST_CASE(test_materials),
        TEST_CASE(test_range_mapped),
    };
    TEST_RUN(cases);
    return test_report();
}
