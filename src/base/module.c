#include "base/module.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

PtrResult ptr_module_path(const char *relative, const char *what, char *path, size_t size,
                          PtrError *err)
{
    ssize_t n = readlink("/proc/self/exe", path, size);
    if (n <= 0 || (size_t)n >= size)
        return ptr_error_set(err, PTR_ERR_INSTALL,
                             "/proc/self/exe: cannot find ptr's own folder, where its %s "
                             "module lives: %s", what, n < 0 ? strerror(errno) : "path too long");
    path[n] = '\0';
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
