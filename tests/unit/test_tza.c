/* Tensor archives (denoise/tza.h) the test writes itself: a float32 and a
 * float16 tensor read back exactly; every truncation, and hostile tables
 * (offsets past the end or wrapping, counts and sizes no file holds, bad
 * magic, version, layout, type, dimensions, names), each one error that
 * names the file; every byte of a good file flipped, never a crash; a file
 * that is missing, or is a folder. */
#include "denoise/tza.h"
#include "test.h"

#include <unistd.h>

typedef struct Bytes {
    unsigned char data[1024];
    size_t size;
} Bytes;

static void put(Bytes *b, uint64_t value, int width)
{
    for (int i = 0; i < width; i++)
        b->data[b->size++] = (unsigned char)(value >> (8 * i));
}

static void put_text(Bytes *b, const char *text)
{
    memcpy(b->data + b->size, text, strlen(text));
    b->size += strlen(text);
}

static void pad(Bytes *b)
{
    while (b->size % 64)
        b->data[b->size++] = 0;
}

/* A table entry, as OIDN's writer lays it out. */
static void put_entry(Bytes *b, const char *name, int ndims, const uint32_t *dims,
                      const char *layout, char type, uint64_t offset)
{
    put(b, strlen(name), 2);
    put_text(b, name);
    put(b, (uint64_t)ndims, 1);
    for (int d = 0; d < ndims; d++)
        put(b, dims[d], 4);
    put_text(b, layout);
    put(b, (uint64_t)type, 1);
    put(b, offset, 8);
}

static const float weights[2 * 1 * 1 * 3] = { 0.5f, -1.25f, 3e-5f, 1e30f, -0.0f, 7.0f };
/* 1, -2.5, the smallest subnormal (2^-24), infinity, 65504 (the largest). */
static const uint16_t halves[5] = { 0x3C00, 0xC100, 0x0001, 0x7C00, 0x7BFF };
static const float halves_as_floats[5] = { 1.0f, -2.5f, 0x1p-24f, INFINITY, 65504.0f };

enum { TABLE_AT = 4 };

/* A good archive: first (oihw 2x1x1x3, float32) and second (x 5,
 * float16). */
static Bytes archive_named(const char *first, const char *second)
{
    Bytes b = { .size = 0 };
    put(&b, 0x41D7, 2);
    put(&b, 2, 1);
    put(&b, 0, 1);
    put(&b, 0, 8); /* the table's offset, below */
    pad(&b);
    size_t weight_at = b.size;
    for (int i = 0; i < 6; i++) {
        uint32_t bits;
        memcpy(&bits, &weights[i], sizeof bits);
        put(&b, bits, 4);
    }
    pad(&b);
    size_t bias_at = b.size;
    for (int i = 0; i < 5; i++)
        put(&b, halves[i], 2);
    pad(&b);
    size_t table = b.size;
    put(&b, 2, 4);
    put_entry(&b, first, 4, (const uint32_t[]){ 2, 1, 1, 3 }, "oihw", 'f', weight_at);
    put_entry(&b, second, 1, (const uint32_t[]){ 5 }, "x", 'h', bias_at);
    size_t end = b.size;
    b.size = TABLE_AT;
    put(&b, table, 8);
    b.size = end;
    return b;
}

static Bytes good_archive(void)
{
    return archive_named("conv.weight", "conv.bias");
}

static void test_good(void)
{
    Bytes b = good_archive();
    PtrTensorArchive *archive = NULL;
    PtrError err = { 0 };
    CHECK_INT(ptr_tza_parse("good.tza", b.data, b.size, &archive, &err), PTR_OK);
    if (!archive)
        return;
    CHECK_INT((int)archive->count, 2);
    const PtrTensor *w = ptr_tza_find(archive, "conv.weight");
    const PtrTensor *bias = ptr_tza_find(archive, "conv.bias");
    CHECK(w && bias && !ptr_tza_find(archive, "conv"));
    if (w && bias) {
        CHECK_INT(w->ndims, 4);
        CHECK_STR(w->layout, "oihw");
        CHECK_INT((int)w->dims[0], 2);
        CHECK_INT((int)w->dims[3], 3);
        CHECK_INT((int)w->count, 6);
        CHECK(!memcmp(w->data, weights, sizeof weights));
        CHECK_STR(bias->layout, "x");
        CHECK_INT((int)bias->count, 5);
        CHECK(!memcmp(bias->data, halves_as_floats, sizeof halves_as_floats));
    }
    ptr_tza_free(archive);
}

/* Sets width bytes at byte at of b to value. */
static void patch(Bytes *b, size_t at, uint64_t value, int width)
{
    size_t end = b->size;
    b->size = at;
    put(b, value, width);
    b->size = end;
}

/* b refused with one error that names the file and says says. */
static void expect_refused(const char *what, const Bytes *b, const char *says)
{
    PtrTensorArchive *archive = NULL;
    PtrError err = { 0 };
    PtrResult res = ptr_tza_parse("hostile.tza", b->data, b->size, &archive, &err);
    if (res == PTR_OK) {
        TEST_FAIL_("%s: parsed", what);
        ptr_tza_free(archive);
    } else if (res != PTR_ERR_INSTALL)
        TEST_FAIL_("%s: %s", what, err.message);
    else if (strncmp(err.message, "hostile.tza: ", 13) || !strstr(err.message, says))
        TEST_FAIL_("%s: '%s' does not name the file and say '%s'", what, err.message, says);
}

/* The good archive with one field patched, refused. */
static void expect_patch_refused(const char *what, size_t at, uint64_t value, int width,
                                 const char *says)
{
    Bytes b = good_archive();
    patch(&b, at, value, width);
    expect_refused(what, &b, says);
}

static void test_hostile(void)
{
    Bytes good = good_archive();
    size_t table = 0;
    for (int i = 7; i >= 0; i--)
        table = table << 8 | good.data[TABLE_AT + i];
    /* The first entry: count (4), name length (2) and "conv.weight" (11),
     * ndims (1), four dims (16), "oihw" (4), type (1), offset (8). */
    const size_t entry = table + 4, ndims = entry + 2 + 11, dims = ndims + 1,
                 layout = dims + 16, type = layout + 4, offset = type + 1;
    expect_patch_refused("magic", 0, 0x1234, 2, "not a tensor archive");
    expect_patch_refused("version", 2, 1, 1, "version 1.0");
    expect_patch_refused("table past the end", TABLE_AT, 1u << 20, 8, "past the end");
    expect_patch_refused("table at 2^64-1", TABLE_AT, UINT64_MAX, 8, "past the end");
    expect_patch_refused("count of 2^32-1", table, 0xFFFFFFFFu, 4, "more than its");
    expect_patch_refused("count of 3", table, 3, 4, "truncated");
    expect_patch_refused("name past the end", entry, 0xFFFF, 2, "truncated");
    expect_patch_refused("a NUL in a name", entry + 2, 0, 1, "NUL");
    expect_patch_refused("no dimensions", ndims, 0, 1, "0 dimensions");
    expect_patch_refused("9 dimensions", ndims, 9, 1, "9 dimensions");
    expect_patch_refused("a zero dimension", dims + 4, 0, 4, "dimension 1 is 0");
    expect_patch_refused("2^32-1 elements", dims, 0xFFFFFFFFu, 4, "runs past the end");
    expect_patch_refused("layout", layout, '4', 1, "layout");
    expect_patch_refused("type", type, 'd', 1, "neither 'f' nor 'h'");
    expect_patch_refused("data past the end", offset, good.size - 8, 8, "runs past the end");
    expect_patch_refused("data offset near 2^64", offset, UINT64_MAX - 8, 8, "runs past the end");
    /* Four dimensions of 2^32-1: a product that would wrap 64 bits. */
    Bytes huge = good_archive();
    for (int d = 0; d < 4; d++)
        patch(&huge, dims + 4 * (size_t)d, 0xFFFFFFFFu, 4);
    expect_refused("dimensions wrapping", &huge, "more elements than any file holds");
    Bytes twice = archive_named("conv.bias", "conv.bias");
    expect_refused("two tensors of one name", &twice, "two tensors are named 'conv.bias'");
    /* Every prefix of the file is truncated somewhere: the table comes last. */
    for (size_t size = 0; size < good.size; size++) {
        Bytes cut = good;
        cut.size = size;
        expect_refused("a truncated file", &cut, "truncated");
    }
}

/* Every byte of a good file set to each of a few values: parsed or refused
 * with a message, never read out of bounds (the sanitizers' builds hold it
 * to that). */
static void test_flipped_bytes(void)
{
    const Bytes good = good_archive();
    const unsigned char values[] = { 0x00, 0x01, 0x7F, 0x80, 0xFF };
    int parsed = 0, refused = 0;
    for (size_t at = 0; at < good.size; at++)
        for (size_t v = 0; v < sizeof values; v++) {
            Bytes b = good;
            b.data[at] = values[v];
            PtrTensorArchive *archive = NULL;
            PtrError err = { 0 };
            if (ptr_tza_parse("flipped.tza", b.data, b.size, &archive, &err) == PTR_OK) {
                parsed++;
                ptr_tza_free(archive);
            } else {
                refused++;
                CHECK(!strncmp(err.message, "flipped.tza: ", 13));
            }
        }
    printf("flipped bytes: %d archives parsed, %d refused\n", parsed, refused);
    CHECK(parsed > 0 && refused > 0);
}

/* From a file: the same tensors; a missing file or a folder, one error
 * naming it. */
static void test_files(void)
{
    const Bytes good = good_archive();
    char path[] = "/tmp/ptr-tza-XXXXXX", missing[sizeof path + 8];
    int fd = mkstemp(path);
    CHECK(fd >= 0 && write(fd, good.data, good.size) == (ssize_t)good.size);
    if (fd >= 0)
        close(fd);
    snprintf(missing, sizeof missing, "%s.missing", path);
    PtrTensorArchive *archive = NULL;
    PtrError err = { 0 };
    CHECK_INT(ptr_tza_read(path, &archive, &err), PTR_OK);
    CHECK(archive && archive->count == 2);
    ptr_tza_free(archive);
    CHECK_INT(ptr_tza_read(missing, &archive, &err), PTR_ERR_INSTALL);
    CHECK(strstr(err.message, missing) && strstr(err.message, "cannot open"));
    CHECK_INT(ptr_tza_read("/tmp", &archive, &err), PTR_ERR_INSTALL);
    CHECK(strstr(err.message, "not a file"));
    CHECK_INT(ptr_tza_read(path, &archive, NULL), PTR_OK); /* err may be NULL */
    ptr_tza_free(archive);
    CHECK_INT(ptr_tza_read(missing, &archive, NULL), PTR_ERR_INSTALL);
    unlink(path);
}

int main(void)
{
    const TestCase cases[] = { TEST_CASE(test_good), TEST_CASE(test_hostile),
                               TEST_CASE(test_flipped_bytes), TEST_CASE(test_files) };
    TEST_RUN(cases);
    return test_report();
}
