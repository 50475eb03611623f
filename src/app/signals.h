/* How the process ends from outside the normal flow. SIGINT and SIGTERM: the
 * first asks for a clean stop (the current pass is finished and its image
 * written), the second ends the process at once. A C++ exception that nothing
 * caught ends it with one line and its exit code (uncaught.cpp). */
#ifndef PTR_SIGNALS_H
#define PTR_SIGNALS_H

#include <signal.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Set by the first signal. */
extern volatile sig_atomic_t ptr_stop_requested;

/* Exit status after a second signal: 128 + SIGINT, as shells report it. */
enum { PTR_EXIT_ABORTED = 130 };

/* Installs the handlers (the terminate handler too) and clears the flag. */
void ptr_signals_install(void);

/* Makes std::terminate print "ptr: MESSAGE", discard a partial output and
 * exit with the code of what was thrown: 6 when memory or a thread was
 * refused, else 1. */
void ptr_uncaught_install(void);

#ifdef __cplusplus
}
#endif

#endif /* PTR_SIGNALS_H */
