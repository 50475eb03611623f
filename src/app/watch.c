#include "app/watch.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { POLL_MS = 200, SETTLE_POLLS = 2 };

static void sleep_ms(long ms)
{
    nanosleep(&(struct timespec){ ms / 1000, (ms % 1000) * 1000000L }, NULL);
}

/* What is compared: a missing file counts as a state too. */
static struct stat look(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0)
        memset(&st, 0, sizeof st);
    return st;
}

static int same(const struct stat *a, const struct stat *b)
{
    return a->st_size == b->st_size && a->st_mtim.tv_sec == b->st_mtim.tv_sec &&
           a->st_mtim.tv_nsec == b->st_mtim.tv_nsec && a->st_ino == b->st_ino;
}

void ptr_watch_free(PtrWatch *watch)
{
    for (size_t i = 0; i < watch->count; i++)
        free(watch->paths[i]);
    free(watch->paths);
    free(watch->seen);
    memset(watch, 0, sizeof *watch);
}

void ptr_watch_set(PtrWatch *watch, const char *scene, const PtrStrings *dependencies)
{
    ptr_watch_free(watch);
    size_t n = 1 + (dependencies ? dependencies->count : 0);
    watch->paths = calloc(n, sizeof *watch->paths);
    watch->seen = calloc(n, sizeof *watch->seen);
    if (!watch->paths || !watch->seen) {
        ptr_watch_free(watch);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        const char *path = i == 0 ? scene : dependencies->lines[i - 1];
        watch->paths[i] = strdup(path);
        if (!watch->paths[i])
            break;
        watch->seen[i] = look(path);
        watch->count = i + 1;
    }
}

static int changed(PtrWatch *watch)
{
    int any = 0;
    for (size_t i = 0; i < watch->count; i++) {
        struct stat now = look(watch->paths[i]);
        if (!same(&now, &watch->seen[i])) {
            watch->seen[i] = now;
            any = 1;
        }
    }
    return any;
}

int ptr_watch_wait(PtrWatch *watch, const volatile sig_atomic_t *stop)
{
    while (!*stop) {
        sleep_ms(POLL_MS);
        if (!changed(watch))
            continue;
        for (int quiet = 0; quiet < SETTLE_POLLS && !*stop;) {
            sleep_ms(POLL_MS);
            quiet = changed(watch) ? 0 : quiet + 1;
        }
        return !*stop;
    }
    return 0;
}
