/* Finds the OpenImageIO module beside the executable and loads it: on a
 * thread of its own when asked early enough to overlap other work, else at
 * first use. */
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

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_t loader;
static int loader_running;  /* started by ptr_image_preload and not joined yet */
static int load_tried;      /* load() ran: module, else load_error, says how it went */
static int exit_waits;      /* join_loader is registered with atexit */
static PtrError load_error; /* why the load failed */
static const PtrImageModule *module; /* set once the module works */

static void load(void)
{
    char path[PATH_SIZE];
    const PtrImageModule *m = NULL;
    if (ptr_module_path(PTR_IMAGE_MODULE_PATH, "image", path, sizeof path, &load_error) == PTR_OK) {
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
                ptr_error_set(&load_error, PTR_ERR_NOMEM,
                              "%s: out of memory: cannot load ptr's image module: %s", path, why);
            else
                ptr_error_set(&load_error, PTR_ERR_INSTALL,
                              "%s: cannot load ptr's image module: %s", path, why);
        } else if (!(m = dlsym(handle, PTR_IMAGE_MODULE_SYMBOL)) || m->size != sizeof *m ||
                   strcmp(m->version, PTR_VERSION)) {
            ptr_error_set(&load_error, PTR_ERR_INSTALL, "%s: not the image module of ptr %s", path,
                          PTR_VERSION);
            m = NULL;
            dlclose(handle);
        }
    }
    load_tried = 1;
    module = m;
}

static void *load_on_thread(void *unused)
{
    (void)unused;
    load();
    return NULL;
}

/* With the lock held. */
static void join_loader_locked(void)
{
    if (loader_running) {
        pthread_join(loader, NULL);
        loader_running = 0;
    }
}

/* Exiting while the thread runs the libraries' constructors would race
 * their destructors. */
static void join_loader(void)
{
    pthread_mutex_lock(&lock);
    join_loader_locked();
    pthread_mutex_unlock(&lock);
}

PtrResult ptr_image_preload(const char *output, PtrError *err)
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
    pthread_mutex_lock(&lock);
    /* A thread that cannot start leaves the load to the first use. */
    if (!loader_running && !load_tried && !pthread_create(&loader, NULL, load_on_thread, NULL)) {
        loader_running = 1;
        if (!exit_waits)
            exit_waits = !atexit(join_loader);
    }
    pthread_mutex_unlock(&lock);
    return PTR_OK;
}

PtrResult ptr_oiio_module(const PtrImageModule **out, PtrError *err)
{
    pthread_mutex_lock(&lock);
    join_loader_locked();
    if (!load_tried)
        load();
    const PtrImageModule *m = module;
    pthread_mutex_unlock(&lock);
    *out = m;
    return m ? PTR_OK : ptr_error_set(err, load_error.code, "%s", load_error.message);
}
