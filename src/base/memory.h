/* How much memory this process can still take without the machine
 * swapping or the process being refused: what a scene's import checks
 * before it allocates for millions of spheres. And pages moved from an
 * array a stage has finished with to the one it fills next (a page bank). */
#ifndef PTR_MEMORY_H
#define PTR_MEMORY_H

#include <stddef.h>
#include <stdint.h>

/* Bytes the process may still allocate: the least of the machine's
 * MemAvailable (/proc/meminfo), the room left under the control group's
 * memory.max, and the room left under the address-space limit (ulimit -v)
 * beyond what is mapped now. UINT64_MAX where none of them can be read. */
uint64_t ptr_memory_available(void);

/* Pages moved from the arrays a pipeline has finished with to those it
 * fills next, in place of giving them back to the machine and faulting
 * fresh ones in: the kernel moves a gigabyte's mappings in about a
 * millisecond, where faulting it in page by page, zeroed, took 0.4 s on the
 * machines ptr is measured on. At 10^8 spheres the build's stages each
 * fill gigabytes (the scene's arrays, the tree's prims, the arrays again
 * in the tree's order) as they empty others. A bank is the caller's, on one
 * thread; zero-initialised it is empty. */
enum {
    /* Entries a stage writes between a take and a put (a million spheres:
     * at most 44 MB of the import's arrays, well within the bank's bytes);
     * the stages of one scene step alike. */
    PTR_PAGE_STEP = 1 << 20,
    PTR_PAGE_BANK_RUNS = 512,
    /* Bytes a bank holds at most: pages beyond go back to the machine, so
     * that banking never keeps much more memory than giving back would. */
    PTR_PAGE_BANK_BYTES = 128 << 20,
};

typedef struct PtrPageBank {
    struct PtrPageRun {
        char *at;
        size_t bytes;
    } run[PTR_PAGE_BANK_RUNS]; /* each one mapping of its own */
    size_t first, runs; /* those held: run[first .. runs - 1], oldest first */
    size_t bytes;
    /* The mappings the process may hold while the bank moves pages, set
     * at its first count, and the moves it may make before it counts them
     * again (each may split a mapping): see bank_open in memory.c. */
    size_t mappings_most, moves_left;
    /* The kernel would not move pages, or the mappings came near
     * mappings_most: the bank holds no pages and gives back those put. */
    int refused;
} PtrPageBank;

/* Takes from base the pages that lie wholly inside base[0 .. to - 1] but
 * not wholly inside base[0 .. from - 1], keeping them mapped: they read as
 * zero afterwards. They go to bank while it has room, else back to the
 * machine (bank NULL: for a stage's last step, whose pages no take
 * follows). For a caller that has finished with base[0 .. to - 1] and
 * gives it up as it goes through it, each call's from the last one's to,
 * so that every whole page goes once. */
void ptr_pages_put(PtrPageBank *bank, void *base, size_t from, size_t to);

/* Puts pages from bank in place of those that lie wholly inside
 * base[from .. to - 1], as many as it has and while it may still move them,
 * for a caller that writes every byte of the range before reading any: a
 * page taken from the bank holds what its last array left there. The rest
 * stay as they were. A move the kernel refuses gives the bank's pages back
 * and stops it. Returns 0 only where the kernel ran out of memory in the
 * middle of a move and the range could not be mapped again: then the caller
 * must not write it, and fails for memory. */
int ptr_pages_take(PtrPageBank *bank, void *base, size_t from, size_t to);

/* Gives back the pages bank still holds; it is then as a new one, and
 * sets its ceiling of mappings afresh at its next count (see bank_open in
 * memory.c): a bank carried from one stage to the next, given back between
 * them, allows each stage what a bank of its own would. */
void ptr_pages_free(PtrPageBank *bank);

#endif /* PTR_MEMORY_H */
