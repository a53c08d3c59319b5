/*
 * replay.c: the plain driver of a fuzz target: each argument is a file or a directory of
 * files, each file is fed once to LLVMFuzzerTestOneInput. CTest runs it over the corpus
 * (tests/fuzz/corpus/...), so every input the fuzzer ever kept is a regression test. Files run
 * in name order, each named on stdout before it runs (the last one named is the one that
 * crashed); a directory without inputs is a failure (a corpus that went missing).
 */
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "util/file.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int run_file(const char *path)
{
	printf("replay: %s\n", path);
	fflush(stdout);
	char *buf = NULL;
	size_t len = 0;
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_file_read(&buf, &len, path, 64u * 1024u * 1024u, &err)) {
		fprintf(stderr, "replay: %s: %s\n", path, err.message);
		return 1;
	}
	/* an exact-size copy, so ASan sees reads past the input's end */
	uint8_t *copy = malloc(len ? len : 1); /* freed below */
	if (!copy) {
		free(buf);
		return 1;
	}
	memcpy(copy, buf, len);
	free(buf);
	LLVMFuzzerTestOneInput(copy, len);
	free(copy);
	return 0;
}

int main(int argc, char **argv)
{
	int failures = 0, files = 0;
	for (int i = 1; i < argc; i++) {
		struct stat st;
		if (stat(argv[i], &st)) {
			perror(argv[i]);
			failures++;
			continue;
		}
		if (!S_ISDIR(st.st_mode)) {
			failures += run_file(argv[i]);
			files++;
			continue;
		}
		struct dirent **names = NULL;
		int n = scandir(argv[i], &names, NULL, alphasort);
		if (n < 0) {
			perror(argv[i]);
			failures++;
			continue;
		}
		int here = 0;
		for (int k = 0; k < n; k++) {
			if (names[k]->d_name[0] != '.') {
				char path[4096];
				snprintf(path, sizeof path, "%s/%s", argv[i], names[k]->d_name);
				failures += run_file(path);
				files++;
				here++;
			}
			free(names[k]);
		}
		free(names);
		if (!here) {
			fprintf(stderr, "replay: %s: no inputs\n", argv[i]);
			failures++;
		}
	}
	printf("replay: %d inputs, %d unreadable or missing\n", files, failures);
	return failures ? 1 : 0;
}
