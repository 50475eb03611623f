/* Kept threads: every piece of work handed over runs exactly once, on another
 * thread, and has returned when ptr_thread_join does; more work than kept
 * threads starts new ones; the same threads serve round after round. */
#include "test.h"

#include <pthread.h>
#include <stdatomic.h>
#include <time.h>

#include "base/threads.h"

enum { KEPT = 2, WORK = 5, ROUNDS = 200 };

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

static void test_every_work_once(void)
{
    ptr_threads_keep(KEPT);
    CHECK_INT(process_threads(), 1 + KEPT);
    ptr_threads_keep(KEPT);
    CHECK_INT(process_threads(), 1 + KEPT);
    Work work[WORK];
    int missed = 0, on_caller = 0;
    for (int round = 0; round < ROUNDS; round++) {
        PtrThread *threads[WORK];
        for (int i = 0; i < WORK; i++) {
            atomic_init(&work[i].runs, 0);
            atomic_init(&work[i].finished, 0);
            threads[i] = ptr_thread_start(count_run, &work[i]);
            CHECK(threads[i] != NULL);
        }
        for (int i = 0; i < WORK; i++) {
            ptr_thread_join(threads[i]);
            missed += !atomic_load(&work[i].finished) || atomic_load(&work[i].runs) != 1;
            on_caller += pthread_equal(work[i].ran_on, pthread_self()) != 0;
        }
    }
    CHECK_INT(missed, 0);
    CHECK_INT(on_caller, 0);
    /* Never more threads than work at once: the same ones serve every round. */
    CHECK_INT(process_threads(), 1 + WORK);
}

int main(void)
{
    test_every_work_once();
    return test_report();
}
