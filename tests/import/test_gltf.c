/* The glTF importer against fixtures whose spheres, materials and camera are
 * worked out by hand from docs/scenes.md, and its transforms' shortcut held
 * to the arithmetic it skips. */
#include <float.h>

#include "gltf/gltf_transforms.h"
#include "importer.h"
#include "test.h"
#include "test_scene.h"

#define FIXTURE(name) PTR_SOURCE_DIR "/tests/fixtures/" name


static const PtrMaterial *material_of(const PtrScene *s, size_t sphere)
{
    return &s->materials[ptr_sphere_material(&s->spheres, sphere)];
}

static int has_warning(const PtrStrings *w, const char *needle)
{
    int n = 0;
    for (size_t i = 0; i < w->count; i++)
        n += strstr(w->lines[i], needle) != NULL;
    return n;
}

static void test_hierarchy(void)
{
    PtrScene s;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(FIXTURE("hierarchy.gltf"), NULL, &s, &w, &err), PTR_OK);

    CHECK_INT(s.spheres.count, 7);
    check_sphere(&s, 0, 12, 0, 0, 2, 1e-5);     /* parent TRS composed with the child's */
    check_sphere(&s, 1, 12, 4, -2, 4, 1e-5);    /* rotated off-centre bounds */
    check_sphere(&s, 2, 0, 5, 0, 0.5f, 1e-5);   /* matrix */
    check_sphere(&s, 3, 0, 0, -3, 0.25f, 1e-5); /* extras.radius overrides the scale */
    check_sphere(&s, 4, 0, 0, 0, 2, 1e-5);      /* non-uniform: the largest axis */
    check_sphere(&s, 5, 0, -100, 0, 1, 1e-5);
    check_sphere(&s, 6, 3, 3, 3, 1, 1e-5);

    CHECK_INT(s.material_count, 5); /* Red is shared by spheres 0, 3 and 4 */
    CHECK_INT(ptr_sphere_material(&s.spheres, 0), ptr_sphere_material(&s.spheres, 3));
    const PtrMaterial *red = material_of(&s, 0), *gold = material_of(&s, 1),
                      *grey = material_of(&s, 2), *lamp = material_of(&s, 5),
                      *glass = material_of(&s, 6);
    CHECK_INT(red->kind, PTR_MATERIAL_DIFFUSE);
    CHECK_FLOAT_EQ(red->albedo.y, 0.1f);
    CHECK_INT(gold->kind, PTR_MATERIAL_METAL);
    CHECK_FLOAT_EQ(gold->fuzz, 0.25f);
    CHECK_FLOAT_EQ(gold->albedo.z, 0.3f);
    CHECK_INT(grey->kind, PTR_MATERIAL_DIFFUSE); /* no material: Blender's grey */
    CHECK_FLOAT_EQ(grey->albedo.x, 0.8f);
    CHECK_INT(lamp->kind, PTR_MATERIAL_DIFFUSE);
    CHECK_FLOAT_EQ(lamp->emission.x, 4.0f);
    CHECK_FLOAT_EQ(lamp->emission.y, 2.0f);
    CHECK_FLOAT_EQ(lamp->emission.z, 1.0f);
    CHECK_INT(glass->kind, PTR_MATERIAL_DIELECTRIC); /* transmission beats metallic */
    CHECK_FLOAT_EQ(glass->ior, 2.0f);                /* an integer in the JSON */
    CHECK_FLOAT_EQ(glass->albedo.x, 0.9f);

    CHECK_NEAR(s.origin[1], 1.0, 1e-12); /* the camera is the scene's origin */
    CHECK_NEAR(s.origin[2], 10.0, 1e-12);
    CHECK_FLOAT_EQ(s.camera.lookfrom.z, 0.0f);
    CHECK_NEAR(s.camera.lookat.z, -8.0, 1e-5);
    CHECK_NEAR(s.camera.up.y, 1.0, 1e-6);
    CHECK_NEAR(s.camera.vfov_deg, 0.5 * 180 / 3.14159265358979, 1e-4);
    CHECK_FLOAT_EQ(s.camera.aperture, 0.1f);
    CHECK_FLOAT_EQ(s.camera.focus_distance, 8.0f);
    CHECK_FLOAT_EQ(s.camera.aspect, 1.5f);

    CHECK_INT(s.sky.kind, PTR_SKY_CONSTANT);
    CHECK_FLOAT_EQ(s.sky.radiance.z, 0.4f);
    CHECK_INT(s.width, 320);
    CHECK_INT(s.height, 240);

    CHECK_INT(w.count, 2);
    CHECK_INT(has_warning(&w, "'Squashed' has a non-uniform scale"), 1);
    CHECK_INT(has_warning(&w, "textures are ignored"), 1);
    ptr_strings_free(&w);
    ptr_scene_free(&s);

    /* --camera picks another camera by camera or node name. */
    PtrImportOptions by_name = { .camera_name = "Other" };
    CHECK_INT(ptr_import_scene(FIXTURE("hierarchy.gltf"), &by_name, &s, &w, &err), PTR_OK);
    CHECK_NEAR(s.origin[0], 5.0, 1e-12);
    CHECK_NEAR(s.camera.lookat.x, -1.0, 1e-6); /* turned to look down -X */
    CHECK_NEAR(s.camera.lookat.z, 0.0, 1e-6);
    CHECK_NEAR(s.camera.vfov_deg, 180 / 3.14159265358979, 1e-4);
    ptr_strings_free(&w);
    ptr_scene_free(&s);

    by_name.camera_name = "Nowhere";
    CHECK_INT(ptr_import_scene(FIXTURE("hierarchy.gltf"), &by_name, &s, &w, &err),
              PTR_ERR_SCENE_INVALID);
    CHECK(strstr(err.message, "Nowhere") != NULL);
    ptr_strings_free(&w);
}

/* The binary container holds the same scene as the text one. */
static void test_glb_matches_gltf(void)
{
    PtrScene a, b;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(PTR_SOURCE_DIR "/scenes/seed.gltf", NULL, &a, &w, &err), PTR_OK);
    CHECK_INT(ptr_import_scene(FIXTURE("seed.glb"), NULL, &b, &w, &err), PTR_OK);
    CHECK_INT(w.count, 0);
    CHECK_INT(a.spheres.count, 4);
    CHECK_INT(b.spheres.count, a.spheres.count);
    size_t n = a.spheres.count * sizeof(float);
    CHECK(!memcmp(a.spheres.cx, b.spheres.cx, n) && !memcmp(a.spheres.cy, b.spheres.cy, n) &&
          !memcmp(a.spheres.cz, b.spheres.cz, n) && !memcmp(a.spheres.radius, b.spheres.radius, n));
    CHECK_INT(b.material_count, a.material_count);
    CHECK(!memcmp(a.materials, b.materials, a.material_count * sizeof *a.materials));
    CHECK(!memcmp(&a.camera, &b.camera, sizeof a.camera));
    ptr_scene_free(&a);
    ptr_scene_free(&b);
}

/* The tangents of the angles at which a sphere's silhouette leaves the
 * view along one image axis, seen from eye looking down -Z: the planes
 * through the eye that touch the sphere and hold the other axis. */
static void silhouette_tangents(double offset, double depth, double r, double *lo, double *hi)
{
    double centre = atan2(offset, depth), spread = asin(r / hypot(offset, depth));
    *lo = tan(centre - spread);
    *hi = tan(centre + spread);
}

/* No camera in the file: one that looks down -Z and fits the spheres'
 * projection to 95% of the image along the axis that binds. The fixture's
 * spheres: radius 1 at (-3, 0, 0) and radius 2 at (3, 2, 1); no resolution,
 * so the image is 16:9. */
static void test_automatic_camera(void)
{
    PtrScene s;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(FIXTURE("no_camera.gltf"), NULL, &s, &w, &err), PTR_OK);
    ptr_strings_free(&w);
    const double spheres[2][4] = { { -3, 0, 0, 1 }, { 3, 2, 1, 2 } };
    double tan_v = tan(20.0 * 3.14159265358979 / 180.0), aspect = 16.0 / 9.0;
    double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
    for (int i = 0; i < 2; i++) {
        const double *c = spheres[i];
        double depth = s.origin[2] - c[2], lo, hi;
        silhouette_tangents(c[0] - s.origin[0], depth, c[3], &lo, &hi);
        x_lo = fmin(x_lo, lo), x_hi = fmax(x_hi, hi);
        silhouette_tangents(c[1] - s.origin[1], depth, c[3], &lo, &hi);
        y_lo = fmin(y_lo, lo), y_hi = fmax(y_hi, hi);
    }
    /* The spheres span 18 units across and 7 up: the width binds, the
     * silhouettes touching 95% of the half-width on both sides; the height
     * holds them inside. */
    CHECK_NEAR(x_hi, 0.95 * tan_v * aspect, 1e-9);
    CHECK_NEAR(x_lo, -0.95 * tan_v * aspect, 1e-9);
    CHECK(y_hi <= 0.95 * tan_v && y_lo >= -0.95 * tan_v);
    CHECK_FLOAT_EQ(s.camera.lookfrom.x, 0.0f); /* coordinates are camera-relative */
    CHECK_FLOAT_EQ(s.camera.lookat.x, 0.0f);
    CHECK_FLOAT_EQ(s.camera.lookat.y, 0.0f);
    CHECK(s.camera.lookat.z < 0.0f);
    CHECK_FLOAT_EQ(s.camera.vfov_deg, 40.0f);
    CHECK_FLOAT_EQ(s.camera.aspect, (float)aspect);
    CHECK_NEAR(s.spheres.cx[0] + s.origin[0], -3.0, 1e-6);
    CHECK_NEAR(s.spheres.cz[1] + s.origin[2], 1.0, 1e-5);
    ptr_scene_free(&s);

    /* Orthographic: the box [-4, 5] x [-1, 4] x [-1, 3], centred; 9 units
     * wide at 16:9 need a view 5.0625 high, more than the box's 5, so again
     * the width binds: half-height 5.0625 / 2 / 0.95. */
    PtrImportOptions ortho = { .auto_projection = PTR_PROJECTION_ORTHOGRAPHIC };
    CHECK_INT(ptr_import_scene(FIXTURE("no_camera.gltf"), &ortho, &s, &w, &err), PTR_OK);
    ptr_strings_free(&w);
    CHECK_INT(s.camera.projection, PTR_PROJECTION_ORTHOGRAPHIC);
    CHECK_NEAR(s.camera.ymag, 5.0625 / 2 / 0.95, 1e-6);
    CHECK_NEAR(s.origin[0], 0.5, 1e-12);
    CHECK_NEAR(s.origin[1], 1.5, 1e-12);
    CHECK(s.origin[2] > 3.0); /* in front of every sphere */
    ptr_scene_free(&s);

    /* An aspect from the command line (both --width and --height): 1:2 makes
     * the width bind harder, the half-height 9 * 2 / 2 / 0.95. */
    ortho.auto_aspect = 0.5;
    CHECK_INT(ptr_import_scene(FIXTURE("no_camera.gltf"), &ortho, &s, &w, &err), PTR_OK);
    ptr_strings_free(&w);
    CHECK_NEAR(s.camera.ymag, 9.0 / 0.95, 1e-5);
    ptr_scene_free(&s);
}

/* --turntable: the camera turned about the vertical axis through the centre
 * of the spheres' box, (0.5, 1), counter-clockwise seen from above. */
static void test_orbit(void)
{
    PtrScene plain, turned;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    PtrImportOptions quarter = { .orbit_degrees = 90 };
    CHECK_INT(ptr_import_scene(FIXTURE("no_camera.gltf"), NULL, &plain, &w, &err), PTR_OK);
    CHECK_INT(ptr_import_scene(FIXTURE("no_camera.gltf"), &quarter, &turned, &w, &err), PTR_OK);
    ptr_strings_free(&w);
    /* A quarter turn about +Y takes an eye at (0.5 + dx, y, 1 + dz) to
     * (0.5 + dz, y, 1 - dx). */
    double dx = plain.origin[0] - 0.5, dz = plain.origin[2] - 1.0;
    CHECK_NEAR(turned.origin[0], 0.5 + dz, 1e-9);
    CHECK_NEAR(turned.origin[1], plain.origin[1], 1e-12);
    CHECK_NEAR(turned.origin[2], 1.0 - dx, 1e-9);
    /* Looking down -Z, it now looks down -X. */
    CHECK_NEAR(turned.camera.lookat.x, plain.camera.lookat.z, 1e-5);
    CHECK_NEAR(turned.camera.lookat.z, 0.0, 1e-5);
    ptr_scene_free(&plain);
    ptr_scene_free(&turned);
}

static void check_bad(const char *path, PtrResult expected, const char *needle)
{
    PtrScene s;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    PtrResult r = ptr_import_scene(path, NULL, &s, &w, &err);
    CHECK_INT(r, expected);
    if (r != expected)
        fprintf(stderr, "  for %s: %s\n", path, err.message);
    /* One line that names the file first, then the problem. */
    CHECK(!strncmp(err.message, path, strlen(path)));
    CHECK(strchr(err.message, '\n') == NULL);
    if (needle && !strstr(err.message, needle))
        TEST_FAIL_("'%s' not in \"%s\"", needle, err.message);
    CHECK_INT(s.spheres.count, 0);
    ptr_strings_free(&w);
    ptr_scene_free(&s);
}

static void test_bad_input(void)
{
    check_bad(FIXTURE("does-not-exist.gltf"), PTR_ERR_SCENE_UNREADABLE, "No such file");
    check_bad(FIXTURE("bad"), PTR_ERR_SCENE_UNREADABLE, "directory");
    check_bad(FIXTURE("bad/truncated.gltf"), PTR_ERR_SCENE_INVALID, NULL);
    check_bad(FIXTURE("bad/empty.gltf"), PTR_ERR_SCENE_INVALID, NULL);
    check_bad(FIXTURE("bad/garbage.glb"), PTR_ERR_SCENE_INVALID, NULL);
    check_bad(FIXTURE("bad/bad_mesh_index.gltf"), PTR_ERR_SCENE_INVALID, "mesh 5");
    check_bad(FIXTURE("bad/cycle.gltf"), PTR_ERR_SCENE_INVALID, "cycle");
    check_bad(FIXTURE("bad/zero_scale.gltf"), PTR_ERR_SCENE_INVALID, "'Flat'");
    check_bad(FIXTURE("bad/no_bounds.gltf"), PTR_ERR_SCENE_INVALID, "bounds");
    check_bad(FIXTURE("bad/bad_sky.gltf"), PTR_ERR_SCENE_INVALID, "sky");
    check_bad(PTR_SOURCE_DIR "/CMakeLists.txt", PTR_ERR_SCENE_INVALID, "unknown scene format");
    /* Compressed files: what is wrong, naming the extension; one that requires
     * an extension ptr lacks says so first, though tinygltf cannot load it. */
    check_bad(FIXTURE("hostile/meshopt_requires_unknown.glb"), PTR_ERR_SCENE_INVALID,
              "requires the glTF extension KHR_texture_basisu");
    check_bad(FIXTURE("hostile/meshopt_stream_truncated.glb"), PTR_ERR_SCENE_INVALID,
              "EXT_meshopt_compression: buffer view 2 has a compressed stream");
    check_bad(FIXTURE("hostile/meshopt_decoded_too_large.glb"), PTR_ERR_SCENE_INVALID,
              "EXT_meshopt_compression: buffer view 2 decodes to 15424 bytes");
}

/* An orthographic camera: its half-height, near plane and aspect ratio
 * (xmag / ymag); warnings for its aperture and for the sphere beyond zfar,
 * which ptr does not clip. */
static void test_orthographic_camera(void)
{
    PtrScene s;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(FIXTURE("orthographic.gltf"), NULL, &s, &w, &err), PTR_OK);
    CHECK_INT(s.camera.projection, PTR_PROJECTION_ORTHOGRAPHIC);
    CHECK_FLOAT_EQ(s.camera.ymag, 2.0f);
    CHECK_FLOAT_EQ(s.camera.znear, 1.0f);
    CHECK_FLOAT_EQ(s.camera.aspect, 1.5f);
    CHECK_NEAR(s.origin[0], 1.0, 1e-12);
    CHECK_NEAR(s.origin[2], 10.0, 1e-12);
    CHECK_NEAR(s.camera.lookat.z, -1.0, 1e-6);
    CHECK_INT(w.count, 2);
    CHECK_INT(has_warning(&w, "camera 'Ortho' is orthographic, which has no depth of field"), 1);
    CHECK_INT(has_warning(&w, "camera 'Ortho': ptr does not clip at zfar (20); 1 sphere"), 1);
    ptr_strings_free(&w);
    ptr_scene_free(&s);

    /* The command line's camera replaces it, and no warning is about the
     * file's camera. */
    const PtrCameraSpec spec = { .lookfrom = { 0, 0, 5 }, .lookat = { 0, 0, 0 },
                                 .up = { 0, 1, 0 }, .ortho_height = 3 };
    PtrImportOptions options = { .camera = &spec };
    CHECK_INT(ptr_import_scene(FIXTURE("orthographic.gltf"), &options, &s, &w, &err), PTR_OK);
    CHECK_INT(s.camera.projection, PTR_PROJECTION_ORTHOGRAPHIC);
    CHECK_FLOAT_EQ(s.camera.ymag, 1.5f);
    CHECK_FLOAT_EQ(s.camera.znear, 0.0f);
    CHECK_INT(w.count, 0);
    ptr_strings_free(&w);
    ptr_scene_free(&s);
}

/* The product with an identity, without its products, is the product's
 * bits: on matrices of zeros of both signs, subnormals, the largest finite
 * numbers and random ones, after an identity with +0 and with -0 off its
 * diagonal (both count as the identity). A version that returned b itself
 * would keep the -0 entries the product makes +0: counted, so that the case
 * cannot pass without any. */
static void test_identity_product(void)
{
    static const double special[] = { 0.0, -0.0, 1.0, -1.0, 5e-324, -5e-324, DBL_MAX,
                                      -DBL_MAX, 1e-300, -1e300, 0.1, -3.5 };
    enum { N = sizeof special / sizeof special[0] };
    const Mat4 identity = { { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 } };
    const Mat4 signed_identity = { { 1, -0.0, 0, -0.0, 0, 1, -0.0, 0, -0.0, 0, 1, -0.0, 0, -0.0,
                                     -0.0, 1 } };
    CHECK(gltf_mat4_is_identity(&identity));
    CHECK(gltf_mat4_is_identity(&signed_identity));
    PtrRng rng = ptr_rng_for_sample(36, 0, 0);
    int negative_zeros = 0;
    for (int trial = 0; trial < 10000; trial++) {
        Mat4 b;
        for (int k = 0; k < 16; k++) {
            const uint64_t r = ptr_rng_next(&rng);
            b.m[k] = r % 2 ? special[(r >> 1) % N] : ((double)(r >> 11) * 0x1p-53 - 0.5) * 1e3;
            negative_zeros += b.m[k] == 0.0 && signbit(b.m[k]);
        }
        const Mat4 fast = gltf_mat4_identity_mul(&b);
        const Mat4 product = gltf_mat4_mul(&identity, &b),
                   signed_product = gltf_mat4_mul(&signed_identity, &b);
        CHECK(memcmp(&product, &fast, sizeof product) == 0);
        CHECK(memcmp(&signed_product, &fast, sizeof product) == 0);
        Mat4 not_identity = identity;
        not_identity.m[trial % 16] = b.m[0] == not_identity.m[trial % 16] ? 2.0 : b.m[0];
        CHECK(!gltf_mat4_is_identity(&not_identity));
    }
    CHECK(negative_zeros > 1000);
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_hierarchy),
        TEST_CASE(test_glb_matches_gltf),
        TEST_CASE(test_automatic_camera),
        TEST_CASE(test_orbit),
        TEST_CASE(test_orthographic_camera),
        TEST_CASE(test_bad_input),
        TEST_CASE(test_identity_product),
    };
    TEST_RUN(cases);
    return test_report();
}
