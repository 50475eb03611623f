/* The image module: every format but EXR through OpenImageIO, loaded at run
 * time by image.c when such a file is first written or read. */
#include "base/shim_error.h"
#include "base/version.h"
#include "image/image_backend.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <new>
#include <string>
#include <vector>

namespace {

OIIO::TypeDesc pixel_type(PtrPixelFormat format)
{
    switch (format) {
    case PTR_PIXEL_UINT8: return OIIO::TypeDesc::UINT8;
    case PTR_PIXEL_UINT16: return OIIO::TypeDesc::UINT16;
    case PTR_PIXEL_HALF: return OIIO::TypeDesc::HALF;
    case PTR_PIXEL_FLOAT: break;
    }
    return OIIO::TypeDesc::FLOAT;
}

int can_write(const char *path)
{
    try {
        return OIIO::ImageOutput::create(path) != nullptr;
    } catch (...) {
        return 0;
    }
}

PtrResult write_image(const char *file, const char *name, const PtrImageLayout *layout,
                      const float *rgb, const float *alpha, PtrPixelFormat format,
                      const PtrImageAttr *attrs, size_t attr_count, PtrError *err)
{
    try {
        auto out = OIIO::ImageOutput::create(name);
        if (!out)
            return ptr_shim_error(err, PTR_ERR_OUTPUT,
                                  std::string(name) + ": no image format for this extension");
        const size_t pixels = size_t(layout->width) * size_t(layout->height);
        std::vector<float> rgba(alpha ? pixels * 4 : 0);
        for (size_t p = 0; p < rgba.size() / 4; p++) {
            std::copy(rgb + 3 * p, rgb + 3 * p + 3, &rgba[4 * p]);
            rgba[4 * p + 3] = alpha[p];
        }
        OIIO::ImageSpec spec(layout->width, layout->height, alpha ? 4 : 3, pixel_type(format));
        spec.x = layout->x;
        spec.y = layout->y;
        spec.full_x = 0;
        spec.full_y = 0;
        spec.full_width = layout->full_width;
        spec.full_height = layout->full_height;
        // Every format here takes straight alpha, as ptr gives it: without
        // this, OpenImageIO would take the colour as premultiplied and divide
        // it by alpha once more.
        if (alpha)
            spec.attribute("oiio:UnassociatedAlpha", 1);
        for (size_t i = 0; i < attr_count; i++) {
            const PtrImageAttr &a = attrs[i];
            switch (a.type) {
            case PTR_ATTR_INT: spec.attribute(a.name, a.int_value); break;
            case PTR_ATTR_FLOAT: spec.attribute(a.name, a.float_value); break;
            case PTR_ATTR_STRING: spec.attribute(a.name, a.string_value); break;
            }
        }
        bool ok = out->open(file, spec) &&
                  out->write_image(OIIO::TypeDesc::FLOAT, alpha ? rgba.data() : rgb);
        ok = out->close() && ok;
        if (!ok)
            return ptr_shim_error(err, PTR_ERR_OUTPUT, std::string(name) + ": " + out->geterror());
        return PTR_OK;
    } catch (...) {
        return ptr_shim_caught(err, PTR_ERR_OUTPUT, name);
    }
}

// Standard error sent to /dev/null while it lives. libpng prints "libpng
// error: ..." itself before it hands OpenImageIO the message (its default
// handler runs after OpenImageIO's returns), and ptr says what failed in
// one line of its own: so while a texture (bytes in memory) decodes, which
// an import does before any render thread starts, stderr is quiet. No
// option of OpenImageIO 2.4 keeps libpng quiet (libpng's png_error calls
// the default handler whenever the reader's returns). If stderr cannot be
// saved, it is left as it is: a stray line beats losing it for good.
class QuietStderr {
public:
    QuietStderr()
    {
        std::fflush(stderr);
        saved_ = dup(STDERR_FILENO);
        if (saved_ < 0)
            return;
        const int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
        if (null >= 0) {
            dup2(null, STDERR_FILENO);
            close(null);
        }
    }
    ~QuietStderr()
    {
        if (saved_ < 0)
            return;
        std::fflush(stderr);
        dup2(saved_, STDERR_FILENO);
        close(saved_);
    }
    QuietStderr(const QuietStderr &) = delete;
    QuietStderr &operator=(const QuietStderr &) = delete;

private:
    int saved_;
};

// The reader of path's format opened on the bytes memory holds, which must
// outlive it, or null with *fault. ImageInput::open with a proxy looks for
// the file itself first and fails without one: the reader is made, then
// given the bytes.
OIIO::ImageInput::unique_ptr open_memory(const char *path, OIIO::Filesystem::IOProxy *memory,
                                         const OIIO::ImageSpec &config, std::string *fault)
{
    auto in = OIIO::ImageInput::create(path, false, &config, memory);
    OIIO::ImageSpec spec;
    if (!in)
        *fault = OIIO::geterror();
    else if (!in->set_ioproxy(memory) || !in->open(path, spec, config))
        *fault = in->geterror();
    else
        return in;
    return nullptr;
}

// The bits of the channels' one unsigned integer type, as
// ptr_image_bits_per_channel says; else 0.
int unsigned_bits(const OIIO::ImageSpec &spec)
{
    for (const OIIO::TypeDesc &channel : spec.channelformats)
        if (channel != spec.format)
            return 0;
    switch (spec.format.basetype) {
    case OIIO::TypeDesc::UINT8: return 8;
    case OIIO::TypeDesc::UINT16: return 16;
    case OIIO::TypeDesc::UINT32: return 32;
    default: return 0;
    }
}

PtrResult read_image(const char *path, const unsigned char *bytes, size_t size, PtrImage **out,
                     PtrError *err)
{
    PtrImage *image = nullptr;
    try {
        // Colour as stored, not premultiplied by alpha on the way in.
        OIIO::ImageSpec config;
        config.attribute("oiio:UnassociatedAlpha", 1);
        OIIO::Filesystem::IOMemReader memory(bytes, bytes ? size : 0);
        std::unique_ptr<QuietStderr> quiet(bytes ? new QuietStderr : nullptr);
        std::string fault;
        auto in = bytes ? open_memory(path, &memory, config, &fault)
                        : OIIO::ImageInput::open(path, &config);
        if (!in)
            return ptr_shim_error(err, PTR_ERR_USAGE,
                                  std::string(path) + ": " + (bytes ? fault : OIIO::geterror()));
        const OIIO::ImageSpec &spec = in->spec();
        std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
        if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()))
            return ptr_shim_error(err, PTR_ERR_USAGE, std::string(path) + ": " + in->geterror());
        size_t pixels = size_t(spec.width) * size_t(spec.height);
        image = ptr_image_alloc(pixels, spec.extra_attribs.size());
        if (!image)
            throw std::bad_alloc();
        image->layout = { spec.width, spec.height, spec.x, spec.y, spec.full_width, spec.full_height };
        image->bits_per_channel = unsigned_bits(spec);
        const int alpha = spec.alpha_channel;
        if (alpha >= 0 && !ptr_image_alloc_alpha(image))
            throw std::bad_alloc();
        for (size_t p = 0; p < pixels; p++) {
            for (int c = 0; c < 3; c++)
                image->rgb[3 * p + size_t(c)] =
                    all[p * size_t(spec.nchannels) + size_t(c < spec.nchannels && c != alpha ? c : 0)];
            if (alpha >= 0)
                image->alpha[p] = all[p * size_t(spec.nchannels) + size_t(alpha)];
        }
        size_t i = 0;
        for (const OIIO::ParamValue &param : spec.extra_attribs)
            if (!ptr_image_set_attr(image, i++, param.name().c_str(), param.get_string().c_str()))
                throw std::bad_alloc();
        in->close();
        *out = image;
        return PTR_OK;
    } catch (...) {
        ptr_image_release(image);
        return ptr_shim_caught(err, PTR_ERR_USAGE, path);
    }
}

} // namespace

extern "C" __attribute__((visibility("default"))) const PtrImageModule ptr_image_module = {
    sizeof(PtrImageModule), PTR_VERSION, can_write, write_image, read_image,
};
