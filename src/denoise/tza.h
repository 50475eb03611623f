/* Tensor archives (.tza): the container Open Image Denoise keeps its trained
 * weights in. A file is a header (the magic 0x41D7, version 2.x, the offset
 * of the table), the tensors' data, each aligned to 64 bytes, and the table:
 * a count, then for each tensor its name, its dimensions, its layout (one
 * letter a dimension: "oihw" for a convolution's weights, "x" for a
 * vector), its element type (float32 'f' or float16 'h') and the offset of
 * its data. Every number is little-endian. */
#ifndef PTR_TZA_H
#define PTR_TZA_H

#include <stddef.h>
#include <stdint.h>

#include "base/result.h"

enum { PTR_TENSOR_MAX_DIMS = 4 };

/* One tensor, its elements as floats (float16 widened) in the file's order:
 * row-major over dims, the last fastest. */
typedef struct PtrTensor {
    const char *name;
    int ndims;
    uint32_t dims[PTR_TENSOR_MAX_DIMS];
    char layout[PTR_TENSOR_MAX_DIMS + 1]; /* ndims letters */
    size_t count;                         /* the product of dims */
    float *data;
} PtrTensor;

typedef struct PtrTensorArchive {
    size_t count;
    PtrTensor *tensors; /* in the table's order */
} PtrTensorArchive;

/* The archive held in size bytes, named name in messages, into *out (for
 * ptr_tza_free): PTR_OK; PTR_ERR_INSTALL with one line naming it and what
 * is wrong for anything but a whole, well-formed archive (every size and
 * offset is checked against the bytes there are: a truncated, oversized or
 * hostile file is an error, never a read out of bounds); PTR_ERR_NOMEM. */
PtrResult ptr_tza_parse(const char *name, const void *bytes, size_t size,
                        PtrTensorArchive **out, PtrError *err);

/* The archive in the file at path, as ptr_tza_parse reads it; a file that
 * cannot be read, or of more than PTR_TZA_MAX_BYTES, is PTR_ERR_INSTALL
 * too (weight files come with the installation), the message saying why
 * (and, for a file that does not exist, how to install the weights). */
enum { PTR_TZA_MAX_BYTES = 1 << 30 };
PtrResult ptr_tza_read(const char *path, PtrTensorArchive **out, PtrError *err);

/* The tensor of this name, or NULL. */
const PtrTensor *ptr_tza_find(const PtrTensorArchive *archive, const char *name);

void ptr_tza_free(PtrTensorArchive *archive);

#endif /* PTR_TZA_H */
