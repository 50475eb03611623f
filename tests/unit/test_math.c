/* Vector maths, random streams and the camera. */
#include <stdint.h>

#include "base/vec.h"
#include "render/camera.h"
#include "sampling/rng.h"
#include "test.h"

static void test_vectors(void)
{
    PtrVec3 a = v3(1, 2, 3), b = v3(4, -5, 6);
    CHECK_FLOAT_EQ(v3_dot(a, b), 12.0f);
    PtrVec3 c = v3_cross(a, b);
    CHECK_FLOAT_EQ(c.x, 27.0f);
    CHECK_FLOAT_EQ(c.y, 6.0f);
    CHECK_FLOAT_EQ(c.z, -13.0f);
    CHECK_FLOAT_EQ(v3_dot(c, a), 0.0f);
    CHECK_FLOAT_EQ(v3_length(v3(3, 4, 12)), 13.0f);
    CHECK_NEAR(v3_length(v3_normalize(v3(1e-20f, 3e-20f, -2e-20f))), 1.0, 1e-6);
    CHECK_FLOAT_EQ(v3_max_abs(v3(-7, 2, 5)), 7.0f);
}

static void test_rng(void)
{
    /* A stream is SplitMix64 from its key: from state 0, the first outputs
     * of Vigna's reference implementation. */
    PtrRng zero = { 0 };
    CHECK(ptr_rng_next(&zero) == UINT64_C(0xe220a8397b1dcdaf));
    CHECK(ptr_rng_next(&zero) == UINT64_C(0x6e789e6aa1b965f4));
    CHECK(ptr_rng_next(&zero) == UINT64_C(0x06c45d188009454f));

    /* Each of seed, pixel and sample gives another stream. */
    PtrRng a = ptr_rng_for_sample(7, 1234, 5), c = ptr_rng_for_sample(7, 1234, 6);
    PtrRng d = ptr_rng_for_sample(8, 1234, 5), e = ptr_rng_for_sample(7, 1235, 5);
    uint64_t va = ptr_rng_next(&a);
    CHECK(va != ptr_rng_next(&c));
    CHECK(va != ptr_rng_next(&d));
    CHECK(va != ptr_rng_next(&e));

    /* Uniform on [0, 1): range, mean 1/2 and variance 1/12. With n = 1e6 the
     * standard error of the mean is 2.9e-4; 5 sigma is 1.5e-3. */
    PtrRng r = ptr_rng_for_sample(1, 0, 0);
    const int n = 1000000;
    double sum = 0, sum2 = 0;
    float lo = 1, hi = 0;
    for (int i = 0; i < n; i++) {
        float u = ptr_rng_float(&r);
        lo = fminf(lo, u);
        hi = fmaxf(hi, u);
        sum += u;
        sum2 += (double)u * u;
    }
    CHECK(lo >= 0.0f && hi < 1.0f);
    CHECK_NEAR(sum / n, 0.5, 1.5e-3);
    CHECK_NEAR(sum2 / n - (sum / n) * (sum / n), 1.0 / 12.0, 1.5e-3);
}

static void test_camera(void)
{
    PtrCamera cam = { .lookfrom = v3(1, 2, 3), .lookat = v3(1, 2, -7), .up = v3(0, 1, 0),
                      .vfov_deg = 90.0f, .focus_distance = 10.0f };
    PtrView view;
    CHECK(ptr_view_init(&view, &cam, 200, 100));

    /* The centre of the image (a pixel corner for even sizes) looks at lookat. */
    PtrVec3 o, d;
    ptr_view_ray(&view, 100, 50, 0.0f, 0.0f, 0.0f, 0.0f, &o, &d);
    CHECK_FLOAT_EQ(o.x, 1.0f);
    CHECK_NEAR(d.x, 0.0, 1e-6);
    CHECK_NEAR(d.y, 0.0, 1e-6);
    CHECK_NEAR(d.z, -1.0, 1e-6);

    /* The top edge is vfov/2 above the axis; the left edge is wider by the
     * aspect ratio. */
    ptr_view_ray(&view, 100, 0, 0.0f, 0.0f, 0.0f, 0.0f, &o, &d);
    CHECK_NEAR(atan2(d.y, -d.z), 0.25 * 3.14159265358979, 1e-6);
    ptr_view_ray(&view, 0, 50, 0.0f, 0.0f, 0.0f, 0.0f, &o, &d);
    CHECK_NEAR(-d.x / -d.z, 2.0, 1e-6);

    /* A lens sample moves the origin within the aperture but every ray of a
     * pixel still meets at the focus plane. */
    cam.aperture = 2.0f;
    CHECK(ptr_view_init(&view, &cam, 200, 100));
    ptr_view_ray(&view, 30, 70, 0.5f, 0.5f, 0.6f, -0.8f, &o, &d);
    PtrVec3 o0, d0;
    ptr_view_ray(&view, 30, 70, 0.5f, 0.5f, 0.0f, 0.0f, &o0, &d0);
    CHECK_NEAR(v3_length(v3_sub(o, o0)), 1.0, 1e-5);
    PtrVec3 p = v3_madd(o, d, 10.0f / -d.z), p0 = v3_madd(o0, d0, 10.0f / -d0.z);
    CHECK_NEAR(v3_length(v3_sub(p, p0)), 0.0, 1e-4);

    /* Degenerate cameras are refused. */
    PtrCamera bad = cam;
    bad.lookat = bad.lookfrom;
    CHECK(!ptr_view_init(&view, &bad, 10, 10));
    bad = cam;
    bad.up = v3(0, 0, 1);
    CHECK(!ptr_view_init(&view, &bad, 10, 10));
    bad = cam;
    bad.vfov_deg = 180.0f;
    CHECK(!ptr_view_init(&view, &bad, 10, 10));
}

/* Parallel rays: every one runs along the view direction from the near
 * plane, the view is 2 ymag high and as wide as the image's aspect ratio
 * makes it, and lens samples change nothing. */
static void test_orthographic_camera(void)
{
    PtrCamera cam = { .lookfrom = v3(0, 0, 10), .lookat = v3(0, 0, 0), .up = v3(0, 1, 0),
                      .projection = PTR_PROJECTION_ORTHOGRAPHIC, .ymag = 2.0f, .znear = 1.5f,
                      .aperture = 3.0f };
    PtrView view;
    CHECK(ptr_view_init(&view, &cam, 200, 100)); /* 0.04 world units a pixel */

    /* Pixel (112, 35)'s corner lies 12 pixels right of the centre and 15
     * up: its ray starts at (0.48, 0.6) on the near plane z = 8.5 and meets
     * the unit sphere at the origin where z = sqrt(1 - 0.48^2 - 0.6^2), at
     * (0.48, 0.6, 0.64). */
    PtrVec3 o, d;
    ptr_view_ray(&view, 112, 35, 0.0f, 0.0f, 0.7f, -0.3f, &o, &d);
    CHECK_NEAR(o.x, 0.48, 1e-6);
    CHECK_NEAR(o.y, 0.6, 1e-6);
    CHECK_FLOAT_EQ(o.z, 8.5f);
    CHECK_FLOAT_EQ(d.x, 0.0f);
    CHECK_FLOAT_EQ(d.y, 0.0f);
    CHECK_FLOAT_EQ(d.z, -1.0f);
    double b = (double)o.x * d.x + (double)o.y * d.y + (double)o.z * d.z;
    double c = (double)o.x * o.x + (double)o.y * o.y + (double)o.z * o.z - 1.0;
    double t = -b - sqrt(b * b - c);
    CHECK_NEAR(o.z + t * d.z, 0.64, 1e-5);

    /* The lens sample moved nothing: the same ray without it. */
    PtrVec3 o0, d0;
    ptr_view_ray(&view, 112, 35, 0.0f, 0.0f, 0.0f, 0.0f, &o0, &d0);
    CHECK(!memcmp(&o, &o0, sizeof o) && !memcmp(&d, &d0, sizeof d));

    /* The image's edges: 2 ymag = 4 high, 4 * 200 / 100 = 8 wide. */
    ptr_view_ray(&view, 0, 0, 0.0f, 0.0f, 0.0f, 0.0f, &o, &d);
    CHECK_NEAR(o.x, -4.0, 1e-6);
    CHECK_NEAR(o.y, 2.0, 1e-6);

    /* Turned and moved, the rays still share the view direction. */
    cam.lookfrom = v3(3, 4, 5);
    cam.lookat = v3(4, 2, 3);
    CHECK(ptr_view_init(&view, &cam, 7, 5));
    PtrVec3 forward = v3_normalize(v3_sub(cam.lookat, cam.lookfrom));
    ptr_view_ray(&view, 6, 0, 0.9f, 0.1f, 0.0f, 0.0f, &o, &d);
    CHECK_NEAR(v3_dot(d, forward), 1.0, 1e-6);
    CHECK_NEAR(v3_dot(v3_sub(o, cam.lookfrom), forward), 1.5, 1e-5); /* on the near plane */

    /* A view of no height, or a near plane behind the camera, is refused. */
    PtrCamera bad = cam;
    bad.ymag = 0.0f;
    CHECK(!ptr_view_init(&view, &bad, 10, 10));
    bad = cam;
    bad.znear = -1.0f;
    CHECK(!ptr_view_init(&view, &bad, 10, 10));
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_vectors),
        TEST_CASE(test_rng),
        TEST_CASE(test_camera),
        TEST_CASE(test_orthographic_camera),
    };
    TEST_RUN(cases);
    return test_report();
}
