/* ptr_sincos_turns against double-precision sin and cos at every number the
 * samplers can give it: the multiples of 2^-24 in [0, 1) (ptr_sample_float),
 * so the bound below is the worst case, not an estimate. */
#include <stdint.h>

#include "test.h"

#include "base/trig.h"

static void test_every_sample(void)
{
    double worst = 0, worst_u = 0;
    for (uint32_t i = 0; i < (1u << 24); i++) {
        float u = (float)i * 0x1.0p-24f, s, c;
        ptr_sincos_turns(u, &s, &c);
        double angle = 2.0 * 3.14159265358979323846 * (double)u;
        double e = fmax(fabs(s - sin(angle)), fabs(c - cos(angle)));
        if (e > worst)
            worst = e, worst_u = u;
    }
    printf("worst absolute error %.3g at u = %.9g\n", worst, worst_u);
    CHECK(worst < 1.1e-7); /* 1.07e-7 measured: under one float ulp of 1 */
}

/* The quarter turns are exact. */
static void test_quarter_turns(void)
{
    const float quarters[4][3] = { { 0.0f, 0.0f, 1.0f }, { 0.25f, 1.0f, 0.0f },
                                   { 0.5f, 0.0f, -1.0f }, { 0.75f, -1.0f, 0.0f } };
    for (int q = 0; q < 4; q++) {
        float s, c;
        ptr_sincos_turns(quarters[q][0], &s, &c);
        CHECK_FLOAT_EQ(s, quarters[q][1]);
        CHECK_FLOAT_EQ(c, quarters[q][2]);
    }
}

int main(void)
{
    const TestCase cases[] = { TEST_CASE(test_every_sample), TEST_CASE(test_quarter_turns) };
    TEST_RUN(cases);
    return test_report();
}
