/* A small program on libptr: a ring of coloured spheres on a ground, made
 * from arrays, rendered and saved.
 *
 *   cc render_spheres.c $(pkg-config --cflags --libs ptr) -o render_spheres
 *   ./render_spheres spheres.png [spheres.exr ...]
 *
 * Each file named is written (EXR as scene-linear floats, other formats
 * through the view); it prints the image's size and mean colour. */
#include <math.h>
#include <stdio.h>

#include <ptr/ptr.h>

enum { RING = 12, SPHERES = RING + 1 };

static int report(const char *what, const PtrErrorInfo *err)
{
    fprintf(stderr, "render_spheres: %s: %s\n", what, err->message);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: render_spheres OUTPUT...\n");
        return 2;
    }
    float centers[3 * SPHERES], radii[SPHERES], colors[3 * SPHERES];
    uint32_t materials[SPHERES];
    for (int i = 0; i < RING; i++) {
        const float angle = 6.2831853f * (float)i / RING;
        centers[3 * i] = 2.0f * cosf(angle);
        centers[3 * i + 1] = 0.0f;
        centers[3 * i + 2] = 2.0f * sinf(angle);
        radii[i] = 0.45f;
        colors[3 * i] = 0.5f + 0.5f * cosf(angle);
        colors[3 * i + 1] = 0.5f + 0.5f * cosf(angle + 2.1f);
        colors[3 * i + 2] = 0.5f + 0.5f * cosf(angle + 4.2f);
        materials[i] = (uint32_t)(i % 2); /* diffuse and metal in turn */
    }
    /* The ground: one large white diffuse sphere. */
    centers[3 * RING] = 0.0f;
    centers[3 * RING + 1] = -1000.45f;
    centers[3 * RING + 2] = 0.0f;
    radii[RING] = 1000.0f;
    colors[3 * RING] = colors[3 * RING + 1] = colors[3 * RING + 2] = 0.8f;
    materials[RING] = 0;

    const PtrMaterialDesc table[] = {
        { .type = PTR_MATERIAL_TYPE_DIFFUSE, .albedo = { 1, 1, 1 } },
        { .type = PTR_MATERIAL_TYPE_METAL, .albedo = { 1, 1, 1 }, .fuzz = 0.1f },
    };
    const PtrCameraDesc camera = {
        .lookfrom = { 0, 3, 6 }, .lookat = { 0, 0, 0 }, .up = { 0, 1, 0 }, .vfov_deg = 40,
    };
    const PtrSceneArrays arrays = {
        .count = SPHERES, .centers = centers, .radii = radii, .colors = colors,
        .material_indices = materials, .materials = table, .material_count = 2,
        .camera = &camera,
    };

    PtrErrorInfo err;
    PtrContext *context;
    PtrSceneHandle *scene;
    PtrFrame *frame;
    if (ptr_context_new(NULL, &context, &err) != PTR_STATUS_OK)
        return report("context", &err);
    int code = 0;
    if (ptr_scene_from_arrays(context, &arrays, &scene, &err) != PTR_STATUS_OK) {
        code = report("scene", &err);
    } else {
        PtrRenderOptions options;
        ptr_render_options_default(&options);
        options.width = 160;
        options.height = 90;
        options.samples = 16;
        if (ptr_scene_render(context, scene, &options, NULL, NULL, &frame, &err) !=
            PTR_STATUS_OK) {
            code = report("render", &err);
        } else {
            const int w = ptr_frame_width(frame), h = ptr_frame_height(frame);
            const float *pixels = ptr_frame_pixels(frame);
            double sum[3] = { 0, 0, 0 };
            for (long p = 0; p < (long)w * h; p++)
                for (int c = 0; c < 3; c++)
                    sum[c] += pixels[3 * p + c];
            printf("%dx%d, mean %.4f %.4f %.4f\n", w, h, sum[0] / ((double)w * h),
                   sum[1] / ((double)w * h), sum[2] / ((double)w * h));
            for (int i = 1; i < argc && !code; i++)
                if (ptr_frame_save(context, argv[i], frame, NULL, &err) != PTR_STATUS_OK)
                    code = report(argv[i], &err);
            ptr_frame_free(frame);
        }
        ptr_scene_handle_free(scene);
    }
    ptr_context_free(context);
    return code;
}
