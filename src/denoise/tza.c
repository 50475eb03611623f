#include "denoise/tza.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* The fewest bytes an entry of the table takes: a name's length (2), the
 * dimension count (1), one dimension (4), one letter of layout (1), the
 * type (1) and the data's offset (8). */
enum { MIN_ENTRY = 2 + 1 + 4 + 1 + 1 + 8, TZA_MAGIC = 0x41D7, TZA_MAJOR = 2 };

typedef struct Reader {
    const unsigned char *bytes;
    size_t size, at; /* at <= size */
} Reader;

/* The little-endian unsigned number of width bytes at p. */
static uint64_t little_endian(const unsigned char *p, int width)
{
    uint64_t v = 0;
    for (int i = width - 1; i >= 0; i--)
        v = v << 8 | p[i];
    return v;
}

/* The number of width bytes at the reader, which it passes: 0 if the bytes
 * run out. */
static int read_uint(Reader *r, int width, uint64_t *value)
{
    if (r->size - r->at < (size_t)width)
        return 0;
    *value = little_endian(r->bytes + r->at, width);
    r->at += (size_t)width;
    return 1;
}

/* ptr_error_set with the archive's name before the message. */
static PtrResult bad(PtrError *err, const char *name, const char *fmt, ...)
{
    char message[sizeof err->message];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(message, sizeof message, fmt, ap);
    va_end(ap);
    return ptr_error_set(err, PTR_ERR_INSTALL, "%s: %s", name, message);
}

/* IEEE binary16 to float: every half is a float exactly. */
static float half_to_float(uint16_t h)
{
    int exponent = h >> 10 & 31, mantissa = h & 1023;
    float magnitude = exponent == 0    ? ldexpf((float)mantissa, -24)
                      : exponent == 31 ? (mantissa ? NAN : INFINITY)
                                       : ldexpf((float)(mantissa | 1024), exponent - 25);
    return h >> 15 ? -magnitude : magnitude;
}

/* Converts count elements of the type at bytes into floats. */
static void widen(const unsigned char *bytes, char type, size_t count, float *data)
{
    for (size_t i = 0; i < count; i++) {
        if (type == 'h') {
            data[i] = half_to_float((uint16_t)little_endian(bytes + 2 * i, 2));
        } else {
            uint32_t bits = (uint32_t)little_endian(bytes + 4 * i, 4);
            memcpy(&data[i], &bits, sizeof bits);
        }
    }
}

/* Entry index of the table at the reader into t. */
static PtrResult read_tensor(Reader *r, const char *name, size_t index, PtrTensor *t,
                             PtrError *err)
{
    uint64_t length, ndims, dim, type, offset;
    if (!read_uint(r, 2, &length) || r->size - r->at < length)
        return bad(err, name, "truncated: the table ends within tensor %zu's name", index);
    const char *text = (const char *)r->bytes + r->at;
    if (memchr(text, '\0', length))
        return bad(err, name, "tensor %zu's name holds a NUL byte", index);
    char *own = malloc(length + 1);
    if (!own)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", name);
    memcpy(own, text, length);
    own[length] = '\0';
    t->name = own;
    r->at += length;
    if (!read_uint(r, 1, &ndims))
        return bad(err, name, "truncated: the table ends within tensor %zu (%s)", index, own);
    if (ndims < 1 || ndims > PTR_TENSOR_MAX_DIMS)
        return bad(err, name, "tensor %zu (%s) has %u dimensions, not 1 to %d", index, own,
                   (unsigned)ndims, PTR_TENSOR_MAX_DIMS);
    t->ndims = (int)ndims;
    t->count = 1;
    for (int d = 0; d < t->ndims; d++) {
        if (!read_uint(r, 4, &dim))
            return bad(err, name, "truncated: the table ends within tensor %zu (%s)", index, own);
        if (dim == 0)
            return bad(err, name, "tensor %zu (%s): dimension %d is 0", index, own, d);
        /* Bounded by the file long before size_t overflows (checked below
         * against its bytes), but a hostile product must not wrap first. */
        if (t->count > SIZE_MAX / 4 / dim)
            return bad(err, name, "tensor %zu (%s) has more elements than any file holds", index,
                       own);
        t->dims[d] = (uint32_t)dim;
        t->count *= (size_t)dim;
    }
    if (r->size - r->at < (size_t)t->ndims)
        return bad(err, name, "truncated: the table ends within tensor %zu (%s)", index, own);
    for (int d = 0; d < t->ndims; d++) {
        char letter = (char)r->bytes[r->at++];
        if (letter < 'a' || letter > 'z')
            return bad(err, name, "tensor %zu (%s): its layout is not %d letters", index, own,
                       t->ndims);
        t->layout[d] = letter;
    }
    if (!read_uint(r, 1, &type) || !read_uint(r, 8, &offset))
        return bad(err, name, "truncated: the table ends within tensor %zu (%s)", index, own);
    if (type != 'f' && type != 'h')
        return bad(err, name, "tensor %zu (%s): element type 0x%02x is neither 'f' nor 'h'",
                   index, own, (unsigned)type);
    size_t element = type == 'h' ? 2 : 4;
    if (t->count > r->size / element || offset > r->size ||
        t->count * element > r->size - offset)
        return bad(err, name,
                   "truncated: tensor %zu (%s), %zu elements of %zu bytes at byte %llu, runs "
                   "past the end of the file (%zu bytes)",
                   index, own, t->count, element, (unsigned long long)offset, r->size);
    t->data = malloc(t->count * sizeof *t->data);
    if (!t->data)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory for tensor %s", name, own);
    widen(r->bytes + offset, (char)type, t->count, t->data);
    return PTR_OK;
}

static int by_name(const void *a, const void *b)
{
    return strcmp((*(const PtrTensor *const *)a)->name, (*(const PtrTensor *const *)b)->name);
}

/* Two tensors of one name would make ptr_tza_find's answer depend on the
 * order: refused. Sorted, so that a table of millions stays quick. */
static PtrResult check_names(const char *name, const PtrTensorArchive *archive, PtrError *err)
{
    const PtrTensor **sorted = malloc((archive->count ? archive->count : 1) * sizeof *sorted);
    if (!sorted)
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", name);
    for (size_t i = 0; i < archive->count; i++)
        sorted[i] = &archive->tensors[i];
    qsort(sorted, archive->count, sizeof *sorted, by_name);
    PtrResult res = PTR_OK;
    for (size_t i = 1; res == PTR_OK && i < archive->count; i++)
        if (!strcmp(sorted[i - 1]->name, sorted[i]->name))
            res = bad(err, name, "two tensors are named '%s'", sorted[i]->name);
    free(sorted);
    return res;
}

PtrResult ptr_tza_parse(const char *name, const void *bytes, size_t size,
                        PtrTensorArchive **out, PtrError *err)
{
    Reader r = { bytes, size, 0 };
    uint64_t magic, major, minor, table, count;
    if (!read_uint(&r, 2, &magic) || !read_uint(&r, 1, &major) || !read_uint(&r, 1, &minor) ||
        !read_uint(&r, 8, &table))
        return bad(err, name, "truncated: %zu bytes, too few for a tensor archive's header",
                   size);
    if (magic != TZA_MAGIC)
        return bad(err, name, "not a tensor archive (.tza): no magic number");
    if (major != TZA_MAJOR)
        return bad(err, name, "tensor archive version %u.%u, where ptr reads %d.x",
                   (unsigned)major, (unsigned)minor, TZA_MAJOR);
    if (table > size)
        return bad(err, name, "truncated: its table lies at byte %llu, past the end (%zu bytes)",
                   (unsigned long long)table, size);
    r.at = (size_t)table;
    if (!read_uint(&r, 4, &count))
        return bad(err, name, "truncated: the file ends within its table");
    /* A count no file of this size can hold is refused before anything is
     * allocated for it. */
    if (count > (size - r.at) / MIN_ENTRY)
        return bad(err, name, "truncated: its table lists %llu tensors, more than its %zu bytes "
                   "can hold",
                   (unsigned long long)count, size - r.at);
    PtrTensorArchive *archive = calloc(1, sizeof *archive);
    if (archive)
        archive->tensors = calloc(count ? (size_t)count : 1, sizeof *archive->tensors);
    if (!archive || !archive->tensors) {
        free(archive);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", name);
    }
    PtrResult res = PTR_OK;
    for (size_t i = 0; res == PTR_OK && i < count; i++) {
        archive->count = i + 1; /* so that ptr_tza_free frees what it holds */
        res = read_tensor(&r, name, i, &archive->tensors[i], err);
    }
    if (res == PTR_OK)
        res = check_names(name, archive, err);
    if (res != PTR_OK) {
        ptr_tza_free(archive);
        return res;
    }
    *out = archive;
    return PTR_OK;
}

PtrResult ptr_tza_read(const char *path, PtrTensorArchive **out, PtrError *err)
{
    FILE *f = fopen(path, "rb");
    if (!f && errno == ENOENT)
        return bad(err, path,
                   "cannot open: %s: scripts/install-deps.sh installs the denoiser's weights "
                   "(or set PTR_WEIGHTS_DIR to their folder)",
                   strerror(errno));
    if (!f)
        return bad(err, path, "cannot open: %s", strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(f);
        return bad(err, path, "not a file");
    }
    if (st.st_size > PTR_TZA_MAX_BYTES) {
        fclose(f);
        return bad(err, path, "%lld bytes, more than any weight file (%d at most)",
                   (long long)st.st_size, PTR_TZA_MAX_BYTES);
    }
    size_t size = (size_t)st.st_size;
    unsigned char *bytes = malloc(size ? size : 1);
    if (!bytes) {
        fclose(f);
        return ptr_error_set(err, PTR_ERR_NOMEM, "%s: out of memory", path);
    }
    size_t got = fread(bytes, 1, size, f);
    fclose(f);
    PtrResult res = got == size ? ptr_tza_parse(path, bytes, size, out, err)
                                : bad(err, path, "cannot read: %zu of %zu bytes", got, size);
    free(bytes);
    return res;
}

const PtrTensor *ptr_tza_find(const PtrTensorArchive *archive, const char *name)
{
    for (size_t i = 0; i < archive->count; i++)
        if (!strcmp(archive->tensors[i].name, name))
            return &archive->tensors[i];
    return NULL;
}

void ptr_tza_free(PtrTensorArchive *archive)
{
    if (!archive)
        return;
    for (size_t i = 0; i < archive->count; i++) {
        free((char *)archive->tensors[i].name);
        free(archive->tensors[i].data);
    }
    free(archive->tensors);
    free(archive);
}
