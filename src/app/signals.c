#include "app/signals.h"

#include <string.h>
#include <unistd.h>

#include "image/image.h"

volatile sig_atomic_t ptr_stop_requested;

static void on_signal(int signo)
{
    (void)signo;
    if (!ptr_stop_requested) {
        ptr_stop_requested = 1;
        return;
    }
    /* Only async-signal-safe calls: a half-written temporary file goes, the
     * output is never touched. */
    ptr_image_discard_partial();
    _exit(PTR_EXIT_ABORTED);
}

void ptr_signals_install(void)
{
    struct sigaction action;
    memset(&action, 0, sizeof action);
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, NULL);
    sigaction(SIGTERM, &action, NULL);
    ptr_uncaught_install();
    ptr_stop_requested = 0;
}
