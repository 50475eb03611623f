#include "base/threads.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "base/cpu.h"

typedef void *(*Work)(void *);

/* fn and done are written under the lock, and read without it only by a
 * thread that spins before it sleeps; each thread on a cache line of its
 * own, so that one's spin does not fetch the line another's writes. */
struct PtrThread {
    _Alignas(64) _Atomic(Work) fn; /* the work given, NULL while it waits for some */
    void *arg;
    atomic_int done; /* fn has returned; cleared by ptr_thread_start */
    PtrThread *next; /* in the list of waiting threads */
    /* fn given or done set: waited on by this thread and its joiner alone.
     * (With one condition for all, each handoff woke every idle kept
     * thread through the kernel, on a 2-vCPU machine taking a vCPU from the
     * two at work: a handoff and back took 12 microseconds, now 5.) */
    pthread_cond_t changed;
};

/* One lock for every kept thread: work is handed over at most a few
 * thousand times a second (the tree build's top levels), never in a loop
 * that would contend. */
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static PtrThread *waiting;
static int kept; /* threads started, waiting or working */
/* Whether a thread may spin before it sleeps: only while the kept threads
 * fit the CPUs (a render's or a build's threads are at most the threads
 * kept, the caller among them), for a spinning thread would take a core
 * from one at work otherwise. */
static atomic_int spin_fits;

/* How long a thread that waits for work or for another thread's end
 * watches for it before it sleeps on the condition. A sleeping thread is
 * woken through the kernel, and on a virtual machine whose other vCPU has
 * gone idle through the hypervisor too: that made a handoff and back some
 * five times slower (docs/intersectors.md, "From one thread to two";
 * bench/scaling prints it). Work handed over in quick succession (the tree
 * build's top levels) then waits far less; a thread that waits longer
 * first spends this long of a core. */
static const double spin_seconds = 200e-6;

static int has_work(const PtrThread *t)
{
    return atomic_load_explicit(&t->fn, memory_order_acquire) != NULL;
}

static int has_ended(const PtrThread *t)
{
    return atomic_load_explicit(&t->done, memory_order_acquire);
}

/* Watches t, without the lock, until it is ready or the spin is over. */
static void spin_until(int (*ready)(const PtrThread *), const PtrThread *t)
{
    if (!atomic_load_explicit(&spin_fits, memory_order_relaxed))
        return;
    const double until = ptr_now_seconds() + spin_seconds;
    for (int i = 1; !ready(t); i++) {
#if defined(__x86_64__) || defined(__i386__)
        __builtin_ia32_pause(); /* the other hyperthread's turn, less power */
#endif
        if (i % 64 == 0 && ptr_now_seconds() > until)
            return;
    }
}

static void *run(void *self)
{
    PtrThread *t = self;
    for (;;) {
        spin_until(has_work, t);
        pthread_mutex_lock(&lock);
        while (!t->fn)
            pthread_cond_wait(&t->changed, &lock);
        const Work fn = t->fn;
        pthread_mutex_unlock(&lock);
        fn(t->arg);
        pthread_mutex_lock(&lock);
        t->fn = NULL;
        t->done = 1;
        pthread_cond_broadcast(&t->changed);
        pthread_mutex_unlock(&lock);
    }
    return NULL;
}

/* A new thread, waiting for work; with the lock held. */
static PtrThread *spawn_locked(void)
{
    PtrThread *t = aligned_alloc(_Alignof(PtrThread), sizeof *t);
    pthread_t id;
    if (!t)
        return NULL;
    memset(t, 0, sizeof *t);
    if (pthread_cond_init(&t->changed, NULL)) {
        free(t);
        return NULL;
    }
    if (pthread_create(&id, NULL, run, t)) {
        pthread_cond_destroy(&t->changed);
        free(t);
        return NULL;
    }
    pthread_detach(id);
    kept++;
    atomic_store_explicit(&spin_fits, kept <= ptr_usable_cpus(), memory_order_relaxed);
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
        pthread_cond_broadcast(&t->changed);
    }
    pthread_mutex_unlock(&lock);
    return t;
}

void ptr_thread_join(PtrThread *t)
{
    spin_until(has_ended, t);
    pthread_mutex_lock(&lock);
    while (!t->done)
        pthread_cond_wait(&t->changed, &lock);
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
    const size_t count = end - begin;
    size_t n = threads < 1 ? 1 : threads > PIECES_MAX ? PIECES_MAX : (size_t)threads;
    if (n > count) /* no thread started for an empty piece */
        n = count ? count : 1;
    for (size_t i = 0; i < n; i++) {
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

typedef struct Split {
    void (*fn)(void *arg, size_t piece, size_t from, size_t to);
    void *arg;
    size_t count, pieces;
} Split;

static void run_split(void *arg, size_t first, size_t end)
{
    const Split *p = arg;
    for (size_t k = first; k < end; k++)
        p->fn(p->arg, k, p->count * k / p->pieces, p->count * (k + 1) / p->pieces);
}

void ptr_parallel_pieces(int threads, size_t count, size_t pieces,
                         void (*fn)(void *arg, size_t piece, size_t from, size_t to), void *arg)
{
    Split p = { fn, arg, count, pieces };
    /* No more threads than pieces: the others would start for nothing. */
    const int busy = threads < 1 || pieces == 0      ? 1
                     : (size_t)threads < pieces ? threads
                                                : (int)pieces;
    ptr_parallel_ranges(busy, 0, pieces, run_split, &p);
}
