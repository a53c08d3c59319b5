/*
 * main.c: the `prsm` command line, one subcommand per job kind (DESIGN.md, "Shape").
 *
 * Exit codes: 0 ok, 1 the request was invalid (the message names the field), 2 the computation
 * failed, 64 usage.
 */
#include <stdio.h>
#include <string.h>


#include "cli/commands.h"
#include "io/global.h"
#include "par/par.h"

static void usage(FILE *out)
{
	fprintf(out,
	        "usage: prsm <command> [options]\n"
	        "\n"
	        "commands:\n"
	        "  analyze FILE|-   nominal analysis of one design (JSON result on stdout)\n"
	        "                   --format json|text, --out FILE\n"
	        "  study FILE|-     Monte Carlo tolerance study (JSON result on stdout)\n"
	        "                   --out FILE, --csv FILE (every sample), --threads N, --quiet\n"
	        "  allocate FILE|-  tolerance allocation at a target yield, verified by Monte Carlo (JSON)\n"
	        "                   --out FILE, --threads N, --quiet\n"
	        "  optimize FILE|-  design optimisation (JSON result on stdout)\n"
	        "                   --out FILE, --quiet\n"
	        "  simulate FILE|-  the dynamics object of a design, a chain or a gear pair: the start-up\n"
	        "                   transient, or the vibration analyses (linear, vibration, sweep,\n"
	        "                   frequency_response, basins); JSON result on stdout:\n"
	        "                   --format json|text, --out FILE, --csv FILE (the series or points),\n"
	        "                   --threads N (sweeps and basins), --quiet\n"
	        "  calibrate FILE|- a design with measured data (a TE curve, a cage ratio, an efficiency):\n"
	        "                   measured - model, the TE lines by spectrum, the line or physical model\n"
	        "                   calibrated with standard errors and identifiability caveats, friction\n"
	        "                   and carrier drag (docs/measured-data.md); JSON result on stdout:\n"
	        "                   --measured CSV (the TE curve), --format json|text, --out FILE\n"
	        "  validate FILE|-  check a design, analyze or simulation request, study, optimisation or\n"
	        "                   allocation document, print every problem\n"
	        "                   --format text|json\n"
	        "  serve            the HTTP/JSON service (default 127.0.0.1:8080, database ./prsm.db)\n"
	        "                   --port N, --db PATH, --workers N; prsm serve --help for all\n"
	        "  batch FILE.jsonl many requests of any kind, one per line, through the cache in parallel\n"
	        "                   (one result per line; run again to resume): --out FILE, --db PATH,\n"
	        "                   --workers N, --threads N\n"
	        "  run-job KIND FILE  one stored service job run by its kind (what a Slurm job of\n"
	        "                   prsm serve --executor slurm runs): --out FILE, --csv, --error, --counts\n"
	        "  bench            throughput of the engine's kernels, as JSON\n"
	        "                   --seconds S (per kernel, default 0.5)\n"
	        "  version          engine and model versions\n"
	        "\n"
	        "MPI: under mpirun or srun, study, batch, allocate, optimize and simulate (sweeps and basins)\n"
	        "run over every rank (rank 0 writes) and the other commands once, on rank 0; --mpi runs\n"
	        "them through MPI without a launcher, --no-mpi never (docs/mpi.md)\n"
	        "\n"
	        "exit codes: 0 ok, 1 invalid request, 2 computation failed, 64 usage\n");
}

/* `prsm study`, `batch`, `allocate`, `optimize` and `simulate` over the ranks of an MPI job: MPI
 * loaded and initialised (only here: every other process starts without it), the command, MPI
 * finalised. */
static int run_par(int (*command)(int, char **), int argc, char **argv, int rank)
{
	const char *cmd = argv[0];
	if (!prsm_par_built()) {
		if (rank == 0)
			fprintf(stderr, "prsm %s: this prsm was built without MPI (the CMake feature PRSM_MPI found none): "
			        "install libopenmpi-dev and openmpi-bin and rebuild, or run it without mpirun, srun and "
			        "--mpi\n", cmd);
		return PRSM_EXIT_USAGE;
	}
	prsm_error err = PRSM_ERROR_INIT;
	if (prsm_par_init(&err)) {
		fprintf(stderr, "prsm %s: %s\n", cmd, err.message);
		return PRSM_EXIT_FAILED;
	}
	int rc = command(argc, argv);
	prsm_par_finalize();
	return rc;
}

int main(int argc, char **argv)
{
	/* --mpi / --no-mpi, anywhere after the program name, are main's */
	int mpi = -1, kept = 1;
	for (int i = 1; i < argc; i++) {
		if (strcmp(argv[i], "--mpi") == 0)
			mpi = 1;
		else if (strcmp(argv[i], "--no-mpi") == 0)
			mpi = 0;
		else
			argv[kept++] = argv[i];
	}
	argc = kept;
	argv[argc] = NULL;
	if (argc < 2) {
		usage(stderr);
		return PRSM_EXIT_USAGE;
	}
	/* GSL's error handler off, cJSON's allocation hooks (io/global.h) */
	prsm_global_init();
	const char *cmd = argv[1];
	/* (version and help never look: they start as they always did) */
	const int quick = strcmp(cmd, "version") == 0 || strcmp(cmd, "--version") == 0 || strcmp(cmd, "help") == 0 ||
	                  strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0;
	int rank = 0, size = 1;
	const int launched = mpi != 0 && !quick && prsm_par_launched(&rank, &size);
	int (*par_command)(int, char **) = strcmp(cmd, "study") == 0      ? prsm_cli_study
	                                   : strcmp(cmd, "batch") == 0    ? prsm_cli_batch
	                                   : strcmp(cmd, "allocate") == 0 ? prsm_cli_allocate
	                                   : strcmp(cmd, "optimize") == 0 ? prsm_cli_optimize
	                                   : strcmp(cmd, "simulate") == 0 ? prsm_cli_simulate
	                                                                  : NULL;
	if (par_command && (mpi == 1 || (launched && size > 1) || (launched && prsm_par_built())))
		return run_par(par_command, argc - 1, argv + 1, rank);
	if (mpi == 1) {
		fprintf(stderr, "prsm: --mpi: only study, batch, allocate, optimize and simulate run over MPI\n");
		return PRSM_EXIT_USAGE;
	}
	if (launched && rank != 0)
		return 0; /* a command that does not spread over ranks runs once, on rank 0 */
	if (strcmp(cmd, "analyze") == 0)
		return prsm_cli_analyze(argc - 1, argv + 1);
	if (strcmp(cmd, "validate") == 0)
		return prsm_cli_validate(argc - 1, argv + 1);
	if (strcmp(cmd, "study") == 0)
		return prsm_cli_study(argc - 1, argv + 1);
	if (strcmp(cmd, "allocate") == 0)
		return prsm_cli_allocate(argc - 1, argv + 1);
	if (strcmp(cmd, "optimize") == 0)
		return prsm_cli_optimize(argc - 1, argv + 1);
	if (strcmp(cmd, "simulate") == 0)
		return prsm_cli_simulate(argc - 1, argv + 1);
	if (strcmp(cmd, "calibrate") == 0)
		return prsm_cli_calibrate(argc - 1, argv + 1);
	if (strcmp(cmd, "serve") == 0)
		return prsm_cli_serve(argc - 1, argv + 1);
	if (strcmp(cmd, "batch") == 0)
		return prsm_cli_batch(argc - 1, argv + 1);
	if (strcmp(cmd, "bench") == 0)
		return prsm_cli_bench(argc - 1, argv + 1);
	if (strcmp(cmd, "run-job") == 0)
		return prsm_cli_run_job(argc - 1, argv + 1);
	if (strcmp(cmd, "version") == 0 || strcmp(cmd, "--version") == 0)
		return prsm_cli_version(argc - 1, argv + 1);
	if (strcmp(cmd, "help") == 0 || strcmp(cmd, "--help") == 0 || strcmp(cmd, "-h") == 0) {
		usage(stdout);
		return 0;
	}
	fprintf(stderr, "prsm: unknown command '%s'\n", cmd);
	usage(stderr);
	return PRSM_EXIT_USAGE;
}
