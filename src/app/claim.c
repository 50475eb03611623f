#define _DEFAULT_SOURCE /* gethostname */
#include "app/claim.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* The claim this process holds, for the keeper and for release. */
static struct {
    pthread_mutex_t lock;
    pthread_cond_t wake;
    char path[PTR_PATH_SIZE + 8]; /* "" when none */
    dev_t dev;
    ino_t ino;
    pthread_t thread;
    int running, quit;
} held = { .lock = PTHREAD_MUTEX_INITIALIZER, .wake = PTHREAD_COND_INITIALIZER };

static int claim_path(const char *output, char *path)
{
    int n = snprintf(path, PTR_PATH_SIZE + 8, "%s.claim", output);
    return n > 0 && n < PTR_PATH_SIZE + 8;
}

static void host_name(char *host, size_t size)
{
    if (gethostname(host, size) != 0)
        snprintf(host, size, "unknown");
    host[size - 1] = '\0';
}

/* Whether the claim at path, holding text, belongs to a process that is
 * gone (see claim.h). */
static int is_stale(const char *path, const char *text)
{
    char host[256], their_host[256];
    long pid;
    host_name(host, sizeof host);
    if (sscanf(text, "%255s %ld", their_host, &pid) == 2 && !strcmp(host, their_host) && pid > 0)
        return kill((pid_t)pid, 0) != 0 && errno == ESRCH;
    struct stat st;
    return stat(path, &st) == 0 && time(NULL) - st.st_mtime > PTR_CLAIM_STALE_SECONDS;
}

/* The first line of a claim file into text. */
static void read_claim(const char *path, char *text, size_t size)
{
    text[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    if (!fgets(text, (int)size, f))
        text[0] = '\0';
    fclose(f);
    text[strcspn(text, "\n")] = '\0';
}

static int exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Creates the claim file exclusively: 1 if made, 0 if one exists, -1 on
 * another error (errno says). */
static int create_claim(const char *path)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd < 0)
        return errno == EEXIST ? 0 : -1;
    char host[256], text[300];
    host_name(host, sizeof host);
    int n = snprintf(text, sizeof text, "%s %ld\n", host, (long)getpid());
    struct stat st;
    int ok = write(fd, text, (size_t)n) == n && fstat(fd, &st) == 0;
    int saved = errno;
    close(fd);
    if (!ok) {
        unlink(path);
        errno = saved;
        return -1;
    }
    pthread_mutex_lock(&held.lock);
    snprintf(held.path, sizeof held.path, "%s", path);
    held.dev = st.st_dev;
    held.ino = st.st_ino;
    pthread_mutex_unlock(&held.lock);
    return 1;
}

PtrClaimState ptr_claim_take(const char *output, char *holder, size_t size, PtrError *err)
{
    char path[PTR_PATH_SIZE + 8];
    holder[0] = '\0';
    if (exists(output))
        return PTR_CLAIM_EXISTS;
    if (!claim_path(output, path)) {
        ptr_error_set(err, PTR_ERR_OUTPUT, "%s: path too long", output);
        return PTR_CLAIM_FAILED;
    }
    /* A stale claim is removed and the claim tried once more: whoever
     * creates it first renders. */
    for (int attempt = 0; attempt < 2; attempt++) {
        int made = create_claim(path);
        if (made < 0) {
            ptr_error_set(err, PTR_ERR_OUTPUT, "%s: cannot create the claim %s: %s", output, path,
                          strerror(errno));
            return PTR_CLAIM_FAILED;
        }
        if (made) {
            /* Another process may have written the output and dropped its
             * claim between the look above and this claim. */
            if (exists(output)) {
                ptr_claim_release(output);
                return PTR_CLAIM_EXISTS;
            }
            return PTR_CLAIM_TAKEN;
        }
        read_claim(path, holder, size);
        if (!is_stale(path, holder))
            return PTR_CLAIM_BUSY;
        fprintf(stderr, "ptr: %s: taking over the stale claim of %s\n", output,
                holder[0] ? holder : "an unknown process");
        unlink(path);
    }
    return PTR_CLAIM_BUSY;
}

void ptr_claim_release(const char *output)
{
    char path[PTR_PATH_SIZE + 8];
    if (!claim_path(output, path))
        return;
    pthread_mutex_lock(&held.lock);
    struct stat st;
    /* Only the claim this process made: a stale-claim takeover elsewhere
     * may have put another's in its place. */
    if (!strcmp(held.path, path) && stat(path, &st) == 0 && st.st_dev == held.dev &&
        st.st_ino == held.ino)
        unlink(path);
    if (!strcmp(held.path, path))
        held.path[0] = '\0';
    pthread_mutex_unlock(&held.lock);
}

/* Touches the claim held every PTR_CLAIM_REFRESH_SECONDS, so that other
 * hosts see it live. */
static void *keep_claims(void *unused)
{
    (void)unused;
    pthread_mutex_lock(&held.lock);
    while (!held.quit) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        until.tv_sec += PTR_CLAIM_REFRESH_SECONDS;
        pthread_cond_timedwait(&held.wake, &held.lock, &until);
        if (!held.quit && held.path[0])
            utimensat(AT_FDCWD, held.path, NULL, 0);
    }
    pthread_mutex_unlock(&held.lock);
    return NULL;
}

PtrResult ptr_claim_keeper_start(PtrError *err)
{
    if (held.running)
        return PTR_OK;
    /* The keeper takes no signals: the render's stop stays the main thread's. */
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    held.running = pthread_create(&held.thread, NULL, keep_claims, NULL) == 0;
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return held.running ? PTR_OK
                        : ptr_error_set(err, PTR_ERR_NOMEM,
                                        "cannot start the thread that keeps claims fresh");
}

void ptr_claim_keeper_stop(void)
{
    if (!held.running)
        return;
    pthread_mutex_lock(&held.lock);
    held.quit = 1;
    pthread_cond_signal(&held.wake);
    pthread_mutex_unlock(&held.lock);
    pthread_join(held.thread, NULL);
    held.running = 0;
}
