/* Giving memory back (ptr_pages_put, and ptr_spheres_release over a
 * scene's arrays): exactly the pages the contract names leave the process
 * (mincore says which pages are resident), every byte the caller has not
 * finished with keeps its value, and releasing a range in steps, each from
 * where the last ended, leaves no page of it behind; a page bank moving
 * those pages under another array's (ptr_pages_take), their bytes with
 * them, across the mappings that leaves, and holding no more than its
 * limits of bytes and of moves; the material array's entries, 1 byte a
 * sphere until the materials need more; and the hash, which needs memory
 * for the file's order, failing without it. */
#define _DEFAULT_SOURCE /* mincore */
#include "test.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/memory.h"
#include "scene/scene.h"

enum { PAGES = 64 };

static size_t page_size(void)
{
    return (size_t)sysconf(_SC_PAGESIZE);
}

/* A buffer of PAGES pages starting mid-page, as a malloc block may: the
 * mapping around it, and where the buffer starts in it. */
typedef struct Buffer {
    unsigned char *map, *data;
    size_t bytes;
} Buffer;

/* Nothing resident yet. */
static Buffer buffer_fresh(void)
{
    const size_t page = page_size();
    Buffer b = { mmap(NULL, (PAGES + 2) * page, PROT_READ | PROT_WRITE,
                      MAP_PRIVATE | MAP_ANONYMOUS, -1, 0), NULL, PAGES * page };
    if (b.map == MAP_FAILED)
        abort();
    b.data = b.map + page / 2;
    return b;
}

/* Every byte written: byte i of the map is 1 + i % 251. */
static Buffer buffer_make(void)
{
    Buffer b = buffer_fresh();
    for (size_t i = 0; i < (PAGES + 2) * page_size(); i++)
        b.map[i] = (unsigned char)(1 + i % 251);
    return b;
}

static int resident(const Buffer *b, size_t page_index)
{
    unsigned char in_core = 0;
    if (mincore(b->map + page_index * page_size(), page_size(), &in_core) != 0)
        abort();
    return in_core & 1;
}

/* Whether exactly pages expect_first .. expect_end - 1 of b->map are
 * released, no byte outside data[0 .. to - 1] (which the caller has
 * finished with) changed, and none inside it other than zero or its old
 * value. */
static void check_released(const Buffer *b, size_t to, size_t expect_first, size_t expect_end,
                           const char *what)
{
    const size_t page = page_size();
    size_t wrong_pages = 0, changed_outside = 0, garbled_inside = 0;
    for (size_t p = 0; p < PAGES + 2; p++)
        wrong_pages += resident(b, p) != !(p >= expect_first && p < expect_end);
    for (size_t i = 0; i < (PAGES + 2) * page; i++) {
        const unsigned char old = (unsigned char)(1 + i % 251);
        const size_t at = i - (size_t)(b->data - b->map); /* wraps below data */
        if (i < (size_t)(b->data - b->map) || at >= to)
            changed_outside += b->map[i] != old;
        else
            garbled_inside += b->map[i] != old && b->map[i] != 0;
    }
    if (wrong_pages || changed_outside || garbled_inside)
        fprintf(stderr, "%s: %zu pages wrongly resident or released, %zu bytes changed "
                        "outside, %zu garbled inside\n", what, wrong_pages, changed_outside,
                garbled_inside);
    CHECK_INT(wrong_pages, 0);
    CHECK_INT(changed_outside, 0);
    CHECK_INT(garbled_inside, 0);
}

/* data starts half a page into map[0]: pages 1 .. are data's whole pages. */
static void test_release_whole_pages_only(void)
{
    const size_t page = page_size();
    Buffer b = buffer_make();
    /* From mid-page 3 of the map to mid-page 9: pages 1 and 2 lie wholly
     * below from, released by an earlier call if any; 3 .. 8 are released,
     * 9 holds bytes past to. */
    const size_t from = 3 * page, to = 9 * page;
    ptr_pages_put(NULL, b.data, from, to);
    check_released(&b, to, 3, 9, "one range");
    munmap(b.map, (PAGES + 2) * page);

    /* From 0: data's own first page is shared with what comes before. */
    b = buffer_make();
    ptr_pages_put(NULL, b.data, 0, b.bytes);
    check_released(&b, b.bytes, 1, PAGES, "the whole buffer");
    munmap(b.map, (PAGES + 2) * page);

    /* Nothing whole inside: nothing released. */
    b = buffer_make();
    ptr_pages_put(NULL, b.data, page / 4, page / 4 + page / 2);
    check_released(&b, page / 4 + page / 2, 0, 0, "less than a page");
    munmap(b.map, (PAGES + 2) * page);
}

/* Steps that end mid-page leave no page behind: each starts at the page the
 * last one stopped before. */
static void test_release_in_steps(void)
{
    const size_t page = page_size();
    Buffer b = buffer_make();
    const size_t step = 3 * page + 1000;
    size_t from = 0;
    for (size_t to = step; from < b.bytes; to += step) {
        if (to > b.bytes)
            to = b.bytes;
        ptr_pages_put(NULL, b.data, from, to);
        from = to;
    }
    check_released(&b, b.bytes, 1, PAGES, "in steps");
    munmap(b.map, (PAGES + 2) * page);
}

/* Whether page p of b->map holds the bytes buffer_make wrote to page
 * source of a buffer's map. */
static int holds_page_of(const Buffer *b, size_t p, size_t source)
{
    const size_t page = page_size();
    size_t differ = 0;
    for (size_t i = 0; i < page; i++)
        differ += b->map[p * page + i] != (unsigned char)(1 + (source * page + i) % 251);
    return differ == 0;
}

/* Pages put in a bank leave their array as ptr_pages_put says, and a take
 * puts them, bytes and all, under another array's whole pages, in the
 * order they were put; a take larger than the bank leaves the rest of its
 * range as it was. */
static void test_bank_moves_pages(void)
{
    const size_t page = page_size();
    PtrPageBank bank = { 0 };
    Buffer from = buffer_make(), to = buffer_fresh();
    ptr_pages_put(&bank, from.data, 0, 10 * page);           /* map pages 1 .. 9 */
    ptr_pages_put(&bank, from.data, 10 * page, 20 * page);   /* 10 .. 19 */
    check_released(&from, 20 * page, 1, 20, "put in a bank");
    CHECK_INT(bank.refused, 0);
    CHECK_INT(bank.runs, 2);
    CHECK(bank.bytes == 19 * page);
    /* to's whole pages from data[page]: map pages 2 .. 29, of which the
     * bank fills 2 .. 20 with from's 1 .. 9, then 10 .. 19. */
    ptr_pages_take(&bank, to.data, page, 30 * page);
    CHECK_INT(bank.runs, 0);
    CHECK(bank.bytes == 0);
    size_t wrong = 0;
    for (size_t p = 1; p < 20; p++)
        wrong += !holds_page_of(&to, 1 + p, p);
    CHECK_INT(wrong, 0);
    size_t resident_after = 0;
    for (size_t p = 21; p < PAGES + 2; p++)
        resident_after += resident(&to, p);
    CHECK_INT(resident_after, 0);
    CHECK_INT(resident(&to, 1), 0);
    ptr_pages_free(&bank);
    munmap(from.map, (PAGES + 2) * page);
    munmap(to.map, (PAGES + 2) * page);
}

/* An array filled from a bank is one mapping for each run it took: putting
 * a range across them banks every page still, and the pages travel on. */
static void test_bank_across_mappings(void)
{
    const size_t page = page_size();
    PtrPageBank bank = { 0 }, again = { 0 };
    Buffer a = buffer_make(), b = buffer_make(), to = buffer_fresh(), last = buffer_fresh();
    ptr_pages_put(&bank, a.data, 0, 8 * page);   /* a's map pages 1 .. 7 */
    ptr_pages_put(&bank, b.data, 0, 12 * page);  /* b's 1 .. 11 */
    ptr_pages_take(&bank, to.data, page, 30 * page); /* to's 2 .. 8 from a, 9 .. 19 from b */
    CHECK(bank.bytes == 0);
    /* From the middle of a's run to the middle of b's: map pages 5 .. 16. */
    ptr_pages_put(&again, to.data, 4 * page + page / 2, 17 * page);
    CHECK_INT(again.refused, 0);
    CHECK(again.bytes == 12 * page);
    CHECK(again.runs >= 2);
    size_t resident_left = 0;
    for (size_t p = 5; p < 17; p++)
        resident_left += resident(&to, p);
    CHECK_INT(resident_left, 0);
    ptr_pages_take(&again, last.data, page, 20 * page); /* last's 2 .. 13 */
    CHECK(again.bytes == 0);
    /* Whatever the runs' order, each of to's pages 5 .. 16 arrives once:
     * a's pages 4 .. 7 and b's 1 .. 8 (a and b were written alike, so
     * the bytes of pages 4 .. 7 arrive twice). */
    size_t found[12] = { 0 }, stray = 0;
    for (size_t p = 2; p < 14; p++) {
        size_t q = 1;
        while (q < 12 && !holds_page_of(&last, p, q))
            q++;
        if (q < 12)
            found[q]++;
        else
            stray++;
    }
    CHECK_INT(stray, 0);
    size_t wrong = 0;
    for (size_t q = 1; q < 12; q++)
        wrong += found[q] != (size_t)(q >= 4 && q <= 7) + (size_t)(q <= 8);
    CHECK_INT(wrong, 0);
    munmap(a.map, (PAGES + 2) * page);
    munmap(b.map, (PAGES + 2) * page);
    munmap(to.map, (PAGES + 2) * page);
    munmap(last.map, (PAGES + 2) * page);
}

/* A bank holds at most PTR_PAGE_BANK_BYTES: the rest of a put goes back to
 * the machine, and freeing the bank gives back what it holds. */
static void test_bank_limit(void)
{
    const size_t page = page_size(), bytes = (size_t)PTR_PAGE_BANK_BYTES + 64 * page;
    unsigned char *array = mmap(NULL, bytes, PROT_READ | PROT_WRITE,
                                MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (array == MAP_FAILED)
        abort();
    memset(array, 7, bytes);
    PtrPageBank bank = { 0 };
    ptr_pages_put(&bank, array, 0, PTR_PAGE_BANK_BYTES - 16 * page);
    ptr_pages_put(&bank, array, PTR_PAGE_BANK_BYTES - 16 * page, bytes);
    CHECK(bank.bytes == PTR_PAGE_BANK_BYTES - 16 * page); /* the second did not fit */
    unsigned char in_core[64];
    CHECK_INT(mincore(array + bytes - 64 * page, 64 * page, in_core), 0);
    size_t kept = 0;
    for (size_t p = 0; p < 64; p++)
        kept += in_core[p] & 1;
    CHECK_INT(kept, 0);
    CHECK_INT(array[bytes - 1], 0);
    ptr_pages_free(&bank);
    CHECK(bank.bytes == 0 && bank.runs == 0);
    munmap(array, bytes);
}

/* Takes go from the oldest run on; a bank whose runs fill its array after
 * some were taken moves those it holds to the front for the next. */
static void test_bank_runs_wrap(void)
{
    const size_t page = page_size(), pages = PTR_PAGE_BANK_RUNS + 2;
    unsigned char *from = mmap(NULL, pages * page, PROT_READ | PROT_WRITE,
                               MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    unsigned char *to = mmap(NULL, pages * page, PROT_READ | PROT_WRITE,
                             MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (from == MAP_FAILED || to == MAP_FAILED)
        abort();
    for (size_t p = 0; p < pages; p++)
        memcpy(from + p * page, &p, sizeof p);
    PtrPageBank bank = { 0 };
    for (size_t p = 0; p < PTR_PAGE_BANK_RUNS; p++) /* a run a page */
        ptr_pages_put(&bank, from, p * page, (p + 1) * page);
    CHECK_INT(bank.runs, PTR_PAGE_BANK_RUNS);
    ptr_pages_take(&bank, to, 0, 2 * page); /* from's pages 0 and 1 */
    CHECK_INT(bank.first, 2);
    ptr_pages_put(&bank, from, PTR_PAGE_BANK_RUNS * page, pages * page);
    CHECK(bank.first == 0 && bank.runs == PTR_PAGE_BANK_RUNS - 1);
    CHECK(bank.bytes == (pages - 2) * page);
    ptr_pages_take(&bank, to, 2 * page, pages * page);
    CHECK(bank.bytes == 0 && bank.runs == 0);
    size_t wrong = 0;
    for (size_t p = 0; p < pages; p++) {
        size_t held;
        memcpy(&held, to + p * page, sizeof held);
        wrong += held != p;
    }
    CHECK_INT(wrong, 0);
    ptr_pages_free(&bank);
    munmap(from, pages * page);
    munmap(to, pages * page);
}

/* The process's mappings: the lines of /proc/self/maps. */
static size_t mappings_held(void)
{
    FILE *f = fopen("/proc/self/maps", "r");
    size_t lines = 0;
    for (int c; f && (c = getc(f)) != EOF;)
        lines += c == '\n';
    if (f)
        fclose(f);
    return lines;
}

/* How the child of test_bank_moves_limit ends. */
enum { CHILD_PASSED = 0, CHILD_FAILED = 3, CHILD_SKIPPED = 4 };

/* A bank whose process comes to have no room for mappings: it gives back
 * the pages it holds and those put since, b's pages 1 .. 7. Run in a child
 * (fork): the bank takes b's first pages while there is room; then the
 * child maps pages one at a time, every other one read-only so that none
 * joins its neighbour, until the kernel refuses, and unmaps two (room for
 * the allocator's own, a sanitizer's too, and less than a bank's
 * quarter). CHILD_SKIPPED where something else (an address space limit)
 * stopped the mapping first. */
static int bank_without_room(const Buffer *b, size_t max_maps)
{
    const size_t page = page_size();
    PtrPageBank bank = { 0 };
    ptr_pages_put(&bank, b->data, 0, 4 * page);
    int failed = bank.bytes != 3 * page;
    void *last[2] = { NULL, NULL };
    for (size_t k = 0; k < max_maps; k++) {
        void *map = mmap(NULL, page, k % 2 ? PROT_READ : PROT_READ | PROT_WRITE,
                         MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (map == MAP_FAILED)
            break;
        last[k % 2] = map;
    }
    for (int k = 0; k < 2; k++)
        if (last[k])
            munmap(last[k], page);
    if (mappings_held() + 4 <= max_maps)
        return CHILD_SKIPPED;
    bank.moves_left = 0; /* as if it had made its moves: it counts again */
    ptr_pages_put(&bank, b->data, 4 * page, 8 * page);
    failed += !bank.refused + (bank.bytes != 0) + (bank.runs != 0);
    for (size_t p = 1; p < 8; p++)
        failed += resident(b, p);
    return failed ? CHILD_FAILED : CHILD_PASSED;
}

/* A bank sets a ceiling at its first count (the mappings held and a
 * quarter of the room left), counts the mappings again each time it has
 * made the moves its last count allowed (a put's or a take's, one a run:
 * as many as there were mappings left under the ceiling), and gives its
 * pages back when it comes near that ceiling. The child below uses up the
 * kernel's own room, not just the ceiling's, so that the count runs where
 * mapping anything more fails. */
static void test_bank_moves_limit(void)
{
    const size_t page = page_size();
    PtrPageBank bank = { 0 };
    Buffer b = buffer_make();
    ptr_pages_put(&bank, b.data, 0, 4 * page);
    FILE *f = fopen("/proc/sys/vm/max_map_count", "r");
    unsigned long max_maps = 0;
    CHECK(f && fscanf(f, "%lu", &max_maps) == 1);
    if (f)
        fclose(f);
    CHECK(bank.moves_left > 0 && bank.moves_left < max_maps / 4);
    CHECK(bank.mappings_most > 0 && bank.mappings_most < max_maps);
    CHECK(bank.bytes == 3 * page);
    bank.moves_left = 1;
    ptr_pages_put(&bank, b.data, 4 * page, 8 * page); /* its last move */
    CHECK(bank.bytes == 7 * page && bank.moves_left == 0);
    ptr_pages_put(&bank, b.data, 8 * page, 12 * page); /* counted again */
    CHECK(bank.bytes == 11 * page && bank.moves_left > 0 && !bank.refused);
    check_released(&b, 12 * page, 1, 12, "a bank that counted again");
    /* A take counts its moves, one a run (three here)... */
    bank.moves_left = 5;
    Buffer to = buffer_fresh();
    CHECK_INT(ptr_pages_take(&bank, to.data, page, 20 * page), 1);
    CHECK(bank.bytes == 0 && bank.moves_left == 2);
    /* ...and counts again in the middle of one. */
    Buffer more = buffer_make(), to_more = buffer_fresh();
    ptr_pages_put(&bank, more.data, 0, 4 * page);
    ptr_pages_put(&bank, more.data, 4 * page, 8 * page);
    CHECK(bank.bytes == 7 * page && bank.runs - bank.first == 2);
    bank.moves_left = 1;
    CHECK_INT(ptr_pages_take(&bank, to_more.data, page, 20 * page), 1);
    CHECK(bank.bytes == 0 && bank.moves_left > 0 && !bank.refused);
    /* Given back, a bank is as a new one, as the tree's build wants of the
     * bank it carries from stage to stage: one that had stopped banks
     * again, under a ceiling counted afresh. */
    bank.refused = 1;
    bank.mappings_most = 1;
    ptr_pages_free(&bank);
    Buffer again = buffer_make();
    ptr_pages_put(&bank, again.data, 0, 4 * page);
    CHECK(!bank.refused && bank.bytes == 3 * page && bank.mappings_most > 1);
    ptr_pages_free(&bank);
    Buffer *buffers[] = { &b, &to, &more, &to_more, &again };
    for (size_t k = 0; k < sizeof buffers / sizeof buffers[0]; k++)
        munmap(buffers[k]->map, (PAGES + 2) * page);

    /* Where a process may hold many more mappings than the kernel's
     * default 65,530, using them up would take long and kernel memory. */
    if (max_maps > (1u << 17)) {
        fprintf(stderr, "vm.max_map_count is %lu: a bank without room not checked\n",
                max_maps);
        return;
    }
    b = buffer_make();
    fflush(NULL);
    const pid_t child = fork();
    if (child == 0)
        _exit(bank_without_room(&b, max_maps));
    int status = -1;
    CHECK(child > 0 && waitpid(child, &status, 0) == child);
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    if (code == CHILD_SKIPPED)
        fprintf(stderr, "a child could not use up its mappings: a bank without room not "
                        "checked\n");
    else if (code != CHILD_PASSED)
        fprintf(stderr, "the child without room ended with status %d\n", status);
    CHECK(code == CHILD_PASSED || code == CHILD_SKIPPED);
    munmap(b.map, (PAGES + 2) * page);
}

/* The tree's use: a scene's arrays, released up to a count, keep the rest
 * (the spheres after the tree and the padding) and value whole. */
static void test_spheres_release(void)
{
    PtrScene scene;
    ptr_scene_init(&scene);
    const size_t count = 300000, kept = 1000;
    CHECK_INT(ptr_spheres_resize(&scene.spheres, count + kept, NULL), PTR_OK);
    PtrSpheres *s = &scene.spheres;
    CHECK_INT(ptr_spheres_make_ids(s, NULL), PTR_OK);
    size_t failed_values = 0;
    for (size_t i = 0; i < count + kept; i++) {
        s->cx[i] = s->cy[i] = s->cz[i] = (float)i;
        s->radius[i] = 1.0f;
        ptr_sphere_set_material(s, i, 7);
        s->id[i] = (uint32_t)i;
        failed_values += ptr_scene_set_sphere_value(&scene, i, 2.0f, NULL) != PTR_OK;
    }
    CHECK_INT(failed_values, 0);
    ptr_spheres_release(s, NULL, 0, count / 2);
    ptr_spheres_release(s, NULL, count / 2, count);
    size_t zeroed = 0, changed_after = 0, values_changed = 0;
    for (size_t i = 0; i < count; i++)
        zeroed += s->cx[i] == 0.0f && s->radius[i] == 0.0f && s->id[i] == 0;
    for (size_t i = count; i < count + kept; i++)
        changed_after += s->cx[i] != (float)i || s->radius[i] != 1.0f ||
                         ptr_sphere_material(s, i) != 7 || s->id[i] != i;
    for (size_t i = 0; i < count + kept; i++)
        values_changed += s->value[i] != 2.0f;
    /* All but the first and the last page of each array below count, which
     * hold bytes of its own and of what lies past it. */
    CHECK(zeroed >= count - 2 * page_size() / sizeof(float));
    CHECK_INT(changed_after, 0);
    CHECK_INT(values_changed, 0);
    CHECK(isnan(s->radius[count + kept])); /* padding */
    ptr_scene_free(&scene);
}

/* The arrays every store of a sphere writes take pages from a bank, the
 * bytes of the arrays put (none zero here, where a fresh page is zero
 * throughout); id and value, which a store does not write, take none. */
static void test_spheres_take_pages(void)
{
    const size_t count = 1 << 20, taken_count = count / 4;
    PtrScene from, to;
    ptr_scene_init(&from);
    ptr_scene_init(&to);
    CHECK_INT(ptr_spheres_resize(&from.spheres, count, NULL), PTR_OK);
    CHECK_INT(ptr_spheres_resize(&to.spheres, count, NULL), PTR_OK);
    CHECK_INT(ptr_spheres_make_ids(&to.spheres, NULL), PTR_OK);
    CHECK_INT(ptr_spheres_make(&to.spheres, (void **)&to.spheres.value, NULL), PTR_OK);
    PtrSpheres *s = &from.spheres;
    for (size_t i = 0; i < count; i++) {
        s->cx[i] = s->cy[i] = s->cz[i] = s->radius[i] = 1.1f; /* bits 0x3f8ccccd */
        ptr_sphere_set_material(s, i, 7);
    }
    PtrPageBank bank = { 0 };
    ptr_spheres_release(s, &bank, 0, count);
    const size_t banked = bank.bytes;
    CHECK_INT(ptr_spheres_take_pages(&to.spheres, &bank, 0, taken_count), 1);
    CHECK(banked > 0 && bank.bytes < banked);
    /* Each stored array's whole pages below taken_count came from the
     * bank: resident, and no byte zero. */
    const size_t page = page_size();
    const unsigned char *stored[5] = { (void *)to.spheres.cx, (void *)to.spheres.cy,
                                       (void *)to.spheres.cz, (void *)to.spheres.radius,
                                       to.spheres.material };
    const size_t entry[5] = { 4, 4, 4, 4, 1 };
    size_t pages = 0, fresh = 0;
    unsigned char in_core;
    for (int k = 0; k < 5; k++) {
        const uintptr_t mask = ~(uintptr_t)(page - 1), at = (uintptr_t)stored[k];
        const uintptr_t first = (at + page - 1) & mask, end = (at + taken_count * entry[k]) & mask;
        for (uintptr_t p = first; p < end; p += page) {
            CHECK_INT(mincore((void *)p, page, &in_core), 0);
            size_t zeros = 0;
            for (size_t i = 0; i < page; i++)
                zeros += ((const unsigned char *)p)[i] == 0;
            fresh += !(in_core & 1) || zeros > 0;
            pages++;
        }
    }
    CHECK(pages > 5 * 40);
    CHECK_INT(fresh, 0);
    size_t untouched = 0;
    const void *other[2] = { to.spheres.id, to.spheres.value };
    for (int k = 0; k < 2; k++) {
        const uintptr_t p = ((uintptr_t)other[k] + 2 * page) & ~(uintptr_t)(page - 1);
        CHECK_INT(mincore((void *)p, page, &in_core), 0);
        untouched += !(in_core & 1);
    }
    CHECK_INT(untouched, 2);
    ptr_pages_free(&bank);
    ptr_scene_free(&from);
    ptr_scene_free(&to);
}

/* Adds materials until the scene has count. */
static void add_materials(PtrScene *scene, size_t count)
{
    const PtrMaterial m = { .kind = PTR_MATERIAL_DIFFUSE, .albedo = { 0.5f, 0.5f, 0.5f } };
    uint32_t index;
    while (scene->material_count < count)
        CHECK_INT(ptr_scene_add_material(scene, &m, &index, NULL), PTR_OK);
}

/* 1 byte a sphere up to 256 materials, 2 up to 65,536, then 4; widening
 * keeps every index, and padding entries stay 0. */
static void test_material_widths(void)
{
    PtrScene scene;
    ptr_scene_init(&scene);
    add_materials(&scene, 256);
    const size_t count = 1000;
    for (size_t i = 0; i < count; i++)
        CHECK_INT(ptr_scene_add_sphere(&scene, v3(0, 0, (float)i), 1.0f, (uint32_t)(i % 256), NULL),
                  PTR_OK);
    PtrSpheres *s = &scene.spheres;
    CHECK_INT(s->material_size, 1);
    const size_t sizes[2] = { 2, 4 }, counts[2] = { 257, 65537 };
    for (int w = 0; w < 2; w++) {
        add_materials(&scene, counts[w]);
        CHECK_INT(s->material_size, sizes[w]);
        ptr_sphere_set_material(s, count - 1, (uint32_t)(counts[w] - 1));
        size_t kept = 0;
        for (size_t i = 0; i + 1 < count; i++)
            kept += ptr_sphere_material(s, i) == i % 256;
        CHECK_INT(kept, count - 1);
        CHECK_INT(ptr_sphere_material(s, count - 1), counts[w] - 1);
        for (size_t i = count; i < s->capacity; i++)
            CHECK_INT(ptr_sphere_material(s, i), 0);
    }
    ptr_scene_free(&scene);
}

/* The address space the process has mapped, in bytes. */
static size_t mapped_bytes(void)
{
    unsigned long pages = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        CHECK_INT(fscanf(f, "%lu", &pages), 1);
        fclose(f);
    }
    return pages * page_size();
}

/* Sanitizers reserve terabytes of address space: a limit means nothing
 * there. */
#if defined(__SANITIZE_ADDRESS__)
#define ADDRESS_LIMITS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ADDRESS_LIMITS 0
#endif
#endif
#ifndef ADDRESS_LIMITS
#define ADDRESS_LIMITS 1
#endif

/* The hash takes the spheres in the file's order: a scene whose first
 * sphere the importer put last (its id saying so) hashes as the same scene
 * in order, its materials (two bytes each: more than 256) and colours too,
 * over a last block of the gather cut short; a sphere's other material or
 * colour makes another fingerprint; the value is the one the build gave
 * while a colour was 8 bytes, 65535 the fourth (it is recorded in images,
 * and parts merge by it); and where that order cannot be
 * allocated, the hash fails with PTR_ERR_NOMEM instead of giving a
 * fingerprint of the arrays' order. */
static void test_hash_in_file_order(void)
{
    enum {
        COUNT = (1 << 22) + 37, /* 16 MB of order: more than the limit leaves */
        MATERIALS = 300,
    };
    PtrScene in_order, reordered;
    ptr_scene_init(&in_order);
    ptr_scene_init(&reordered);
    for (int m = 0; m < MATERIALS; m++) {
        const PtrMaterial material = { .kind = PTR_MATERIAL_DIFFUSE,
                                       .albedo = v3((float)m / MATERIALS, 0.5f, 0.5f) };
        uint32_t index;
        CHECK_INT(ptr_scene_add_material(&in_order, &material, &index, NULL), PTR_OK);
        CHECK_INT(ptr_scene_add_material(&reordered, &material, &index, NULL), PTR_OK);
    }
    CHECK_INT(ptr_spheres_resize(&in_order.spheres, COUNT, NULL), PTR_OK);
    CHECK_INT(ptr_spheres_resize(&reordered.spheres, COUNT, NULL), PTR_OK);
    CHECK_INT(ptr_spheres_make_ids(&reordered.spheres, NULL), PTR_OK);
    CHECK_INT(ptr_spheres_make(&in_order.spheres, (void **)&in_order.spheres.color, NULL), PTR_OK);
    CHECK_INT(ptr_spheres_make(&reordered.spheres, (void **)&reordered.spheres.color, NULL),
              PTR_OK);
    CHECK_INT((int)in_order.spheres.material_size, 2);
    for (size_t i = 0; i < COUNT; i++) {
        const size_t file = (i + 1) % COUNT; /* sphere 0 of the file last */
        PtrSpheres *a = &in_order.spheres, *b = &reordered.spheres;
        a->cx[i] = a->cy[i] = a->cz[i] = (float)i;
        a->radius[i] = i ? 1.0f : 1000.0f;
        ptr_sphere_set_material(a, i, (uint32_t)(i % MATERIALS));
        b->cx[i] = b->cy[i] = b->cz[i] = (float)file;
        b->radius[i] = file ? 1.0f : 1000.0f;
        ptr_sphere_set_material(b, i, (uint32_t)(file % MATERIALS));
        b->id[i] = (uint32_t)file;
        for (int k = 0; k < 3; k++) {
            a->color[3 * i + k] = (uint16_t)(i * 4 + (size_t)k);
            b->color[3 * i + k] = (uint16_t)(file * 4 + (size_t)k);
        }
    }
    uint64_t expected = 0, hash = 1;
    CHECK_INT(ptr_scene_hash(&in_order, &expected, NULL), PTR_OK);
    CHECK_INT(ptr_scene_hash(&reordered, &hash, NULL), PTR_OK);
    CHECK(hash == expected);
    CHECK(expected == UINT64_C(0x36e6d3396303b865));
    if (ADDRESS_LIMITS) {
        struct rlimit old, tight;
        CHECK_INT(getrlimit(RLIMIT_AS, &old), 0);
        tight = old;
        tight.rlim_cur = mapped_bytes() + ((size_t)1 << 20);
        CHECK_INT(setrlimit(RLIMIT_AS, &tight), 0);
        PtrError err = { 0 };
        hash = 1;
        const PtrResult r = ptr_scene_hash(&reordered, &hash, &err);
        CHECK_INT(setrlimit(RLIMIT_AS, &old), 0);
        CHECK_INT(r, PTR_ERR_NOMEM);
        CHECK(hash == 1 && err.code == PTR_ERR_NOMEM && err.message[0]);
    }
    /* After the limit's case, whose order is the first allocated: glibc
     * keeps a freed order in its heap for the next. */
    ptr_sphere_set_material(&reordered.spheres, COUNT - 1, 1); /* the file's first */
    CHECK_INT(ptr_scene_hash(&reordered, &hash, NULL), PTR_OK);
    CHECK(hash != expected);
    ptr_sphere_set_material(&reordered.spheres, COUNT - 1, 0);
    reordered.spheres.color[3 * (COUNT - 1) + 2] ^= 1;
    CHECK_INT(ptr_scene_hash(&reordered, &hash, NULL), PTR_OK);
    CHECK(hash != expected);
    reordered.spheres.color[3 * (COUNT - 1) + 2] ^= 1;
    ptr_scene_free(&in_order);
    ptr_scene_free(&reordered);
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_release_whole_pages_only),
        TEST_CASE(test_release_in_steps),
        TEST_CASE(test_bank_moves_pages),
        TEST_CASE(test_bank_across_mappings),
        TEST_CASE(test_bank_limit),
        TEST_CASE(test_bank_moves_limit),
        TEST_CASE(test_bank_runs_wrap),
        TEST_CASE(test_spheres_release),
        TEST_CASE(test_spheres_take_pages),
        TEST_CASE(test_material_widths),
        TEST_CASE(test_hash_in_file_order),
    };
    TEST_RUN(cases);
    return test_report();
}
