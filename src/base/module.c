#define _GNU_SOURCE /* dladdr1 */
#include "base/module.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <link.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The file this code was loaded from into path: libptr.so's where the code
 * is the library's (its link map names it), else the executable's (the main
 * program's link map has no name). */
static PtrResult own_file(const char *what, char *path, size_t size, PtrError *err)
{
    Dl_info info;
    struct link_map *map = NULL;
    if (dladdr1((void *)ptr_module_path, &info, (void **)&map, RTLD_DL_LINKMAP) && map &&
        map->l_name && map->l_name[0]) {
        char resolved[PATH_MAX];
        const int found = realpath(map->l_name, resolved) != NULL;
        if (!found || strlen(resolved) >= size)
            return ptr_error_set(err, PTR_ERR_INSTALL,
                                 "%s: cannot find ptr's own folder, where its %s module "
                                 "lives: %s", map->l_name, what,
                                 found ? "path too long" : strerror(errno));
        memcpy(path, resolved, strlen(resolved) + 1);
        return PTR_OK;
    }
    ssize_t n = readlink("/proc/self/exe", path, size);
    if (n <= 0 || (size_t)n >= size)
        return ptr_error_set(err, PTR_ERR_INSTALL,
                             "/proc/self/exe: cannot find ptr's own folder, where its %s "
                             "module lives: %s", what, n < 0 ? strerror(errno) : "path too long");
    path[n] = '\0';
    return PTR_OK;
}

PtrResult ptr_module_path(const char *relative, const char *what, char *path, size_t size,
                          PtrError *err)
{
    PtrResult res = own_file(what, path, size, err);
    if (res != PTR_OK)
        return res;
    *strrchr(path, '/') = '\0'; /* the kernel gives an absolute path */
    for (char *slash; !strncmp(relative, "../", 3) && (slash = strrchr(path, '/')); relative += 3)
        *slash = '\0';
    size_t used = strlen(path);
    if ((size_t)snprintf(path + used, size - used, "/%s", relative) >= size - used)
        return ptr_error_set(err, PTR_ERR_INSTALL, "%s: path too long for ptr's %s module", path,
                             what);
    return PTR_OK;
}

int ptr_dl_out_of_memory(const char *why)
{
    static const char *const signs[] = {
        "failed to map segment", "cannot map zero-fill pages", "cannot allocate",
        "Cannot allocate memory", "out of memory",
    };
    for (size_t i = 0; i < sizeof signs / sizeof signs[0]; i++)
        if (strstr(why, signs[i]))
            return 1;
    return 0;
}
