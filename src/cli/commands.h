/*
 * commands.h: the subcommands of the prsm command line. Each takes the arguments after the
 * program name (argv[0] is the command) and returns the process exit code.
 */
#ifndef PRSM_CLI_COMMANDS_H
#define PRSM_CLI_COMMANDS_H

enum { PRSM_EXIT_OK = 0, PRSM_EXIT_INVALID = 1, PRSM_EXIT_FAILED = 2, PRSM_EXIT_USAGE = 64 };

/* Largest request file the CLI reads, bytes. */
#define PRSM_CLI_MAX_REQUEST_BYTES (16u * 1024u * 1024u)

int prsm_cli_analyze(int argc, char **argv);
int prsm_cli_validate(int argc, char **argv);
int prsm_cli_bench(int argc, char **argv);
int prsm_cli_version(int argc, char **argv);

#endif
