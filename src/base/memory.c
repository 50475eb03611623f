#define _DEFAULT_SOURCE /* madvise */
#include "base/memory.h"

#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

/* The number after key in a "key value" text file (kB scaled by unit), or
 * UINT64_MAX if the file or the key is missing. */
static uint64_t read_field(const char *path, const char *key, uint64_t unit)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return UINT64_MAX;
    char line[256];
    uint64_t value = UINT64_MAX;
    const size_t n = strlen(key);
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, key, n)) {
            unsigned long long v;
            if (sscanf(line + n, "%llu", &v) == 1)
                value = (uint64_t)v * unit;
            break;
        }
    fclose(f);
    return value;
}

/* A file holding one number ("max": no limit), or UINT64_MAX. */
static uint64_t read_number(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return UINT64_MAX;
    unsigned long long v;
    int ok = fscanf(f, "%llu", &v) == 1;
    fclose(f);
    return ok ? (uint64_t)v : UINT64_MAX;
}

static uint64_t min_u64(uint64_t a, uint64_t b)
{
    return a < b ? a : b;
}

uint64_t ptr_memory_available(void)
{
    uint64_t room = read_field("/proc/meminfo", "MemAvailable:", 1024);
    /* cgroup v2, the process's own group as the container sees it. */
    const uint64_t max = read_number("/sys/fs/cgroup/memory.max");
    const uint64_t current = read_number("/sys/fs/cgroup/memory.current");
    if (max != UINT64_MAX && current != UINT64_MAX)
        room = min_u64(room, max > current ? max - current : 0);
    struct rlimit limit;
    if (getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY) {
        const uint64_t mapped = read_field("/proc/self/status", "VmSize:", 1024);
        if (mapped != UINT64_MAX)
            room = min_u64(room, limit.rlim_cur > mapped ? limit.rlim_cur - mapped : 0);
    }
    return room;
}

void ptr_memory_release(void *base, size_t from, size_t to)
{
    const uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE), start = (uintptr_t)base;
    const uintptr_t first = (start + page - 1) & ~(page - 1); /* base's page may hold more */
    uintptr_t lo = (start + from) & ~(page - 1);
    const uintptr_t hi = (start + to) & ~(page - 1);
    if (lo < first)
        lo = first;
    if (hi > lo) /* a hint: where refused, the memory is only given back later */
        (void)madvise((void *)lo, hi - lo, MADV_DONTNEED);
}
