/* Bundles of paths: eight paths at a time, one per lane, with their state in
 * structure-of-arrays form. Each bounce is a few loops over the lanes, which
 * the compiler turns into vector code: camera rays, the packet intersector
 * (accel/isect.h) or the tree lane by lane, hit points and normals, the sky
 * and emission, and scattering (all three materials computed, the lane's own
 * selected). Lanes whose paths end take the next camera sample at once, so the
 * vector stays full. What few paths need (light sampling, fuzzy metal, huge
 * spheres) runs lane by lane through the path tracer's own functions
 * (path.h) after the vector loops.
 *
 * Every lane computes exactly the operations render.c's trace_path computes
 * for its path, in the same order, through the same inline functions; no
 * FMA contraction and IEEE operations throughout make the vector code's
 * results the scalar code's, bit for bit (the file is built with -mavx2:
 * src/CMakeLists.txt). Results go to a buffer and are added to the pixels in
 * sample order, as the path tracer adds them. */
#include <math.h>
#include <stdint.h>

#include "accel/spawn.h"
#include "render/path.h"

enum { LANES = PTR_PACKET_LANES, FREE = -1 };

/* Each stage of a bounce stays a function of its own: inlined into one body
 * (as gcc does with functions called once), seed.gltf took 1.3-1.55x as long;
 * kept apart, they also show as the stages of a profile. */
#define STAGE static __attribute__((noinline))

/* The paths in flight. */
typedef struct Lanes {
    PtrRayPacket ray;
    PtrHitPacket hit;
    float throughput[3][LANES], radiance[3][LANES];
    uint64_t key[LANES];   /* the sampler's pixel key */
    uint32_t index[LANES]; /* the sample index */
    int depth[LANES];
    int slot[LANES];       /* the result the path fills, or FREE */
    int traced[LANES];     /* the lane's hit is found already (a camera ray's) */
    PtrLitVertex lit[LANES];
} Lanes;

/* One bounce's findings for every lane. */
typedef struct Vertex {
    int hit[LANES];
    uint32_t sphere[LANES]; /* 0 for a miss */
    uint32_t kind[LANES];
    float albedo[3][LANES], emission[3][LANES], ior[LANES], fuzz[LANES];
    float point[3][LANES], normal[3][LANES];
    float out[3][LANES]; /* the scattered direction */
    int scattered[LANES];
} Vertex;

/* A round: samples [first, first + span) of every pixel still sampling. */
typedef struct Round {
    int x[PTR_TILE_PIXELS], y[PTR_TILE_PIXELS];
    uint64_t key[PTR_TILE_PIXELS];
    double *sums[PTR_TILE_PIXELS];
    int pixels;
    uint32_t first, span, items; /* item k: pixel k / span, sample first + k % span */
} Round;

/* Camera rays for items [first, first + LANES), made together, and with
 * the tree traced together (traced). */
typedef struct CameraBatch {
    uint32_t first;
    int x[LANES], y[LANES];
    uint64_t key[LANES];
    uint32_t index[LANES];
    PtrRayPacket ray;
    PtrHitPacket hit;
    int traced;
} CameraBatch;

static inline PtrVec3 lane_v3(const float a[3][LANES], int l)
{
    return v3(a[0][l], a[1][l], a[2][l]);
}

static inline void set_lane_v3(float a[3][LANES], int l, PtrVec3 v)
{
    a[0][l] = v.x, a[1][l] = v.y, a[2][l] = v.z;
}

static PtrRay lane_ray(const Lanes *lanes, int l)
{
    const PtrRayPacket *r = &lanes->ray;
    return (PtrRay){ { r->org[0][l], r->org[1][l], r->org[2][l] }, r->tmin[l],
                     { r->dir[0][l], r->dir[1][l], r->dir[2][l] }, r->tmax[l] };
}

static void set_lane_ray(Lanes *lanes, int l, PtrRay ray)
{
    PtrRayPacket *r = &lanes->ray;
    for (int a = 0; a < 3; a++) {
        r->org[a][l] = ray.org[a];
        r->dir[a][l] = ray.dir[a];
    }
    r->tmin[l] = ray.tmin;
    r->tmax[l] = ray.tmax;
}

/* ptr_sampler_pair_bits of every lane's pixel key, sample index and pair
 * dim, into bits[0][l] and bits[1][l]. In steps, each a loop over the lanes
 * that the compiler turns into vector instructions: one loop mixing the
 * 64-bit key hashes with the 32-bit Owen scrambling is only partly
 * vectorised by gcc. */
static inline void lanes_pair_bits(PtrSamplerKind kind, const uint64_t key[LANES],
                                   const uint32_t index[LANES], const uint32_t dim[LANES],
                                   uint32_t bits[restrict 2][LANES])
{
    uint64_t pair_key[LANES], scramble[LANES];
    for (int l = 0; l < LANES; l++)
        pair_key[l] = ptr_sampler_pair_key(key[l], dim[l]);
    if (kind == PTR_SAMPLER_INDEPENDENT) {
        for (int l = 0; l < LANES; l++) {
            uint32_t pair[2];
            ptr_independent_pair_bits(pair_key[l], index[l], pair);
            bits[0][l] = pair[0];
            bits[1][l] = pair[1];
        }
        return;
    }
    for (int l = 0; l < LANES; l++)
        scramble[l] = ptr_mix64(pair_key[l]);
    for (int l = 0; l < LANES; l++) {
        uint32_t pair[2];
        ptr_sobol_pair_bits((uint32_t)pair_key[l], scramble[l], index[l], pair);
        bits[0][l] = pair[0];
        bits[1][l] = pair[1];
    }
}

STAGE void camera_rays(const PtrPathJob *job, CameraBatch *batch)
{
    uint32_t pixel_dim[LANES], lens_dim[LANES], pixel[2][LANES], lens[2][LANES];
    for (int l = 0; l < LANES; l++) {
        pixel_dim[l] = PTR_DIM_PIXEL;
        lens_dim[l] = PTR_DIM_LENS;
    }
    lanes_pair_bits(job->settings->sampler, batch->key, batch->index, pixel_dim, pixel);
    lanes_pair_bits(job->settings->sampler, batch->key, batch->index, lens_dim, lens);
    for (int l = 0; l < LANES; l++) {
        PtrVec3 o, d;
        const uint32_t pixel_bits[2] = { pixel[0][l], pixel[1][l] },
                       lens_bits[2] = { lens[0][l], lens[1][l] };
        ptr_path_camera_ray_from_bits(job, pixel_bits, lens_bits, batch->x[l], batch->y[l], &o, &d);
        set_lane_v3(batch->ray.org, l, o);
        set_lane_v3(batch->ray.dir, l, d);
        batch->ray.tmin[l] = 0.0f;
        batch->ray.tmax[l] = INFINITY;
    }
}

/* Starts loading what find_surfaces reads of a hit's sphere that its
 * intersection test did not: its material and colour entries. From 10^7
 * spheres on they are cache misses, which then overlap the other lanes'
 * tracing instead of following it. */
static inline void prefetch_surface(const PtrSpheres *spheres, uint32_t sphere)
{
    if (sphere == PTR_NO_HIT)
        return;
    __builtin_prefetch((const char *)spheres->material + sphere * spheres->material_size);
    if (spheres->color)
        __builtin_prefetch(&spheres->color[3 * (size_t)sphere]);
}

/* A batch's camera rays through the tree as one packet: they leave one
 * pixel (items are a pixel's samples), so they go down the tree together.
 * Brute force traces all lanes together anyway, and huge spheres need
 * ptr_trace. */
STAGE void trace_camera_rays(const PtrPathJob *job, CameraBatch *batch)
{
    const PtrAccel *accel = job->accel;
    batch->traced = accel->kind == PTR_ACCEL_BVH && !job->scene->huge.count;
    if (batch->traced) {
        accel->isect.bvh_closest_hit_packet(&batch->ray, &accel->bvh, accel->spheres, &batch->hit);
        for (int l = 0; l < LANES; l++)
            prefetch_surface(accel->spheres, batch->hit.sphere[l]);
    }
}

STAGE void make_camera_batch(const PtrPathJob *job, const Round *round, uint32_t first,
                              CameraBatch *batch)
{
    batch->first = first;
    for (int l = 0; l < LANES; l++) {
        uint32_t item = first + (uint32_t)l < round->items ? first + (uint32_t)l : first;
        uint32_t p = item / round->span;
        batch->x[l] = round->x[p];
        batch->y[l] = round->y[p];
        batch->key[l] = round->key[p];
        batch->index[l] = round->first + item % round->span;
    }
    camera_rays(job, batch);
    trace_camera_rays(job, batch);
}

/* Gives free lanes the round's next items; returns the lanes in flight. */
STAGE int refill(const PtrPathJob *job, const Round *round, Lanes *lanes, CameraBatch *batch,
                  uint32_t *next)
{
    int active = 0;
    for (int l = 0; l < LANES; l++) {
        if (lanes->slot[l] == FREE && *next < round->items) {
            if (*next - batch->first >= LANES)
                make_camera_batch(job, round, *next, batch);
            int b = (int)(*next - batch->first);
            const PtrRayPacket *r = &batch->ray;
            set_lane_ray(lanes, l,
                         (PtrRay){ { r->org[0][b], r->org[1][b], r->org[2][b] }, r->tmin[b],
                                   { r->dir[0][b], r->dir[1][b], r->dir[2][b] }, r->tmax[b] });
            lanes->traced[l] = batch->traced;
            if (batch->traced) {
                lanes->hit.t[l] = batch->hit.t[b];
                lanes->hit.sphere[l] = batch->hit.sphere[b];
            }
            lanes->key[l] = batch->key[b];
            lanes->index[l] = batch->index[b];
            lanes->depth[l] = 0;
            lanes->slot[l] = (int)(*next)++;
            lanes->lit[l].sampled = 0;
            set_lane_v3(lanes->throughput, l, v3_splat(1.0f));
            set_lane_v3(lanes->radiance, l, v3_splat(0.0f));
        }
        active += lanes->slot[l] != FREE;
    }
    return active;
}

/* Closest hits of the lanes in flight: the packet kernel for brute force,
 * else ptr_trace lane by lane (the tree, huge spheres) for the lanes whose
 * camera ray was not traced with its batch. */
STAGE void trace(const PtrPathJob *job, Lanes *lanes)
{
    const PtrAccel *accel = job->accel;
    if (accel->kind == PTR_ACCEL_BRUTE && !job->scene->huge.count) {
        accel->isect.closest_hit_packet(&lanes->ray, accel->spheres, accel->searched, &lanes->hit);
        return;
    }
    for (int l = 0; l < LANES; l++) {
        if (lanes->slot[l] != FREE && !lanes->traced[l]) {
            PtrRay ray = lane_ray(lanes, l);
            PtrHit hit;
            ptr_trace(accel, &ray, &hit);
            prefetch_surface(accel->spheres, hit.sphere);
            lanes->hit.t[l] = hit.t;
            lanes->hit.sphere[l] = hit.sphere;
        }
        lanes->traced[l] = 0;
    }
}

/* Each lane's hit: its sphere's material (tinted by the sphere's colour),
 * the point on its surface and the outward normal there. */
STAGE void find_surfaces(const PtrPathJob *job, Lanes *restrict lanes, Vertex *restrict v)
{
    const PtrScene *scene = job->scene;
    const PtrSpheres *spheres = &scene->spheres;
    if (!spheres->count) {
        for (int l = 0; l < LANES; l++)
            v->hit[l] = 0;
    } else {
        /* Local restrict pointers: the arrays do not alias v, so the
         * loop's loads become gathers. */
        const PtrMaterial *restrict materials = scene->materials;
        const float *restrict cx = spheres->cx, *restrict cy = spheres->cy,
                    *restrict cz = spheres->cz, *restrict radius = spheres->radius;
        for (int l = 0; l < LANES; l++) {
            v->hit[l] = lanes->hit.sphere[l] != PTR_NO_HIT;
            /* Sphere 0 stands in for a miss (masked, not selected: a
             * select would become a pointer the gathers cannot use). */
            uint32_t s = lanes->hit.sphere[l] & (0u - (uint32_t)v->hit[l]);
            uint32_t m = ptr_sphere_material(spheres, s);
            v->sphere[l] = s;
            v->kind[l] = materials[m].kind;
            v->ior[l] = materials[m].ior;
            v->fuzz[l] = materials[m].fuzz;
            set_lane_v3(v->albedo, l, materials[m].albedo);
            set_lane_v3(v->emission, l, materials[m].emission);
            PtrVec3 point, normal;
            ptr_sphere_surface(v3(cx[s], cy[s], cz[s]), radius[s], lane_v3(lanes->ray.org, l),
                               lane_v3(lanes->ray.dir, l), lanes->hit.t[l], &point, &normal);
            set_lane_v3(v->normal, l, normal);
            set_lane_v3(v->point, l, point);
        }
        for (int l = 0; l < LANES; l++)
            set_lane_v3(v->albedo, l,
                        ptr_path_albedo(spheres, v->sphere[l], lane_v3(v->albedo, l)));
    }
    if (scene->huge.count)
        for (int l = 0; l < LANES; l++)
            if (lanes->slot[l] != FREE && v->hit[l] && ptr_path_in_double(job, v->sphere[l])) {
                PtrRay ray = lane_ray(lanes, l);
                PtrHit hit = { lanes->hit.t[l], lanes->hit.sphere[l] };
                PtrVec3 point, normal;
                ptr_path_surface(job, &ray, &hit, &point, &normal);
                set_lane_v3(v->point, l, point);
                set_lane_v3(v->normal, l, normal);
            }
}

/* Emission found after light sampling is weighed against that sample. */
STAGE void emission_weights(const PtrPathJob *job, const Lanes *restrict lanes,
                            const Vertex *restrict v, float weight[LANES])
{
    for (int l = 0; l < LANES; l++)
        weight[l] = 1.0f;
    /* Without light sampling no vertex is lit and every weight stays 1:
     * skipped here, not found lane by lane below. */
    if (!job->sample_lights)
        return;
    for (int l = 0; l < LANES; l++)
        if (lanes->slot[l] != FREE && v->hit[l] &&
            ptr_path_weighs_emission(&lanes->lit[l], lane_v3(v->emission, l)))
            weight[l] = ptr_path_emission_weight(job, &lanes->lit[l], v->sphere[l],
                                                 lane_v3(lanes->ray.dir, l), lane_v3(v->point, l),
                                                 lane_v3(v->normal, l));
}

/* The loop of add_sky_and_emission under one sky: inlined where the sky's
 * kind is a constant, so that ptr_sky_radiance's switch folds away and the
 * loop vectorises. */
static inline __attribute__((always_inline)) void add_found(Lanes *restrict lanes,
                                                            const Vertex *restrict v,
                                                            const float weight[LANES], PtrSky sky)
{
    for (int l = 0; l < LANES; l++) {
        PtrVec3 sky_l = ptr_sky_radiance(&sky, lane_v3(lanes->ray.dir, l));
        set_lane_v3(lanes->radiance, l,
                    ptr_path_add_found(lane_v3(lanes->radiance, l), lane_v3(lanes->throughput, l),
                                       v->hit[l], sky_l, lane_v3(v->emission, l), weight[l]));
    }
}

/* What the lanes found: the sky where they missed, emission where they hit
 * an emitter. The sky kinds of today each get a loop of their own; any
 * other takes the loop that looks the kind up lane by lane. */
STAGE void add_sky_and_emission(const PtrPathJob *job, Lanes *restrict lanes,
                                const Vertex *restrict v, const float weight[LANES])
{
    const PtrSky *sky = &job->scene->sky;
    switch (sky->kind) {
    case PTR_SKY_GRADIENT:
        add_found(lanes, v, weight, (PtrSky){ .kind = PTR_SKY_GRADIENT });
        break;
    case PTR_SKY_CONSTANT:
        add_found(lanes, v, weight,
                  (PtrSky){ .kind = PTR_SKY_CONSTANT, .radiance = sky->radiance });
        break;
    default:
        add_found(lanes, v, weight, *sky);
        break;
    }
}

/* The passes of the lanes in flight, lane by lane, kept in the result
 * each path fills (passes[slot], begun at its camera ray): where they met
 * a surface, and the sky where they missed. */
STAGE void record_passes(const PtrPathJob *job, const Lanes *restrict lanes,
                         const Vertex *restrict v, PtrPathPass *passes)
{
    for (int l = 0; l < LANES; l++) {
        if (lanes->slot[l] == FREE)
            continue;
        PtrPathPass *pass = &passes[lanes->slot[l]];
        if (lanes->depth[l] == 0)
            *pass = ptr_path_pass_start();
        PtrVec3 dir = lane_v3(lanes->ray.dir, l);
        if (v->hit[l])
            ptr_path_pass_surface(pass, (PtrMaterialKind)v->kind[l], v->fuzz[l],
                                  lane_v3(v->albedo, l),
                                  ptr_facing_normal(dir, lane_v3(v->normal, l)));
        else
            ptr_path_pass_sky(pass, ptr_sky_radiance(&job->scene->sky, dir));
    }
}

/* Light sampling at the diffuse vertices, lane by lane. */
STAGE void sample_emitters(const PtrPathJob *job, Lanes *restrict lanes, const Vertex *restrict v,
                           uint64_t *rays)
{
    const PtrScene *scene = job->scene;
    for (int l = 0; l < LANES; l++) {
        if (lanes->slot[l] == FREE || !v->hit[l])
            continue;
        PtrVec3 dir = lane_v3(lanes->ray.dir, l), normal = lane_v3(v->normal, l);
        PtrLitVertex *lit = &lanes->lit[l];
        *lit = ptr_path_vertex(job, (PtrMaterialKind)v->kind[l], lanes->depth[l],
                               lane_v3(v->point, l), v->sphere[l], v3_dot(dir, normal) < 0.0f);
        if (!lit->sampled)
            continue;
        PtrMaterial m = scene->materials[ptr_sphere_material(&scene->spheres, v->sphere[l])];
        m.albedo = lane_v3(v->albedo, l);
        PtrSampler sampler = { job->settings->sampler, lanes->key[l], lanes->index[l] };
        PtrVec3 light = ptr_path_sample_emitter(job, &sampler, lanes->depth[l], &m, lit,
                                                ptr_facing_normal(dir, normal), normal, rays);
        PtrVec3 radiance = lane_v3(lanes->radiance, l);
        set_lane_v3(lanes->radiance, l,
                    v3_add(radiance, v3_mul(lane_v3(lanes->throughput, l), light)));
    }
}

/* The lanes' numbers of pair slot of their bounce, as floats. */
STAGE void bounce_numbers(const PtrPathJob *job, const Lanes *restrict lanes, int slot,
                           float u0[restrict LANES], float u1[restrict LANES])
{
    uint32_t dim[LANES], bits[2][LANES];
    for (int l = 0; l < LANES; l++)
        dim[l] = ptr_bounce_dim(lanes->depth[l], slot);
    lanes_pair_bits(job->settings->sampler, lanes->key, lanes->index, dim, bits);
    for (int l = 0; l < LANES; l++) {
        u0[l] = ptr_sample_float(bits[0][l]);
        u1[l] = ptr_sample_float(bits[1][l]);
    }
}

/* ptr_scatter's directions, every material's computed and the lane's kept;
 * fuzzy metal lane by lane after. The third number (the Fresnel coin, the
 * fuzz radius) is drawn only when a lane needs it. */
STAGE void scatter(const PtrPathJob *job, Lanes *restrict lanes, Vertex *restrict v)
{
    const PtrScene *scene = job->scene;
    const PtrMaterial *materials = scene->materials;
    float u[3][LANES], unused[LANES];
    int third = 0;
    for (int l = 0; l < LANES; l++)
        third |= lanes->slot[l] != FREE && v->hit[l] &&
                 ptr_scatter_reads_third((PtrMaterialKind)v->kind[l]);
    bounce_numbers(job, lanes, PTR_SLOT_BSDF, u[0], u[1]);
    if (third)
        bounce_numbers(job, lanes, PTR_SLOT_BSDF_EXTRA, u[2], unused);
    else
        for (int l = 0; l < LANES; l++)
            u[2][l] = 0.0f;
    for (int l = 0; l < LANES; l++) {
        const float ul[3] = { u[0][l], u[1][l], u[2][l] };
        set_lane_v3(v->out, l,
                    ptr_scatter_direction((PtrMaterialKind)v->kind[l], v->ior[l],
                                          lane_v3(lanes->ray.dir, l), lane_v3(v->normal, l), ul,
                                          &v->scattered[l]));
    }
    for (int l = 0; l < LANES; l++) {
        if (lanes->slot[l] == FREE || !v->hit[l] ||
            !ptr_scatter_is_fuzzy((PtrMaterialKind)v->kind[l], v->fuzz[l]))
            continue;
        const float ul[3] = { u[0][l], u[1][l], u[2][l] };
        set_lane_v3(v->out, l,
                    ptr_scatter_fuzzy_metal(v->fuzz[l], lane_v3(lanes->ray.dir, l),
                                            lane_v3(v->normal, l), ul, &v->scattered[l]));
    }
    if (job->sample_lights)
        for (int l = 0; l < LANES; l++)
            if (lanes->slot[l] != FREE && v->hit[l] && lanes->lit[l].sampled)
                lanes->lit[l].scatter_pdf = ptr_material_pdf(
                    &materials[ptr_sphere_material(&scene->spheres, v->sphere[l])],
                    ptr_facing_normal(lane_v3(lanes->ray.dir, l), lane_v3(v->normal, l)),
                    lane_v3(v->out, l));
}

/* The next ray of every path that goes on; the result of every path that
 * ends, which frees its lane: its radiance, and whether its camera ray hit
 * a sphere (a path past its first ray did). */
STAGE void continue_or_end(const PtrPathJob *job, Lanes *restrict lanes, const Vertex *restrict v,
                            PtrVec3 *results, unsigned char *covered)
{
    const PtrScene *scene = job->scene;
    const PtrSpheres *spheres = &scene->spheres;
    int go_on[LANES];
    if (spheres->count) {
        const float *restrict cx = spheres->cx, *restrict cy = spheres->cy,
                    *restrict cz = spheres->cz, *restrict radius = spheres->radius;
        for (int l = 0; l < LANES; l++) {
            PtrVec3 throughput =
                v3_mul(lane_v3(lanes->throughput, l),
                       ptr_scatter_attenuation((PtrMaterialKind)v->kind[l], lane_v3(v->albedo, l)));
            go_on[l] = v->hit[l] & ptr_path_goes_on(job->settings, lanes->depth[l],
                                                    v->scattered[l], throughput);
            set_lane_v3(lanes->throughput, l, throughput);
            uint32_t s = v->sphere[l];
            PtrRay next = ptr_spawn_ray(v3(cx[s], cy[s], cz[s]), radius[s], lane_v3(v->normal, l),
                                        lane_v3(v->out, l));
            for (int a = 0; a < 3; a++) {
                lanes->ray.org[a][l] = next.org[a];
                lanes->ray.dir[a][l] = next.dir[a];
            }
            lanes->ray.tmin[l] = next.tmin;
            lanes->ray.tmax[l] = next.tmax;
        }
    } else
        for (int l = 0; l < LANES; l++)
            go_on[l] = 0;
    for (int l = 0; l < LANES; l++) {
        if (lanes->slot[l] == FREE)
            continue;
        if (!go_on[l]) {
            results[lanes->slot[l]] = lane_v3(lanes->radiance, l);
            covered[lanes->slot[l]] = lanes->depth[l] > 0 || v->hit[l];
            lanes->slot[l] = FREE;
            continue;
        }
        if (scene->huge.count && ptr_path_in_double(job, v->sphere[l]))
            set_lane_ray(lanes, l, ptr_path_leave(job, v->sphere[l], lane_v3(v->point, l),
                                                  lane_v3(v->normal, l), lane_v3(v->out, l)));
        lanes->depth[l]++;
    }
}

static void render_round(const PtrPathJob *job, const Round *round, PtrVec3 *results,
                         unsigned char *covered, PtrPathPass *passes, uint64_t *rays)
{
    Lanes lanes;
    Vertex vertex;
    float weight[LANES];
    CameraBatch batch = { .first = 0 };
    uint32_t next = 0;
    /* Free lanes still go through the vector loops: they hold a valid ray
     * and a miss. */
    for (int l = 0; l < LANES; l++) {
        lanes.slot[l] = FREE;
        lanes.traced[l] = 0;
        set_lane_ray(&lanes, l, (PtrRay){ { 0, 0, 0 }, 0.0f, { 0, 0, 1 }, INFINITY });
        lanes.hit.t[l] = INFINITY;
        lanes.hit.sphere[l] = PTR_NO_HIT;
    }
    if (round->items)
        make_camera_batch(job, round, 0, &batch);
    for (;;) {
        int active = refill(job, round, &lanes, &batch, &next);
        if (!active)
            break;
        *rays += (uint64_t)active;
        trace(job, &lanes);
        find_surfaces(job, &lanes, &vertex);
        emission_weights(job, &lanes, &vertex, weight);
        add_sky_and_emission(job, &lanes, &vertex, weight);
        if (passes)
            record_passes(job, &lanes, &vertex, passes);
        if (job->sample_lights)
            sample_emitters(job, &lanes, &vertex, rays);
        scatter(job, &lanes, &vertex);
        continue_or_end(job, &lanes, &vertex, results, covered);
    }
}

PTR_DECL_RENDER_TILE(ptr_render_tile_bundled_avx2)
{
    const PtrRenderSettings *s = job->settings;
    Round round;
    PtrVec3 results[PTR_TILE_PIXELS * PTR_ADAPTIVE_STEP];
    unsigned char covered[PTR_TILE_PIXELS * PTR_ADAPTIVE_STEP];
    PtrPathPass pass_results[PTR_TILE_PIXELS * PTR_ADAPTIVE_STEP];
    PtrPathPass *passes = s->passes ? pass_results : NULL;
    uint64_t end = (uint64_t)job->first + job->count;
    /* Rounds end where adaptive sampling may stop a pixel, so a round's
     * samples are all ones the path tracer would take too. */
    for (uint64_t a = job->first; a < end;) {
        uint64_t b = (a / PTR_ADAPTIVE_STEP + 1) * PTR_ADAPTIVE_STEP;
        b = b < end ? b : end;
        round.pixels = 0;
        round.first = (uint32_t)a;
        round.span = (uint32_t)(b - a);
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                double *acc = ptr_path_pixel_sums(job, x, y);
                if (acc[PTR_ACCUM_STOPPED])
                    continue;
                round.x[round.pixels] = x;
                round.y[round.pixels] = y;
                round.key[round.pixels] = ptr_path_pixel_key(job, x, y);
                round.sums[round.pixels++] = acc;
            }
        round.items = (uint32_t)round.pixels * round.span;
        if (ptr_path_may_trace(s, 0))
            render_round(job, &round, results, covered, passes, rays);
        else
            for (uint32_t i = 0; i < round.items; i++) {
                results[i] = v3_splat(0.0f);
                covered[i] = 0;
                if (passes)
                    passes[i] = ptr_path_pass_start();
            }
        for (int p = 0; p < round.pixels; p++)
            for (uint32_t i = 0; i < round.span; i++)
                ptr_path_accumulate(s, round.sums[p], round.first + i,
                                    results[(uint32_t)p * round.span + i],
                                    covered[(uint32_t)p * round.span + i],
                                    passes ? &passes[(uint32_t)p * round.span + i] : NULL);
        a = b;
    }
}
