/* The C reference intersector against rays whose answers are known. */
#include <stdint.h>

#include "accel/isect.h"
#include "sampling/rng.h"
#include "scene/scene.h"
#include "test.h"

static PtrRay make_ray(PtrVec3 o, PtrVec3 d)
{
    d = v3_normalize(d);
    return (PtrRay){ { o.x, o.y, o.z }, 0.0f, { d.x, d.y, d.z }, INFINITY };
}

static void one_sphere(PtrScene *s, PtrVec3 c, float r)
{
    ptr_scene_init(s);
    CHECK_INT(ptr_scene_add_sphere(s, c, r, 0, NULL), PTR_OK);
}

static PtrHit closest(const PtrScene *s, PtrRay ray, int *found)
{
    PtrHit hit = { -1.0f, 12345 };
    *found = ptr_closest_hit_c(&ray, &s->spheres, s->spheres.count, &hit);
    return hit;
}

static void test_reference_rays(void)
{
    PtrScene s;
    int found;
    PtrHit h;

    one_sphere(&s, v3(0, 0, -5), 1.0f);
    h = closest(&s, make_ray(v3(0, 0, 0), v3(0, 0, -1)), &found); /* head-on */
    CHECK(found);
    CHECK_FLOAT_EQ(h.t, 4.0f);
    CHECK_INT(h.sphere, 0);

    h = closest(&s, make_ray(v3(0, 0, 0), v3(0, 0, 1)), &found); /* behind the origin */
    CHECK(!found);
    CHECK_INT(h.sphere, PTR_NO_HIT);
    CHECK_FLOAT_EQ(h.t, INFINITY);

    h = closest(&s, make_ray(v3(0, 0, 0), v3(0, 1, -2)), &found); /* clear miss */
    CHECK(!found);

    h = closest(&s, make_ray(v3(0, 0, -5), v3(0.6f, 0, 0.8f)), &found); /* from the centre */
    CHECK(found);
    CHECK_FLOAT_EQ(h.t, 1.0f);

    h = closest(&s, make_ray(v3(0, 0.5f, -5), v3(0, 1, 0)), &found); /* inside, off centre */
    CHECK(found);
    CHECK_FLOAT_EQ(h.t, 0.5f);

    /* Tangent: the line passes exactly one radius from the centre. */
    h = closest(&s, make_ray(v3(0, 1, 0), v3(0, 0, -1)), &found);
    CHECK(found);
    CHECK_FLOAT_EQ(h.t, 5.0f);
    h = closest(&s, make_ray(v3(0, 1.0001f, 0), v3(0, 0, -1)), &found);
    CHECK(!found);

    /* tmin and tmax bound the answer; tmin skips the near root to the far one. */
    PtrRay r = make_ray(v3(0, 0, 0), v3(0, 0, -1));
    r.tmin = 4.5f;
    h = closest(&s, r, &found);
    CHECK(found);
    CHECK_FLOAT_EQ(h.t, 6.0f);
    r.tmin = 0.0f;
    r.tmax = 3.5f;
    h = closest(&s, r, &found);
    CHECK(!found);
    CHECK_FLOAT_EQ(h.t, 3.5f);
    ptr_scene_free(&s);
}

static void test_many_spheres(void)
{
    PtrScene s;
    ptr_scene_init(&s);
    /* Spheres along -Z at distances 10, 9, ..., 1 (so the last is nearest),
     * and a duplicate of the nearest with a higher index. */
    for (int i = 0; i < 10; i++)
        CHECK_INT(ptr_scene_add_sphere(&s, v3(0, 0, -(float)(10 - i) - 0.25f), 0.25f, 0, NULL), PTR_OK);
    CHECK_INT(ptr_scene_add_sphere(&s, v3(0, 0, -1.25f), 0.25f, 0, NULL), PTR_OK);
    CHECK_INT(s.spheres.capacity % PTR_SPHERE_BLOCK, 0);
    CHECK((uintptr_t)s.spheres.cx % PTR_SPHERE_ALIGN == 0);

    int found;
    PtrHit h = closest(&s, make_ray(v3(0, 0, 0), v3(0, 0, -1)), &found);
    CHECK(found);
    CHECK_FLOAT_EQ(h.t, 1.0f);
    CHECK_INT(h.sphere, 9); /* ties go to the lowest index */

    /* Padding entries are never hit, even when a kernel runs over them. */
    PtrRay r = make_ray(v3(0, 0, 0), v3(0, 0, -1));
    PtrHit all;
    CHECK(ptr_closest_hit_c(&r, &s.spheres, s.spheres.capacity, &all));
    CHECK_INT(all.sphere, 9);
    PtrScene origin;
    one_sphere(&origin, v3(0, 0, -100), 1.0f);
    r = make_ray(v3(0, 0, 0), v3(1, 0, 0)); /* padding sits at the origin */
    CHECK(!ptr_closest_hit_c(&r, &origin.spheres, origin.spheres.capacity, &all));
    ptr_scene_free(&origin);
    ptr_scene_free(&s);
}

/* Random rays at moderate magnitudes against the root computed in long
 * double from the same float inputs. The error is measured in ulps of the
 * largest magnitude the computation handles, max(|o - c|, r): no float method
 * can do better than a fraction of that, whatever t is. */
static void test_random_against_long_double(void)
{
    PtrRng rng = ptr_rng_for_sample(99, 0, 0);
    double worst = 0;
    int hits = 0;
    for (int i = 0; i < 100000; i++) {
        PtrScene s;
        PtrVec3 c = v3(20 * ptr_rng_float(&rng) - 10, 20 * ptr_rng_float(&rng) - 10,
                       20 * ptr_rng_float(&rng) - 10);
        float radius = 0.1f + 3 * ptr_rng_float(&rng);
        one_sphere(&s, c, radius);
        PtrVec3 o = v3(20 * ptr_rng_float(&rng) - 10, 20 * ptr_rng_float(&rng) - 10,
                       20 * ptr_rng_float(&rng) - 10);
        /* Aim near the centre so that most rays hit well inside the disc. */
        PtrVec3 aim = v3_add(c, v3_scale(v3(ptr_rng_float(&rng) - 0.5f,
                                            ptr_rng_float(&rng) - 0.5f,
                                            ptr_rng_float(&rng) - 0.5f), radius));
        PtrRay ray = make_ray(o, v3_sub(aim, o));
        int found;
        PtrHit h = closest(&s, ray, &found);
        ptr_scene_free(&s);

        long double f[3] = { (long double)ray.org[0] - c.x, (long double)ray.org[1] - c.y,
                             (long double)ray.org[2] - c.z };
        long double d[3] = { ray.dir[0], ray.dir[1], ray.dir[2] };
        long double a = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        long double b = f[0] * d[0] + f[1] * d[1] + f[2] * d[2];
        long double cc = f[0] * f[0] + f[1] * f[1] + f[2] * f[2] - (long double)radius * radius;
        long double disc = b * b - a * cc;
        if (disc < 0) {
            CHECK(!found);
            continue;
        }
        long double t0 = (-b - sqrtl(disc)) / a, t1 = (-b + sqrtl(disc)) / a;
        long double t = t0 > 0 ? t0 : t1;
        if (t <= 0) {
            CHECK(!found);
            continue;
        }
        CHECK(found);
        hits++;
        long double scale = fmaxl(sqrtl(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), radius);
        double rel = (double)(fabsl(h.t - t) / (scale * 0x1p-23L));
        if (rel > worst)
            worst = rel;
    }
    printf("random rays: %d hits, worst error %.2f ulps of max(|o - c|, r)\n", hits, worst);
    CHECK(hits > 50000);
    CHECK(worst < 6.0); /* 3.5 seen; a few roundings of that magnitude */
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_reference_rays),
        TEST_CASE(test_many_spheres),
        TEST_CASE(test_random_against_long_double),
    };
    TEST_RUN(cases);
    return test_report();
}
