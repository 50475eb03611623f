/* Threads that outlive their work, started once and reused: a render starts
 * its workers again at every pass, and starting a thread takes glibc's lock
 * on thread-local storage, which a dlopen holds for its whole load (the image
 * module's 260 libraries, a quarter of a second). Threads kept from before the
 * load start work without that lock. */
#ifndef PTR_THREADS_H
#define PTR_THREADS_H

#include <stddef.h>

typedef struct PtrThread PtrThread;

/* Makes sure count threads exist to take work, starting those missing (fewer
 * if the system refuses): a second call with the same count starts none. */
void ptr_threads_keep(int count);

/* Runs fn(arg) on a waiting thread, or on a new one (kept afterwards) if none
 * waits. Returns NULL if no thread could be started. */
PtrThread *ptr_thread_start(void *(*fn)(void *), void *arg);

/* Waits until fn has returned; the thread then waits for other work. A
 * kept thread waiting for work, and a caller waiting here, first watch for
 * it up to 200 microseconds, a core's worth (while the kept threads fit the
 * CPUs), then sleep. */
void ptr_thread_join(PtrThread *thread);

/* Runs fn(arg, from, to) over begin .. end - 1 cut into one contiguous
 * piece a thread, the calling thread taking the first (and any a thread
 * could not be started for). For work whose result does not depend on how
 * it is cut. */
void ptr_parallel_ranges(int threads, size_t begin, size_t end,
                         void (*fn)(void *arg, size_t from, size_t to), void *arg);

/* Runs fn(arg, k, from, to) for each piece k < pieces of 0 .. count - 1,
 * piece k being count * k / pieces .. count * (k + 1) / pieces - 1, the
 * pieces shared out as ptr_parallel_ranges shares its range: for work that
 * keeps a result a piece, which the caller then takes in the pieces' order,
 * so that the result does not depend on which thread ran which piece. (A
 * caller whose piece count follows the thread count also needs results that
 * do not depend on how the items are grouped: minima, maxima, PtrHugeChoice.) */
void ptr_parallel_pieces(int threads, size_t count, size_t pieces,
                         void (*fn)(void *arg, size_t piece, size_t from, size_t to), void *arg);

#endif /* PTR_THREADS_H */
