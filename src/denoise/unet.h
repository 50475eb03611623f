/* Open Image Denoise's U-Nets, built from the tensors of a weight archive
 * and run on one tile: 3x3 convolutions (ReLU after all but the last), four
 * 2x2 max-poolings on the way down, four nearest-neighbour upsamplings on
 * the way up, each followed by the concatenation of the encoder's feature
 * map of that size (docs/denoise.md). */
#ifndef PTR_UNET_H
#define PTR_UNET_H

#include <stddef.h>

#include "base/cpu.h"
#include "base/result.h"
#include "denoise/conv.h"

/* Channels of the networks' outputs: colour, albedo or normal. */
enum { PTR_UNET_OUTPUT_CHANNELS = 3 };

/* Four poolings: a tile's sides are multiples of 16. */
enum { PTR_UNET_ALIGNMENT = 16 };

/* n rounded up to a multiple of PTR_UNET_ALIGNMENT. */
static inline size_t ptr_unet_align(size_t n)
{
    return (n + PTR_UNET_ALIGNMENT - 1) / PTR_UNET_ALIGNMENT * PTR_UNET_ALIGNMENT;
}

/* The most convolutions a network has (OIDN's UNetLarge). */
enum { PTR_UNET_MAX_CONVS = 19 };

/* One convolution and what surrounds it in the network. */
typedef struct PtrUnetConv {
    size_t in, out;  /* padded channels, multiples of PTR_CONV_BLOCK */
    float *weights;  /* packed (conv.h) */
    float *bias;     /* out floats, zero past the tensor's */
    int level;       /* the resolution it runs at: 1 / 2^level */
    int concat;      /* -1: it reads the map before it; else that map upsampled,
                      * followed by pooled map number concat (0: the input) */
    size_t concat_channels; /* that map's padded channels */
    int pool;        /* 0; or its output is pooled into map number pool */
} PtrUnetConv;

typedef struct PtrUnet {
    int count; /* convolutions, in the order they run */
    PtrUnetConv conv[PTR_UNET_MAX_CONVS];
    PtrConvTable table;
} PtrUnet;

/* The network whose weights are in the archive at path, which takes
 * input_channels channels (9: colour, albedo and normal; 3: one of them),
 * its convolutions run through the kernel table of this CPU level. Both of
 * OIDN's architectures: UNet (enc_conv0 .. dec_conv0) and UNetLarge
 * (enc_conv1a .. dec_conv1c), told apart as OIDN does, by enc_conv1b.
 * PTR_ERR_INSTALL naming the file for a tensor missing or of a shape other
 * than the network's; PTR_ERR_NOMEM. */
PtrResult ptr_unet_load(const char *path, size_t input_channels, PtrCpuLevel level,
                        PtrUnet **out, PtrError *err);

void ptr_unet_free(PtrUnet *unet);

/* The overlap tiles on the pooling grid need, so that each pixel a tile
 * keeps is the whole image's to the bit: how far past an edge on the grid
 * the pixels beside it reach into the input, rounded up to the grid. A 3x3
 * convolution at level k reaches 2^k pixels further, plus one pixel where
 * an odd reach at one level meets the coarser level (UNet: 80 pixels,
 * UNetLarge: 94, so 96; from a pixel off the grid, up to 94 and 108). */
size_t ptr_unet_overlap(const PtrUnet *unet);

/* Feature maps kept for reuse. A tile's run takes its maps from here and
 * gives them back, so that the next tile's maps are the same memory: each
 * new page costs a fault and the kernel's zeroing (at 1920x1080, maps new
 * to every step cost 1.2 million faults, about 3.5 s of system time
 * against 16 s of user time), and a map's interior need not be zeroed at
 * all, since the step that makes it writes it whole. */
typedef struct PtrUnetMaps PtrUnetMaps;

/* An empty set of maps, or NULL when memory runs out. */
PtrUnetMaps *ptr_unet_maps_new(void);

/* Frees every map of the set, given back or not. */
void ptr_unet_maps_free(PtrUnetMaps *maps);

/* A feature map of width x height pixels and channels channels with its
 * border (conv.h) zero and its interior as it was last left (to be
 * written whole before it is read), 64-byte aligned; the least of the
 * set's free maps that is large enough, else a new one; NULL when memory
 * runs out. */
float *ptr_unet_map_take(PtrUnetMaps *maps, size_t width, size_t height, size_t channels);

/* Gives back a map taken from maps (NULL: nothing). */
void ptr_unet_map_give(PtrUnetMaps *maps, float *map);

/* Runs the network on a tile of width x height pixels (multiples of
 * PTR_UNET_ALIGNMENT): input is a feature map of PTR_CONV_BLOCK channels
 * (its border zero), output one of PTR_CONV_BLOCK channels too, of which
 * the first PTR_UNET_OUTPUT_CHANNELS hold the result. The maps between
 * come from maps and are given back. Each layer's rows are split between
 * threads threads; the result does not depend on how. PTR_ERR_NOMEM. */
PtrResult ptr_unet_run(const PtrUnet *unet, PtrUnetMaps *maps, const float *input, size_t width,
                       size_t height, int threads, float *output, PtrError *err);

/* The network's two resamplings, on feature maps with borders (only their
 * interiors are written), rows y0 .. y1 - 1 of the output:
 * 2x2 max-pooling of a map of 2*width x 2*height into width x height... */
void ptr_unet_pool(float *dst, const float *src, size_t width, size_t channels, size_t y0,
                   size_t y1);

/* ...and nearest upsampling of a map of width/2 x height/2 with up_channels
 * channels, concatenated with a map of width x height with skip_channels:
 * dst has up_channels + skip_channels. */
void ptr_unet_upsample_concat(float *dst, const float *up, size_t up_channels, const float *skip,
                              size_t skip_channels, size_t width, size_t y0, size_t y1);

#endif /* PTR_UNET_H */
