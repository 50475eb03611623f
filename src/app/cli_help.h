/* What the command line prints instead of rendering: --help, --version and
 * --print-dispatch, on stdout. */
#ifndef PTR_CLI_HELP_H
#define PTR_CLI_HELP_H

#include "app/cli_options.h"

/* Prints what options->print asks for, the CPU level being options'. */
void ptr_print_requested(const PtrOptions *options);

#endif /* PTR_CLI_HELP_H */
