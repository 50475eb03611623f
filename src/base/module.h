/* ptr's modules: shared objects beside the executable (or libptr.so),
 * loaded only when a render needs what they hold (the OpenImageIO writers,
 * the live view), so that a render without them never pays for their
 * libraries. */
#ifndef PTR_MODULE_H
#define PTR_MODULE_H

#include <stddef.h>

#include "base/result.h"

/* The path of a module given relative to the folder of the file this code
 * runs from: the executable's, or libptr.so's when the code is the
 * library's ("../lib/ptr/NAME.so": each leading "../" takes a folder off,
 * so that messages show a plain path; lib/libptr.so and bin/ptr are both
 * one folder below the top), in path. what names the module in messages
 * ("image", "live"). PTR_ERR_INSTALL if the folder cannot be found. */
PtrResult ptr_module_path(const char *relative, const char *what, char *path, size_t size,
                          PtrError *err);

/* Whether dlopen failed for want of memory. It reports text alone (errno
 * does not survive it), so this knows glibc's words for the cases: a mapping
 * refused (a segment, the zero-filled pages) or an allocation failed. */
int ptr_dl_out_of_memory(const char *why);

#endif /* PTR_MODULE_H */
