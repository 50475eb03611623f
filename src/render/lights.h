/* Emissive spheres as lights: choosing one by its power, and sampling the
 * directions from a point towards it. */
#ifndef PTR_LIGHTS_H
#define PTR_LIGHTS_H

#include <stdint.h>

#include "base/result.h"
#include "scene/scene.h"

/* Every sphere with an emission above zero, and Walker's alias table over
 * their powers: a pick costs the same for one emitter or a million. */
typedef struct PtrLights {
    uint32_t count;
    uint32_t *sphere;    /* index in scene->spheres */
    float *keep;         /* alias table: probability of keeping the column */
    uint32_t *alias;     /* else this column */
    double total_power;
} PtrLights;

PtrResult ptr_lights_init(PtrLights *lights, const PtrScene *scene, PtrError *err);
void ptr_lights_free(PtrLights *lights);

/* Picks a light (an index into lights->sphere) from two uniform 32-bit
 * numbers. */
uint32_t ptr_lights_pick(const PtrLights *lights, const uint32_t bits[2]);

/* The probability ptr_lights_pick picks the sphere, an emitter. */
float ptr_lights_pick_pdf(const PtrLights *lights, const PtrScene *scene, uint32_t sphere);

/* Where a point stands towards a light sphere: outside it, it sees a cone of
 * directions; inside it, the whole inner surface. */
typedef enum PtrLightView { PTR_LIGHT_UNSEEN, PTR_LIGHT_FROM_OUTSIDE, PTR_LIGHT_FROM_INSIDE } PtrLightView;

/* How point p sees the sphere (centre c, radius r). own_side says whether p
 * lies on this very sphere: 0 if not, 1 on its outside (it cannot see
 * itself), -1 on its inside. */
PtrLightView ptr_light_view(PtrVec3 p, PtrVec3 c, float r, int own_side);

/* Samples a direction from p towards the sphere: from outside, uniformly in
 * the cone it subtends; from inside, towards a uniform point of its surface.
 * Writes the unit direction, the distance to the sphere's surface along it,
 * and the density per solid angle. Returns 0 if the sample is unusable. */
int ptr_light_sample(PtrLightView view, PtrVec3 p, PtrVec3 c, float r, const float u[2],
                     PtrVec3 *dir, float *distance, float *pdf);

/* The density per solid angle ptr_light_sample gives the direction from p
 * that meets the sphere at distance t, with outward normal n there. */
float ptr_light_pdf(PtrLightView view, PtrVec3 p, PtrVec3 c, float r, PtrVec3 dir, float t,
                    PtrVec3 n);

#endif /* PTR_LIGHTS_H */
