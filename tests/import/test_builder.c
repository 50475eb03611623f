/* What every importer builds with (importers/builder.h): each sphere keeps
 * its material through the builder's entries, which are as wide as the
 * scene's and widen with it, whether a sphere is added alone or a batch is
 * added and filled. */
#include <stdint.h>

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

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_material_widths),
    };
    TEST_RUN(cases);
    return test_report();
}
