/* Finds the live module beside the executable (../lib/ptr/ from its
 * folder, as the image module) and loads it when a render asks for a live
 * view. The loader keeps nothing: the caller keeps the module it gets (a
 * second load gets the same one: the dynamic linker counts them). */
#include "live/live.h"

#include <dlfcn.h>
#include <string.h>

#include "base/module.h"
#include "base/version.h"

enum { PATH_SIZE = 4096 };

PtrResult ptr_live_module(const PtrLiveModule **out, PtrError *err)
{
    char path[PATH_SIZE];
    PtrResult res = ptr_module_path(PTR_LIVE_MODULE_PATH, "live", path, sizeof path, err);
    if (res != PTR_OK)
        return res;
    void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        const char *why = dlerror();
        return ptr_error_set(err, ptr_dl_out_of_memory(why) ? PTR_ERR_NOMEM : PTR_ERR_INSTALL,
                             "cannot load ptr's live module: %s", why);
    }
    const PtrLiveModule *m = dlsym(handle, PTR_LIVE_MODULE_SYMBOL);
    if (!m || m->size != sizeof *m || strcmp(m->version, PTR_VERSION)) {
        dlclose(handle);
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: not the live module of ptr %s", path,
                             PTR_VERSION);
    }
    *out = m;
    return PTR_OK;
}
