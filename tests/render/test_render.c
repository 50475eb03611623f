/* Whole renders with closed-form answers, and determinism across threads. */
#include <stdint.h>

#include "importer.h"
#include "render/render.h"
#include "test.h"

typedef struct Image {
    int width, height;
    float *rgb;
} Image;

static Image render(const PtrScene *scene, PtrRenderSettings settings)
{
    PtrIsectTable isect;
    ptr_isect_init(&isect, PTR_KERNEL_C, scene->spheres.count);
    const PtrAccel accel = ptr_accel_brute(&isect, scene);
    Image img = { settings.width, settings.height,
                  malloc((size_t)settings.width * settings.height * 3 * sizeof(float)) };
    PtrError err = { 0 };
    CHECK_INT(ptr_render(scene, &accel, &settings, img.rgb, NULL, &err), PTR_OK);
    return img;
}

/* One sphere of the given material at the origin, seen from distance 5
 * through a 20 degree field of view (the sphere subtends 23 degrees), in a
 * constant sky of radiance 1. */
static PtrScene furnace(PtrMaterial material)
{
    PtrScene s;
    uint32_t m;
    ptr_scene_init(&s);
    CHECK_INT(ptr_scene_add_material(&s, &material, &m), PTR_OK);
    CHECK_INT(ptr_scene_add_sphere(&s, v3(0, 0, 0), 1.0f, m), PTR_OK);
    s.sky = (PtrSky){ .kind = PTR_SKY_CONSTANT, .radiance = v3_splat(1.0f) };
    s.camera = (PtrCamera){ .lookfrom = v3(0, 0, 5), .lookat = v3(0, 0, 0),
                            .up = v3(0, 1, 0), .vfov_deg = 20.0f, .focus_distance = 5.0f };
    return s;
}

/* Every pixel of the central 8x8 block of a 16x16 image lies well inside the
 * sphere's disc: each must equal the expected radiance exactly. */
static void check_centre(const Image *img, float expected, const char *what)
{
    int wrong = 0;
    for (int y = 4; y < 12; y++)
        for (int x = 4; x < 12; x++)
            for (int c = 0; c < 3; c++)
                if (img->rgb[3 * (y * 16 + x) + c] != expected) {
                    if (!wrong)
                        fprintf(stderr, "%s: pixel (%d, %d) is %.9g, not %.9g\n", what, x, y,
                                img->rgb[3 * (y * 16 + x) + c], expected);
                    wrong++;
                }
    CHECK_INT(wrong, 0);
}

static void test_furnaces(void)
{
    const PtrRenderSettings settings = { .width = 16, .height = 16, .samples = 16, .seed = 1,
                                         .max_depth = 50, .threads = 2 };
    struct {
        const char *what;
        PtrMaterial material;
        float expected;
    } cases[] = {
        { "diffuse 0.5", { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.5f) }, 0.5f },
        { "mirror 0.7", { .kind = PTR_MATERIAL_METAL, .albedo = v3_splat(0.7f) }, 0.7f },
        { "clear glass", { .kind = PTR_MATERIAL_DIELECTRIC, .albedo = v3_splat(1), .ior = 1.5f },
          1.0f },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        PtrScene s = furnace(cases[i].material);
        Image img = render(&s, settings);
        check_centre(&img, cases[i].expected, cases[i].what);
        free(img.rgb);
        ptr_scene_free(&s);
    }
}

/* A camera inside a diffuse emitter of albedo a and emission E: every path
 * hits the wall max_depth times, so each pixel is E * (1 + a + ... + a^(D-1)).
 * Light sampling keeps it exact: from a point on a sphere's inside, a
 * uniform point of its surface has the very density cos / pi of scattering
 * (the chord makes the same angle with both ends' normals), so every light
 * sample carries a E and both MIS weights are 1/2. */
static void test_inside_emitter(void)
{
    PtrMaterial wall = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = v3_splat(0.5f),
                         .emission = v3_splat(1.0f) };
    PtrScene s = furnace(wall);
    s.spheres.radius[0] = 100.0f;
    s.sky.kind = PTR_SKY_BLACK;
    PtrRenderSettings settings = { .width = 16, .height = 16, .samples = 4, .seed = 1,
                                   .max_depth = 3, .threads = 1 };
    Image img = render(&s, settings);
    check_centre(&img, 1.75f, "emitter, depth 3");
    free(img.rgb);

    settings.max_depth = 50;
    img = render(&s, settings);
    int wrong = 0;
    for (int i = 0; i < 16 * 16 * 3; i++)
        wrong += fabs(img.rgb[i] - 2.0 * (1.0 - pow(0.5, 50))) > 2.4e-7;
    CHECK_INT(wrong, 0);
    free(img.rgb);
    ptr_scene_free(&s);
}

/* Thread counts give the same bits, seeds others: on seed.gltf, and on
 * lamps.gltf (light sampling, glass and metal) with either sampler. */
static void check_thread_independence(const char *path, PtrSamplerKind sampler)
{
    PtrScene s;
    PtrStrings warnings = { 0 };
    PtrError err = { 0 };
    CHECK_INT(ptr_import_scene(path, NULL, &s, &warnings, &err), PTR_OK);
    ptr_strings_free(&warnings);
    PtrRenderSettings settings = { .width = 67, .height = 43, .samples = 3, .seed = 9,
                                   .max_depth = 50, .threads = 1, .sampler = sampler };
    Image one = render(&s, settings);
    settings.threads = 2;
    Image two = render(&s, settings);
    settings.threads = 7;
    Image seven = render(&s, settings);
    size_t bytes = 67 * 43 * 3 * sizeof(float);
    CHECK(memcmp(one.rgb, two.rgb, bytes) == 0);
    CHECK(memcmp(one.rgb, seven.rgb, bytes) == 0);
    settings.seed = 10;
    Image other = render(&s, settings);
    CHECK(memcmp(one.rgb, other.rgb, bytes) != 0);
    free(one.rgb);
    free(two.rgb);
    free(seven.rgb);
    free(other.rgb);
    ptr_scene_free(&s);
}

static void test_thread_independence(void)
{
    check_thread_independence(PTR_SOURCE_DIR "/scenes/seed.gltf", PTR_SAMPLER_SOBOL);
    check_thread_independence(PTR_SOURCE_DIR "/scenes/lamps.gltf", PTR_SAMPLER_SOBOL);
    check_thread_independence(PTR_SOURCE_DIR "/scenes/lamps.gltf", PTR_SAMPLER_INDEPENDENT);
}

int main(void)
{
    test_furnaces();
    test_inside_emitter();
    test_thread_independence();
    return test_report();
}
