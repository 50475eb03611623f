/* The ways of tracing rays the stability suite compares: ptr's, at every
 * intersector level this machine has, and the counter-examples. */
#ifndef PTR_TEST_METHODS_H
#define PTR_TEST_METHODS_H

#include "accel/isect.h"
#include "base/cpu.h"

typedef struct Method {
    const char *name;
    PtrIsectTable isect;
    float fixed_tmin; /* 0: ptr's scaled offset */
    unsigned build_flags; /* PtrBuildFlags: recentred, huge spheres in double */
    int is_ptr;       /* ptr's own method: it must pass everything */
} Method;

/* The counter-examples and ptr's C method, then one method a CPU level above
 * none: the most there can be, whatever the CPU. */
enum { FIXED_METHODS = 5, MAX_METHODS = FIXED_METHODS + PTR_CPU_LEVEL_COUNT - 1 };

/* Fills methods, which holds capacity of them; returns how many. Exits with
 * a message if they do not fit, rather than writing past the array. */
int stability_methods(Method *methods, int capacity);

/* How many of the n methods are ptr's own, and how many stability_methods
 * must give: the C reference, and one a CPU level above none where the
 * build has assembly. A suite checks the two agree, or it could pass
 * without testing ptr at all. */
int stability_ptr_methods(const Method *methods, int n);
int stability_ptr_levels(void);

#endif
