#include "color.h"
#include "base/shim_error.h"

#include <OpenColorIO/OpenColorIO.h>

#include <cmath>
#include <functional>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>

namespace OCIO = OCIO_NAMESPACE;

struct PtrColor {
    OCIO::ConstConfigRcPtr config;
    std::string source;
    std::string display, view, look, view_space;
    OCIO::ConstCPUProcessorRcPtr cpu;
};

namespace {

std::string join(const std::string &label, int count, const std::function<const char *(int)> &name)
{
    std::string list = label;
    for (int i = 0; i < count; i++)
        list += std::string(i ? ", '" : " '") + name(i) + "'";
    return list;
}

} // namespace

extern "C" PtrResult ptr_color_open(const char *path, PtrColor **out, PtrError *err)
{
    const char *env = std::getenv("OCIO");
    const bool from_env = !path && env && *env;
    const std::string source = path ? path : from_env ? env : "embedded";
    const std::string label = path       ? "OCIO config " + source
                              : from_env ? "OCIO config " + source + " (from $OCIO)"
                                         : "embedded OCIO config";
    try {
        auto color = std::make_unique<PtrColor>();
        if (path || from_env) {
            color->config = OCIO::Config::CreateFromFile(source.c_str());
        } else {
            std::istringstream text(ptr_embedded_ocio_config);
            color->config = OCIO::Config::CreateFromStream(text);
        }
        color->config->validate();
        if (!color->config->hasRole(OCIO::ROLE_SCENE_LINEAR))
            throw OCIO::Exception("the config has no scene_linear role, which ptr renders in");
        if (color->config->getNumDisplays() < 1)
            throw OCIO::Exception("the config has no display");
        color->source = source;
        *out = color.release();
        return PTR_OK;
    } catch (...) {
        return ptr_shim_caught(err, PTR_ERR_COLOR, label);
    }
}

extern "C" void ptr_color_close(PtrColor *color) { delete color; }
extern "C" const char *ptr_color_source(const PtrColor *c) { return c->source.c_str(); }
extern "C" const char *ptr_color_display(const PtrColor *c) { return c->display.c_str(); }
extern "C" const char *ptr_color_view(const PtrColor *c) { return c->view.c_str(); }
extern "C" const char *ptr_color_look(const PtrColor *c) { return c->look.c_str(); }
extern "C" const char *ptr_color_view_space(const PtrColor *c) { return c->view_space.c_str(); }

extern "C" PtrResult ptr_color_select(PtrColor *color, const char *display, const char *view,
                                      const char *look, float exposure_stops, PtrError *err)
{
    try {
        const OCIO::ConstConfigRcPtr &config = color->config;
        std::string d = display ? display : config->getDefaultDisplay();
        bool known = false;
        for (int i = 0; i < config->getNumDisplays(); i++)
            known = known || d == config->getDisplay(i);
        if (!known) {
            return ptr_shim_error(
                err, PTR_ERR_USAGE,
                join("unknown display '" + d + "'; " + color->source + " has",
                     config->getNumDisplays(), [&](int i) { return config->getDisplay(i); }));
        }
        std::string v = view ? view : config->getDefaultView(d.c_str());
        known = false;
        for (int i = 0; i < config->getNumViews(d.c_str()); i++)
            known = known || v == config->getView(d.c_str(), i);
        if (!known) {
            return ptr_shim_error(err, PTR_ERR_USAGE,
                                  join("unknown view '" + v + "' for display '" + d + "'; it has",
                                       config->getNumViews(d.c_str()),
                                       [&](int i) { return config->getView(d.c_str(), i); }));
        }
        if (look && *look && !config->getLook(look)) {
            return ptr_shim_error(
                err, PTR_ERR_USAGE,
                join(std::string("unknown look '") + look + "'; " + color->source + " has",
                     config->getNumLooks(), [&](int i) { return config->getLookNameByIndex(i); }));
        }

        auto transform = OCIO::DisplayViewTransform::Create();
        transform->setSrc(OCIO::ROLE_SCENE_LINEAR);
        transform->setDisplay(d.c_str());
        transform->setView(v.c_str());
        auto pipeline = OCIO::LegacyViewingPipeline::Create();
        pipeline->setDisplayViewTransform(transform);
        if (look && *look) {
            pipeline->setLooksOverrideEnabled(true);
            pipeline->setLooksOverride(look);
        }
        if (exposure_stops != 0.0f) {
            double gain = std::pow(2.0, double(exposure_stops));
            const double m44[16] = { gain, 0, 0, 0, 0, gain, 0, 0, 0, 0, gain, 0, 0, 0, 0, 1 };
            auto exposure = OCIO::MatrixTransform::Create();
            exposure->setMatrix(m44);
            pipeline->setLinearCC(exposure);
        }
        color->cpu = pipeline->getProcessor(config)->getDefaultCPUProcessor();
        color->display = d;
        color->view = v;
        color->look = look ? look : "";
        color->view_space = config->getDisplayViewColorSpaceName(d.c_str(), v.c_str());
        return PTR_OK;
    } catch (...) {
        return ptr_shim_caught(err, PTR_ERR_COLOR, "OCIO config " + color->source);
    }
}

extern "C" PtrResult ptr_color_apply(const PtrColor *color, float *rgb, size_t pixels,
                                     PtrError *err)
{
    try {
        OCIO::PackedImageDesc image(rgb, long(pixels), 1, 3);
        color->cpu->apply(image);
        return PTR_OK;
    } catch (...) {
        return ptr_shim_caught(err, PTR_ERR_COLOR, "OCIO");
    }
}

extern "C" PtrResult ptr_color_list(const PtrColor *color, FILE *out, PtrError *err)
try {
    const OCIO::ConstConfigRcPtr &config = color->config;
    std::fprintf(out, "config: %s\n", color->source.c_str());
    const char *default_display = config->getDefaultDisplay();
    for (int i = 0; i < config->getNumDisplays(); i++) {
        const char *d = config->getDisplay(i);
        std::fprintf(out, "display: %s%s\n", d, std::string(d) == default_display ? " (default)" : "");
        const char *default_view = config->getDefaultView(d);
        for (int j = 0; j < config->getNumViews(d); j++) {
            const char *v = config->getView(d, j);
            std::fprintf(out, "  view: %s%s\n", v, std::string(v) == default_view ? " (default)" : "");
        }
    }
    for (int i = 0; i < config->getNumLooks(); i++)
        std::fprintf(out, "look: %s\n", config->getLookNameByIndex(i));
    return PTR_OK;
} catch (...) {
    return ptr_shim_caught(err, PTR_ERR_COLOR, "OCIO config " + color->source);
}
