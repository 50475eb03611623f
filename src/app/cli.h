/* The ptr command line: parse, import, render, write. Kept in the library so
 * that tests drive exactly what the executable runs. */
#ifndef PTR_CLI_H
#define PTR_CLI_H

/* Runs ptr with the given arguments and returns the process exit code.
 * Errors and statistics go to stderr, --help and --version to stdout. */
int ptr_cli_main(int argc, char **argv);

#endif /* PTR_CLI_H */
