#include "app/scene_json.h"

#include <math.h>
#include <stdlib.h>

#include "app/report.h"

/* Floats print with 9 significant digits, enough to read back the same
 * float exactly. */
static void write_vec(FILE *out, PtrVec3 v)
{
    fprintf(out, "[%.9g, %.9g, %.9g]", v.x, v.y, v.z);
}

/* A position in world coordinates: the scene's origin plus its offset. */
static void write_point(FILE *out, const PtrScene *scene, PtrVec3 v)
{
    fprintf(out, "[%.17g, %.17g, %.17g]", scene->origin[0] + v.x, scene->origin[1] + v.y,
            scene->origin[2] + v.z);
}

static const char *material_kind(PtrMaterialKind kind)
{
    switch (kind) {
    case PTR_MATERIAL_DIFFUSE: return "diffuse";
    case PTR_MATERIAL_METAL: return "metal";
    case PTR_MATERIAL_DIELECTRIC: return "dielectric";
    }
    return "unknown";
}

static void write_sky(FILE *out, const PtrSky *sky)
{
    switch (sky->kind) {
    case PTR_SKY_GRADIENT: fputs("\"gradient\"", out); return;
    case PTR_SKY_BLACK: fputs("\"black\"", out); return;
    case PTR_SKY_CONSTANT: write_vec(out, sky->radiance); return;
    }
}

PtrResult ptr_scene_write_json(FILE *out, const char *path, const PtrScene *scene,
                               const PtrStrings *warnings)
{
    const PtrSpheres *s = &scene->spheres;
    /* In the file's order, whatever order the arrays are in. */
    size_t *by_id = malloc((s->count ? s->count : 1) * sizeof *by_id);
    if (!by_id)
        return PTR_ERR_NOMEM;
    for (size_t i = 0; i < s->count; i++)
        by_id[ptr_sphere_id(s, i)] = i;
    fputs("{\n  \"scene\": ", out);
    ptr_json_string(out, path);
    fputs(",\n  \"spheres\": [", out);
    for (size_t n = 0; n < s->count; n++) {
        size_t i = by_id[n];
        fprintf(out, "%s\n    {\"center\": ", n ? "," : "");
        write_point(out, scene, ptr_sphere_centre(s, i));
        fprintf(out, ", \"radius\": %.9g, \"material\": %u", s->radius[i],
                ptr_sphere_material(s, i));
        if (s->color) {
            fputs(", \"color\": ", out);
            write_vec(out, ptr_sphere_color(s, i));
        }
        if (s->value && !isnan(s->value[n]))
            fprintf(out, ", \"value\": %.9g", s->value[n]);
        fputc('}', out);
    }
    free(by_id);
    fputs("\n  ],\n  \"materials\": [", out);
    for (size_t i = 0; i < scene->material_count; i++) {
        const PtrMaterial *m = &scene->materials[i];
        fprintf(out, "%s\n    {\"kind\": \"%s\", \"albedo\": ", i ? "," : "",
                material_kind(m->kind));
        write_vec(out, m->albedo);
        if (m->kind == PTR_MATERIAL_METAL)
            fprintf(out, ", \"fuzz\": %.9g", m->fuzz);
        if (m->kind == PTR_MATERIAL_DIELECTRIC)
            fprintf(out, ", \"ior\": %.9g", m->ior);
        fputs(", \"emission\": ", out);
        write_vec(out, m->emission);
        fputc('}', out);
    }
    const PtrCamera *c = &scene->camera;
    fputs("\n  ],\n  \"camera\": {\"lookfrom\": ", out);
    write_point(out, scene, c->lookfrom);
    fputs(", \"lookat\": ", out);
    write_point(out, scene, c->lookat);
    fputs(", \"up\": ", out);
    write_vec(out, c->up);
    if (c->projection == PTR_PROJECTION_ORTHOGRAPHIC)
        fprintf(out, ", \"projection\": \"orthographic\", \"ymag\": %.9g, \"znear\": %.9g",
                c->ymag, c->znear);
    else
        fprintf(out, ", \"projection\": \"perspective\", \"vfov_deg\": %.9g, "
                     "\"aperture\": %.9g, \"focus_distance\": %.9g",
                c->vfov_deg, c->aperture, c->focus_distance);
    fprintf(out, ", \"aspect\": %.9g},\n  \"sky\": ", c->aspect);
    write_sky(out, &scene->sky);
    if (scene->width > 0)
        fprintf(out, ",\n  \"resolution\": [%d, %d]", scene->width, scene->height);
    fputs(",\n  \"warnings\": [", out);
    for (size_t i = 0; i < warnings->count; i++) {
        fputs(i ? ", " : "", out);
        ptr_json_string(out, warnings->lines[i]);
    }
    fputs("]\n}\n", out);
    return PTR_OK;
}
