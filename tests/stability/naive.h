/* The textbook ray-sphere test, kept only as the counter-example the
 * stability suite measures ptr's method against. */
#ifndef PTR_TEST_NAIVE_H
#define PTR_TEST_NAIVE_H

#include "accel/isect.h"

/* The quadratic's discriminant as b*b - c and the roots -b -/+ sqrt(disc),
 * all in float: both differences cancel catastrophically, for small spheres
 * seen from afar and for the far root of rays that start near a surface. */
PTR_DECL_CLOSEST_HIT(naive_closest_hit);

#endif
