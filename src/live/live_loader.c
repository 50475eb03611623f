/* Finds the live module beside the executable (../lib/ptr/ from its
 * folder, as the image module) and loads it, once, when a render asks for
 * a live view. */
#include "live/live.h"

#include <dlfcn.h>
#include <pthread.h>
#include <string.h>

#include "base/module.h"
#include "base/version.h"

enum { PATH_SIZE = 4096 };

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static const PtrLiveModule *module;

PtrResult ptr_live_module(const PtrLiveModule **out, PtrError *err)
{
    pthread_mutex_lock(&lock);
    const PtrLiveModule *m = module;
    char path[PATH_SIZE];
    PtrResult res = m ? PTR_OK
                      : ptr_module_path(PTR_LIVE_MODULE_PATH, "live", path, sizeof path, err);
    if (!m && res == PTR_OK) {
        void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            const char *why = dlerror();
            res = ptr_error_set(err, ptr_dl_out_of_memory(why) ? PTR_ERR_NOMEM : PTR_ERR_INSTALL,
                                "cannot load ptr's live module: %s", why);
        } else if (!(m = dlsym(handle, PTR_LIVE_MODULE_SYMBOL)) || m->size != sizeof *m ||
                   strcmp(m->version, PTR_VERSION)) {
            res = ptr_error_set(err, PTR_ERR_INSTALL, "%s: not the live module of ptr %s", path,
                                PTR_VERSION);
            m = NULL;
            dlclose(handle);
        }
        module = m;
    }
    pthread_mutex_unlock(&lock);
    *out = m;
    return res;
}
