/*
 * kinds.c: the table of job kinds (see kind.h). One line per kind.
 */
#include "job/kind.h"

#include <stdlib.h>
#include <string.h>

const prsm_job_kind *const prsm_job_kinds[] = {
	&prsm_job_kind_study,
	&prsm_job_kind_optimization,
	&prsm_job_kind_allocation,
	&prsm_job_kind_analysis,
	&prsm_job_kind_simulation,
	&prsm_job_kind_calibration,
};

const size_t prsm_job_kind_count = sizeof prsm_job_kinds / sizeof prsm_job_kinds[0];

const prsm_job_kind *prsm_job_kind_by_collection(const char *collection)
{
	for (size_t i = 0; i < prsm_job_kind_count; i++)
		if (strcmp(prsm_job_kinds[i]->collection, collection) == 0)
			return prsm_job_kinds[i];
	return NULL;
}

const prsm_job_kind *prsm_job_kind_by_name(const char *name)
{
	for (size_t i = 0; i < prsm_job_kind_count; i++)
		if (strcmp(prsm_job_kinds[i]->name, name) == 0)
			return prsm_job_kinds[i];
	return NULL;
}

int prsm_job_text(char **text, size_t *len, int (*write)(FILE *f, const void *ctx), const void *ctx)
{
	*text = NULL;
	*len = 0;
	char *buf = NULL;
	size_t size = 0;
	FILE *f = open_memstream(&buf, &size); /* buf handed to the caller on success */
	if (!f)
		return PRSM_ENOMEM;
	int rc = write(f, ctx);
	if (fclose(f) && !rc)
		rc = PRSM_EIO;
	if (rc) {
		free(buf);
		return rc;
	}
	*text = buf;
	*len = size;
	return 0;
}

void prsm_job_output_free(prsm_job_output *o)
{
	free(o->result);
	free(o->csv);
	o->result = o->csv = NULL;
	o->result_len = o->csv_len = 0;
}
