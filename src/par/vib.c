/*
 * vib.c: the split of dyn/vib.h over the ranks (see vib.h).
 */
#include "par/vib.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "par/par.h"

static int exchange(void *ctx, const void *mine, size_t len, prsm_vib_share *shares, prsm_error *err)
{
	(void)ctx;
	prsm_vib_share_head h;
	if (prsm_par_fault()) {
		memset(&h, 0, sizeof h);
		h.code = PRSM_EIO;
		snprintf(h.message, sizeof h.message, "injected failure (PRSM_PAR_FAULT)");
		mine = &h;
		len = sizeof h;
	}
	const int size = prsm_par_size(), leader = prsm_par_rank() == 0;
	prsm_par_blob *all = leader ? calloc((size_t)size, sizeof *all) : NULL;
	if (leader && !all)
		prsm_par_abort(2, "out of memory for %d ranks' results", size);
	int rc = prsm_par_gather(mine, len, all, err);
	if (rc) {
		prsm_par_blobs_free(all, leader ? size : 0);
		free(all);
		return rc;
	}
	if (leader) {
		for (int q = 0; q < size; q++) {
			shares[q].data = all[q].data;
			shares[q].len = all[q].len;
		}
		free(all);
	}
	return 0;
}

void prsm_par_vib_split(prsm_vib_split *sp)
{
	memset(sp, 0, sizeof *sp);
	sp->parts = prsm_par_size();
	sp->part = prsm_par_rank();
	sp->exchange = exchange;
	sp->ctx = NULL;
}
