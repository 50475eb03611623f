/* Minimal test harness: checks print both operands with file and line, and a
 * test program ends with "N passed, N failed" and a matching exit status. A
 * program that made no check fails: it could not have failed otherwise. One
 * that cannot run here returns test_skip's code, which CMake gives ctest as
 * SKIP_RETURN_CODE. test_run runs a program's cases in a shuffled order, so
 * that a case depending on what another left behind shows. */
#ifndef PTR_TEST_H
#define PTR_TEST_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sampling/rng.h"

static int test_passed, test_failed;

#define TEST_FAIL_(fmt, ...)                                                  \
    do {                                                                      \
        test_failed++;                                                        \
        fprintf(stderr, "%s:%d: " fmt "\n", __FILE__, __LINE__, __VA_ARGS__); \
    } while (0)

#define CHECK(cond)                                                           \
    do {                                                                      \
        if (cond) test_passed++;                                              \
        else TEST_FAIL_("CHECK(%s) failed", #cond);                           \
    } while (0)

#define CHECK_INT(a, b)                                                       \
    do {                                                                      \
        long long a_ = (long long)(a), b_ = (long long)(b);                   \
        if (a_ == b_) test_passed++;                                          \
        else TEST_FAIL_("%s == %s: %lld != %lld", #a, #b, a_, b_);            \
    } while (0)

/* Exact equality of floats, printed to the last bit. */
#define CHECK_FLOAT_EQ(a, b)                                                  \
    do {                                                                      \
        double a_ = (double)(a), b_ = (double)(b);                            \
        if (a_ == b_) test_passed++;                                          \
        else TEST_FAIL_("%s == %s: %.9g (%a) != %.9g (%a)", #a, #b, a_, a_, b_, b_); \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                 \
    do {                                                                      \
        double a_ = (double)(a), b_ = (double)(b), t_ = (double)(tol);        \
        if (fabs(a_ - b_) <= t_) test_passed++;                               \
        else TEST_FAIL_("|%s - %s| <= %s: |%.9g - %.9g| = %.3g", #a, #b, #tol, \
                        a_, b_, fabs(a_ - b_));                               \
    } while (0)

#define CHECK_STR(a, b)                                                       \
    do {                                                                      \
        const char *a_ = (a), *b_ = (b);                                      \
        if (a_ && b_ && !strcmp(a_, b_)) test_passed++;                       \
        else TEST_FAIL_("%s == %s: \"%s\" != \"%s\"", #a, #b,                 \
                        a_ ? a_ : "(null)", b_ ? b_ : "(null)");              \
    } while (0)

static inline int test_report(void)
{
    printf("%d passed, %d failed\n", test_passed, test_failed);
    if (!test_passed && !test_failed) {
        fprintf(stderr, "no check ran: a test that checks nothing cannot fail\n");
        return 1;
    }
    return test_failed ? 1 : 0;
}

/* ctest's code for a test that did not run (tests/CMakeLists.txt). */
#define TEST_SKIP_CODE 77

/* Ends a test that cannot run here, saying why. */
static inline int test_skip(const char *reason)
{
    printf("skipped: %s\n", reason);
    return TEST_SKIP_CODE;
}

typedef struct TestCase {
    const char *name;
    void (*run)(void);
} TestCase;

#define TEST_CASE(fn) { #fn, fn }

/* Runs the cases in an order shuffled by a seed: PTR_TEST_SEED's value, or
 * one from the clock, printed so that a failing order can be replayed. */
static inline void test_run(const TestCase *cases, size_t count)
{
    const char *given = getenv("PTR_TEST_SEED");
    uint64_t seed = given && *given ? strtoull(given, NULL, 0) : (uint64_t)time(NULL);
    printf("case order: PTR_TEST_SEED=%llu\n", (unsigned long long)seed);
    size_t order[64];
    if (count > sizeof order / sizeof order[0]) {
        TEST_FAIL_("%zu cases: test_run takes at most %zu", count, sizeof order / sizeof order[0]);
        return;
    }
    /* Fisher-Yates. */
    PtrRng rng = ptr_rng_for_sample(seed, 0, 0);
    for (size_t i = 0; i < count; i++)
        order[i] = i;
    for (size_t i = count; i > 1; i--) {
        size_t j = (size_t)(ptr_rng_next(&rng) % i), t = order[i - 1];
        order[i - 1] = order[j];
        order[j] = t;
    }
    for (size_t i = 0; i < count; i++) {
        const TestCase *c = &cases[order[i]];
        int failed_before = test_failed;
        printf("case %s\n", c->name);
        c->run();
        if (test_failed != failed_before)
            printf("case %s FAILED\n", c->name);
    }
}

#define TEST_RUN(cases) test_run(cases, sizeof(cases) / sizeof((cases)[0]))

#endif /* PTR_TEST_H */
