/*
 * options.c: the command-line options the subcommands share: whole-number option values, and
 * the options of the commands that run one document (`prsm study`, `optimize`, `allocate`):
 * FILE|-, --out FILE, --quiet, and where the command has them --csv FILE and --threads N.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/commands.h"
#include "mc/engine.h"

int prsm_cli_int_option(long long *out, const char *command, const char *opt, const char *value, long long lo,
                        long long hi)
{
	char *end = NULL;
	errno = 0;
	long long v = value ? strtoll(value, &end, 10) : 0;
	if (!value || !*value || *end || errno || v < lo || v > hi) {
		fprintf(stderr, "prsm %s: %s takes an integer %lld..%lld\n", command, opt, lo, hi);
		return -1;
	}
	*out = v;
	return 0;
}

int prsm_cli_doc_options_parse(prsm_cli_doc_options *o, int argc, char **argv, const char *command, int with)
{
	memset(o, 0, sizeof *o);
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		int has_value = i + 1 < argc;
		if (strcmp(a, "--out") == 0 && has_value) {
			o->out_path = argv[++i];
		} else if ((with & PRSM_CLI_WITH_CSV) && strcmp(a, "--csv") == 0 && has_value) {
			o->csv_path = argv[++i];
		} else if ((with & PRSM_CLI_WITH_THREADS) && strcmp(a, "--threads") == 0 && has_value) {
			long long n;
			if (prsm_cli_int_option(&n, command, a, argv[++i], 1, PRSM_MC_MAX_THREADS))
				return -1;
			o->threads = (int)n;
		} else if (strcmp(a, "--quiet") == 0) {
			o->quiet = 1;
		} else if (a[0] == '-' && a[1] != '\0') {
			fprintf(stderr, "prsm %s: unknown option '%s'\n", command, a);
			return -1;
		} else if (!o->path) {
			o->path = a;
		} else {
			fprintf(stderr, "prsm %s: more than one file given\n", command);
			return -1;
		}
	}
	if (!o->path) {
		fprintf(stderr, "usage: prsm %s FILE|- [--out FILE]%s%s [--quiet]\n", command,
		        with & PRSM_CLI_WITH_CSV ? " [--csv FILE]" : "", with & PRSM_CLI_WITH_THREADS ? " [--threads N]" : "");
		return -1;
	}
	return 0;
}
