/* Kept threads: every piece of work handed over runs exactly once, on another
 * thread, and has returned when ptr_thread_join does; the same threads serve
 * round after round. ptr_parallel_ranges covers its range exactly once,
 * whatever the thread count, with at least one thread and never more than
 * asked; ptr_thread_count gives a request's threads. Thread counts are
 * bounds, not exact numbers: the system may refuse a thread, and the cases
 * run in any order over the same process's threads. */
#include "test.h"

#include <pthread.h>
#include <stdatomic.h>
#include <time.h>

#include "base/cpu.h"
#include "base/threads.h"

enum { KEPT = 2, WORK = 5, ROUNDS = 200 };

/* The most threads any case asked to exist at once, besides the caller:
 * the process must never hold more. */
static int most_asked;

static void asked(int threads)
{
    if (threads > most_asked)
        most_asked = threads;
}

/* The process's threads, from the kernel's count. */
static int process_threads(void)
{
    FILE *status = fopen("/proc/self/status", "r");
    char line[256];
    int threads = -1;
    while (status && fgets(line, sizeof line, status))
        if (!strncmp(line, "Threads:", 8))
            threads = atoi(line + 8);
    if (status)
        fclose(status);
    return threads;
}

/* Kept threads exist, at most as many as asked; asking again starts none. */
static void test_keep(void)
{
    asked(KEPT);
    ptr_threads_keep(KEPT);
    int after = process_threads();
    CHECK(after >= 2);
    CHECK(after <= 1 + most_asked);
    ptr_threads_keep(KEPT);
    CHECK_INT(process_threads(), after);
}

typedef struct Work {
    atomic_int runs;
    pthread_t ran_on;
    atomic_int finished;
} Work;

static void *count_run(void *arg)
{
    Work *w = arg;
    atomic_fetch_add(&w->runs, 1);
    w->ran_on = pthread_self();
    /* Long enough that the joiner really waits now and then. */
    struct timespec pause = { 0, 20000 };
    nanosleep(&pause, NULL);
    atomic_store(&w->finished, 1);
    return NULL;
}

static void test_every_work_once(void)
{
    asked(WORK);
    Work work[WORK];
    int missed = 0, on_caller = 0, started = 0;
    for (int round = 0; round < ROUNDS; round++) {
        PtrThread *threads[WORK];
        for (int i = 0; i < WORK; i++) {
            atomic_init(&work[i].runs, 0);
            atomic_init(&work[i].finished, 0);
            threads[i] = ptr_thread_start(count_run, &work[i]);
            started += threads[i] != NULL;
        }
        for (int i = 0; i < WORK; i++) {
            if (!threads[i])
                continue;
            ptr_thread_join(threads[i]);
            missed += !atomic_load(&work[i].finished) || atomic_load(&work[i].runs) != 1;
            on_caller += pthread_equal(work[i].ran_on, pthread_self()) != 0;
        }
    }
    CHECK_INT(started, ROUNDS * WORK);
    CHECK_INT(missed, 0);
    CHECK_INT(on_caller, 0);
    /* Never more threads than asked at once: the same ones serve every round. */
    int threads = process_threads();
    CHECK(threads >= 2);
    CHECK(threads <= 1 + most_asked);
}

enum { RANGE_BEGIN = 3, RANGE_END = 1000, MAX_SEEN = 128 };

/* What the pieces of one ptr_parallel_ranges did: how often each index was
 * visited, its sum of squares, and the threads that ran pieces. */
typedef struct Ranges {
    atomic_int visits[RANGE_END];
    atomic_ullong sum;
    pthread_mutex_t lock;
    pthread_t seen[MAX_SEEN];
    int seen_count;
} Ranges;

static void visit(void *arg, size_t from, size_t to)
{
    Ranges *r = arg;
    unsigned long long sum = 0;
    for (size_t i = from; i < to; i++) {
        atomic_fetch_add(&r->visits[i], 1);
        sum += (unsigned long long)i * i;
    }
    atomic_fetch_add(&r->sum, sum);
    pthread_mutex_lock(&r->lock);
    int known = 0;
    for (int t = 0; t < r->seen_count; t++)
        known |= pthread_equal(r->seen[t], pthread_self()) != 0;
    if (!known && r->seen_count < MAX_SEEN)
        r->seen[r->seen_count++] = pthread_self();
    pthread_mutex_unlock(&r->lock);
}

static void test_parallel_ranges(void)
{
    /* The sum of i^2 over [3, 1000), in closed form: (n-1)n(2n-1)/6 up to
     * n = 1000, less 0 + 1 + 4. */
    const unsigned long long expected = 999ull * 1000 * 1999 / 6 - 5;
    const int counts[] = { 0, 1, 2, 3, 7, 64, 100 };
    for (size_t c = 0; c < sizeof counts / sizeof counts[0]; c++) {
        const int threads = counts[c];
        asked(threads < 1 ? 1 : threads);
        static Ranges r;
        memset(&r, 0, sizeof r);
        pthread_mutex_init(&r.lock, NULL);
        ptr_parallel_ranges(threads, RANGE_BEGIN, RANGE_END, visit, &r);
        int wrong = 0;
        for (int i = 0; i < RANGE_END; i++)
            wrong += atomic_load(&r.visits[i]) != (i >= RANGE_BEGIN);
        CHECK_INT(wrong, 0);
        CHECK_INT(atomic_load(&r.sum), expected);
        /* At least the caller's thread, never more than asked (0 means 1). */
        CHECK(r.seen_count >= 1);
        CHECK(r.seen_count <= (threads < 1 ? 1 : threads));
        pthread_mutex_destroy(&r.lock);
        printf("%3d threads asked: %d ran pieces\n", threads, r.seen_count);
    }
    CHECK(process_threads() <= 1 + most_asked);
}

/* The thread count of a request: as asked above 0, else one per CPU the
 * process may run on. */
static void test_thread_count(void)
{
    CHECK_INT(ptr_thread_count(1), 1);
    CHECK_INT(ptr_thread_count(3), 3);
    CHECK_INT(ptr_thread_count(0), ptr_usable_cpus());
    CHECK_INT(ptr_thread_count(-2), ptr_usable_cpus());
}

int main(void)
{
    const TestCase cases[] = {
        TEST_CASE(test_keep),
        TEST_CASE(test_every_work_once),
        TEST_CASE(test_parallel_ranges),
        TEST_CASE(test_thread_count),
    };
    TEST_RUN(cases);
    return test_report();
}
