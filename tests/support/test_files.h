/* For tests that write files and run the command line in process: a
 * temporary folder of their own, paths in it, ptr_cli_main with a
 * NULL-terminated argument list, and images read back in any format. */
#ifndef PTR_TEST_FILES_H
#define PTR_TEST_FILES_H

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "app/cli.h"
#include "image/image.h"

static char test_dir[64];

/* Creates /tmp/ptr-NAME-XXXXXX; returns 0 if it cannot. */
static int test_dir_create(const char *name)
{
    snprintf(test_dir, sizeof test_dir, "/tmp/ptr-%s-XXXXXX", name);
    return mkdtemp(test_dir) != NULL;
}

static void test_dir_remove(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", test_dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", test_dir);
}

/* A path in the test's folder; the last 16 stay valid. */
static char *test_path(const char *name)
{
    static char paths[16][192];
    static int next;
    char *p = paths[next++ % 16];
    snprintf(p, sizeof paths[0], "%s/%s", test_dir, name);
    return p;
}

/* ptr ARG... (NULL-terminated); returns the exit code. */
static int test_ptr(const char *first, ...)
{
    char *argv[40] = { "ptr", (char *)first };
    int argc = 2;
    va_list ap;
    va_start(ap, first);
    for (char *a; argc < 39 && (a = va_arg(ap, char *));)
        argv[argc++] = a;
    va_end(ap);
    argv[argc] = NULL;
    return ptr_cli_main(argc, argv);
}

/* Reads an image as ptr would, with an image module loader of its own. */
static inline PtrResult test_image_read(const char *path, PtrImage **out, PtrError *err)
{
    PtrImageLoader *images = NULL;
    PtrResult res = ptr_image_loader_new(&images, err);
    if (res == PTR_OK)
        res = ptr_image_read(images, path, out, err);
    ptr_image_loader_free(images);
    return res;
}

#endif /* PTR_TEST_FILES_H */
