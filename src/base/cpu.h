/* What the CPU can run, capped by a user mask.
 *
 * Levels are cumulative: a level is granted only if every level below it is
 * too. AVX levels need the OS to save the wider registers on a context
 * switch, which XGETBV reports; CPUID alone is not enough. */
#ifndef PTR_CPU_H
#define PTR_CPU_H

#include "base/result.h"

typedef enum PtrCpuLevel {
    PTR_CPU_NONE,   /* portable C only */
    PTR_CPU_SSE41,
    PTR_CPU_AVX2,   /* AVX2 and FMA */
    PTR_CPU_AVX512, /* AVX-512 F */
    PTR_CPU_LEVEL_COUNT,
} PtrCpuLevel;

/* The highest level this CPU and OS support, ignoring any cap. */
PtrCpuLevel ptr_cpu_detected(void);

/* The detected level capped by PTR_CPUMASK in the environment (a name
 * ptr_cpu_parse_level does not know caps nothing). Callers cap it further
 * for themselves (ptr's --cpumask) and pass the level on to what they call:
 * the process keeps no level of its own. */
PtrCpuLevel ptr_cpu_level(void);

/* "none", "sse41", "avx2", "avx512". */
const char *ptr_cpu_level_name(PtrCpuLevel level);

/* Parses a level name; PTR_ERR_USAGE if it is not one. */
PtrResult ptr_cpu_parse_level(const char *name, PtrCpuLevel *level, PtrError *err);

/* The number of CPUs this process may run on (its affinity: taskset,
 * cpusets; at least 1, at most 1024): the default thread count. */
int ptr_usable_cpus(void);

/* The threads a run asked for (--threads), or one per CPU it may run on
 * (ptr_usable_cpus) where it asked for none (0 or less). */
int ptr_thread_count(int requested);

/* Seconds on a monotonic clock, for timing. */
double ptr_now_seconds(void);

#endif /* PTR_CPU_H */
