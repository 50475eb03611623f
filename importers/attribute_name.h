/* The one rule by which --color-by names a per-sphere attribute
 * (docs/scenes.md), shared by the glTF and structure importers. Plain C and
 * C++ both. */
#ifndef PTR_ATTRIBUTE_NAME_H
#define PTR_ATTRIBUTE_NAME_H

#include <strings.h>

/* Whether the attribute key is the one name asks for: the same letters in
 * any case, the leading underscore optional. */
static inline int ptr_attribute_named(const char *key, const char *name)
{
    if (*key == '_' && *name != '_')
        key++;
    return strcasecmp(key, name) == 0;
}

#endif /* PTR_ATTRIBUTE_NAME_H */
