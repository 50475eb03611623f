/* Finds the live module beside the executable (../lib/ptr/ from its
 * folder, as the image module) and loads it, once, when a render asks for
 * a live view. */
#include "live/live.h"

#include <dlfcn.h>
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "base/version.h"

enum { PATH_SIZE = 4096 };

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static const PtrLiveModule *module;

/* PTR_LIVE_MODULE_PATH ("../lib/ptr/NAME.so") from the executable's folder. */
static PtrResult module_path(char *path, size_t size, PtrError *err)
{
    ssize_t n = readlink("/proc/self/exe", path, size);
    if (n <= 0 || (size_t)n >= size)
        return ptr_error_set(err, PTR_ERR_INSTALL,
                             "/proc/self/exe: cannot find ptr's own folder, where its live "
                             "module lives: %s", n < 0 ? strerror(errno) : "path too long");
    path[n] = '\0';
    const char *relative = PTR_LIVE_MODULE_PATH;
    *strrchr(path, '/') = '\0';
    for (char *slash; !strncmp(relative, "../", 3) && (slash = strrchr(path, '/')); relative += 3)
        *slash = '\0';
    size_t used = strlen(path);
    if ((size_t)snprintf(path + used, size - used, "/%s", relative) >= size - used)
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: path too long for ptr's live module",
                             path);
    return PTR_OK;
}

const PtrLiveModule *ptr_live_module(PtrError *err)
{
    pthread_mutex_lock(&lock);
    const PtrLiveModule *m = module;
    char path[PATH_SIZE];
    if (!m && module_path(path, sizeof path, err) == PTR_OK) {
        void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!handle) {
            const char *why = dlerror();
            ptr_error_set(err, strstr(why, "memory") || strstr(why, "cannot allocate")
                                   ? PTR_ERR_NOMEM : PTR_ERR_INSTALL,
                          "cannot load ptr's live module: %s", why);
        } else if (!(m = dlsym(handle, PTR_LIVE_MODULE_SYMBOL)) || m->size != sizeof *m ||
                   strcmp(m->version, PTR_VERSION)) {
            ptr_error_set(err, PTR_ERR_INSTALL, "%s: not the live module of ptr %s", path,
                          PTR_VERSION);
            m = NULL;
            dlclose(handle);
        }
        module = m;
    }
    pthread_mutex_unlock(&lock);
    return m;
}
