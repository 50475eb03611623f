/* SIGINT and SIGTERM: the first asks for a clean stop (the current pass is
 * finished and its image written), the second ends the process at once. */
#ifndef PTR_SIGNALS_H
#define PTR_SIGNALS_H

#include <signal.h>

/* Set by the first signal. */
extern volatile sig_atomic_t ptr_stop_requested;

/* Exit status after a second signal: 128 + SIGINT, as shells report it. */
enum { PTR_EXIT_ABORTED = 130 };

/* Installs the handlers and clears the flag. */
void ptr_signals_install(void);

#endif /* PTR_SIGNALS_H */
