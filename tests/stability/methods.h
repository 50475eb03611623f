/* The ways of tracing rays the stability suite compares: ptr's, at every
 * intersector level this machine has, and the counter-examples. */
#ifndef PTR_TEST_METHODS_H
#define PTR_TEST_METHODS_H

#include "accel/isect.h"

typedef struct Method {
    const char *name;
    PtrIsectTable isect;
    float fixed_tmin; /* 0: ptr's scaled offset */
    int recentre;     /* scene coordinates relative to the camera */
    int is_ptr;       /* ptr's own method: it must pass everything */
} Method;

enum { MAX_METHODS = 8 };

/* Fills methods; returns how many. */
int stability_methods(Method *methods);

#endif
