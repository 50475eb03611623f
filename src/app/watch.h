/* Waiting for a scene's files to change (ptr --watch). */
#ifndef PTR_WATCH_H
#define PTR_WATCH_H

#include <signal.h>
#include <stddef.h>
#include <sys/stat.h>

#include "importer.h"

typedef struct PtrWatch {
    char **paths;
    struct stat *seen;
    size_t count;
} PtrWatch;

/* Watches scene and the files it depends on, as they are now. */
void ptr_watch_set(PtrWatch *watch, const char *scene, const PtrStrings *dependencies);
void ptr_watch_free(PtrWatch *watch);

/* Polls until a watched file's time or size changes and then stays put for a
 * moment (editors write in several steps): returns 1. Returns 0 as soon as
 * *stop is set. */
int ptr_watch_wait(PtrWatch *watch, const volatile sig_atomic_t *stop);

#endif /* PTR_WATCH_H */
