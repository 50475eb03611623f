/* The table's closest_hit_packet, eight rays against a run of spheres: every
 * level's kernel against ptr_closest_hit_packet_c, which is the one-ray
 * reference lane by lane, bit for bit in every lane. */
#include <stdio.h>
#include <string.h>

#include "checkasm.h"

/* Eight rays against the case's spheres: its own ray in some lanes, in the
 * others rays from near it aimed at one of its spheres (or anywhere), with
 * the case's distribution of tmin and tmax. */
static void fill_packet(const Case *c, PtrRng *rng, PtrRayPacket *p)
{
    const PtrSpheres *s = &c->scene.spheres;
    for (int k = 0; k < PTR_PACKET_LANES; k++) {
        Case lane = { .ray = c->ray };
        if (k && ptr_rng_float(rng) < 0.7f) {
            PtrVec3 o = v3(c->ray.org[0], c->ray.org[1], c->ray.org[2]), d = random_unit(rng);
            if (s->count) {
                size_t i = (size_t)(ptr_rng_float(rng) * (float)s->count) % s->count;
                o = v3_add(o, v3_scale(random_unit(rng), s->radius[i] * ptr_rng_float(rng)));
                PtrVec3 target = v3_add(ptr_sphere_centre(s, i),
                                        v3_scale(random_unit(rng), s->radius[i] * ptr_rng_float(rng)));
                PtrVec3 to = v3_sub(target, o);
                if (v3_max_abs(to) > 0 && ptr_rng_float(rng) < 0.8f)
                    d = to;
            }
            set_ray(&lane, o, d, rng);
        }
        const PtrRay *r = &lane.ray;
        for (int a = 0; a < 3; a++) {
            p->org[a][k] = r->org[a];
            p->dir[a][k] = r->dir[a];
        }
        p->tmin[k] = r->tmin;
        p->tmax[k] = r->tmax;
    }
}

void check_closest_hit_packet(const PtrIsectTable *tables, PtrCpuLevel top, const Case *c,
                              PtrRng *rng, Tally *tally)
{
    PtrRayPacket rays;
    PtrHitPacket ref;
    fill_packet(c, rng, &rays);
    memset(&ref, 0xaa, sizeof ref);
    ptr_closest_hit_packet_c(&rays, &c->scene.spheres, c->count, &ref);
    for (int k = 0; k < PTR_PACKET_LANES; k++)
        tally->hits += ref.sphere[k] != PTR_NO_HIT;
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
        if (tables[l].closest_hit_packet == ptr_closest_hit_packet_c)
            continue;
        PtrHitPacket got;
        memset(&got, 0x55, sizeof got);
        ptr_checked_call_packet(tables[l].closest_hit_packet, &rays, &c->scene.spheres, c->count,
                                &got, &tally->status[l]);
        for (int k = 0; k < PTR_PACKET_LANES; k++)
            if ((got.sphere[k] != ref.sphere[k] || memcmp(&got.t[k], &ref.t[k], sizeof got.t[k])) &&
                tally->mismatches[l]++ < 5)
                fprintf(stderr, "%s packet lane %d differs from c: t %a sphere %u, c: t %a sphere %u\n",
                        tables[l].name, k, got.t[k], got.sphere[k], ref.t[k], ref.sphere[k]);
    }
}
