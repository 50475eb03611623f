/* How much memory this process can still take without the machine
 * swapping or the process being refused: what a scene's import checks
 * before it allocates for millions of spheres. */
#ifndef PTR_MEMORY_H
#define PTR_MEMORY_H

#include <stdint.h>

/* Bytes the process may still allocate: the least of the machine's
 * MemAvailable (/proc/meminfo), the room left under the control group's
 * memory.max, and the room left under the address-space limit (ulimit -v)
 * beyond what is mapped now. UINT64_MAX where none of them can be read. */
uint64_t ptr_memory_available(void);

#endif /* PTR_MEMORY_H */
