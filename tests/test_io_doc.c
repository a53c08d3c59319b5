/*
 * test_io_doc.c: the table-driven reader (io/doc.h, tables generated from the annotated
 * schemas) against the hand-written reader it replaces, side by side (issue 24, item 5).
 *
 * Every design in studies/ and in the fuzz corpora, and thousands of variants of them (each
 * member in turn replaced by a value of every JSON type, by numbers at and just beyond the
 * schema's limits, removed, or joined by a misspelt key; each property of the schema the design
 * lacks added with each of those values), go through both readers; the
 * return codes, the problem lists (pointer, code, message, in order) and the structs must be
 * identical; the same for the analyze request's "assembly" options, the study, and the
 * optimisation and allocation documents (their examples with variants, each member also
 * repeated; tests/schema_test.py's invalid documents; the fuzz corpora; each under two of the
 * callers' caps). The legacy readers (tests/legacy/) go once every document is ported.
 */
#include "test_support.h"

#include <dirent.h>

#include "app/study.h"
#include "io/design_json.h"
#include "io/errors_json.h"
#include "io/global.h"
#include "io/study_json.h"
#include "io/json_util.h"
#include "legacy/design_reader_legacy.h"
#include "legacy/opt_alloc_reader_legacy.h"

typedef struct {
	int documents, valid, invalid;
} tally;

/* One document through both readers: the return codes (ra, rb), the problem lists (pointer,
 * code, message, in order, and the count dropped) and the structs (sa, sb: size bytes) must be
 * identical; what differs is printed with the document. `what` names the part. */
static void check_same(const char *what, const cJSON *doc, int ra, int rb, const prsm_problems *pa,
                       const prsm_problems *pb, const void *sa, const void *sb, size_t size, tally *t)
{
	t->documents++;
	if (ra == 0)
		t->valid++;
	else
		t->invalid++;
	int same = ra == rb && pa->count == pb->count && pa->dropped == pb->dropped;
	for (int i = 0; same && i < pa->count; i++)
		same = !strcmp(pa->items[i].pointer, pb->items[i].pointer) && !strcmp(pa->items[i].code, pb->items[i].code) &&
		       !strcmp(pa->items[i].message, pb->items[i].message);
	/* memcmp first: a study is some 700 kB, and a byte loop is slow under the sanitizers */
	size_t at = size;
	const unsigned char *x = sa, *y = sb;
	if (size && memcmp(sa, sb, size) != 0)
		for (at = 0; at < size && x[at] == y[at]; at++)
			;
	if (same && at == size)
		return;
	char *text = cJSON_PrintUnformatted(doc);
	print_error("%s %s\nlegacy rc %d, %d problems; table rc %d, %d problems", what, text, ra, pa->count, rb,
	            pb->count);
	if (at < size)
		print_error("; the structs differ from byte %zu on", at);
	print_error("\n");
	for (int i = 0; i < pa->count; i++)
		print_error("  legacy: %s %s %s\n", pa->items[i].pointer, pa->items[i].code, pa->items[i].message);
	for (int i = 0; i < pb->count; i++)
		print_error("  table:  %s %s %s\n", pb->items[i].pointer, pb->items[i].code, pb->items[i].message);
	cJSON_free(text);
	fail();
}

static void compare_design(const cJSON *doc, tally *t)
{
	prsm_design a, b;
	prsm_problems pa, pb;
	prsm_problems_init(&pa);
	prsm_problems_init(&pb);
	memset(&a, 0, sizeof a);
	memset(&b, 0, sizeof b);
	int ra = prsm_legacy_design_from_json(&a, doc, "/design", &pa);
	int rb = prsm_io_design_from_json(&b, doc, "/design", &pb);
	check_same("design", doc, ra, rb, &pa, &pb, &a, &b, sizeof a, t);
}

typedef void (*compare_fn)(const cJSON *doc, tally *t);

/* The analyze request's "assembly" options, read for case A by both readers. */
static prsm_design assembly_design;

static void compare_assembly(const cJSON *doc, tally *t)
{
	prsm_assembly_options a, b;
	prsm_problems pa, pb;
	prsm_problems_init(&pa);
	prsm_problems_init(&pb);
	memset(&a, 0, sizeof a);
	memset(&b, 0, sizeof b);
	int ra = prsm_legacy_assembly_options_from_json(&a, doc, "/assembly", &assembly_design, &pa);
	int rb = prsm_io_assembly_options_from_json(&b, doc, "/assembly", &assembly_design, &pb);
	check_same("assembly", doc, ra, rb, &pa, &pb, &a, &b, sizeof a, t);
}

/* ---- the whole study reader ---------------------------------------------------------------- */

/* Two loaded studies (about 1 MB each) and their problem and warning lists, reused. */
static prsm_io_study *study_pair[2];
static prsm_problems study_lists[4];

/* Padding bytes: what a struct copied from a local holds there is whatever the stack held. */
static void clear_dist_padding(prsm_dist *d)
{
	memset((char *)d + sizeof d->kind, 0, offsetof(prsm_dist, p) - sizeof d->kind);
}

/* The pointers a loaded study holds into itself (the engine's model and its bindings), as
 * offsets from the struct, and its padding cleared, so that two loaded structs compare byte for
 * byte. */
static void normalise(prsm_io_study *s)
{
	const size_t used = offsetof(prsm_mc_variable, group) + sizeof s->study.vars[0].group;
	for (size_t i = 0; i < PRSM_MC_MAX_VARIABLES; i++) {
		clear_dist_padding(&s->study.vars[i].dist);
		memset((char *)&s->study.vars[i] + used, 0, sizeof s->study.vars[i] - used);
	}
	for (size_t i = 0; i < PRSM_IO_STUDY_MAX_TOLERANCES; i++)
		clear_dist_padding(&s->tolerances[i].dist);
	const void **p[] = {(const void **)&s->prsm.as, (const void **)&s->prsm.an, (const void **)&s->prsm.bindings,
	                    (const void **)&s->prsm.loss_screw_loads_N, (const void **)&s->prsm.loss_nut_loads_N,
	                    (const void **)&s->study.model.ctx};
	for (size_t i = 0; i < sizeof p / sizeof p[0]; i++) {
		const char *at = *p[i];
		if (at >= (const char *)s && at < (const char *)(s + 1))
			*p[i] = (const void *)(uintptr_t)(at - (const char *)s + 1);
	}
}

/* Under the sanitizers, whose runs look for memory errors and races rather than differences,
 * every STUDY_STRIDE-th study document is compared: a design study's analysis under them costs
 * most of the run. */
#if defined(__SANITIZE_THREAD__)
#define STUDY_STRIDE 16
#elif defined(__SANITIZE_ADDRESS__)
#define STUDY_STRIDE 4
#else
#define STUDY_STRIDE 1
#endif

/* One document through the study reader before the port (tests/legacy/study_reader_legacy.c) and
 * today's: return codes, problems, warnings and the loaded structs must be identical. */
static void compare_study(const cJSON *doc, tally *t)
{
	static unsigned long calls;
	/* expression models (issue 21) came after the port: the legacy reader has none */
	const cJSON *model = cJSON_GetObjectItemCaseSensitive(doc, "model");
	if (cJSON_IsObject(model) && !cJSON_GetObjectItemCaseSensitive(model, "benchmark") &&
	    (cJSON_GetObjectItemCaseSensitive(model, "expression") || cJSON_GetObjectItemCaseSensitive(model, "expressions") ||
	     cJSON_GetObjectItemCaseSensitive(model, "inputs") || cJSON_GetObjectItemCaseSensitive(model, "constants")))
		return;
	/* neither have dynamic outputs (issue 17 item 4): documents with the dynamics sections, a
	 * dynamic tolerance or output are left out */
	if (cJSON_GetObjectItemCaseSensitive(doc, "dynamics") || cJSON_GetObjectItemCaseSensitive(doc, "dynamic_monte_carlo"))
		return;
	const cJSON *it;
	cJSON_ArrayForEach(it, cJSON_GetObjectItemCaseSensitive(doc, "tolerances"))
	{
		const cJSON *p = cJSON_GetObjectItemCaseSensitive(it, "parameter");
		if (cJSON_IsString(p) && (strncmp(p->valuestring, "ring_gear.", 10) == 0 || strcmp(p->valuestring, "damping_ratio") == 0))
			return;
	}
	cJSON_ArrayForEach(it, cJSON_GetObjectItemCaseSensitive(doc, "outputs"))
	{
		prsm_output_kind k;
		if (cJSON_IsString(it) && prsm_output_parse(it->valuestring, &k) == 0 && prsm_output_is_dynamic(k))
			return;
	}
	if (calls++ % STUDY_STRIDE)
		return;
	prsm_io_study *a = study_pair[0], *b = study_pair[1];
	for (int k = 0; k < 4; k++)
		prsm_problems_init(&study_lists[k]);
	const int ra = prsm_legacy_study_load(a, doc, &study_lists[2], &study_lists[0]);
	prsm_io_study_options hooks; /* the reader as the application runs it (app/study.h) */
	prsm_app_study_options(&hooks);
	const int rb = prsm_io_study_read(b, doc, &hooks, &study_lists[3], &study_lists[1]);
	normalise(a);
	normalise(b);
	check_same("study", doc, ra, rb, &study_lists[0], &study_lists[1], a, b, sizeof *a, t);
	tally w = {0, 0, 0};
	check_same("study warnings", doc, ra, rb, &study_lists[2], &study_lists[3], NULL, NULL, 0, &w);
}

static void study_pair_alloc(void)
{
	for (int k = 0; k < 2; k++) {
		study_pair[k] = calloc(1, sizeof *study_pair[k]);
		assert_non_null(study_pair[k]);
	}
}

static void study_pair_free(void)
{
	free(study_pair[0]);
	free(study_pair[1]);
	study_pair[0] = study_pair[1] = NULL;
}

/* A study's "monte_carlo" and "sensitivity" sections: each variant in place in one study. */
static cJSON *section_study;

static void compare_section(const char *key, const cJSON *sec, tally *t)
{
	cJSON_ReplaceItemInObjectCaseSensitive(section_study, key, cJSON_Duplicate(sec, 1));
	compare_study(section_study, t);
}

static void compare_mc(const cJSON *mc, tally *t)
{
	compare_section("monte_carlo", mc, t);
}

static void compare_sens(const cJSON *sec, tally *t)
{
	compare_section("sensitivity", sec, t);
}

/* Every value a member could wrongly (or rightly) hold. */
static cJSON *variant(int k, double limit_hint)
{
	switch (k) {
	case 0: return cJSON_CreateNull();
	case 1: return cJSON_CreateTrue();
	case 2: return cJSON_CreateString("x");
	case 3: return cJSON_CreateArray();
	case 4: return cJSON_CreateObject();
	case 5: return cJSON_CreateNumber(-1.0);
	case 6: return cJSON_CreateNumber(0.0);
	case 7: return cJSON_CreateNumber(0.5);
	case 8: return cJSON_CreateNumber(1.0);
	case 9: return cJSON_CreateNumber(2.5);
	case 10: return cJSON_CreateNumber(91.0);
	case 11: return cJSON_CreateNumber(1e300);
	case 12: return cJSON_CreateNumber(-1e300);
	case 13: return cJSON_CreateNumber(limit_hint);
	case 14: return cJSON_CreateNumber(limit_hint * (1.0 + 1e-12));
	case 15: return cJSON_CreateNumber(nextafter(limit_hint, 0.0));
	case 16: return cJSON_CreateString("left");
	case 17: return cJSON_CreateString("opposite_side");
	case 18: return cJSON_CreateNumber(93.0);
	default: return NULL;
	}
}
#define VARIANTS 19

/* The schema's limits that numbers are tried at, beside the generic values (limit_set: the ones
 * of the document at hand). */
static const double limits[] = {12, 50, 90, 64, 500, 5000, 20000, 2000, 1e8, 1e5, 50000, 1000, 1e6, 45, 5, 2, 6};
static const double *limit_set = limits;
static size_t n_limit_set = sizeof limits / sizeof limits[0];
/* 1: mutate_all also repeats each member (a duplicate key) */
static int mutate_duplicates;

/* Every member of every object under node, in turn: replaced by each variant, removed, and a
 * misspelt sibling added; each resulting document compared. root is the whole design. */
/* Members whose insides mutate_all leaves alone (a study's design and error set: their readers
 * are compared on their own; in a study each variant would cost a design analysis). */
static const char *const *mutate_skip;

static int skipped(const cJSON *m)
{
	for (const char *const *k = mutate_skip; k && *k && m->string; k++)
		if (strcmp(*k, m->string) == 0)
			return 1;
	return 0;
}

static void mutate_all(cJSON *root, cJSON *node, tally *t, compare_fn compare_one)
{
	if (!cJSON_IsObject(node) && !cJSON_IsArray(node))
		return;
	for (cJSON *m = node->child; m; m = m->next) {
		cJSON saved = *m;
		for (int k = 0; k < VARIANTS; k++) {
			for (size_t l = 0; l < (k >= 13 && k <= 15 ? n_limit_set : 1); l++) {
				cJSON *v = variant(k, limit_set[l]);
				/* put v's value in m's place, keeping m's key and links */
				m->type = v->type;
				m->valuedouble = v->valuedouble;
				m->valueint = v->valueint;
				m->valuestring = v->valuestring;
				m->child = NULL;
				compare_one(root, t);
				m->type = saved.type;
				m->valuedouble = saved.valuedouble;
				m->valueint = saved.valueint;
				m->valuestring = saved.valuestring;
				m->child = saved.child;
				cJSON_Delete(v);
			}
		}
		if (!skipped(m))
			mutate_all(root, m, t, compare_one);
	}
	if (cJSON_IsObject(node)) {
		/* each member removed in turn: unlinked and linked back by hand, so the document stays
		 * exactly as it was (cJSON keeps first->prev pointing at the last member) */
		for (cJSON *m = node->child; m; m = m->next) {
			const int first = m == node->child;
			if (first) {
				node->child = m->next;
				if (m->next)
					m->next->prev = m->prev;
			} else {
				m->prev->next = m->next;
				if (m->next)
					m->next->prev = m->prev;
				else
					node->child->prev = m->prev;
			}
			compare_one(root, t);
			if (first) {
				node->child = m;
				if (m->next)
					m->next->prev = m;
			} else {
				m->prev->next = m;
				if (m->next)
					m->next->prev = m;
				else
					node->child->prev = m;
			}
		}
		/* each member repeated: a duplicate key at the end (the reader reads the first) */
		for (cJSON *m = node->child; mutate_duplicates && m; m = m->next) {
			cJSON *dup = cJSON_Duplicate(m, 1);
			cJSON *last = node->child->prev;
			last->next = dup;
			dup->prev = last;
			node->child->prev = dup;
			compare_one(root, t);
			last->next = NULL;
			node->child->prev = last;
			cJSON_Delete(dup);
			if (m == last)
				break;
		}
		/* a misspelt key beside the others */
		if (node->child && node->child->string) {
			char bad[64];
			snprintf(bad, sizeof bad, "%.40sx", node->child->string);
			cJSON_AddNumberToObject(node, bad, 1.0);
			compare_one(root, t);
			cJSON_DeleteItemFromObjectCaseSensitive(node, bad);
		}
	}
}

static const cJSON *schema_root;

/* The schema node of a property, $ref to $defs followed. */
static const cJSON *resolve(const cJSON *node)
{
	const cJSON *ref = cJSON_GetObjectItemCaseSensitive(node, "$ref");
	if (cJSON_IsString(ref) && strncmp(ref->valuestring, "#/$defs/", 8) == 0)
		return cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(schema_root, "$defs"),
		                                        ref->valuestring + 8);
	return node;
}

/* Every property of the schema that node lacks, added in turn with every variant value (an
 * object property as an empty object, then filled the same way): the members the examples never
 * use are read too. */
static void fill_absent(cJSON *root, cJSON *node, const cJSON *schema, tally *t, compare_fn compare_one)
{
	const cJSON *props = cJSON_GetObjectItemCaseSensitive(resolve(schema), "properties");
	for (const cJSON *p = props ? props->child : NULL; p; p = p->next) {
		cJSON *have = cJSON_GetObjectItemCaseSensitive(node, p->string);
		const cJSON *ps = resolve(p);
		const int is_object = cJSON_GetObjectItemCaseSensitive(ps, "properties") != NULL;
		if (have) {
			if (is_object && cJSON_IsObject(have) && !skipped(have))
				fill_absent(root, have, ps, t, compare_one);
			continue;
		}
		for (int k = 0; k < VARIANTS; k++)
			for (size_t l = 0; l < (k >= 13 && k <= 15 ? n_limit_set : 1); l++) {
				cJSON_AddItemToObject(node, p->string, variant(k, limit_set[l]));
				compare_one(root, t);
				cJSON_DeleteItemFromObjectCaseSensitive(node, p->string);
			}
		if (is_object) {
			cJSON *obj = cJSON_AddObjectToObject(node, p->string);
			compare_one(root, t);
			fill_absent(root, obj, ps, t, compare_one);
			cJSON_DeleteItemFromObjectCaseSensitive(node, p->string);
		}
	}
}

static cJSON *read_json(const char *path)
{
	size_t len = 0;
	char *text = prsm_test_read_file(path, &len);
	if (!text)
		return NULL;
	prsm_problems p;
	prsm_problems_init(&p);
	cJSON *doc = prsm_json_parse(text, len, &p);
	free(text);
	return doc;
}

/* The designs a document holds: itself when it has a geometry, its "design", its "study"'s. */
static void designs_of(const cJSON *doc, const cJSON **out, int *n)
{
	*n = 0;
	if (!cJSON_IsObject(doc))
		return;
	if (cJSON_GetObjectItemCaseSensitive(doc, "geometry"))
		out[(*n)++] = doc;
	const cJSON *d = cJSON_GetObjectItemCaseSensitive(doc, "design");
	if (d)
		out[(*n)++] = d;
	const cJSON *s = cJSON_GetObjectItemCaseSensitive(doc, "study");
	if (s && cJSON_GetObjectItemCaseSensitive(s, "design"))
		out[(*n)++] = cJSON_GetObjectItemCaseSensitive(s, "design");
}

static void each_file(const char *dir, void (*fn)(const char *path, void *ctx), void *ctx)
{
	DIR *d = opendir(dir);
	if (!d)
		return;
	struct dirent *e;
	char **names = NULL;
	size_t n = 0;
	while ((e = readdir(d)) != NULL) {
		if (e->d_name[0] == '.')
			continue;
		names = realloc(names, (n + 1) * sizeof *names);
		const size_t size = strlen(dir) + strlen(e->d_name) + 2;
		names[n] = malloc(size);
		snprintf(names[n], size, "%s/%s", dir, e->d_name);
		n++;
	}
	closedir(d);
	for (size_t i = 0; i < n; i++) {
		fn(names[i], ctx);
		free(names[i]);
	}
	free(names);
}

typedef struct {
	tally *t, *assembly, *study;
	int mutate;
} walk_ctx;

static void check_file(const char *path, void *vctx)
{
	walk_ctx *c = vctx;
	cJSON *doc = read_json(path);
	if (!doc)
		return;
	const cJSON *designs[3];
	int n;
	designs_of(doc, designs, &n);
	for (int i = 0; i < n; i++) {
		compare_design(designs[i], c->t);
		if (c->mutate) {
			cJSON *copy = cJSON_Duplicate(designs[i], 1);
			mutate_all(copy, copy, c->t, compare_design);
			fill_absent(copy, copy, schema_root, c->t, compare_design);
			cJSON_Delete(copy);
		}
	}
	/* the document itself (not a design, mostly): both must refuse it alike */
	compare_design(doc, c->t);
	/* its assembly options, when it has them, and the document itself as options */
	const cJSON *as = cJSON_GetObjectItemCaseSensitive(doc, "assembly");
	if (as)
		compare_assembly(as, c->assembly);
	compare_assembly(doc, c->assembly);
	/* the document as a study, and the study it holds (an allocation's, an optimisation's) */
	if (c->study) {
		compare_study(doc, c->study);
		const cJSON *s = cJSON_GetObjectItemCaseSensitive(doc, "study");
		if (s)
			compare_study(s, c->study);
	}
	cJSON_Delete(doc);
}

static void test_examples_and_variants(void **state)
{
	(void)state;
	char src[512], dir[1024];
	prsm_test_source_dir(src, sizeof src);
	tally t = {0, 0, 0}, ta = {0, 0, 0};
	walk_ctx c = {&t, &ta, NULL, 1};
	snprintf(dir, sizeof dir, "%s/schemas/design.schema.json", src);
	cJSON *schema = read_json(dir);
	assert_non_null(schema);
	schema_root = schema;
	snprintf(dir, sizeof dir, "%s/studies", src);
	each_file(dir, check_file, &c);
	print_message("studies/ and their variants: %d documents (%d valid, %d invalid), identical\n", t.documents,
	              t.valid, t.invalid);
	assert_true(t.valid >= 10);
	assert_true(t.invalid > 1000);
	cJSON_Delete(schema);
	schema_root = NULL;
}

static void test_fuzz_corpora(void **state)
{
	(void)state;
	char src[512], dir[1024];
	prsm_test_source_dir(src, sizeof src);
	tally t = {0, 0, 0}, ta = {0, 0, 0}, ts = {0, 0, 0};
	walk_ctx c = {&t, &ta, &ts, 0};
	study_pair_alloc();
	const char *kinds[] = {"request", "study", "optimization", "allocation"};
	for (int k = 0; k < 4; k++) {
		snprintf(dir, sizeof dir, "%s/tests/fuzz/corpus/%s", src, kinds[k]);
		each_file(dir, check_file, &c);
	}
	study_pair_free();
	print_message("fuzz corpora: %d documents (%d valid, %d invalid), identical\n", t.documents, t.valid, t.invalid);
	print_message("fuzz corpora as studies: %d documents (%d valid, %d invalid), identical\n", ts.documents, ts.valid,
	              ts.invalid);
	assert_true(t.documents > 300);
	assert_true(ts.documents > 250 / STUDY_STRIDE && ts.valid >= 15 / STUDY_STRIDE);
}

/* The assembly options of every example and their variants (the analyze request's $defs). */
static void test_assembly_options(void **state)
{
	(void)state;
	char src[512], path[1024];
	prsm_test_source_dir(src, sizeof src);
	snprintf(path, sizeof path, "%s/studies/case-a.json", src);
	cJSON *design = read_json(path);
	prsm_problems p;
	prsm_problems_init(&p);
	assert_int_equal(prsm_io_design_from_json(&assembly_design, design, "", &p), 0);
	assert_int_equal(prsm_design_resolve(&assembly_design, &p), 0);
	cJSON_Delete(design);
	snprintf(path, sizeof path, "%s/schemas/analyze-request.schema.json", src);
	cJSON *schema = read_json(path);
	assert_non_null(schema);
	schema_root = schema;
	const cJSON *node = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(schema, "$defs"), "assembly");
	tally t = {0, 0, 0};
	const char *seeds[] = {"{}", "{\"mode\": \"exact\", \"angles_per_revolution\": 64, \"stroke_mm\": 150}",
	                       "{\"angles_per_revolution\": 4096, \"spectrum_revolutions\": 1000}",
	                       "{\"angles_per_revolution\": 1000, \"stroke_mm\": 10000, \"curve\": true}"};
	for (size_t i = 0; i < sizeof seeds / sizeof seeds[0]; i++) {
		cJSON *doc = cJSON_Parse(seeds[i]);
		compare_assembly(doc, &t);
		mutate_all(doc, doc, &t, compare_assembly);
		fill_absent(doc, doc, node, &t, compare_assembly);
		cJSON_Delete(doc);
	}
	print_message("assembly options and their variants: %d documents (%d valid, %d invalid), identical\n",
	              t.documents, t.valid, t.invalid);
	assert_true(t.invalid > 100 && t.valid > 20);
	cJSON_Delete(schema);
	schema_root = NULL;
}

/* The monte_carlo and sensitivity sections of a study and their variants (the study's $defs),
 * each read as part of the whole study by both readers. */
static void test_study_monte_carlo(void **state)
{
	(void)state;
	char src[512], path[1024];
	prsm_test_source_dir(src, sizeof src);
	snprintf(path, sizeof path, "%s/studies/case-a-tolerances.json", src);
	section_study = read_json(path);
	assert_non_null(section_study);
	study_pair_alloc();
	snprintf(path, sizeof path, "%s/schemas/study.schema.json", src);
	cJSON *schema = read_json(path);
	assert_non_null(schema);
	schema_root = schema;
	const cJSON *node = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(schema, "$defs"), "monte_carlo");
	tally t = {0, 0, 0};
	const cJSON *outputs = cJSON_GetObjectItemCaseSensitive(section_study, "outputs");
	const char *first = cJSON_IsArray(outputs) && cJSON_IsString(outputs->child) ? outputs->child->valuestring : "backlash_um";
	char with_targets[512];
	snprintf(with_targets, sizeof with_targets,
	         "{\"samples\": 4096, \"seed\": 7, \"failure\": {\"policy\": \"abort\"},"
	         " \"targets\": [{\"output\": \"%s\", \"standard_error\": 0.1}, {\"output\": \"nope\", \"cv\": 1}]}",
	         first);
	const char *seeds[] = {"{}", with_targets, "{\"sampler\": \"sobol\", \"block_size\": 64, \"time_cap_s\": 5}"};
	cJSON *own = cJSON_Duplicate(cJSON_GetObjectItemCaseSensitive(section_study, "monte_carlo"), 1);
	for (size_t i = 0; i < sizeof seeds / sizeof seeds[0]; i++) {
		cJSON *mc = cJSON_Parse(seeds[i]);
		assert_non_null(mc);
		compare_mc(mc, &t);
		mutate_all(mc, mc, &t, compare_mc);
		fill_absent(mc, mc, node, &t, compare_mc);
		cJSON_Delete(mc);
	}
	if (own)
		compare_mc(own, &t);
	cJSON_Delete(own);
	/* the sensitivity section beside it */
	const cJSON *sens_node = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(schema, "$defs"),
	                                                          "sensitivity");
	tally ts = {0, 0, 0};
	const char *sens_seeds[] = {"{}", "{\"sobol\": true, \"src\": false}",
	                            "{\"sobol\": {\"samples\": 1024, \"bootstrap\": 0, \"sampler\": \"random\"}}",
	                            "{\"sobol\": {\"sampler\": \"lhs\", \"bootstrap\": 1}}"};
	for (size_t i = 0; i < sizeof sens_seeds / sizeof sens_seeds[0]; i++) {
		cJSON *sec = cJSON_Parse(sens_seeds[i]);
		assert_non_null(sec);
		compare_sens(sec, &ts);
		mutate_all(sec, sec, &ts, compare_sens);
		fill_absent(sec, sec, sens_node, &ts, compare_sens);
		cJSON_Delete(sec);
	}
	print_message("study sensitivity sections and their variants: %d documents (%d valid, %d invalid), identical\n",
	              ts.documents, ts.valid, ts.invalid);
	assert_true(ts.invalid > 50 / STUDY_STRIDE && ts.valid > 10 / STUDY_STRIDE);
	print_message("study monte_carlo sections and their variants: %d documents (%d valid, %d invalid), identical\n",
	              t.documents, t.valid, t.invalid);
	assert_true(t.invalid > 100 / STUDY_STRIDE && t.valid > 20 / STUDY_STRIDE);
	cJSON_Delete(schema);
	schema_root = NULL;
	cJSON_Delete(section_study);
	section_study = NULL;
	study_pair_free();
}

/* The study documents: studies/ (and the studies its allocations hold), the documents
 * tests/schema_test.py builds (printed by tests/legacy/study_documents.py: the studies it runs,
 * the invalid ones, those beyond the schema, the valid ones); case-a-tolerances.json and some of
 * section 9's with their variants outside the design and the error set. */
static const char *const study_skip[] = {"design", "errors", NULL};

static void study_variants(cJSON *doc, tally *t)
{
	compare_study(doc, t);
	if (!cJSON_IsObject(doc))
		return;
	mutate_all(doc, doc, t, compare_study);
	fill_absent(doc, doc, schema_root, t, compare_study);
}

static void check_study_file(const char *path, void *vctx)
{
	cJSON *doc = read_json(path);
	if (!doc)
		return;
	cJSON *s = cJSON_GetObjectItemCaseSensitive(doc, "tolerances") ? doc : cJSON_GetObjectItemCaseSensitive(doc, "study");
	if (cJSON_IsObject(s) && strstr(path, "/case-a-tolerances.json")) /* a design study's variants */
		study_variants(s, vctx);
	else if (cJSON_IsObject(s))
		compare_study(s, vctx);
	cJSON_Delete(doc);
}

static void test_study_documents(void **state)
{
	(void)state;
	char src[512], path[1024], cmd[1600];
	prsm_test_source_dir(src, sizeof src);
	snprintf(path, sizeof path, "%s/schemas/study.schema.json", src);
	cJSON *schema = read_json(path);
	assert_non_null(schema);
	schema_root = schema;
	mutate_skip = study_skip;
	study_pair_alloc();
	tally t = {0, 0, 0}, tt = {0, 0, 0};
	snprintf(path, sizeof path, "%s/studies", src);
	each_file(path, check_study_file, &t);
	print_message("studies/ and their variants as studies: %d documents (%d valid, %d invalid), identical\n",
	              t.documents, t.valid, t.invalid);
	assert_true(t.valid > 100 / STUDY_STRIDE && t.invalid > 1000 / STUDY_STRIDE);
	snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s/tests/legacy/study_documents.py' '%s'", src, src);
	FILE *p = popen(cmd, "r");
	assert_non_null(p);
	char *line = NULL;
	size_t cap = 0;
	ssize_t len;
	int lines = 0;
	while ((len = getline(&line, &cap, p)) > 0) {
		lines++;
		prsm_problems pp;
		prsm_problems_init(&pp);
		cJSON *doc = prsm_json_parse(line, (size_t)len, &pp);
		/* with their variants: the benchmark studies section 9 runs (lines 1, 2, 4, 7), its two
		 * bases and the one with many mistakes (9 to 11); the others as they are (a design study's
		 * variants cost a design analysis each); NaN the parser refuses */
		if (doc && lines <= 11 && lines != 3 && lines != 5 && lines != 6 && lines != 8)
			study_variants(doc, &tt);
		else if (doc)
			compare_study(doc, &tt);
		cJSON_Delete(doc);
	}
	free(line);
	assert_int_equal(pclose(p), 0);
	print_message("schema_test.py's %d study documents and their variants: %d documents (%d valid, %d invalid), "
	              "identical\n", lines, tt.documents, tt.valid, tt.invalid);
	assert_true(lines > 150 && tt.valid > 1000 / STUDY_STRIDE && tt.invalid > 5000 / STUDY_STRIDE);
	study_pair_free();
	mutate_skip = NULL;
	cJSON_Delete(schema);
	schema_root = NULL;
}

/* ---- the allocation and optimisation documents ------------------------------------------------ */

/* Their limits that numbers are tried at. */
static const double doc_limits[] = {100, 50, 500000, 1e100, 20, 30, 0.5, 1e-4, 4000000, 2147483647, 16, 64, 65536,
                                    1e15, 1e6, 86400, 0.1, 9007199254740991.0, 600, 1000, 12, 500, 90, 40, 95};

/* The caps the callers give (0: the document's own): each document is read under each. */
static const size_t alloc_caps[] = {0, 100000};

/* One allocation document through the reader before the port (tests/legacy/) and today's, under
 * each sample cap: return codes, problems and warnings identical, and the loaded structs (their
 * studies normalised as the study comparison's are) byte for byte. The tally counts the
 * document once (under the first cap). */
static void compare_allocation(const cJSON *doc, tally *t)
{
	static unsigned long calls;
	if (calls++ % STUDY_STRIDE)
		return;
	tally other = {0, 0, 0};
	for (size_t k = 0; k < sizeof alloc_caps / sizeof alloc_caps[0]; k++) {
		prsm_io_allocation *a = NULL, *b = NULL;
		for (int l = 0; l < 4; l++)
			prsm_problems_init(&study_lists[l]);
		const int ra = prsm_legacy_allocation_read(&a, doc, alloc_caps[k], &study_lists[2], &study_lists[0]);
		prsm_io_study_options hooks;
		prsm_app_study_options(&hooks);
		const int rb = prsm_io_allocation_read(&b, doc, alloc_caps[k], &hooks, &study_lists[3], &study_lists[1]);
		if (ra == 0 && rb == 0) {
			assert_true((a->study == NULL) == (b->study == NULL));
			if (a->study) {
				normalise(a->study);
				normalise(b->study);
				tally ts = {0, 0, 0};
				check_same("allocation's study", doc, ra, rb, &study_lists[0], &study_lists[1], a->study, b->study,
				           sizeof *a->study, &ts);
			}
			prsm_io_study *sa = a->study, *sb = b->study;
			a->study = b->study = NULL;
			check_same("allocation", doc, ra, rb, &study_lists[0], &study_lists[1], a, b, sizeof *a, k ? &other : t);
			a->study = sa;
			b->study = sb;
		} else {
			check_same("allocation", doc, ra, rb, &study_lists[0], &study_lists[1], NULL, NULL, 0, k ? &other : t);
		}
		tally w = {0, 0, 0};
		check_same("allocation warnings", doc, ra, rb, &study_lists[2], &study_lists[3], NULL, NULL, 0, &w);
		prsm_io_allocation_free(a);
		prsm_io_allocation_free(b);
	}
}

/* A document and its variants (each member replaced, removed, repeated, misspelt; each absent
 * property added) outside the skipped members. */
static void doc_variants(cJSON *doc, tally *t, compare_fn compare_one)
{
	compare_one(doc, t);
	if (!cJSON_IsObject(doc))
		return;
	mutate_all(doc, doc, t, compare_one);
	fill_absent(doc, doc, schema_root, t, compare_one);
}

/* The documents tests/schema_test.py builds for kind (tests/legacy/opt_alloc_documents.py, the
 * examples first): each with its variants when `variants`, else as it is. Returns their count. */
static int schema_test_documents(const char *src, const char *kind, int variants, tally *t, compare_fn compare_one)
{
	char cmd[1600];
	snprintf(cmd, sizeof cmd, "/usr/bin/python3 '%s/tests/legacy/opt_alloc_documents.py' '%s' %s", src, src, kind);
	FILE *p = popen(cmd, "r");
	assert_non_null(p);
	char *line = NULL;
	size_t cap = 0;
	ssize_t len;
	int lines = 0;
	while ((len = getline(&line, &cap, p)) > 0) {
		lines++;
		prsm_problems pp;
		prsm_problems_init(&pp);
		cJSON *doc = prsm_json_parse(line, (size_t)len, &pp);
		if (doc && variants)
			doc_variants(doc, t, compare_one);
		else if (doc)
			compare_one(doc, t);
		cJSON_Delete(doc);
	}
	free(line);
	assert_int_equal(pclose(p), 0);
	return lines;
}

/* Every file of a directory, as it is. */
typedef struct {
	tally *t;
	compare_fn compare_one;
} corpus_ctx;

static void corpus_file(const char *path, void *vctx)
{
	corpus_ctx *c = vctx;
	cJSON *doc = read_json(path);
	if (doc)
		c->compare_one(doc, c->t);
	cJSON_Delete(doc);
}

static const char *const doc_skip[] = {"design", "errors", "study", NULL};

/* The allocation documents: the examples (in schema_test.py's list) and their variants outside
 * the embedded study and design (whose readers are compared above), schema_test.py's invalid
 * ones, the fuzz corpus. */
static void test_allocation_documents(void **state)
{
	(void)state;
	char src[512], path[1024];
	prsm_test_source_dir(src, sizeof src);
	snprintf(path, sizeof path, "%s/schemas/allocation.schema.json", src);
	cJSON *schema = read_json(path);
	assert_non_null(schema);
	schema_root = schema;
	mutate_skip = doc_skip;
	mutate_duplicates = 1;
	limit_set = doc_limits;
	n_limit_set = sizeof doc_limits / sizeof doc_limits[0];
	study_pair_alloc();
	tally t = {0, 0, 0}, tf = {0, 0, 0};
	const int lines = schema_test_documents(src, "allocation", 1, &t, compare_allocation);
	print_message("schema_test.py's %d allocation documents and their variants: %d documents (%d valid, %d "
	              "invalid), identical\n", lines, t.documents, t.valid, t.invalid);
	assert_true(lines >= 9 && t.valid > 2000 / STUDY_STRIDE && t.invalid > 30000 / STUDY_STRIDE);
	snprintf(path, sizeof path, "%s/tests/fuzz/corpus/allocation", src);
	corpus_ctx c = {&tf, compare_allocation};
	each_file(path, corpus_file, &c);
	print_message("the allocation fuzz corpus: %d documents (%d valid, %d invalid), identical\n", tf.documents,
	              tf.valid, tf.invalid);
	assert_true(tf.documents >= 50 / STUDY_STRIDE);
	study_pair_free();
	limit_set = limits;
	n_limit_set = sizeof limits / sizeof limits[0];
	mutate_duplicates = 0;
	mutate_skip = NULL;
	cJSON_Delete(schema);
	schema_root = NULL;
}

/* The evaluation caps the callers give (0: the document's own). */
static const size_t opt_caps[] = {0, 500};
static prsm_io_optimization *opt_pair[2];

/* One optimisation document through the reader before the port and today's, under each cap:
 * return codes, problems and warnings identical, and the loaded structs byte for byte (the
 * robust constraints' pointer into the struct as an offset, the candidates' study document as
 * its text). */
static void compare_optimization(const cJSON *doc, tally *t)
{
	static unsigned long calls;
	if (calls++ % STUDY_STRIDE)
		return;
	prsm_io_optimization *a = opt_pair[0], *b = opt_pair[1];
	tally other = {0, 0, 0};
	for (size_t k = 0; k < sizeof opt_caps / sizeof opt_caps[0]; k++) {
		for (int l = 0; l < 4; l++)
			prsm_problems_init(&study_lists[l]);
		const int ra = prsm_legacy_optimization_read(a, doc, opt_caps[k], &study_lists[2], &study_lists[0]);
		prsm_io_study_options hooks;
		prsm_app_study_options(&hooks);
		const int rb = prsm_io_optimization_read(b, doc, opt_caps[k], &hooks, &study_lists[3], &study_lists[1]);
		size_t size = 0;
		if (ra == 0 && rb == 0) {
			size = sizeof *a;
			char *sa = a->study ? cJSON_PrintUnformatted(a->study) : NULL;
			char *sb = b->study ? cJSON_PrintUnformatted(b->study) : NULL;
			if ((sa == NULL) != (sb == NULL) || (sa && strcmp(sa, sb))) {
				print_error("optimisation: the robust study documents differ\n%s\n%s\n", sa ? sa : "-", sb ? sb : "-");
				fail();
			}
			cJSON_free(sa);
			cJSON_free(sb);
			prsm_io_optimization *o[2] = {a, b};
			for (int l = 0; l < 2; l++) {
				cJSON_Delete(o[l]->study);
				o[l]->study = NULL;
				if (o[l]->spec.robust == &o[l]->robust)
					o[l]->spec.robust = (prsm_robust *)(uintptr_t)1;
			}
		}
		check_same("optimisation", doc, ra, rb, &study_lists[0], &study_lists[1], a, b, size, k ? &other : t);
		tally w = {0, 0, 0};
		check_same("optimisation warnings", doc, ra, rb, &study_lists[2], &study_lists[3], NULL, NULL, 0, &w);
		prsm_io_optimization_release(a);
		prsm_io_optimization_release(b);
	}
}

/* The optimisation documents: the examples and schema_test.py's invalid ones with their
 * variants outside the base design (compared above), the fuzz corpus. */
static void test_optimization_documents(void **state)
{
	(void)state;
	char src[512], path[1024];
	prsm_test_source_dir(src, sizeof src);
	snprintf(path, sizeof path, "%s/schemas/optimization.schema.json", src);
	cJSON *schema = read_json(path);
	assert_non_null(schema);
	schema_root = schema;
	mutate_skip = doc_skip;
	mutate_duplicates = 1;
	limit_set = doc_limits;
	n_limit_set = sizeof doc_limits / sizeof doc_limits[0];
	for (int k = 0; k < 2; k++) {
		opt_pair[k] = calloc(1, sizeof *opt_pair[k]);
		assert_non_null(opt_pair[k]);
	}
	tally t = {0, 0, 0}, tf = {0, 0, 0};
	const int lines = schema_test_documents(src, "optimization", 1, &t, compare_optimization);
	print_message("schema_test.py's %d optimisation documents and their variants: %d documents (%d valid, %d "
	              "invalid), identical\n", lines, t.documents, t.valid, t.invalid);
	assert_true(lines >= 18 && t.valid > 500 / STUDY_STRIDE && t.invalid > 5000 / STUDY_STRIDE);
	snprintf(path, sizeof path, "%s/tests/fuzz/corpus/optimization", src);
	corpus_ctx c = {&tf, compare_optimization};
	each_file(path, corpus_file, &c);
	print_message("the optimisation fuzz corpus: %d documents (%d valid, %d invalid), identical\n", tf.documents,
	              tf.valid, tf.invalid);
	assert_true(tf.documents >= 50 / STUDY_STRIDE);
	free(opt_pair[0]);
	free(opt_pair[1]);
	limit_set = limits;
	n_limit_set = sizeof limits / sizeof limits[0];
	mutate_duplicates = 0;
	mutate_skip = NULL;
	cJSON_Delete(schema);
	schema_root = NULL;
}

/* The schemas' "default"s are what the C init functions set: checked by the generated
 * prsm_io_defaults_<table> (scripts/gen-io-tables.py), one problem per difference. */
int prsm_io_defaults_design(prsm_problems *problems);
int prsm_io_defaults_assembly_options(prsm_problems *problems);
int prsm_io_defaults_study_monte_carlo(prsm_problems *problems);
int prsm_io_defaults_study_sensitivity(prsm_problems *problems);
int prsm_io_defaults_sobol(prsm_problems *problems);

static void test_schema_defaults(void **state)
{
	(void)state;
	int (*const check[])(prsm_problems *) = {prsm_io_defaults_design, prsm_io_defaults_assembly_options,
	                                          prsm_io_defaults_study_monte_carlo, prsm_io_defaults_study_sensitivity,
	                                          prsm_io_defaults_sobol};
	for (size_t i = 0; i < sizeof check / sizeof check[0]; i++) {
		prsm_problems p;
		prsm_problems_init(&p);
		const int bad = check[i](&p);
		for (int k = 0; k < p.count; k++)
			print_error("%s: %s\n", p.items[k].pointer, p.items[k].message);
		assert_int_equal(bad, 0);
	}
}

int main(void)
{
	prsm_global_init();
	if (getenv("PRSM_TEST_FILTER")) /* e.g. "test_optimization*": one part of the proof */
		cmocka_set_test_filter(getenv("PRSM_TEST_FILTER"));
	if (getenv("PRSM_TEST_SKIP")) /* the rest (tests/CMakeLists.txt runs the two side by side) */
		cmocka_set_skip_filter(getenv("PRSM_TEST_SKIP"));
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(test_examples_and_variants),
		cmocka_unit_test(test_fuzz_corpora),
		cmocka_unit_test(test_assembly_options),
		cmocka_unit_test(test_study_monte_carlo),
		cmocka_unit_test(test_study_documents),
		cmocka_unit_test(test_allocation_documents),
		cmocka_unit_test(test_optimization_documents),
		cmocka_unit_test(test_schema_defaults),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
