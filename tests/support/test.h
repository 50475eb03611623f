/* Minimal test harness: checks print both operands with file and line, and a
 * test program ends with "N passed, N failed" and a matching exit status. */
#ifndef PTR_TEST_H
#define PTR_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    return test_failed ? 1 : 0;
}

#endif /* PTR_TEST_H */
