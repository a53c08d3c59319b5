/*
 * prsm_model.h: the roller screw as a Monte Carlo model (docs/model/errors-and-assembly.md, docs/model/kinematics-efficiency-stiffness-life.md).
 *
 * Each sampled variable is bound to one error of model/errors.h (or a friction coefficient):
 * the sample's value times `scale` is added to the base error set, then the assembly is
 * evaluated for the outputs the study asks for, in linear or exact mode. Per-roller
 * tolerances bind one variable per roller; a radial error's phase is a variable of its own.
 */
#ifndef PRSM_MC_PRSM_MODEL_H
#define PRSM_MC_PRSM_MODEL_H

#include "dyn/vib_mc.h"
#include "mc/engine.h"
#include "model/assembly.h"

typedef enum {
	PRSM_PART_SCREW = 0,
	PRSM_PART_NUT = 1,
	PRSM_PART_CARRIER = 2,
	PRSM_PART_ROLLER = 3,
	PRSM_PART_FRICTION = 4,         /* offset 0: screw-roller mu, 1: nut-roller mu */
	PRSM_PART_DYNAMICS = 5          /* the dynamic model's own tolerances (MODEL-DYNAMICS.md §8.6),
	                                   absolute values: offset PRSM_DYN_TOL_* */
} prsm_part;

/* PRSM_PART_DYNAMICS offsets: ring_gear.mesh_error_um (e_g, m), ring_gear.backlash_um (b_g, m),
 * damping_ratio (zeta_a = zeta_g, -) */
enum { PRSM_DYN_TOL_MESH_ERROR = 0, PRSM_DYN_TOL_BACKLASH = 1, PRSM_DYN_TOL_DAMPING = 2, PRSM_DYN_TOLS = 3 };

typedef struct {
	prsm_part part;
	int roller;                     /* PRSM_PART_ROLLER: which roller, -1 every roller (shared);
	                                   screw/nut: -1 adds to every start's index (shared
	                                   start_index), else 0 */
	size_t offset;                  /* byte offset of the double in prsm_body_errors,
	                                   prsm_roller_errors or prsm_carrier_errors */
	double scale;                   /* engine units (mm, rad, mm/mm) per input unit */
} prsm_mc_binding;

/* Outputs a study of a design may ask for. */
typedef enum {
	PRSM_OUT_BACKLASH = 0,          /* backlash_um: B at screw angle 0 */
	PRSM_OUT_BACKLASH_MIN,          /* backlash_min_um: min of B over one screw revolution */
	PRSM_OUT_BACKLASH_MAX,          /* backlash_max_um */
	PRSM_OUT_SHARING,               /* load_sharing_factor: max roller load / (F/Z) at the operating load */
	PRSM_OUT_STIFFNESS,             /* stiffness_N_per_um: dF/du at the operating load (contacts only) */
	PRSM_OUT_STIFFNESS_RATIO,       /* stiffness_ratio: over the nominal-gap stiffness */
	PRSM_OUT_TE_PP,                 /* te_pp_um: transmission error p-p over one revolution */
	PRSM_OUT_TE_RMS,                /* te_rms_um */
	PRSM_OUT_EFFICIENCY,            /* efficiency_sliding (older name: efficiency): direct, sliding
	                                   (docs/model/kinematics-efficiency-stiffness-life.md) */
	PRSM_OUT_EFFICIENCY_BACK,       /* efficiency_back */
	PRSM_OUT_UNIT_STIFFNESS,        /* nut_unit_stiffness_N_per_um: the sampled contacts' dF/du in
	                                   series with the rest of the nut unit's compliance (threads,
	                                   cores, nut body: docs/model/kinematics-efficiency-stiffness-life.md) as the nominal design has it,
	                                   so that the error-free sample is prsm analyze's
	                                   stiffness.axial_N_per_um */
	PRSM_OUT_EFFICIENCY_LOSSES,     /* efficiency_with_losses: direct efficiency with every loss of
	                                   docs/model/kinematics-efficiency-stiffness-life.md (sliding, spin, gear mesh, drag) at the sample's
	                                   friction and the nominal load distribution, so the error-free
	                                   sample is prsm analyze's efficiency.eta */
	/* dynamic outputs (MODEL-DYNAMICS.md §8.6; need the study's dynamics section, prsm_mc_dyn) */
	PRSM_OUT_DYN_PEAK_TE,           /* peak_dynamic_te_um: max |X - X_static| over the window */
	PRSM_OUT_DYN_THREAD_FORCE,      /* peak_thread_force_N */
	PRSM_OUT_DYN_AXIAL_RMS,         /* axial_vibration_rms_m_s2: RMS nut acceleration */
	PRSM_OUT_DYN_CONTACT_LOSS,      /* contact_loss: 1 when a contact leaves its loaded flank, else 0 */
	PRSM_OUT_DYN_MESH_FORCE,        /* mesh_force_peak_N: both meshes of a roller, max over rollers */
	PRSM_OUT_DYN_REGIME,            /* regime: 1 P1, m period m windows, 0 non-periodic */
	PRSM_OUT_DYN_INTEGRATED,        /* integrated: 1 when the screen failed and the sample was integrated */
	PRSM_OUT_DYN_LYAPUNOV,          /* lyapunov_max (§8.6), 1/s: the largest Lyapunov exponent, the
	                                   largest Floquet exponent of a screened sample, Benettin's
	                                   estimate over PRSM_MC_DYN_LYAPUNOV_WINDOWS windows of an
	                                   integrated one */
	PRSM_OUT_COUNT
} prsm_output_kind;

#define PRSM_OUT_DYN_FIRST PRSM_OUT_DYN_PEAK_TE
/* 1 for an output of the dynamic model */
int prsm_output_is_dynamic(prsm_output_kind k);

/* The names are the schema's: study.schema.json, $defs/output_name, whose "x-prsm" gives each
 * its constant here (the build fails when they disagree); the generated prsm_vocab.h has them,
 * and PRSM_OUTPUT_NAMES_TEXT, every name for messages. */
const char *prsm_output_name(prsm_output_kind k);
int prsm_output_parse(const char *name, prsm_output_kind *out); /* 0 or PRSM_ENOTFOUND */

/* The dynamic model of a study (MODEL-DYNAMICS.md §8.6): each sample's statics in the study's
 * assembly mode give the inputs of §8.3 (the TE lines fitted at the named orders, the backlash,
 * the nut unit's axial stiffness), its dynamic tolerances the gear branch and damping; every
 * thread builds its own reduced model from design, analysis, dyn and vib. */
#define PRSM_MC_DYN_ORDERS 5
#define PRSM_MC_DYN_RECORD_MAX 4096
#define PRSM_MC_DYN_LYAPUNOV_WINDOWS 16 /* Benettin windows of an integrated sample (lyapunov_max) */
typedef struct {
	const prsm_design *design;      /* the study's design and its nominal analysis */
	const prsm_analysis *analysis;
	prsm_dyn_options dyn;           /* inertia, friction, load of the dynamics section */
	prsm_vib_options vib;           /* its vibration section (the nominal gear backlash, mesh error,
	                                   damping ratios, speed) */
	prsm_vib_mc_options options;    /* screen and integration */
	double window_rev;              /* W, screw revolutions */
	int n_orders;                   /* named TE orders (§8.3.4) */
	double order_kstar[PRSM_MC_DYN_ORDERS]; /* their orders with k*, per screw revolution */
	double order_kc[PRSM_MC_DYN_ORDERS];    /* with the statics' carrier ratio (the fit's) */
	int record_n;                   /* TE record: record_n angles ... */
	int per_rev;                    /* ... per_rev per screw revolution from 0 */
	double projection[2 * PRSM_MC_DYN_ORDERS][PRSM_MC_DYN_RECORD_MAX]; /* least squares: cos and
	                                   sin coefficient of order k = row 2k, 2k+1 dotted with the record, mm/mm */
} prsm_mc_dyn;

/* Set up d's TE fit for the assembly as in mode, measuring angles_per_revolution (W from the
 * named orders at the statics ratio when window_rev <= 0). design, analysis, dyn, vib, options
 * set by the caller. Returns 0 or PRSM_EINVAL / PRSM_ENOCONVERGE (err). */
int prsm_mc_dyn_prepare(prsm_mc_dyn *d, const prsm_assembly *as, int angles_per_revolution, double window_rev,
                        prsm_error *err);

typedef struct {
	const prsm_assembly *as;        /* prepared design (prsm_assembly_init) */
	const prsm_analysis *an;        /* its nominal analysis (kinematics, contacts) */
	prsm_errors base;               /* errors every sample starts from (zero, or measured) */
	int mode;                       /* PRSM_MODE_LINEAR or _EXACT */
	int angles_per_revolution;      /* for the outputs over a revolution */
	double measuring_load_N;        /* TE measuring load, N */
	double unit_rest_compliance_mm_per_N; /* nut unit minus contacts at the operating load:
	                                   1/k_unit - 1/k_contacts of the nominal design, mm/N (>= 0;
	                                   set by the loader when nut_unit_stiffness_N_per_um is asked) */
	const double *loss_screw_loads_N; /* efficiency_with_losses: the nominal distribution's normal */
	const double *loss_nut_loads_N;   /* loads of one roller's n_t contacts, N (set by the loader) */
	size_t n_bindings;
	const prsm_mc_binding *bindings;/* one per variable */
	size_t n_outputs;
	prsm_output_kind outputs[PRSM_MC_MAX_OUTPUTS];
	const prsm_mc_dyn *dyn;         /* the dynamic outputs' model (NULL: none asked) */
} prsm_mc_prsm;

/* The engine's view of p (p must outlive it). Its workspace is allocated once per thread. */
void prsm_prsm_mc_model(prsm_mc_model *out, const prsm_mc_prsm *p);

#endif
