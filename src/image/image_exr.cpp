/* EXR through OpenEXR, the format's reference library, linked in: it loads in
 * a few milliseconds, where OpenImageIO's 260 libraries take a core for a
 * quarter of a second. The files are those OpenImageIO wrote for ptr before
 * (tests/cli/test_exr.sh): zip compression, R, G, B at the depth asked and the
 * float "samples" channel of adaptive renders, a data window for regions, the
 * capture date, and every attribute ptr gives but OpenImageIO's own (oiio:*),
 * which it never wrote to EXR; and now the float layers of the albedo and
 * normal passes (--passes) and of a denoised image's noisy colour
 * (--denoise), which OpenImageIO did not write for ptr. */
#include "base/shim_error.h"
#include "image/image_backend.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <Imath/half.h>

#include <algorithm>
#include <climits>
#include <cstdlib>
#include <cstdio>
#include <ctime>
#include <new>
#include <string>
#include <utility>
#include <vector>

namespace {

const char *const rgb_names[3] = { "R", "G", "B" };
const char *const albedo_names[3] = { "albedo.R", "albedo.G", "albedo.B" };
const char *const normal_names[3] = { "normal.X", "normal.Y", "normal.Z" };
const char *const noisy_names[3] = { "noisy.R", "noisy.G", "noisy.B" };

/* "YYYY:MM:DD HH:MM:SS", local time: the form of EXR's capDate. */
std::string capture_date()
{
    char text[32] = "";
    std::time_t now = std::time(nullptr);
    std::tm local;
    if (localtime_r(&now, &local))
        std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &local);
    return text;
}

/* A slice of interleaved pixels whose first one sits at the data window's
 * corner: OpenEXR addresses a slice by absolute pixel coordinates. */
Imf::Slice slice(Imf::PixelType type, const char *first, size_t x_stride, size_t y_stride,
                 const PtrImageLayout &layout)
{
    const char *origin = first - layout.x * ptrdiff_t(x_stride) - layout.y * ptrdiff_t(y_stride);
    return Imf::Slice(type, const_cast<char *>(origin), x_stride, y_stride);
}

/* A layer of three float channels named names, interleaved in pixels, into
 * frame. */
void insert_layer(Imf::FrameBuffer &frame, const char *const names[3], const float *pixels,
                  const PtrImageLayout &layout)
{
    const char *first = reinterpret_cast<const char *>(pixels);
    for (size_t c = 0; c < 3; c++)
        frame.insert(names[c], slice(Imf::FLOAT, first + c * sizeof(float), 3 * sizeof(float),
                                     size_t(layout.width) * 3 * sizeof(float), layout));
}

/* A layer of the file read into a new array of three floats a pixel, or
 * NULL where the file has no channel of its first name. */
float *read_layer(Imf::FrameBuffer &frame, const Imf::ChannelList &channels,
                  const char *const names[3], const PtrImageLayout &layout)
{
    if (!channels.findChannel(names[0]))
        return nullptr;
    float *pixels = static_cast<float *>(
        std::malloc(std::max<size_t>(1, size_t(layout.width) * size_t(layout.height)) * 3 *
                    sizeof(float)));
    if (!pixels)
        throw std::bad_alloc();
    insert_layer(frame, names, pixels, layout);
    return pixels;
}

} // namespace

extern "C" PtrResult ptr_exr_set_threads(int threads, PtrError *err)
{
    try {
        // One thread is the caller's own: no pool.
        Imf::setGlobalThreadCount(threads > 1 ? threads : 0);
        return PTR_OK;
    } catch (...) {
        return ptr_shim_caught(err, PTR_ERR_INTERNAL, "OpenEXR's threads");
    }
}

extern "C" PtrResult ptr_exr_write(const char *file, const char *name,
                                   const PtrImageLayout *layout, const float *rgb,
                                   const float *alpha, const PtrImageExtras *extras,
                                   PtrPixelFormat format,
                                   const PtrImageAttr *attrs, size_t attr_count, PtrError *err)
{
    try {
        const Imath::Box2i display(Imath::V2i(0, 0),
                                   Imath::V2i(layout->full_width - 1, layout->full_height - 1));
        const Imath::Box2i data(Imath::V2i(layout->x, layout->y),
                                Imath::V2i(layout->x + layout->width - 1,
                                           layout->y + layout->height - 1));
        Imf::Header header(display, data, 1.0f, Imath::V2f(0, 0), 1.0f, Imf::INCREASING_Y,
                           Imf::ZIP_COMPRESSION);
        const bool is_half = format == PTR_PIXEL_HALF;
        for (const char *channel : rgb_names)
            header.channels().insert(channel, Imf::Channel(is_half ? Imf::HALF : Imf::FLOAT));
        if (alpha)
            header.channels().insert("A", Imf::Channel(is_half ? Imf::HALF : Imf::FLOAT));
        const float *sample_counts = extras ? extras->sample_counts : nullptr;
        const float *albedo = extras ? extras->albedo : nullptr;
        const float *normal = extras ? extras->normal : nullptr;
        const float *noisy = extras ? extras->noisy : nullptr;
        if (sample_counts)
            header.channels().insert("samples", Imf::Channel(Imf::FLOAT));
        for (size_t c = 0; c < 3; c++) {
            if (albedo)
                header.channels().insert(albedo_names[c], Imf::Channel(Imf::FLOAT));
            if (normal)
                header.channels().insert(normal_names[c], Imf::Channel(Imf::FLOAT));
            if (noisy)
                header.channels().insert(noisy_names[c], Imf::Channel(Imf::FLOAT));
        }
        for (size_t i = 0; i < attr_count; i++) {
            const PtrImageAttr &a = attrs[i];
            if (std::string(a.name).compare(0, 5, "oiio:") == 0)
                continue;
            switch (a.type) {
            case PTR_ATTR_INT: header.insert(a.name, Imf::IntAttribute(a.int_value)); break;
            case PTR_ATTR_FLOAT: header.insert(a.name, Imf::FloatAttribute(a.float_value)); break;
            case PTR_ATTR_STRING:
                header.insert(a.name, Imf::StringAttribute(a.string_value ? a.string_value : ""));
                break;
            }
        }
        Imf::addCapDate(header, capture_date());
        header.setType(Imf::SCANLINEIMAGE);

        // Half pixels are rounded to nearest, as OpenImageIO rounded them.
        const size_t pixels = size_t(layout->width) * size_t(layout->height);
        std::vector<Imath::half> halves(is_half ? pixels * 3 : 0);
        std::copy(rgb, rgb + halves.size(), halves.begin());
        std::vector<Imath::half> alpha_halves(is_half && alpha ? pixels : 0);
        if (alpha)
            std::copy(alpha, alpha + alpha_halves.size(), alpha_halves.begin());
        const Imf::PixelType type = is_half ? Imf::HALF : Imf::FLOAT;
        const size_t size = is_half ? sizeof(Imath::half) : sizeof(float);
        const char *first = is_half ? reinterpret_cast<const char *>(halves.data())
                                    : reinterpret_cast<const char *>(rgb);
        Imf::FrameBuffer frame;
        for (size_t c = 0; c < 3; c++)
            frame.insert(rgb_names[c], slice(type, first + c * size, 3 * size,
                                             size_t(layout->width) * 3 * size, *layout));
        if (alpha)
            frame.insert("A", slice(type,
                                    is_half ? reinterpret_cast<const char *>(alpha_halves.data())
                                            : reinterpret_cast<const char *>(alpha),
                                    size, size_t(layout->width) * size, *layout));
        if (sample_counts)
            frame.insert("samples", slice(Imf::FLOAT, reinterpret_cast<const char *>(sample_counts),
                                          sizeof(float), size_t(layout->width) * sizeof(float),
                                          *layout));
        if (albedo)
            insert_layer(frame, albedo_names, albedo, *layout);
        if (normal)
            insert_layer(frame, normal_names, normal, *layout);
        if (noisy)
            insert_layer(frame, noisy_names, noisy, *layout);
        Imf::OutputFile out(file, header);
        out.setFrameBuffer(frame);
        out.writePixels(layout->height);
        return PTR_OK;
    } catch (...) {
        return ptr_shim_caught(err, PTR_ERR_OUTPUT, name);
    }
}

extern "C" PtrResult ptr_exr_read(const char *path, PtrImage **out, PtrError *err)
{
    PtrImage *image = nullptr;
    try {
        Imf::InputFile in(path);
        const Imf::Header &header = in.header();
        const Imath::Box2i data = header.dataWindow(), display = header.displayWindow();
        const long long width = 1LL + data.max.x - data.min.x, height = 1LL + data.max.y - data.min.y;
        const long long full_width = 1LL + display.max.x - display.min.x,
                        full_height = 1LL + display.max.y - display.min.y;
        if (width > INT_MAX || height > INT_MAX || full_width > INT_MAX || full_height > INT_MAX)
            return ptr_shim_error(err, PTR_ERR_USAGE, std::string(path) + ": image too large");
        PtrImageLayout layout = { int(width), int(height), data.min.x, data.min.y,
                                  int(full_width), int(full_height) };
        // Text, integer and float attributes, as text; the standard ones of
        // other types (windows, channels, compression) are in the layout.
        std::vector<std::pair<std::string, std::string>> attrs;
        for (auto a = header.begin(); a != header.end(); ++a) {
            char number[32];
            if (auto *s = dynamic_cast<const Imf::StringAttribute *>(&a.attribute())) {
                attrs.emplace_back(a.name(), s->value());
            } else if (auto *n = dynamic_cast<const Imf::IntAttribute *>(&a.attribute())) {
                std::snprintf(number, sizeof number, "%d", n->value());
                attrs.emplace_back(a.name(), number);
            } else if (auto *f = dynamic_cast<const Imf::FloatAttribute *>(&a.attribute())) {
                std::snprintf(number, sizeof number, "%g", double(f->value()));
                attrs.emplace_back(a.name(), number);
            }
        }
        image = ptr_image_alloc(size_t(layout.width) * size_t(layout.height), attrs.size());
        if (!image)
            throw std::bad_alloc();
        image->layout = layout;
        for (size_t i = 0; i < attrs.size(); i++)
            if (!ptr_image_set_attr(image, i, attrs[i].first.c_str(), attrs[i].second.c_str()))
                throw std::bad_alloc();

        // R, G and B; a grey image (Y alone) in all three; A, the passes
        // and the noisy colour if there are; the rest dropped.
        const Imf::ChannelList &channels = header.channels();
        char *first = reinterpret_cast<char *>(image->rgb);
        const size_t row = size_t(layout.width) * 3 * sizeof(float);
        Imf::FrameBuffer frame;
        const bool grey = !channels.findChannel("R") && channels.findChannel("Y");
        for (size_t c = 0; c < (grey ? 1 : 3); c++)
            frame.insert(grey ? "Y" : rgb_names[c],
                         slice(Imf::FLOAT, first + c * sizeof(float), 3 * sizeof(float), row,
                               layout));
        if (channels.findChannel("A")) {
            if (!ptr_image_alloc_alpha(image))
                throw std::bad_alloc();
            frame.insert("A", slice(Imf::FLOAT, reinterpret_cast<char *>(image->alpha),
                                    sizeof(float), size_t(layout.width) * sizeof(float), layout));
        }
        image->albedo = read_layer(frame, channels, albedo_names, layout);
        image->normal = read_layer(frame, channels, normal_names, layout);
        image->noisy = read_layer(frame, channels, noisy_names, layout);
        in.setFrameBuffer(frame);
        in.readPixels(data.min.y, data.max.y);
        for (size_t p = 0; grey && p < size_t(layout.width) * size_t(layout.height); p++)
            image->rgb[3 * p + 1] = image->rgb[3 * p + 2] = image->rgb[3 * p];
        *out = image;
        return PTR_OK;
    } catch (...) {
        ptr_image_release(image);
        return ptr_shim_caught(err, PTR_ERR_USAGE, path);
    }
}
