/* How much memory this process can still take without the machine
 * swapping or the process being refused: what a scene's import checks
 * before it allocates for millions of spheres. */
#ifndef PTR_MEMORY_H
#define PTR_MEMORY_H

#include <stddef.h>
#include <stdint.h>

/* Bytes the process may still allocate: the least of the machine's
 * MemAvailable (/proc/meminfo), the room left under the control group's
 * memory.max, and the room left under the address-space limit (ulimit -v)
 * beyond what is mapped now. UINT64_MAX where none of them can be read. */
uint64_t ptr_memory_available(void);

/* Gives the machine back the pages that lie wholly inside base[0 .. to - 1]
 * but not wholly inside base[0 .. from - 1], keeping them mapped: they read
 * as zero afterwards. For a caller that has finished with base[0 .. to - 1]
 * and releases an allocation as it goes through it, each call's from the
 * last one's to, so that every whole page is given back once: at 10^8
 * spheres, gigabytes the build then has for itself. */
void ptr_memory_release(void *base, size_t from, size_t to);

#endif /* PTR_MEMORY_H */
