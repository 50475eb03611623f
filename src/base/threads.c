#include "base/threads.h"

#include <pthread.h>
#include <stdlib.h>

struct PtrThread {
    void *(*fn)(void *); /* the work given, NULL while it waits for some */
    void *arg;
    int done;            /* fn has returned; cleared by ptr_thread_join */
    PtrThread *next;     /* in the list of waiting threads */
};

/* One lock and one condition for every kept thread: work is handed over a
 * few times a pass, never in a loop that would contend. */
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t changed = PTHREAD_COND_INITIALIZER;
static PtrThread *waiting;
static int kept; /* threads started, waiting or working */

static void *run(void *self)
{
    PtrThread *t = self;
    pthread_mutex_lock(&lock);
    for (;;) {
        while (!t->fn)
            pthread_cond_wait(&changed, &lock);
        pthread_mutex_unlock(&lock);
        t->fn(t->arg);
        pthread_mutex_lock(&lock);
        t->fn = NULL;
        t->done = 1;
        pthread_cond_broadcast(&changed);
    }
    return NULL;
}

/* A new thread, waiting for work; with the lock held. */
static PtrThread *spawn_locked(void)
{
    PtrThread *t = calloc(1, sizeof *t);
    pthread_t id;
    if (!t)
        return NULL;
    if (pthread_create(&id, NULL, run, t)) {
        free(t);
        return NULL;
    }
    pthread_detach(id);
    kept++;
    return t;
}

void ptr_threads_keep(int count)
{
    pthread_mutex_lock(&lock);
    while (kept < count) {
        PtrThread *t = spawn_locked();
        if (!t)
            break;
        t->next = waiting;
        waiting = t;
    }
    pthread_mutex_unlock(&lock);
}

PtrThread *ptr_thread_start(void *(*fn)(void *), void *arg)
{
    pthread_mutex_lock(&lock);
    PtrThread *t = waiting;
    if (t)
        waiting = t->next;
    else
        t = spawn_locked();
    if (t) {
        t->arg = arg;
        t->done = 0;
        t->fn = fn;
        pthread_cond_broadcast(&changed);
    }
    pthread_mutex_unlock(&lock);
    return t;
}

void ptr_thread_join(PtrThread *t)
{
    pthread_mutex_lock(&lock);
    while (!t->done)
        pthread_cond_wait(&changed, &lock);
    t->next = waiting;
    waiting = t;
    pthread_mutex_unlock(&lock);
}

typedef struct Piece {
    void (*fn)(void *arg, size_t begin, size_t end);
    void *arg;
    size_t begin, end;
} Piece;

static void *run_piece(void *arg)
{
    Piece *p = arg;
    p->fn(p->arg, p->begin, p->end);
    return NULL;
}

enum { PIECES_MAX = 64 };

void ptr_parallel_ranges(int threads, size_t begin, size_t end,
                         void (*fn)(void *arg, size_t begin, size_t end), void *arg)
{
    Piece pieces[PIECES_MAX];
    PtrThread *ids[PIECES_MAX];
    const size_t n = threads < 1 ? 1 : threads > PIECES_MAX ? PIECES_MAX : (size_t)threads;
    for (size_t i = 0; i < n; i++) {
        const size_t count = end - begin;
        pieces[i] = (Piece){ fn, arg, begin + count * i / n, begin + count * (i + 1) / n };
        ids[i] = i > 0 ? ptr_thread_start(run_piece, &pieces[i]) : NULL;
    }
    for (size_t i = 0; i < n; i++)
        if (!ids[i])
            run_piece(&pieces[i]);
    for (size_t i = 1; i < n; i++)
        if (ids[i])
            ptr_thread_join(ids[i]);
}
