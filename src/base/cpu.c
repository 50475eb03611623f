#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT */
#include "base/cpu.h"

#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#if defined(__x86_64__) || defined(_M_X64)
#include <cpuid.h>

static int xgetbv_low(void)
{
    unsigned int eax, edx;
    __asm__ volatile("xgetbv" : "=a"(eax), "=d"(edx) : "c"(0));
    return (int)eax;
}

static PtrCpuLevel detect(void)
{
    unsigned int a, b, c, d;
    if (!__get_cpuid(1, &a, &b, &c, &d) || !(c & bit_SSE4_1))
        return PTR_CPU_NONE;
    /* The AVX2 level includes FMA (the denoiser's convolutions are fused
     * multiply-adds): every AVX2 CPU has it, and a CPU that reports AVX2
     * without it runs as SSE4.1. */
    const int has_fma = (c & bit_FMA) != 0;
    /* OSXSAVE and AVX, then XCR0: SSE (bit 1) and AVX (bit 2) state saved. */
    if (!(c & bit_OSXSAVE) || !(c & bit_AVX) || (xgetbv_low() & 0x6) != 0x6)
        return PTR_CPU_SSE41;
    if (__get_cpuid_max(0, NULL) < 7)
        return PTR_CPU_SSE41;
    __cpuid_count(7, 0, a, b, c, d);
    if (!(b & bit_AVX2) || !has_fma)
        return PTR_CPU_SSE41;
    /* AVX-512 F and VL (the tree's traversal runs it on ymm registers), and
     * XCR0 opmask (5), ZMM0-15 upper (6), ZMM16-31 (7) saved. */
    if (!(b & bit_AVX512F) || !(b & bit_AVX512VL) || (xgetbv_low() & 0xe6) != 0xe6)
        return PTR_CPU_AVX2;
    return PTR_CPU_AVX512;
}
#else
static PtrCpuLevel detect(void)
{
    return PTR_CPU_NONE;
}
#endif

static const char *const level_names[PTR_CPU_LEVEL_COUNT] = {
    "none", "sse41", "avx2", "avx512",
};

PtrCpuLevel ptr_cpu_detected(void)
{
    return detect();
}

PtrCpuLevel ptr_cpu_level(void)
{
    PtrCpuLevel level = detect();
    PtrCpuLevel env_cap = level;
    const char *env = getenv("PTR_CPUMASK");
    if (env && ptr_cpu_parse_level(env, &env_cap, NULL) == PTR_OK && env_cap < level)
        level = env_cap;
    return level;
}

const char *ptr_cpu_level_name(PtrCpuLevel level)
{
    return level < PTR_CPU_LEVEL_COUNT ? level_names[level] : "unknown";
}

PtrResult ptr_cpu_parse_level(const char *name, PtrCpuLevel *level, PtrError *err)
{
    for (int i = 0; i < PTR_CPU_LEVEL_COUNT; i++)
        if (!strcmp(name, level_names[i])) {
            *level = (PtrCpuLevel)i;
            return PTR_OK;
        }
    return ptr_error_set(err, PTR_ERR_USAGE, "'%s' is not none, sse41, avx2 or avx512", name);
}

int ptr_usable_cpus(void)
{
    /* The CPUs this process may run on, which taskset, a container's or a
     * batch system's cpuset can make fewer than the machine's: a thread
     * more than them only waits. sched_getaffinity fails where the kernel
     * allows for more than CPU_SETSIZE (1024) CPUs; then the machine's
     * online count. */
    cpu_set_t allowed;
    long n = sched_getaffinity(0, sizeof allowed, &allowed) == 0 ? CPU_COUNT(&allowed)
                                                                  : sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)(n < 1024 ? n : 1024) : 1;
}

int ptr_thread_count(int requested)
{
    return requested > 0 ? requested : ptr_usable_cpus();
}

double ptr_now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
