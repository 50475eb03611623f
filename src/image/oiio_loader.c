/* Finds the OpenImageIO module beside the executable and loads it for the
 * loader's owner: on a thread of its own when asked early enough to overlap
 * other work, else at first use. A second loader loads the same module
 * (the dynamic linker counts it) and shares no state with the first. */
#include "image/image_backend.h"

#include <dlfcn.h>
#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/module.h"
#include "base/version.h"

enum { PATH_SIZE = 4096 };

struct PtrImageLoader {
    pthread_mutex_t lock;
    pthread_t thread;
    int thread_running;           /* started by ptr_image_preload and not joined yet */
    int load_tried;               /* load() ran: module, else load_error, says how it went */
    PtrError load_error;          /* why the load failed */
    const PtrImageModule *module; /* set once the module works */
};

PtrResult ptr_image_loader_new(PtrImageLoader **out, PtrError *err)
{
    PtrImageLoader *loader = calloc(1, sizeof *loader);
    if (!loader)
        return ptr_error_set(err, PTR_ERR_NOMEM, "out of memory for the image module's loader");
    pthread_mutex_init(&loader->lock, NULL);
    *out = loader;
    return PTR_OK;
}

static void load(PtrImageLoader *loader)
{
    char path[PATH_SIZE];
    const PtrImageModule *m = NULL;
    PtrError *load_error = &loader->load_error;
    if (ptr_module_path(PTR_IMAGE_MODULE_PATH, "image", path, sizeof path, load_error) == PTR_OK) {
        /* Lazy binding, as when a program links the libraries: binding all of
         * their functions up front costs a tenth more. */
        void *handle = dlopen(path, RTLD_LAZY | RTLD_LOCAL);
        if (!handle) {
            /* dlerror names the file it could not open: the module or a library it needs. */
            const char *why = dlerror();
            size_t len = strlen(path);
            if (!strncmp(why, path, len) && !strncmp(why + len, ": ", 2))
                why += len + 2;
            if (ptr_dl_out_of_memory(why))
                ptr_error_set(load_error, PTR_ERR_NOMEM,
                              "%s: out of memory: cannot load ptr's image module: %s", path, why);
            else
                ptr_error_set(load_error, PTR_ERR_INSTALL,
                              "%s: cannot load ptr's image module: %s", path, why);
        } else if (!(m = dlsym(handle, PTR_IMAGE_MODULE_SYMBOL)) || m->size != sizeof *m ||
                   strcmp(m->version, PTR_VERSION)) {
            ptr_error_set(load_error, PTR_ERR_INSTALL, "%s: not the image module of ptr %s", path,
                          PTR_VERSION);
            m = NULL;
            dlclose(handle);
        }
    }
    loader->load_tried = 1;
    loader->module = m;
}

static void *load_on_thread(void *loader)
{
    load(loader);
    return NULL;
}

/* With the lock held. */
static void join_loader_locked(PtrImageLoader *loader)
{
    if (loader->thread_running) {
        pthread_join(loader->thread, NULL);
        loader->thread_running = 0;
    }
}

void ptr_image_loader_free(PtrImageLoader *loader)
{
    if (!loader)
        return;
    join_loader_locked(loader);
    pthread_mutex_destroy(&loader->lock);
    free(loader);
}

PtrResult ptr_image_preload(PtrImageLoader *loader, const char *output, PtrError *err)
{
    if (ptr_image_is_exr(output))
        return PTR_OK;
    char path[PATH_SIZE];
    PtrResult found = ptr_module_path(PTR_IMAGE_MODULE_PATH, "image", path, sizeof path, err);
    if (found != PTR_OK)
        return found;
    if (access(path, R_OK))
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: ptr's image module is missing: %s", path,
                             strerror(errno));
    pthread_mutex_lock(&loader->lock);
    /* A thread that cannot start leaves the load to the first use. */
    if (!loader->thread_running && !loader->load_tried &&
        !pthread_create(&loader->thread, NULL, load_on_thread, loader))
        loader->thread_running = 1;
    pthread_mutex_unlock(&loader->lock);
    return PTR_OK;
}

PtrResult ptr_oiio_module(PtrImageLoader *loader, const char *path, const PtrImageModule **out,
                          PtrError *err)
{
    if (!loader)
        return ptr_error_set(err, PTR_ERR_USAGE, "%s: only EXR can be read or written here",
                             path);
    pthread_mutex_lock(&loader->lock);
    join_loader_locked(loader);
    if (!loader->load_tried)
        load(loader);
    const PtrImageModule *m = loader->module;
    pthread_mutex_unlock(&loader->lock);
    *out = m;
    return m ? PTR_OK
             : ptr_error_set(err, loader->load_error.code, "%s", loader->load_error.message);
}
