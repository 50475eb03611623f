/* The ways of tracing rays the stability suite compares: ptr's, at every
 * intersector level this machine has, and the counter-examples. */
#ifndef PTR_TEST_METHODS_H
#define PTR_TEST_METHODS_H

#include "accel/isect.h"

typedef struct Method {
    const char *name;
    PtrIsectTable isect;
    float fixed_tmin; /* 0: ptr's scaled offset */
    unsigned build_flags; /* PtrBuildFlags: recentred, huge spheres in double */
    int is_ptr;       /* ptr's own method: it must pass everything */
} Method;

enum { MAX_METHODS = 8 };

/* Fills methods; returns how many. */
int stability_methods(Method *methods);

#endif
