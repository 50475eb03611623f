/* The image module: image.h through OpenImageIO, loaded at run time by image.c. */
#include "image/image_module.h"
#include "shim_error.h"
#include "version.h"

#include <OpenImageIO/imageio.h>

#include <csignal>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

struct PtrImage {
    PtrImageLayout layout = {};
    int width = 0, height = 0;
    std::vector<float> rgb;
    std::map<std::string, std::string> attrs;
};

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

/* "dir/name.ext" -> "dir/.name.ptr-PID.ext": hidden, unique to this process,
 * and keeping the extension for tools that look at it. */
std::string temporary_name(const std::string &path)
{
    size_t slash = path.rfind('/');
    size_t base = slash == std::string::npos ? 0 : slash + 1;
    size_t dot = path.rfind('.');
    if (dot == std::string::npos || dot < base)
        dot = path.size();
    return path.substr(0, base) + "." + path.substr(base, dot - base) + ".ptr-" +
           std::to_string(getpid()) + path.substr(dot);
}

// The temporary file of the write under way, for ptr_image_discard_partial:
// plain storage a signal handler may read.
char partial_path[4096];
volatile std::sig_atomic_t partial_active;

int can_write(const char *path)
{
    try {
        return OIIO::ImageOutput::create(path) != nullptr;
    } catch (...) {
        return 0;
    }
}

void discard_partial(void)
{
    if (partial_active)
        unlink(partial_path);
}

PtrResult write_image(const char *path, const PtrImageLayout *layout, const float *rgb,
                      const float *sample_counts, PtrPixelFormat format,
                      const PtrImageAttr *attrs, size_t attr_count, PtrError *err)
{
    std::string tmp;
    try {
        // The writer is chosen from the real name; the temporary name only
        // receives the bytes.
        auto out = OIIO::ImageOutput::create(path);
        if (!out)
            return ptr_shim_error(err, PTR_ERR_OUTPUT,
                                  std::string(path) + ": no image format for this extension");
        int channels = sample_counts ? 4 : 3;
        OIIO::ImageSpec spec(layout->width, layout->height, channels, pixel_type(format));
        std::vector<float> interleaved;
        if (sample_counts) {
            // Counts stay whole numbers whatever the colour channels' depth.
            spec.channelnames = { "R", "G", "B", "samples" };
            spec.channelformats = { pixel_type(format), pixel_type(format), pixel_type(format),
                                    OIIO::TypeDesc::FLOAT };
            spec.alpha_channel = -1;
            size_t pixels = (size_t)layout->width * (size_t)layout->height;
            interleaved.resize(pixels * 4);
            for (size_t p = 0; p < pixels; p++) {
                std::memcpy(&interleaved[4 * p], &rgb[3 * p], 3 * sizeof(float));
                interleaved[4 * p + 3] = sample_counts[p];
            }
        }
        spec.x = layout->x;
        spec.y = layout->y;
        spec.full_x = 0;
        spec.full_y = 0;
        spec.full_width = layout->full_width;
        spec.full_height = layout->full_height;
        for (size_t i = 0; i < attr_count; i++) {
            const PtrImageAttr &a = attrs[i];
            switch (a.type) {
            case PTR_ATTR_INT: spec.attribute(a.name, a.int_value); break;
            case PTR_ATTR_FLOAT: spec.attribute(a.name, a.float_value); break;
            case PTR_ATTR_STRING: spec.attribute(a.name, a.string_value); break;
            }
        }
        tmp = temporary_name(path);
        if (tmp.size() < sizeof partial_path) {
            std::memcpy(partial_path, tmp.c_str(), tmp.size() + 1);
            partial_active = 1;
        }
        if (!out->open(tmp, spec)) {
            partial_active = 0;
            std::remove(tmp.c_str());
            return ptr_shim_error(err, PTR_ERR_OUTPUT, std::string(path) + ": " + out->geterror());
        }
        bool ok = out->write_image(OIIO::TypeDesc::FLOAT, sample_counts ? interleaved.data() : rgb);
        ok = out->close() && ok;
        if (!ok) {
            std::remove(tmp.c_str());
            partial_active = 0;
            return ptr_shim_error(err, PTR_ERR_OUTPUT, std::string(path) + ": " + out->geterror());
        }
        if (std::rename(tmp.c_str(), path) != 0) {
            const std::string why = std::strerror(errno);
            std::remove(tmp.c_str());
            partial_active = 0;
            return ptr_shim_error(err, PTR_ERR_OUTPUT,
                                  std::string(path) + ": cannot replace file: " + why);
        }
        partial_active = 0;
        return PTR_OK;
    } catch (...) {
        if (!tmp.empty())
            std::remove(tmp.c_str());
        partial_active = 0;
        return ptr_shim_caught(err, PTR_ERR_OUTPUT, path);
    }
}

PtrImage *read_image(const char *path, PtrError *err)
{
    try {
        auto in = OIIO::ImageInput::open(path);
        if (!in) {
            ptr_shim_error(err, PTR_ERR_USAGE, std::string(path) + ": " + OIIO::geterror());
            return nullptr;
        }
        const OIIO::ImageSpec &spec = in->spec();
        std::vector<float> all(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
        if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data())) {
            ptr_shim_error(err, PTR_ERR_USAGE, std::string(path) + ": " + in->geterror());
            return nullptr;
        }
        auto image = std::make_unique<PtrImage>();
        image->width = spec.width;
        image->height = spec.height;
        image->layout = { spec.width, spec.height, spec.x, spec.y, spec.full_width, spec.full_height };
        size_t pixels = size_t(spec.width) * size_t(spec.height);
        image->rgb.resize(pixels * 3);
        for (size_t p = 0; p < pixels; p++)
            for (int c = 0; c < 3; c++)
                image->rgb[3 * p + size_t(c)] =
                    all[p * size_t(spec.nchannels) + size_t(c < spec.nchannels ? c : 0)];
        for (const OIIO::ParamValue &param : spec.extra_attribs)
            image->attrs[param.name().string()] = param.get_string();
        in->close();
        return image.release();
    } catch (...) {
        ptr_shim_caught(err, PTR_ERR_USAGE, path);
    }
    return nullptr;
}

void free_image(PtrImage *image) { delete image; }
int image_width(const PtrImage *image) { return image->width; }
int image_height(const PtrImage *image) { return image->height; }
PtrImageLayout image_layout(const PtrImage *image) { return image->layout; }
const float *image_pixels(const PtrImage *image) { return image->rgb.data(); }

const char *image_attr(const PtrImage *image, const char *name)
{
    auto it = image->attrs.find(name);
    return it == image->attrs.end() ? nullptr : it->second.c_str();
}

} // namespace

extern "C" __attribute__((visibility("default"))) const PtrImageModule ptr_image_module = {
    sizeof(PtrImageModule), PTR_VERSION, can_write, write_image, discard_partial, read_image,
    free_image, image_width, image_height, image_layout, image_pixels, image_attr,
};
