/*
 * vib.h: a sweep's or basin grid's tasks over the ranks of an MPI job (dyn/vib.h prsm_vib_split;
 * docs/mpi.md "Sweeps and basins").
 */
#ifndef PRSM_PAR_VIB_H
#define PRSM_PAR_VIB_H

#include "dyn/vib.h"

/* sp: parts = the ranks, part = this rank, the exchange a gather to rank 0 (prsm_par_gather). The
 * test hook PRSM_PAR_FAULT (par.h) acts at the exchange: fail:R sends rank R's failure instead of
 * its results, exit:R exits there. Needs prsm_par_init. */
void prsm_par_vib_split(prsm_vib_split *sp);

#endif
