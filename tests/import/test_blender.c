/* Scenes exported by Blender 3.4 itself (scripts/blender_fixtures.py sets the
 * values checked here): glTF (.gltf + .bin, .glb) and OBJ (with and without
 * its PBR extensions) import as set in Blender, and the glTF and OBJ exports
 * render to the same image. */
#include "image/image.h"
#include "importer.h"
#include "test.h"
#include "test_files.h"

#define BLENDER(name) PTR_SOURCE_DIR "/tests/fixtures/blender/" name

typedef struct Expected {
    const char *what;
    double centre[3], radius;
    PtrMaterialKind kind;
    float albedo[3], fuzz, ior, emission[3];
} Expected;

static const Expected expected[] = {
    { "ground", { 0, -100, 0 }, 100, PTR_MATERIAL_DIFFUSE, { 0.5f, 0.5f, 0.5f }, 0, 0, { 0, 0, 0 } },
    { "clay", { 0, 1, 0 }, 1, PTR_MATERIAL_DIFFUSE, { 0.8f, 0.2f, 0.1f }, 0, 0, { 0, 0, 0 } },
    { "brass", { 2.5, 1, 0 }, 1, PTR_MATERIAL_METAL, { 0.9f, 0.8f, 0.6f }, 0.25f, 0, { 0, 0, 0 } },
    { "glass", { -2.5, 1, 0 }, 1, PTR_MATERIAL_DIELECTRIC, { 1, 1, 1 }, 0, 1.45f, { 0, 0, 0 } },
    { "lamp", { 0, 3.5, -2 }, 0.5, PTR_MATERIAL_DIFFUSE, { 0.1f, 0.1f, 0.1f }, 0, 0, { 4, 3.6f, 3.2f } },
};
enum { SPHERES = sizeof expected / sizeof expected[0] };

/* The sphere at that centre, or -1 (exporters choose their own order). */
static long find(const PtrScene *s, const double c[3])
{
    for (size_t i = 0; i < s->spheres.count; i++)
        if (fabs(s->origin[0] + s->spheres.cx[i] - c[0]) < 1e-3 &&
            fabs(s->origin[1] + s->spheres.cy[i] - c[1]) < 1e-3 &&
            fabs(s->origin[2] + s->spheres.cz[i] - c[2]) < 1e-3)
            return (long)i;
    return -1;
}

/* pbr: 0 for the OBJ written without its PBR extensions, where Blender's
 * exporter drops transmission (the glass comes out white diffuse). */
static void check_file(const char *path, int pbr, int has_camera)
{
    PtrScene s;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(path, NULL, &s, &w, &err), PTR_OK);
    if (err.code)
        fprintf(stderr, "%s\n", err.message);
    CHECK_INT(s.spheres.count, SPHERES);
    CHECK_INT(w.count, 0);
    for (int e = 0; e < SPHERES; e++) {
        const Expected *x = &expected[e];
        long i = find(&s, x->centre);
        if (i < 0) {
            TEST_FAIL_("%s: no sphere for the %s", path, x->what);
            continue;
        }
        const PtrMaterial *m = &s.materials[ptr_sphere_material(&s.spheres, i)];
        CHECK_NEAR(s.spheres.radius[i], x->radius, 1e-4 * x->radius);
        PtrMaterialKind kind = !pbr && x->kind == PTR_MATERIAL_DIELECTRIC ? PTR_MATERIAL_DIFFUSE : x->kind;
        CHECK_INT(m->kind, kind);
        if (kind != PTR_MATERIAL_DIELECTRIC) {
            CHECK_NEAR(m->albedo.x, x->albedo[0], 1e-6);
            CHECK_NEAR(m->albedo.y, x->albedo[1], 1e-6);
            CHECK_NEAR(m->albedo.z, x->albedo[2], 1e-6);
        }
        if (kind == PTR_MATERIAL_METAL)
            CHECK_NEAR(m->fuzz, x->fuzz, 1e-6); /* Pr, or from Ns without PBR */
        if (kind == PTR_MATERIAL_DIELECTRIC) {
            CHECK_NEAR(m->ior, x->ior, 1e-6);
            CHECK_NEAR(m->albedo.x, 1.0, 1e-6);
        }
        CHECK_NEAR(m->emission.x, x->emission[0], 1e-5);
        CHECK_NEAR(m->emission.y, x->emission[1], 1e-5);
        CHECK_NEAR(m->emission.z, x->emission[2], 1e-5);
    }
    if (has_camera) { /* Blender's camera: from (0, 2, 10) at (0, 1, 0), 40 degrees, 320x240 */
        CHECK_NEAR(s.origin[1], 2.0, 1e-5);
        CHECK_NEAR(s.origin[2], 10.0, 1e-5);
        PtrVec3 dir = v3_normalize(v3_sub(s.camera.lookat, s.camera.lookfrom));
        CHECK_NEAR(dir.y, -1.0 / sqrt(101.0), 1e-5);
        CHECK_NEAR(dir.z, -10.0 / sqrt(101.0), 1e-5);
        CHECK_NEAR(s.camera.vfov_deg, 40.0, 1e-3);
        CHECK_NEAR(s.camera.aspect, 320.0 / 240.0, 1e-6);
    }
    ptr_strings_free(&w);
    ptr_scene_free(&s);
}

/* The glTF and OBJ exports through one camera: block means agree. The
 * geometry differs by the exporters' rounding only, so the same seed gives
 * nearly the same paths; 0.02 is several times the noise of an 8x8 block
 * mean at 64 samples (about 0.004). */
static void test_same_image(void)
{
    const char *cam[] = { "--lookfrom", "0,2,10", "--lookat", "0,1,0", "--vfov", "40" };
    CHECK_INT(test_ptr(BLENDER("spheres.gltf"), "-o", test_path("gltf.exr"), "--width", "64",
                       "--height", "48", "--samples", "64", cam[0], cam[1], cam[2], cam[3], cam[4],
                       cam[5], "--quiet", NULL), 0);
    CHECK_INT(test_ptr(BLENDER("spheres.obj"), "-o", test_path("obj.exr"), "--width", "64",
                       "--height", "48", "--samples", "64", cam[0], cam[1], cam[2], cam[3], cam[4],
                       cam[5], "--quiet", NULL), 0);
    PtrError err;
    PtrImage *a = NULL, *b = NULL;
    CHECK_INT(test_image_read(test_path("gltf.exr"), &a, &err), PTR_OK);
    CHECK_INT(test_image_read(test_path("obj.exr"), &b, &err), PTR_OK);
    if (!a || !b)
        return;
    double worst = 0, mean = 0;
    for (int by = 0; by < 6; by++)
        for (int bx = 0; bx < 8; bx++)
            for (int c = 0; c < 3; c++) {
                double sa = 0, sb = 0;
                for (int y = 8 * by; y < 8 * by + 8; y++)
                    for (int x = 8 * bx; x < 8 * bx + 8; x++) {
                        sa += ptr_image_pixels(a)[3 * (y * 64 + x) + c];
                        sb += ptr_image_pixels(b)[3 * (y * 64 + x) + c];
                    }
                worst = fmax(worst, fabs(sa - sb) / 64);
                mean += sa / (64 * 48 * 3);
            }
    printf("glTF vs OBJ export of one Blender scene: worst 8x8 block difference %.4f (image mean %.3f)\n",
           worst, mean);
    CHECK(worst < 0.02);
    CHECK(mean > 0.1); /* not two black images */
    ptr_image_free(a);
    ptr_image_free(b);
}

static void test_gltf_file(void)
{
    check_file(BLENDER("spheres.gltf"), 1, 1);
}

static void test_glb_file(void)
{
    check_file(BLENDER("spheres.glb"), 1, 1);
}

static void test_obj_file(void)
{
    check_file(BLENDER("spheres.obj"), 1, 0);
}

static void test_obj_file_without_pbr(void)
{
    check_file(BLENDER("spheres_nopbr.obj"), 0, 0);
}

int main(void)
{
    if (!test_dir_create("test-blender"))
        return 1;
    const TestCase cases[] = {
        TEST_CASE(test_gltf_file),
        TEST_CASE(test_glb_file),
        TEST_CASE(test_obj_file),
        TEST_CASE(test_obj_file_without_pbr),
        TEST_CASE(test_same_image),
    };
    TEST_RUN(cases);
    test_dir_remove();
    return test_report();
}
