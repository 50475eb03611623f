#define _GNU_SOURCE /* mremap */
#include "base/memory.h"

#include <errno.h>
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

/* The pages that lie wholly inside base[from .. to - 1]: [*lo, *hi). With
 * finished set, those wholly inside base[0 .. to - 1] but not inside
 * base[0 .. from - 1]: the page that holds base[from] too, where a call
 * before, to from, left it. */
static void pages_in(void *base, size_t from, size_t to, int finished, uintptr_t *lo,
                     uintptr_t *hi)
{
    const uintptr_t page = (uintptr_t)sysconf(_SC_PAGESIZE), start = (uintptr_t)base;
    const uintptr_t first = (start + page - 1) & ~(page - 1); /* base's page may hold more */
    *lo = finished ? (start + from) & ~(page - 1) : (start + from + page - 1) & ~(page - 1);
    *hi = (start + to) & ~(page - 1);
    if (*lo < first)
        *lo = first;
    if (*hi < *lo)
        *hi = *lo;
}

/* Lines of a text file (0 if it cannot be read). */
static size_t count_lines(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    char chunk[65536];
    size_t lines = 0, n;
    while ((n = fread(chunk, 1, sizeof chunk, f)) > 0)
        for (size_t i = 0; i < n; i++)
            lines += chunk[i] == '\n';
    fclose(f);
    return lines;
}

/* A quarter of the room for mappings left to a process holding `held`.
 * Each page run a bank moves can split a mapping in two (the array's, or a
 * run's), and a process holds at most vm.max_map_count mappings (65,530 by
 * default), past which most new mappings (thread stacks, large blocks)
 * fail. */
static size_t mapping_room(size_t held)
{
    const uint64_t max = read_number("/proc/sys/vm/max_map_count");
    return max != UINT64_MAX && max > held ? (size_t)(max - held) / 4 : 0;
}

/* Stops bank for good (the kernel would not move pages, or the mappings
 * came near its ceiling): it gives back the pages it holds, and those put
 * from now on. */
static void bank_stop(PtrPageBank *bank)
{
    ptr_pages_free(bank);
    bank->refused = 1;
}

/* Whether bank may move pages now. At its first count a bank sets its
 * ceiling: the mappings the process held then and a quarter of the room
 * left. At each count it may make as many moves as there are mappings left
 * under the ceiling (a move splits at most one mapping in two). Most moves
 * split none, since a run moved next to the one before joins it: at 10^8
 * spheres the tree's copy made 15,700 moves and the process held 2,900
 * mappings more. So each time the bank has made the moves its last count
 * allowed, it counts again; within MOVES_MIN of the ceiling, or where the
 * mappings cannot be counted, it stops and gives its pages back. (Counted once, the room ran out halfway
 * through the 10^8 write-back, which faulted the rest of its pages in: 1.2-
 * 1.4 s where it now takes 0.5.) */
static int bank_open(PtrPageBank *bank)
{
    enum { MOVES_MIN = 64 }; /* below this, a count every few moves */
    if (!bank->refused && bank->moves_left == 0) {
        const size_t held = count_lines("/proc/self/maps");
        if (!held) { /* unreadable: no count to keep under a ceiling */
            bank_stop(bank);
            return 0;
        }
        if (!bank->mappings_most)
            bank->mappings_most = held + mapping_room(held);
        bank->moves_left = bank->mappings_most >= held + MOVES_MIN
                               ? bank->mappings_most - held : 0;
        if (!bank->moves_left)
            bank_stop(bank);
    }
    return !bank->refused; /* moves_left is above 0 unless the bank stopped */
}

/* Moves the pages of [lo, hi) into bank, the range left mapped and empty;
 * false where the bank is full (errno ENOSPC) or the kernel refuses. */
static int bank_run(PtrPageBank *bank, uintptr_t lo, uintptr_t hi)
{
    if (bank->runs == PTR_PAGE_BANK_RUNS && bank->first > 0) { /* room the takes left */
        memmove(bank->run, bank->run + bank->first,
                (bank->runs - bank->first) * sizeof *bank->run);
        bank->runs -= bank->first;
        bank->first = 0;
    }
    if (bank->runs == PTR_PAGE_BANK_RUNS || bank->bytes + (hi - lo) > PTR_PAGE_BANK_BYTES) {
        errno = ENOSPC;
        return 0;
    }
    /* The new address too (NULL: the kernel's choice): the kernel reads
     * it with MREMAP_DONTUNMAP, and a stray value fails the call. */
    void *at = mremap((void *)lo, hi - lo, hi - lo, MREMAP_MAYMOVE | MREMAP_DONTUNMAP, NULL);
    if (at == MAP_FAILED)
        return 0;
    bank->run[bank->runs++] = (struct PtrPageRun){ at, hi - lo };
    bank->bytes += hi - lo;
    bank->moves_left--;
    return 1;
}

/* Banks [lo, hi), or gives it back to the machine. */
static void put_range(PtrPageBank *bank, uintptr_t lo, uintptr_t hi, uintptr_t page)
{
    if (bank && bank_open(bank)) {
        if (bank_run(bank, lo, hi))
            return;
        /* An array filled from the bank is a mapping for each run it took,
         * and the kernel moves one mapping at a time: a range that spans
         * several is halved until each piece is one. A page it will not
         * move (Linux before 5.7) stops the bank. */
        if (errno == EINVAL || errno == EFAULT) {
            if (hi - lo > page) {
                const uintptr_t mid = lo + (hi - lo) / page / 2 * page;
                put_range(bank, lo, mid, page);
                put_range(bank, mid, hi, page);
                return;
            }
            bank_stop(bank);
        }
    }
    /* A hint: where refused, the memory is only given back later. */
    (void)madvise((void *)lo, hi - lo, MADV_DONTNEED);
}

void ptr_pages_put(PtrPageBank *bank, void *base, size_t from, size_t to)
{
    uintptr_t lo, hi;
    pages_in(base, from, to, 1, &lo, &hi);
    if (hi > lo)
        put_range(bank, lo, hi, (uintptr_t)sysconf(_SC_PAGESIZE));
}

int ptr_pages_take(PtrPageBank *bank, void *base, size_t from, size_t to)
{
    uintptr_t lo, hi;
    pages_in(base, from, to, 0, &lo, &hi);
    while (lo < hi && bank->first < bank->runs && bank_open(bank)) {
        struct PtrPageRun *run = &bank->run[bank->first];
        const size_t n = run->bytes < hi - lo ? run->bytes : hi - lo;
        /* The oldest run's first n bytes (the rest stays one mapping):
         * pages go out in the order they came in. Taken newest first, at
         * 10^8 spheres, where the tree's copy fills eight ranges a step
         * (the root's children), they split more mappings: with a bank's
         * room counted once, as it then was, the write-back ran out of
         * moves earlier, and the process faulted 1.94 million pages where
         * it faulted 1.62 (docs/intersectors.md, "The root chosen before
         * the copy"). */
        if (mremap(run->at, n, n, MREMAP_MAYMOVE | MREMAP_FIXED, (void *)lo) == MAP_FAILED) {
            /* Some kernels unmap the destination before they move the
             * pages, and may then fail (out of memory): map it again, empty,
             * where it is gone. (A kernel before 4.17 takes the address as a
             * hint, and maps elsewhere where the range is still there.) */
            void *again = mmap((void *)lo, n, PROT_READ | PROT_WRITE,
                               MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED_NOREPLACE, -1, 0);
            const int kept = again != MAP_FAILED || errno == EEXIST;
            if (again != MAP_FAILED && again != (void *)lo)
                munmap(again, n);
            bank_stop(bank);
            return kept;
        }
        bank->moves_left--;
        run->at += n;
        run->bytes -= n;
        bank->bytes -= n;
        if (run->bytes == 0 && ++bank->first == bank->runs)
            bank->first = bank->runs = 0;
        lo += n;
    }
    return 1;
}

void ptr_pages_free(PtrPageBank *bank)
{
    for (size_t k = bank->first; k < bank->runs; k++)
        munmap(bank->run[k].at, bank->run[k].bytes);
    *bank = (PtrPageBank){ 0 };
}
