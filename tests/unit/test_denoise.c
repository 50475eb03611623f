/* The denoiser's parts that have closed forms (denoise/transfer.h,
 * denoise/unet.h): the PU transfer function and its inverse, the guides'
 * mappings for their own networks (sRGB, [-1, 1] to [0, 1]), the exposure
 * of constant images, pooling and upsampling, the tiles' overlap for each
 * architecture; its errors: a quality that
 * does not exist, a missing weight file (for each quality), one that
 * cannot be read, an archive whose tensors are not the U-Net's. The networks themselves are checked
 * against NumPy by check_denoise_network. */
#include "denoise/denoise.h"
#include "denoise/transfer.h"
#include "denoise/unet.h"
#include "test.h"

#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

static void pu_round_trip(void)
{
    for (float y = 1e-9f; y < 65504.0f; y *= 1.37f) {
        float back = ptr_pu_inverse(ptr_pu_forward(y));
        CHECK_NEAR(back / y, 1.0, 2e-5);
    }
    CHECK_FLOAT_EQ(ptr_pu_forward(0.0f), 0.0f);
    /* The three pieces meet where the curve's constants say. */
    CHECK_NEAR(ptr_pu_forward(1.57945760e-06f), 2.23151711e-03, 1e-8);
    CHECK_NEAR(ptr_pu_forward(3.22087631e-02f), 3.70974749e-01, 1e-6);
    PtrTransfer t;
    ptr_transfer_init(&t, 2.0f);
    float color[3] = { 65504.0f / 2, 1.0f, 0.0f }, albedo[3] = { -1.0f, 0.5f, 2.0f },
          normal[3] = { -2.0f, 0.0f, NAN }, in[9], out[3];
    ptr_transfer_input(&t, color, albedo, normal, in);
    CHECK_NEAR(in[0], 1.0, 1e-6); /* the largest value maps to 1 */
    CHECK_FLOAT_EQ(in[2], 0.0f);
    CHECK_FLOAT_EQ(in[3], 0.0f);
    CHECK_FLOAT_EQ(in[4], 0.5f);
    CHECK_FLOAT_EQ(in[5], 1.0f);
    CHECK_FLOAT_EQ(in[6], 0.0f);
    CHECK_FLOAT_EQ(in[7], 0.5f);
    CHECK_FLOAT_EQ(in[8], 0.5f);
    ptr_transfer_output(&t, in, out);
    for (int k = 0; k < 3; k++)
        CHECK_NEAR(out[k], color[k], 2e-5 * color[k]);
}

static void guides_round_trip(void)
{
    for (float y = 1e-6f; y <= 1.0f; y *= 1.21f)
        CHECK_NEAR(ptr_srgb_inverse(ptr_srgb_forward(y)) / y, 1.0, 1e-5);
    CHECK_NEAR(ptr_srgb_forward(1.0f), 1.0, 1e-6);
    float albedo[3] = { 0.25f, 1.5f, NAN }, normal[3] = { -0.6f, 0.8f, 3.0f }, x[3], back[3];
    ptr_transfer_albedo_input(albedo, x);
    CHECK_NEAR(x[1], 1.0, 1e-6); /* clamped to 1 first */
    CHECK_FLOAT_EQ(x[2], 0.0f);
    ptr_transfer_albedo_output(x, back);
    CHECK_NEAR(back[0], 0.25, 1e-6);
    CHECK_FLOAT_EQ(back[1], 1.0f);
    CHECK_FLOAT_EQ(back[2], 0.0f);
    ptr_transfer_normal_input(normal, x);
    CHECK_NEAR(x[0], 0.2, 1e-7);
    CHECK_FLOAT_EQ(x[2], 1.0f);
    ptr_transfer_normal_output(x, back);
    CHECK_NEAR(back[0], -0.6, 1e-6);
    CHECK_NEAR(back[1], 0.8, 1e-6);
    CHECK_FLOAT_EQ(back[2], 1.0f);
    float below[3] = { -1.0f, NAN, 7.0f }; /* a network's output out of range */
    ptr_transfer_normal_output(below, back);
    CHECK_FLOAT_EQ(back[0], -1.0f);
    CHECK_FLOAT_EQ(back[1], -1.0f);
    CHECK_FLOAT_EQ(back[2], 1.0f);
}

static void autoexposure_of_constant_images(void)
{
    enum { W = 37, H = 21 };
    static float image[W * H * 4];
    for (size_t i = 0; i < W * H; i++) {
        image[4 * i] = 0.5f;
        image[4 * i + 1] = 2.0f;
        image[4 * i + 2] = 4.0f;
        image[4 * i + 3] = NAN; /* the fourth float is not read */
    }
    double luminance = 0.212671 * 0.5 + 0.715160 * 2.0 + 0.072169 * 4.0;
    CHECK_NEAR(ptr_autoexposure(image, 4, W, H), 0.18 / luminance, 1e-6);
    memset(image, 0, sizeof image);
    CHECK_FLOAT_EQ(ptr_autoexposure(image, 4, W, H), 1.0f);
}

static void pooling_and_upsampling(void)
{
    enum { C = PTR_CONV_BLOCK, W = 4, H = 4 };
    float src[(W + 2) * (H + 2) * C] = { 0 }, pooled[(W / 2 + 2) * (H / 2 + 2) * C] = { 0 };
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < C; c++)
                src[((y + 1) * (W + 2) + x + 1) * C + c] = (float)((y * 7 + x * 3) % 5 - c);
    ptr_unet_pool(pooled, src, W / 2, C, 0, H / 2);
    for (int y = 0; y < H / 2; y++)
        for (int x = 0; x < W / 2; x++)
            for (int c = 0; c < C; c++) {
                float m = -1e30f;
                for (int k = 0; k < 4; k++) {
                    float v = (float)(((2 * y + k / 2) * 7 + (2 * x + k % 2) * 3) % 5 - c);
                    m = v > m ? v : m;
                }
                CHECK_FLOAT_EQ(pooled[((y + 1) * (W / 2 + 2) + x + 1) * C + c], m);
            }
    float joined[(W + 2) * (H + 2) * 2 * C] = { 0 };
    ptr_unet_upsample_concat(joined, pooled, C, src, C, W, 0, H);
    for (int y = 0; y < H + 2; y++)
        for (int x = 0; x < W + 2; x++)
            for (int c = 0; c < 2 * C; c++) {
                float got = joined[(y * (W + 2) + x) * 2 * C + c];
                int inside = y > 0 && y <= H && x > 0 && x <= W;
                float want = !inside ? 0.0f
                             : c < C ? pooled[(((y - 1) / 2 + 1) * (W / 2 + 2) + (x - 1) / 2 + 1) * C + c]
                                     : src[(y * (W + 2) + x) * C + c - C];
                CHECK_FLOAT_EQ(got, want);
            }
}

static void qualities(void)
{
    PtrDenoiseQuality q;
    PtrError err;
    CHECK_INT(ptr_denoise_quality_parse("fast", &q, NULL), PTR_OK);
    CHECK_INT(q, PTR_DENOISE_FAST);
    CHECK_INT(ptr_denoise_quality_parse("balanced", &q, NULL), PTR_OK);
    CHECK_INT(q, PTR_DENOISE_BALANCED);
    CHECK_INT(ptr_denoise_quality_parse("high", &q, NULL), PTR_OK);
    CHECK_INT(q, PTR_DENOISE_HIGH);
    CHECK_INT(ptr_denoise_quality_parse("best", &q, &err), PTR_ERR_USAGE);
    CHECK(strstr(err.message, "'best'") != NULL);
}

static void missing_weights(void)
{
    PtrDenoiser *d = NULL;
    PtrError err;
    CHECK_INT(ptr_denoiser_new(PTR_DENOISE_BALANCED, "/nonexistent/weights", PTR_CPU_NONE, &d,
                               &err),
              PTR_ERR_INSTALL);
    CHECK(strstr(err.message, "/nonexistent/weights/rt_hdr_alb_nrm.tza") != NULL);
    CHECK(strstr(err.message, "scripts/install-deps.sh") != NULL);
    CHECK(d == NULL);
    CHECK_INT(ptr_denoiser_new(PTR_DENOISE_FAST, "/nonexistent/weights", PTR_CPU_NONE, &d, NULL),
              PTR_ERR_INSTALL);
    /* High quality filters the albedo first. */
    CHECK_INT(ptr_denoiser_new(PTR_DENOISE_HIGH, "/nonexistent/weights", PTR_CPU_NONE, &d, &err),
              PTR_ERR_INSTALL);
    CHECK(strstr(err.message, "/nonexistent/weights/rt_alb_large.tza") != NULL);
    CHECK(d == NULL);
}

/* Writes an archive of one layer, enc_conv0, with in input channels. */
static void write_one_layer(const char *path, uint32_t in)
{
    FILE *f = fopen(path, "wb");
    uint32_t out = 32, count = out * in * 9;
    unsigned char header[16] = { 0xD7, 0x41, 2, 0 };
    uint64_t table = 64 + ((uint64_t)count * 4 + 63) / 64 * 64 + 128;
    memcpy(header + 4, &table, 8); /* the test runs on little-endian x86-64 */
    fwrite(header, 1, 12, f);
    for (long at = 12; at < (long)table; at++)
        fputc(0, f);
    uint32_t n = 2;
    fwrite(&n, 4, 1, f);
    const char *names[2] = { "enc_conv0.weight", "enc_conv0.bias" };
    uint64_t offsets[2] = { 64, table - 128 };
    for (int t = 0; t < 2; t++) {
        uint16_t length = (uint16_t)strlen(names[t]);
        fwrite(&length, 2, 1, f);
        fwrite(names[t], 1, length, f);
        unsigned char ndims = t ? 1 : 4;
        fputc(ndims, f);
        uint32_t dims[4] = { out, in, 3, 3 };
        fwrite(dims, 4, ndims, f);
        fwrite(t ? "x" : "oihw", 1, ndims, f);
        fputc('f', f);
        fwrite(&offsets[t], 8, 1, f);
    }
    fclose(f);
}

#define TEMP_FOLDER "/tmp/ptr_denoise_XXXXXX"
enum { PATH_SIZE = 64 };

/* A new folder, dir (of sizeof TEMP_FOLDER), for the balanced quality's
 * weight file, path (of PATH_SIZE). */
static void weights_folder(char *dir, char *path)
{
    strcpy(dir, TEMP_FOLDER);
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, PATH_SIZE, "%s/rt_hdr_alb_nrm.tza", dir);
}

/* The balanced denoiser of the weights in dir, which fails: its code, its
 * message in err. */
static PtrResult refused(const char *dir, PtrError *err)
{
    PtrDenoiser *d = NULL;
    PtrResult res = ptr_denoiser_new(PTR_DENOISE_BALANCED, dir, PTR_CPU_NONE, &d, err);
    CHECK(d == NULL);
    return res;
}

static void archives_not_a_unet(void)
{
    char dir[sizeof TEMP_FOLDER], path[PATH_SIZE];
    weights_folder(dir, path);
    PtrError err;
    write_one_layer(path, 8); /* the input has 9 channels */
    CHECK_INT(refused(dir, &err), PTR_ERR_INSTALL);
    CHECK(strstr(err.message, path) != NULL);
    CHECK(strstr(err.message, "enc_conv0.weight") != NULL);
    write_one_layer(path, 9); /* right, but the rest is missing */
    CHECK_INT(refused(dir, &err), PTR_ERR_INSTALL);
    CHECK(strstr(err.message, "no tensor enc_conv1.weight") != NULL);
    unlink(path);
    rmdir(dir);
}

/* A weight file that is there but cannot be read: the message says why, in
 * one line naming the file, and gives the installation's hint only where
 * the file is missing. */
static void weights_unreadable(void)
{
    char dir[sizeof TEMP_FOLDER], path[PATH_SIZE];
    weights_folder(dir, path);
    PtrError err;
    CHECK(mkdir(path, 0700) == 0); /* a folder where the file should be */
    CHECK_INT(refused(dir, &err), PTR_ERR_INSTALL);
    CHECK(strstr(err.message, path) && strstr(err.message, "not a file"));
    CHECK(!strstr(err.message, "install-deps") && !strchr(err.message, '\n'));
    rmdir(path);
    CHECK(symlink(path, path) == 0); /* a link to itself: stat fails, not for want of a file */
    CHECK_INT(refused(dir, &err), PTR_ERR_INSTALL);
    CHECK(strstr(err.message, path) && strstr(err.message, strerror(ELOOP)));
    CHECK(!strstr(err.message, "install-deps"));
    unlink(path);
    write_one_layer(path, 9);
    CHECK(chmod(path, 0) == 0);
    if (access(path, R_OK) != 0) { /* root reads it anyway */
        CHECK_INT(refused(dir, &err), PTR_ERR_INSTALL);
        CHECK(strstr(err.message, path) && strstr(err.message, strerror(EACCES)));
        CHECK(!strstr(err.message, "install-deps"));
    }
    unlink(path);
    rmdir(dir);
}

/* A network's layout as ptr_unet_load builds it, without weights: each
 * convolution's level, the pooled map it joins (-1: none) and the map its
 * output is pooled into (0: none), from OIDN's training/model.py. */
static void layout(PtrUnet *unet, const int (*convs)[3], int count)
{
    unet->count = count;
    for (int l = 0; l < count; l++) {
        unet->conv[l].level = convs[l][0];
        unet->conv[l].concat = convs[l][1];
        unet->conv[l].pool = convs[l][2];
    }
}

/* The overlap is the reach past a 16-pixel edge of the pixels beside it,
 * counted by hand: from dec_conv0 back, UNet's convolutions reach
 * 3 + 2 * 2 + 2 * 4 + 2 * 8 + 2 * 16 + 8 + 4 + 2 + 2 * 1 = 79 pixels, and
 * the first upsampling (3 convolutions at full size: an odd reach) cuts
 * one pixel more into the grid: 80. UNetLarge's reach 93, so 94, and 96 on
 * the grid. */
static void tile_overlaps(void)
{
    static const int unet[][3] = {
        { 0, -1, 0 }, { 0, -1, 1 }, { 1, -1, 2 }, { 2, -1, 3 }, { 3, -1, 4 }, { 4, -1, 0 },
        { 4, -1, 0 }, { 3, 3, 0 },  { 3, -1, 0 }, { 2, 2, 0 },  { 2, -1, 0 }, { 1, 1, 0 },
        { 1, -1, 0 }, { 0, 0, 0 },  { 0, -1, 0 }, { 0, -1, 0 },
    };
    static const int large[][3] = {
        { 0, -1, 0 }, { 0, -1, 1 }, { 1, -1, 0 }, { 1, -1, 2 }, { 2, -1, 0 },
        { 2, -1, 3 }, { 3, -1, 0 }, { 3, -1, 4 }, { 4, -1, 0 }, { 4, -1, 0 },
        { 3, 3, 0 },  { 3, -1, 0 }, { 2, 2, 0 },  { 2, -1, 0 }, { 1, 1, 0 },
        { 1, -1, 0 }, { 0, 0, 0 },  { 0, -1, 0 }, { 0, -1, 0 },
    };
    PtrUnet net = { 0 };
    layout(&net, unet, (int)(sizeof unet / sizeof unet[0]));
    CHECK_INT(ptr_unet_overlap(&net), 80);
    layout(&net, large, (int)(sizeof large / sizeof large[0]));
    CHECK_INT(ptr_unet_overlap(&net), 96);
    /* One 3x3 convolution, at full size: one pixel, 16 on the grid. */
    static const int one[][3] = { { 0, -1, 0 } };
    layout(&net, one, 1);
    CHECK_INT(ptr_unet_overlap(&net), 16);
}

int main(void)
{
    static const TestCase cases[] = {
        TEST_CASE(pu_round_trip),   TEST_CASE(guides_round_trip),
        TEST_CASE(autoexposure_of_constant_images),
        TEST_CASE(pooling_and_upsampling), TEST_CASE(qualities),
        TEST_CASE(missing_weights), TEST_CASE(archives_not_a_unet),
        TEST_CASE(weights_unreadable), TEST_CASE(tile_overlaps),
    };
    TEST_RUN(cases);
    return test_report();
}
