/* The OBJ importer: objects and groups, sphere fitting, every MTL rule of
 * docs/scenes.md (Blender 3.4's exporter, with and without its PBR keys),
 * warnings, errors with line numbers, and a camera from the command line. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "importer.h"
#include "test.h"
#include "test_scene.h"

#define OBJ(name) PTR_SOURCE_DIR "/tests/fixtures/obj/" name


static const PtrMaterial *material(const PtrScene *s, size_t sphere)
{
    return &s->materials[ptr_sphere_material(&s->spheres, sphere)];
}

static void test_materials(void)
{
    PtrScene s;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(OBJ("spheres.obj"), NULL, &s, &w, &err), PTR_OK);
    CHECK_INT(s.spheres.count, 6); /* the Cube is skipped */
    check_sphere(&s, 0, 0, -100, 0, 99, 1e-4);
    check_sphere(&s, 1, 0, 1, 0, 1, 1e-4);
    check_sphere(&s, 3, -3, 1, 0, 0.5, 1e-4);
    check_sphere(&s, 4, 0, 3, 0, 0.25, 1e-4); /* "Ball.SPHERE.001": any case */

    const PtrMaterial *none = material(&s, 0), *red = material(&s, 1), *glass = material(&s, 2),
                      *brushed = material(&s, 3), *chrome = material(&s, 4), *lamp = material(&s, 5);
    CHECK_INT(none->kind, PTR_MATERIAL_DIFFUSE); /* no usemtl yet: grey 0.8 */
    CHECK_FLOAT_EQ(none->albedo.y, 0.8f);
    CHECK_INT(red->kind, PTR_MATERIAL_DIFFUSE);
    CHECK_FLOAT_EQ(red->albedo.x, 0.8f);
    CHECK_FLOAT_EQ(red->albedo.z, 0.05f);
    CHECK_INT(glass->kind, PTR_MATERIAL_DIELECTRIC); /* Tf, illum 4 */
    CHECK_FLOAT_EQ(glass->ior, 1.33f);
    CHECK_FLOAT_EQ(glass->albedo.x, 0.9f);      /* attenuation = Tf */
    CHECK_INT(brushed->kind, PTR_MATERIAL_METAL); /* illum 3, no Pr: fuzz from Ns */
    CHECK_NEAR(brushed->fuzz, 1.0 - sqrt(0.81), 1e-6);
    CHECK_FLOAT_EQ(brushed->albedo.y, 0.8f);
    CHECK_INT(chrome->kind, PTR_MATERIAL_METAL); /* Pm 1, Pr 0.3 */
    CHECK_FLOAT_EQ(chrome->fuzz, 0.3f);
    CHECK_INT(lamp->kind, PTR_MATERIAL_DIFFUSE);
    CHECK_FLOAT_EQ(lamp->emission.x, 4.0f);
    CHECK_FLOAT_EQ(lamp->emission.z, 2.0f);
    CHECK_INT(s.material_count, 6); /* Red is used twice, stored once */

    CHECK_INT(w.count, 1);
    CHECK(w.count && strstr(w.lines[0], "'Cube' is skipped") && strstr(w.lines[0], "spheres.obj:"));
    ptr_strings_free(&w);
    ptr_scene_free(&s);

    /* --fit-all-objects fits the Cube too. */
    PtrImportOptions all = { .fit_all_objects = 1 };
    CHECK_INT(ptr_import_scene(OBJ("spheres.obj"), &all, &s, &w, &err), PTR_OK);
    CHECK_INT(s.spheres.count, 7);
    check_sphere(&s, 6, 5, 5, 5, 1, 1e-4);
    CHECK_INT(w.count, 0);
    ptr_strings_free(&w);
    ptr_scene_free(&s);
}

static void test_groups_and_missing_mtl(void)
{
    PtrScene s;
    PtrStrings w = { 0 }, deps = { 0 };
    PtrError err = { 0 };
    /* No o lines: the groups are the objects; relative indices work. */
    CHECK_INT(ptr_import_scene(OBJ("groups.obj"), NULL, &s, &w, &err), PTR_OK);
    CHECK_INT(s.spheres.count, 2);
    check_sphere(&s, 0, 1, 2, 3, 0.5, 1e-4);
    check_sphere(&s, 1, -1, 0, 0, 2, 1e-4);
    ptr_scene_free(&s);

    PtrImportOptions options = { .dependencies = &deps };
    CHECK_INT(ptr_import_scene(OBJ("missing_mtl.obj"), &options, &s, &w, &err), PTR_OK);
    CHECK_INT(w.count, 1);
    CHECK(w.count && strstr(w.lines[0], "nowhere.mtl cannot be read"));
    CHECK_INT(material(&s, 0)->kind, PTR_MATERIAL_DIFFUSE);
    CHECK_FLOAT_EQ(material(&s, 0)->albedo.x, 0.8f);
    CHECK_INT(deps.count, 1); /* --watch watches the .mtl too */
    ptr_strings_free(&w);
    ptr_strings_free(&deps);
    ptr_scene_free(&s);
}

/* An object of spheres (12 x 8 latitude-longitude meshes along x) whose
 * faces alternate between two usemtl, face by face, each sphere's first
 * face under "Missing", which the library lacks: its spheres are grey, the
 * others' red, and the missing name is reported once, not once a run. */
static void test_alternating_materials(void)
{
    enum { SPHERES = 4, SEGMENTS = 12, RINGS = 8 };
    char dir[] = "/tmp/ptr-obj-XXXXXX", path[64];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/alternating.obj", dir);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f)
        return;
    fprintf(f, "mtllib %s\no Balls.sphere\n", OBJ("spheres.mtl"));
    const double pi = acos(-1.0);
    for (int s = 0; s < SPHERES; s++) {
        for (int ring = 0; ring <= RINGS; ring++)
            for (int seg = 0; seg < SEGMENTS; seg++) {
                const double theta = pi * ring / RINGS, phi = 2 * pi * seg / SEGMENTS;
                fprintf(f, "v %.17g %.17g %.17g\n", 3.0 * s + sin(theta) * cos(phi), cos(theta),
                        sin(theta) * sin(phi));
            }
        const int first = s * (RINGS + 1) * SEGMENTS + 1, faces = RINGS * SEGMENTS;
        for (int face = 0; face < faces; face++) {
            const int ring = face / SEGMENTS, seg = face % SEGMENTS;
            const int a = first + ring * SEGMENTS + seg;
            const int b = first + ring * SEGMENTS + (seg + 1) % SEGMENTS;
            fprintf(f, "usemtl %s\nf %d %d %d %d\n", face % 2 ? "Red" : "Missing", a, b,
                    b + SEGMENTS, a + SEGMENTS);
        }
    }
    fclose(f);
    PtrScene sc;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(path, NULL, &sc, &w, &err), PTR_OK);
    CHECK_INT(sc.spheres.count, SPHERES);
    size_t missing = 0;
    for (size_t i = 0; i < w.count; i++)
        missing += strstr(w.lines[i], "material 'Missing' is not in its material library") != NULL;
    CHECK_INT(missing, 1);
    for (size_t i = 0; i < sc.spheres.count; i++) {
        check_sphere(&sc, i, 3.0 * (double)i, 0, 0, 1, 1e-4);
        CHECK_FLOAT_EQ(material(&sc, i)->albedo.x, 0.8f); /* grey, not Red's 0.8, 0.05, 0.05 */
        CHECK_FLOAT_EQ(material(&sc, i)->albedo.z, 0.8f);
    }
    ptr_strings_free(&w);
    ptr_scene_free(&sc);
    unlink(path);
    rmdir(dir);
}

static void test_camera_override(void)
{
    PtrScene s;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    const PtrCameraSpec camera = { .lookfrom = { 0, 2, 12 }, .lookat = { 0, 2, 0 },
                                   .up = { 0, 1, 0 }, .vfov_deg = 50, .aperture = 0.1 };
    PtrImportOptions options = { .camera = &camera };
    CHECK_INT(ptr_import_scene(OBJ("spheres.obj"), &options, &s, &w, &err), PTR_OK);
    CHECK_NEAR(s.origin[2], 12, 1e-12);
    CHECK_FLOAT_EQ(s.camera.vfov_deg, 50.0f);
    CHECK_FLOAT_EQ(s.camera.aperture, 0.1f);
    CHECK_FLOAT_EQ(s.camera.focus_distance, 12.0f); /* the look-at point is in focus */
    ptr_strings_free(&w);
    ptr_scene_free(&s);

    /* It replaces a glTF's camera too. */
    CHECK_INT(ptr_import_scene(PTR_SOURCE_DIR "/scenes/seed.gltf", &options, &s, &w, &err), PTR_OK);
    CHECK_NEAR(s.origin[1], 2, 1e-12);
    CHECK_FLOAT_EQ(s.camera.vfov_deg, 50.0f);
    ptr_strings_free(&w);
    ptr_scene_free(&s);
}

static void check_bad(const char *path, const char *needle)
{
    PtrScene s;
    PtrStrings w = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(path, NULL, &s, &w, &err), PTR_ERR_SCENE_INVALID);
    if (!strstr(err.message, needle))
        TEST_FAIL_("'%s' not in \"%s\"", needle, err.message);
    ptr_strings_free(&w);
    ptr_scene_free(&s);
}

static void test_errors(void)
{
    check_bad(PTR_SOURCE_DIR "/tests/fixtures/bad/bad_index.obj", "bad_index.obj:5: vertex 9 does not exist");
    check_bad(PTR_SOURCE_DIR "/tests/fixtures/bad/nan_vertex.obj", "nan_vertex.obj:3: a vertex needs");
    check_bad(PTR_SOURCE_DIR "/tests/fixtures/bad/garbage.obj", "garbage.obj:1: binary data");
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_materials),
        TEST_CASE(test_groups_and_missing_mtl),
        TEST_CASE(test_alternating_materials),
        TEST_CASE(test_camera_override),
        TEST_CASE(test_errors),
    };
    TEST_RUN(cases);
    return test_report();
}
