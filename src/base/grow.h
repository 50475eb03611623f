/* An array grown by doubling, for lists of unknown length: the importers',
 * and the scene's materials. */
#ifndef PTR_GROW_H
#define PTR_GROW_H

#include <stdlib.h>

#include "base/result.h"

/* *items, of *capacity items of size bytes, made room for need of them
 * (its capacity doubled from 16 until it holds them): PTR_OK, or
 * PTR_ERR_NOMEM with *items as it was. */
static inline PtrResult ptr_grow(void **items, size_t *capacity, size_t need, size_t size)
{
    if (need <= *capacity)
        return PTR_OK;
    size_t c = *capacity ? *capacity : 16;
    while (c < need)
        c *= 2;
    void *p = realloc(*items, c * size);
    if (!p)
        return PTR_ERR_NOMEM;
    *items = p;
    *capacity = c;
    return PTR_OK;
}

#endif /* PTR_GROW_H */
