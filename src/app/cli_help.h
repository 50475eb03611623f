/* What the command line prints instead of rendering: --help, --version and
 * --print-dispatch, on stdout. */
#ifndef PTR_CLI_HELP_H
#define PTR_CLI_HELP_H

void ptr_print_help(void);
void ptr_print_version(void);
void ptr_print_dispatch(void);

#endif /* PTR_CLI_HELP_H */
