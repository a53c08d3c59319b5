/*
 * errors.c: the error set (docs/model/errors-and-assembly.md).
 */
#include "model/errors.h"

#include <string.h>

void prsm_errors_zero(prsm_errors *e, int rollers)
{
	memset(e, 0, sizeof *e);
	if (rollers < 0)
		rollers = 0;
	e->rollers = rollers > PRSM_ERRORS_MAX_ROLLERS ? PRSM_ERRORS_MAX_ROLLERS : rollers;
}

static int zero_doubles(const double *v, size_t n)
{
	for (size_t i = 0; i < n; i++)
		if (v[i] != 0.0)
			return 0;
	return 1;
}

int prsm_errors_all_zero(const prsm_errors *e)
{
	/* every member is a double except `rollers` */
	if (!zero_doubles((const double *)&e->screw, sizeof e->screw / sizeof(double)) ||
	    !zero_doubles((const double *)&e->nut, sizeof e->nut / sizeof(double)) ||
	    !zero_doubles((const double *)&e->carrier, sizeof e->carrier / sizeof(double)))
		return 0;
	for (int j = 0; j < e->rollers; j++)
		if (!zero_doubles((const double *)&e->roller[j], sizeof e->roller[j] / sizeof(double)))
			return 0;
	return 1;
}
