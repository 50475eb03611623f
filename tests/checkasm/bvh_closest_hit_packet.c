/* The table's bvh_closest_hit_packet, eight rays through the tree together:
 * every assembly level's against the C reference, lane by lane the C
 * traversal (return value aside: the same t and sphere, to the bit), on the
 * scenes of bvh_closest_hit.c. Two kinds of packet: eight unrelated rays,
 * which part at the root, and eight coherent ones (one origin, directions
 * within a small cone, as a pixel's camera rays), which go down together and
 * part deep in the tree, with every lane's tmin and tmax its own. */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "checkasm.h"

enum { PACKETS_PER_SCENE = 250 };

static void set_lane(PtrRayPacket *p, int k, const PtrRay *r)
{
    for (int a = 0; a < 3; a++) {
        p->org[a][k] = r->org[a];
        p->dir[a][k] = r->dir[a];
    }
    p->tmin[k] = r->tmin;
    p->tmax[k] = r->tmax;
}

/* Eight rays around one drawn ray: its origin, its direction turned by up
 * to spread radians (0: the same ray eight times). */
static void coherent_packet(PtrRayPacket *p, PtrRay ray, float spread, PtrRng *rng)
{
    const PtrVec3 d = v3(ray.dir[0], ray.dir[1], ray.dir[2]);
    for (int k = 0; k < PTR_PACKET_LANES; k++) {
        PtrVec3 turned = v3_normalize(v3_madd(d, random_unit(rng), spread));
        PtrRay lane = ray;
        lane.dir[0] = turned.x, lane.dir[1] = turned.y, lane.dir[2] = turned.z;
        set_lane(p, k, &lane);
    }
}

uint64_t check_bvh_closest_hit_packet(const PtrIsectTable *tables, PtrCpuLevel top,
                                      const PtrBvh *bvh, const PtrSpheres *s, DrawRayFn draw,
                                      PtrRng *rng, Tally *tally)
{
    static const float spreads[] = { 0.0f, 1e-4f, 1e-2f, 0.2f };
    for (int n = 0; n < PACKETS_PER_SCENE; n++) {
        PtrRayPacket rays;
        if (n % 2) {
            for (int k = 0; k < PTR_PACKET_LANES; k++) {
                const PtrRay r = draw(s, rng);
                set_lane(&rays, k, &r);
            }
        } else {
            coherent_packet(&rays, draw(s, rng), spreads[(n / 2) % 4], rng);
        }
        PtrHitPacket ref;
        ptr_bvh_closest_hit_packet_c(&rays, bvh, s, &ref);
        for (int k = 0; k < PTR_PACKET_LANES; k++)
            tally->hits += ref.sphere[k] != PTR_NO_HIT;
        for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
            if (tables[l].bvh_closest_hit_packet == ptr_bvh_closest_hit_packet_c)
                continue;
            PtrHitPacket got;
            memset(&got, 0x55, sizeof got); /* unwritten lanes show */
            ptr_checked_call_bvh_packet(tables[l].bvh_closest_hit_packet, &rays, bvh, s, &got,
                                        &tally->status[l]);
            for (int k = 0; k < PTR_PACKET_LANES; k++) {
                if (!memcmp(&got.t[k], &ref.t[k], sizeof got.t[k]) &&
                    got.sphere[k] == ref.sphere[k])
                    continue;
                if (tally->mismatches[l]++ < 5)
                    fprintf(stderr,
                            "%s tree packet lane %d differs from c: t %a (c %a), sphere %" PRIu32
                            " (c %" PRIu32 "), tmin %a, tmax %a\n",
                            tables[l].name, k, got.t[k], ref.t[k], got.sphere[k], ref.sphere[k],
                            rays.tmin[k], rays.tmax[k]);
            }
        }
    }
    return PACKETS_PER_SCENE;
}

void report_bvh_closest_hit_packet(const PtrIsectTable *tables, PtrCpuLevel top,
                                   uint64_t packets, const Tally *tally, int *passed,
                                   int *failed)
{
    for (int l = PTR_CPU_SSE41; l <= (int)top; l++) {
        if (tables[l].bvh_closest_hit_packet == ptr_bvh_closest_hit_packet_c ||
            (l > PTR_CPU_SSE41 && tables[l].bvh_closest_hit_packet == tables[l - 1].bvh_closest_hit_packet))
            continue;
        const CheckedCallStatus *st = &tally->status[l];
        printf("tree packet %-7s %" PRIu64 " packets (%" PRIu64 " lanes hit): %" PRIu64
               " lanes differ from c%s%s\n",
               tables[l].name, packets, tally->hits, tally->mismatches[l],
               st->failures & 1 ? "; a callee-saved register was clobbered" : "",
               st->failures & 2 ? "; returned with dirty upper YMM state (no vzeroupper)" : "");
        tally->mismatches[l] || st->failures ? ++*failed : ++*passed;
    }
}
