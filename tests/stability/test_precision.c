/* Precision of single rays, for ptr's intersector at every level and for the
 * naive method:
 *
 * - reference rays: the hit distance computed in long double from the same
 *   float inputs, over scales drawn log-uniformly across 16 decades; the
 *   error is reported in ulps of t, by decade of the sphere's distance, and
 *   bounded for rays that are not grazing;
 * - no re-hit: a ray leaving a hit point outward never meets the same sphere
 *   again, and one leaving it inward meets it only at the far side. */
#include <stdint.h>

#include "accel/spawn.h"
#include "methods.h"
#include "naive.h"
#include "sampling/rng.h"
#include "test.h"

static float uniform(PtrRng *rng, float lo, float hi)
{
    return lo + (hi - lo) * ptr_rng_float(rng);
}

static double log_uniform(PtrRng *rng, double lo, double hi)
{
    return pow(10.0, lo + (hi - lo) * (double)ptr_rng_float(rng));
}

static PtrVec3 random_unit(PtrRng *rng)
{
    float z = uniform(rng, -1, 1), phi = uniform(rng, 0, 2 * PTR_PI);
    float r = sqrtf(ptr_maxf(0, 1 - z * z));
    return v3_normalize(v3(r * cosf(phi), r * sinf(phi), z));
}

/* The ulp of a float's magnitude. */
static double ulp_of(double x)
{
    int e;
    frexp(fabs(x), &e);
    return ldexp(1.0, e - 24);
}

enum { DECADES = 16, FIRST_DECADE = -6 };

static Method methods[MAX_METHODS];
static int method_count;
static int leave_cases = 300000;

static void test_reference_rays(void)
{
    const int n = method_count;
    /* Row m < n: methods[m] (n <= MAX_METHODS); row n: the naive method. */
    double worst[MAX_METHODS + 1][DECADES] = { { 0 } };
    PtrIsectTable naive = { .closest_hit = naive_closest_hit, .name = "naive" };
    const int rays = 200000;
    int measured = 0;
    PtrRng rng = ptr_rng_for_sample(11, 0, 0);

    for (int i = 0; i < rays; i++) {
        /* A sphere of radius 10^[-6, 10) at 1.5 to 1000 radii from the ray's
         * origin, aimed at the inner 90% of its disc. */
        double radius = log_uniform(&rng, FIRST_DECADE, FIRST_DECADE + DECADES);
        double distance = radius * log_uniform(&rng, 0.18, 3);
        PtrVec3 dir = random_unit(&rng);
        PtrVec3 o = v3_scale(random_unit(&rng), (float)(radius * log_uniform(&rng, -3, 1)));
        PtrVec3 c = v3_add(o, v3_scale(dir, (float)distance));
        PtrVec3 side = v3_normalize(v3_cross(dir, random_unit(&rng)));
        PtrVec3 aim = v3_add(c, v3_scale(side, (float)(radius * 0.9 * ptr_rng_float(&rng))));
        PtrScene s;
        ptr_scene_init(&s);
        ptr_scene_add_sphere(&s, c, (float)radius, 0, NULL);
        PtrVec3 d = v3_normalize(v3_sub(aim, o));
        PtrRay ray = { { o.x, o.y, o.z }, 0, { d.x, d.y, d.z }, INFINITY };

        long double f[3] = { (long double)o.x - c.x, (long double)o.y - c.y, (long double)o.z - c.z };
        long double dd[3] = { d.x, d.y, d.z };
        long double a = dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2];
        long double b = f[0] * dd[0] + f[1] * dd[1] + f[2] * dd[2];
        long double r = s.spheres.radius[0];
        long double cc = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] - r * r;
        long double disc = b * b - a * cc;
        if (disc < 0 || cc <= 0) { /* aimed past the rim by rounding, or inside */
            ptr_scene_free(&s);
            continue;
        }
        long double t = (-b - sqrtl(disc)) / a;
        measured++;
        int decade = (int)floor(log10((double)distance)) - FIRST_DECADE;
        decade = decade < 0 ? 0 : decade >= DECADES ? DECADES - 1 : decade;
        for (int m = -1; m < n; m++) {
            if (m >= 0 && !methods[m].is_ptr)
                continue;
            PtrHit hit;
            const PtrIsectTable *table = m < 0 ? &naive : &methods[m].isect;
            double ulps = INFINITY;
            if (table->closest_hit(&ray, &s.spheres, 1, &hit))
                ulps = (double)fabsl(hit.t - t) / ulp_of((double)t);
            double *w = &worst[m < 0 ? n : m][decade];
            *w = fmax(*w, ulps);
        }
        ptr_scene_free(&s);
    }

    printf("Hit distance error in ulps of t (worst of %d rays), by distance to the sphere:\n",
           measured);
    /* Aimed at the inner 90% of the disc, a ray passes the rim by rounding
     * only at the largest distances: nearly all are measured. */
    CHECK(measured >= rays * 99 / 100);
    printf("%-10s", "distance");
    for (int m = 0; m < n; m++)
        if (methods[m].is_ptr)
            printf(" %12s", methods[m].name);
    printf(" %12s\n", "naive");
    double bound = 0;
    for (int k = 0; k < DECADES; k++) {
        printf("1e%-+8d", FIRST_DECADE + k);
        for (int m = 0; m <= n; m++) {
            if (m < n && !methods[m].is_ptr)
                continue;
            printf(" %12.3g", worst[m][k]);
            if (m < n)
                bound = fmax(bound, worst[m][k]);
        }
        printf("\n");
    }
    /* A few roundings of well-conditioned terms: 6.3 measured. */
    CHECK(bound <= 8.0);
    printf("ptr: at most %.2f ulps at every scale\n\n", bound);
}

/* Rays leaving hit points: outward ones must miss the sphere they left,
 * inward ones must cross it to the far side. Returns the failures, and in
 * *tested how many hit points were left. */
static int leave_surfaces(const PtrIsectTable *isect, int cases, uint64_t seed, int verbose,
                          int *tested_out)
{
    PtrRng rng = ptr_rng_for_sample(seed, 0, 0);
    int rehits = 0, short_chords = 0, tested = 0;
    for (int i = 0; i < cases; i++) {
        double radius = log_uniform(&rng, -4, 6);
        /* Centres up to 10^7 from the scene origin (the camera), as for a
         * ground sphere far bigger than the scene. */
        PtrVec3 c = v3_scale(random_unit(&rng), (float)(radius * log_uniform(&rng, -3, 1)));
        PtrVec3 o = v3_add(c, v3_scale(random_unit(&rng), (float)(radius * (1 + log_uniform(&rng, -3, 2)))));
        PtrVec3 target = v3_add(c, v3_scale(random_unit(&rng), (float)radius));
        PtrScene s;
        ptr_scene_init(&s);
        ptr_scene_add_sphere(&s, c, (float)radius, 0, NULL);
        PtrVec3 d = v3_normalize(v3_sub(target, o));
        PtrRay ray = { { o.x, o.y, o.z }, 0, { d.x, d.y, d.z }, INFINITY };
        PtrHit hit;
        if (!isect->closest_hit(&ray, &s.spheres, 1, &hit)) {
            ptr_scene_free(&s);
            continue;
        }
        tested++;
        PtrVec3 point, n;
        ptr_sphere_surface(c, (float)radius, o, d, hit.t, &point, &n);
        /* Outward, down to grazing: cos from 10^-4 to 1. */
        PtrVec3 tangent = v3_normalize(v3_cross(n, random_unit(&rng)));
        float cosine = (float)log_uniform(&rng, -4, 0);
        PtrVec3 out = v3_normalize(v3_add(v3_scale(n, cosine), v3_scale(tangent, sqrtf(1 - cosine * cosine))));
        PtrRay leave = ptr_spawn_ray(c, (float)radius, n, out);
        PtrHit again;
        if (isect->closest_hit(&leave, &s.spheres, 1, &again)) {
            if (verbose && rehits < 3)
                fprintf(stderr, "re-hit: radius %g, |c| %g, cos %g, t %g\n", radius,
                        v3_length(c), cosine, again.t);
            rehits++;
        }
        /* Inward: the chord to the far side is 2 r cos. */
        PtrVec3 in = v3_normalize(v3_sub(v3_scale(tangent, sqrtf(1 - cosine * cosine)), v3_scale(n, cosine)));
        PtrRay enter = ptr_spawn_ray(c, (float)radius, n, in);
        double chord = 2.0 * radius * cosine;
        if (!isect->closest_hit(&enter, &s.spheres, 1, &again) || again.t < 0.5 * chord) {
            if (verbose && short_chords < 3)
                fprintf(stderr, "inward: radius %g, |c| %g, cos %g, t %g, chord %g\n", radius,
                        v3_length(c), cosine, again.t, chord);
            short_chords++;
        }
        ptr_scene_free(&s);
    }
    if (verbose)
        printf("%s: %d hit points left outward and inward: %d re-hits, %d inward rays "
               "stopped short of the far side\n", isect->name, tested, rehits, short_chords);
    *tested_out = tested;
    return rehits + short_chords;
}

static void test_leave_surfaces(void)
{
    for (int m = 0; m < method_count; m++)
        if (methods[m].is_ptr) {
            int tested;
            CHECK_INT(leave_surfaces(&methods[m].isect, leave_cases, 5, 1, &tested), 0);
            /* Every ray is aimed at a point of the sphere from outside it. */
            CHECK(tested >= leave_cases * 99 / 100 && tested > 0);
        }
}

int main(int argc, char **argv)
{
    method_count = stability_methods(methods, MAX_METHODS);
    CHECK_INT(stability_ptr_methods(methods, method_count), stability_ptr_levels());
    if (argc > 1)
        leave_cases = atoi(argv[1]);
    const TestCase cases[] = { TEST_CASE(test_reference_rays), TEST_CASE(test_leave_surfaces) };
    TEST_RUN(cases);
    return test_report();
}
