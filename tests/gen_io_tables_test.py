#!/usr/bin/python3
"""The schema-to-C table generator (scripts/gen-io-tables.py) refuses what would let the C
reader and the schema disagree: a property without an annotation, an annotation naming no
member, a struct member no property fills, a type that does not fit the member.

Usage: gen_io_tables_test.py SOURCE_DIR"""
import copy
import json
import os
import subprocess
import sys
import tempfile
import re

INDEXED = re.compile(r'(\.\w+) = \d+ /\* (.*?) \*/(?=[,}])')

src = os.path.abspath(sys.argv[1])
gen = os.path.join(src, 'scripts', 'gen-io-tables.py')
with open(os.path.join(src, 'schemas', 'design.schema.json'), encoding='utf-8') as f:
    design = json.load(f)
failed = 0


def run(schema, header_edit=None, name='design.schema.json'):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, name)
        with open(path, 'w', encoding='utf-8') as f:
            json.dump(schema, f)
        src_dir = os.path.join(src, 'src')
        if header_edit:
            # a copy of the headers with one edit (a new struct member)
            src_dir = os.path.join(tmp, 'src')
            os.makedirs(os.path.join(src_dir, 'model'))
            with open(os.path.join(src, 'src', 'model', 'design.h'), encoding='utf-8') as f:
                text = f.read()
            old, new = header_edit
            assert old in text
            with open(os.path.join(src_dir, 'model', 'design.h'), 'w', encoding='utf-8') as f:
                f.write(text.replace(old, new))
        r = subprocess.run(['/usr/bin/python3', gen, '--out-dir', os.path.join(tmp, 'out'), '--src',
                            src_dir, path], capture_output=True, text=True)
        text = ''
        for name in ('prsm_io_tables.c', 'prsm_io_enums.h'):
            out = os.path.join(tmp, 'out', name)
            if os.path.exists(out):
                with open(out, encoding='utf-8') as f:
                    text += f.read()
        # the fields name strings, tables and functions by index, with what the index names in a
        # comment (".name = 7 /* "pitch_mm" */"): the checks below read the named form
        text = INDEXED.sub(r'\1 = \2', text)
        vocab = os.path.join(tmp, 'out', 'prsm_vocab.h')  # the vocabularies, plain C
        if os.path.exists(vocab):
            with open(vocab, encoding='utf-8') as f:
                text += f.read()
        return r.returncode, r.stderr + text


def check(name, schema, want_rc, want_text='', header_edit=None, file='design.schema.json'):
    global failed
    rc, err = run(schema, header_edit, file)
    ok = rc == want_rc and want_text in err
    print(('ok   ' if ok else 'FAIL ') + name + ('' if ok else f': rc {rc}, stderr {err.strip()!r}'))
    failed += not ok


def props(s, *path):
    node = s
    for k in path:
        node = node['properties'][k]
    return node


check('the project schema generates', design, 0)
check("an enum's names are exported, for the C code that writes them", design, 0,
      '\nconst char *const prsm_io_t_design_geometry_hand_names[] = {"right", "left", NULL};')
s = copy.deepcopy(design)
del props(s, 'losses', 'seal_torque_Nm')['x-prsm']
check('a property without x-prsm is refused', s, 1, '/losses/seal_torque_Nm has no "x-prsm"')
s = copy.deepcopy(design)
props(s, 'friction', 'nut_roller')['x-prsm']['field'] = 'mu_nut'
check('an annotation naming no member is refused', s, 1, 'has no member "mu_nut"')
s = copy.deepcopy(design)
props(s, 'life', 'preload_N')['x-prsm']['field'] = 'p_allow_MPa'
check('a member no property fills is refused', s, 1, 'life.preload_N')
s = copy.deepcopy(design)
props(s, 'geometry', 'pitch_mm')['x-prsm']['field'] = 'rollers'
check('a number into an int member is refused', s, 1, 'is int')
s = copy.deepcopy(design)
props(s, 'geometry', 'starts')['maximum'] = 13
check('a C limit that differs from the schema fails the build (its static assert)', s, 0,
      '#if defined(__GNUC__) && !defined(__clang__)\n_Static_assert(PRSM_DESIGN_STARTS_MAX == 13.0, ')
check('... and test_io_defaults with any compiler (clang has no floating constant expressions)', s, 0,
      'if (!((double)(PRSM_DESIGN_STARTS_MAX) == 13.0)) {')
s = copy.deepcopy(design)
props(s, 'geometry', 'hand')['x-prsm']['values'] = ['PRSM_HAND_RIGHT']
check('an enum with a C constant missing is refused', s, 1, 'one C constant per enum name')
s = copy.deepcopy(design)
props(s, 'geometry', 'hand')['x-prsm'] = {'field': 'hand', 'constants': {
    'prefix': 'PRSM_T_HAND_', 'count': 'PRSM_T_HANDS', 'name': 'prsm_t_hand_name'}}
check('"constants" generate an enum\'s C constants and its count', s, 0,
      'enum {\n\tPRSM_T_HAND_RIGHT = 0, /* "right" */\n\tPRSM_T_HAND_LEFT = 1, /* "left" */\n};\n'
      '#define PRSM_T_HANDS 2\n')
check('... its name function, bounds-checked', s, 0,
      'return v >= 0 && v < PRSM_T_HANDS ? prsm_io_t_design_geometry_hand_names[v] : "unknown";')
check('... and the values they are, when "values" is left out', s, 0,
      'static const int prsm_io_t_design_geometry_hand_values[] = {PRSM_T_HAND_RIGHT, PRSM_T_HAND_LEFT};')
props(s, 'geometry', 'hand')['x-prsm']['values'] = ['PRSM_HAND_RIGHT', 'PRSM_HAND_LEFT']
check('"values" that are not the generated constants are refused', s, 1, 'must be the constants')

# docs/hacking.md's worked example: a new numeric field is one schema property and one member
member = ('\tdouble lp_material_factor;', '\tdouble preload_spring_N_per_mm; /* N/mm */\n\tdouble lp_material_factor;')
s = copy.deepcopy(design)
props(s, 'life')['properties']['preload_spring_N_per_um'] = {
    'type': 'number', 'minimum': 0, 'maximum': 1e6,
    'x-prsm': {'field': 'preload_spring_N_per_mm', 'scale': 1000.0}}
check('the worked example: property + member generate the field', s, 0,
      '.name = "preload_spring_N_per_um", .required = 0, .offset = offsetof(prsm_design_life, '
      'preload_spring_N_per_mm), .kind = PRSM_IO_NUMBER, .min = 0.0, .max = 1000000.0', member)
check('the worked example: the member alone fails', design, 1, 'life.preload_spring_N_per_mm', member)
check('the worked example: the property alone fails', s, 1, 'has no member "preload_spring_N_per_mm"')

# ---- the study document: steps, arrays, maps, strings into char arrays, "by" ----------------
with open(os.path.join(src, 'schemas', 'study.schema.json'), encoding='utf-8') as f:
    study = json.load(f)
D = '$defs'


def study_check(name, edit, want_rc, want_text=''):
    s = copy.deepcopy(study)
    if edit:
        edit(s)
    check(name, s, want_rc, want_text, file='study.schema.json')


def note(s, *path):
    """The x-prsm of the property at path (property names; '$defs/x' starts in $defs)."""
    node = s
    for k in path:
        node = node[D][k[6:]] if k.startswith('$defs/') else node['properties'][k]
    return node.setdefault('x-prsm', {})


study_check('the study schema generates: a step where "order" puts it', None, 0,
            '{.name = NULL, .required = 0, .kind = PRSM_IO_STEP, .step = prsm_io_step_design},')
study_check('an array into a C array: its message, its count, its items\' table', None, 0,
            '.kind = PRSM_IO_ARRAY, .min_items = 1, .max_items = 64, .code = "bad_array", .message = "tolerances: '
            'an array of 1 to 64 tolerances", .offset = offsetof(prsm_io_study, tolerances), .stored = 1, '
            '.item_size = sizeof(prsm_io_tolerance), .count_offset = offsetof(prsm_io_study, n_tolerances), '
            '.count_size = sizeof(size_t), .child = &prsm_io_t_study_tolerances}')
study_check('maxItems that differs from the C array fails the build (its static assert)',
            lambda s: s['properties']['tolerances'].update(maxItems=65), 0,
            '_Static_assert(sizeof(((prsm_io_study *)0)->tolerances) / sizeof(prsm_io_tolerance) == 65')
study_check('an array without "message" is refused',
            lambda s: note(s, 'tolerances').pop('message'), 1, 'an array needs "message"')
study_check('an array "field" without "count" is refused',
            lambda s: note(s, 'tolerances').pop('count'), 1, '"field" names a C array, with "count"')
study_check('scratch items need their struct',
            lambda s: s[D]['correlation']['x-prsm'].pop('struct'), 1, 'the items\' x-prsm names no "struct"')
study_check('a member of an array\'s items that no property fills is refused',
            lambda s: s[D]['tolerance']['properties']['cpk'].update({'x-prsm': {'covered': 'x'}}), 1,
            'members of prsm_io_tolerance that no property fills and "computed" does not list: cpk')
study_check('numbers fill a double array, with the schema\'s limits (the largest double: no bound)', None, 0,
            '.message = "a: an array of 1 to 64 numbers is required", .offset = offsetof(prsm_bench_model, coef), '
            '.stored = 1, .item_size = sizeof(double), .count_offset = offsetof(prsm_bench_model, inputs), '
            '.count_size = sizeof(size_t), .items = PRSM_IO_NUMBER, .min = 0.0, .max = INFINITY')
study_check('a string fills a char array', None, 0,
            '.kind = PRSM_IO_STRING, .capacity = sizeof(((prsm_io_study *)0)->name), .max_chars = 100}')
study_check('a string into a member that is not a char array is refused',
            lambda s: note(s, 'name').update(field='n_tolerances'), 1, 'a string fills a char array')
study_check('a map: its key step and its items\' table', None, 0,
            '{.name = "specs", .required = 0, .kind = PRSM_IO_MAP, .key = prsm_io_key_spec, '
            '.child = &prsm_io_t_study_specs, .step = prsm_io_step_spec}')
study_check('a map without "key" is refused', lambda s: note(s, 'specs').pop('key'), 1, 'a map needs "key"')
study_check('"by" naming no step is refused',
            lambda s: s[D]['tolerance']['properties']['cpk']['x-prsm'].update(by='nosuch'), 1,
            '"by" names nosuch, which is no step or hook')
study_check('a field "by" a step is left to it (deferred), required when a branch requires it', None, 0,
            '.offset = offsetof(prsm_io_tolerance, dist.kind), .kind = PRSM_IO_ENUM, .names = '
            'prsm_io_t_study_tolerances_distribution_names, .values = prsm_io_t_study_tolerances_distribution_values, '
            '.deferred = 1}')
study_check('what a step writes must be members',
            lambda s: s['x-prsm']['order'][1]['writes'].append('nosuch'), 1, 'has no member "nosuch"')
study_check('a member only a step fills, and it does not say so, is refused',
            lambda s: s['x-prsm']['order'][1]['writes'].remove('assembly_options'), 1,
            'members of prsm_io_study that no property fills and "computed" does not list: assembly_options')
study_check('a property of a oneOf branch without x-prsm is refused',
            lambda s: s[D]['model']['oneOf'][2]['properties']['constant'].pop('x-prsm'), 1,
            '/constant has no "x-prsm"')
study_check('a section\'s defaults function runs at its turn; its defaults are checked', None, 0,
            '.init = prsm_io_init_study_monte_carlo, .kind = PRSM_IO_OBJECT')
study_check('... and a schema default it does not set is reported by prsm_io_defaults_study_monte_carlo()',
            lambda s: s[D]['monte_carlo']['properties']['samples'].update(default=20000), 0,
            'if (!(s->samples == 20000)) {')

# ---- a vocabulary: the study's output names, by their C constants, for src/mc ----------------
OUTPUTS = ('output_name', 'x-prsm')
study_check('a vocabulary gives each name by its C constant, and the count is asserted', None, 0,
            '_Static_assert(PRSM_OUT_COUNT == 20, "PRSM_OUT_COUNT differs from the names of study.schema.json '
            '$defs/output_name");\n#define PRSM_OUTPUT_NAMES { \\\n\t[PRSM_OUT_BACKLASH] = "backlash_um", \\')
study_check('... a "deprecated" name is an older one, of a constant another name has', None, 0,
            '#define PRSM_OUTPUT_OLDER_NAMES {"efficiency", NULL}\n#define PRSM_OUTPUT_OLDER_VALUES {PRSM_OUT_EFFICIENCY}')
study_check('... every current name in one text, for messages', None, 0,
            '#define PRSM_OUTPUT_NAMES_TEXT "backlash_um, backlash_min_um, backlash_max_um, load_sharing_factor, ')
study_check('a vocabulary name without its C constant is refused', lambda s: s[D][OUTPUTS[0]][OUTPUTS[1]]['values'].pop(),
            1, '$defs/output_name: a vocabulary is a oneOf of "const" names, one C constant each in "values"')
study_check('a name\'s attributes: true is 1, a string a C string, a number a double (NAN where not given)', None, 0,
            '#define PRSM_OUTPUT_RANGE { \\\n\t[PRSM_OUT_SHARING] = "at least 1", \\')
study_check('... a number on every current name', None, 0,
            '#define PRSM_OUTPUT_HIGH { \\\n\t[PRSM_OUT_BACKLASH] = NAN, \\')
study_check('an attribute both true and a number is refused',
            lambda s: s[D]['output_name']['oneOf'][3]['x-prsm'].update(low=True), 1,
            'the attribute "low" is true, a string or a number on every name that has it')
study_check('two current names of one C constant are refused',
            lambda s: s[D]['output_name']['oneOf'][9].pop('deprecated'), 1,
            '$defs/output_name: each C constant has one name')

# ---- the allocation and optimisation documents: "missing", "when", sections "by" a step -------
docs = {}
for name in ('allocation', 'optimization'):
    with open(os.path.join(src, 'schemas', f'{name}.schema.json'), encoding='utf-8') as f:
        docs[name] = json.load(f)


def doc_check(doc, name, edit, want_rc, want_text=''):
    s = copy.deepcopy(docs[doc])
    if edit:
        edit(s)
    check(name, s, want_rc, want_text, file=f'{doc}.schema.json')


def alloc_item(s, *path):
    """The x-prsm of an allocate item's property."""
    node = s['properties']['allocate']['items']
    for k in path:
        node = node['properties'][k]
    return node.setdefault('x-prsm', {})


doc_check('allocation', 'the allocation schema generates: a required member\'s own problem when it is missing', None,
          0, '{.name = "cost", .required = 1, .missing = "cost is required: {\\"model\\": ..., \\"coefficient\\": ...}"')
doc_check('allocation', '"missing" on a member that is not required is refused',
          lambda s: alloc_item(s, 'bounds').update(missing='x'), 1, '"missing" is the problem of a required member')
doc_check('optimization', 'the optimisation schema generates: an array\'s "missing" with {min} and {max}', None, 0,
          '.missing = "is required (1..4 objectives)", .kind = PRSM_IO_ARRAY')
doc_check('allocation', '"when": the keys of the object when the condition fails, and the condition', None, 0,
          'prsm_io_t_allocation_allocate_keys_else[] = {"parameter", "cost", "bounds", NULL};')
doc_check('allocation', '... the table names the int of the document it tests', None, 0,
          '.keys_else = prsm_io_t_allocation_allocate_keys_else, .when_offset = offsetof(prsm_io_allocation, '
          'is_study), .when_not = 1}')
doc_check('allocation', '... and the fields it governs', None, 0,
          '{.name = "sd_ratio", .required = 0, .when = 1, .offset = offsetof(prsm_io_alloc_tolerance, sd_ratio)')
doc_check('allocation', '"when" naming a member that is not an int of the document is refused',
          lambda s: alloc_item(s, 'sd_ratio').update(when='!name'), 1, 'not an int member of prsm_io_allocation')
doc_check('allocation', 'two conditions in one table are refused',
          lambda s: alloc_item(s, 'sd_ratio').update(when='is_study'), 1, '"when" must name one condition')
doc_check('allocation', 'a section "by" a step is read when the step asks', None, 0,
          '{.name = "analytic", .required = 0, .offset = 0, .kind = PRSM_IO_OBJECT, .child = '
          '&prsm_io_t_allocation_analytic, .deferred = 1}')
doc_check('allocation', 'a section "by" no step or hook is refused',
          lambda s: s['properties']['analytic']['x-prsm'].update(by='nosuch'), 1,
          '"by" names nosuch, which is no step or hook')
doc_check('allocation', 'the member a section\'s "init" sets counts as filled (without it: refused)',
          lambda s: s['properties']['constraints']['items']['properties']['spec']['x-prsm'].pop('init'), 1,
          'members of prsm_io_alloc_constraint that no property fills and "computed" does not list: has_spec')
doc_check('allocation', 'an array of scratch items counts them ("count" without "field")', None, 0,
          '.message = "constraints: an array of 1 to 16 outputs with a target", .count_offset = '
          'offsetof(prsm_io_allocation, model.m), .count_size = sizeof(size_t), .item_size = '
          'sizeof(prsm_io_alloc_constraint)')
doc_check('allocation', '... into an int or a size_t only',
          lambda s: s['properties']['constraints']['x-prsm'].update(count='model.nominal'), 1,
          'the count model.nominal is an int or a size_t')

# ---- a generated init: the struct's defaults function written from the schema's defaults -----
with open(os.path.join(src, 'schemas', 'dynamics.schema.json'), encoding='utf-8') as f:
    docs['dynamics'] = json.load(f)


def linear(s):
    """The dynamics schema's linear section (a table root with a generated init)."""
    return s['$defs']['linear']


doc_check('dynamics', '"init": {"generate"} writes the function: zero, the schema\'s defaults, then "set"', None, 0,
          'void prsm_io_vib_linear_init(prsm_io_vib_linear *s)\n{\n\tmemset(s, 0, sizeof *s);\n'
          '\ts->input = PRSM_VIB_IN_MESH_ERROR;\n\ts->input_roller = 0;\n\ts->output = PRSM_VIB_OUT_MESH_DEFLECTION;\n'
          '\ts->output_roller = 0;\n\ts->from_frequency_ratio = 0.5;\n\ts->to_frequency_ratio = 1.5;\n'
          '\ts->points = 401;\n\ts->from_Hz = NAN;\n\ts->to_Hz = NAN;\n}')
doc_check('dynamics', '... a schema default is one edit: the function follows',
          lambda s: linear(s)['properties']['points'].update(default=801), 0, '\ts->points = 801;\n')
doc_check('dynamics', '... and a default removed leaves the member zero',
          lambda s: linear(s)['properties']['points'].pop('default'), 0, '\ts->to_frequency_ratio = 1.5;\n\ts->from_Hz')
doc_check('dynamics', 'an integer fills a long member (time.max_steps)', None, 0,
          '.offset = offsetof(prsm_dyn_options, time.max_steps), .kind = PRSM_IO_LONG, .min = 1.0, .max = 1000000000.0')
doc_check('dynamics', '... and its default is checked against the init function', None, 0,
          'if (!(s->time.max_steps == 10000000)) {')
doc_check('dynamics', '"only": a member that belongs with one value of its sibling enum (required then)', None, 0,
          '{.name = "value_Nm", .required = 0, .only_key = "kind", .only_offset = offsetof(prsm_dyn_options, '
          'input.kind), .only_value = PRSM_DYN_INPUT_TORQUE, .only_code = "input_kind", .only_message = "a speed input '
          'is given in rad/s (value_rad_s); value_Nm needs \\"kind\\": \\"torque\\"", .only_required = "a torque '
          'input needs value_Nm, the motor torque in N m", .offset = offsetof(prsm_dyn_options, input.signal.value)')
doc_check('dynamics', '"only" with a sibling that is no enum is refused',
          lambda s: s['properties']['input']['properties']['value_Nm']['x-prsm']['only'].update({'with': 'ramp_time_s'}),
          1, '"only" names ramp_time_s, which is no enum member of this object')
doc_check('dynamics', '"only" with a value the sibling does not have is refused',
          lambda s: s['properties']['input']['properties']['value_Nm']['x-prsm']['only'].update({'is': 'current'}),
          1, '"only": kind has no value \'current\'')
doc_check('dynamics', '"only" without its message is refused',
          lambda s: s['properties']['input']['properties']['value_Nm']['x-prsm']['only'].pop('message'),
          1, '"only" is {"with", "is", "code", "message"} (and "required")')
doc_check('dynamics', '"set" naming no member is refused',
          lambda s: linear(s)['x-prsm']['init']['set'].append({'field': 'nosuch', 'value': 1}), 1, 'nosuch')
doc_check('dynamics', '"set" on a member with a schema default is refused',
          lambda s: linear(s)['x-prsm']['init']['set'].append({'field': 'points', 'value': 3}), 1,
          '"set" gives points, which has a schema default')
doc_check('dynamics', 'an "init" object without "generate" is refused',
          lambda s: linear(s)['x-prsm'].update(init={'set': []}), 1,
          '"init" is a function\'s name or {"generate": "name", "set": [...]}')


def rule(s, k):
    """The dynamics root's k-th rule."""
    return s['x-prsm']['rules'][k]


RULE_CHECKS = [  # (name, edit of the dynamics schema or None, exit code, text the output holds)
    ('"rules": one rule per member, in the listed order, the sibling\'s names and default', None, 0,
     '{.member = "gear_pair", .with = "analysis", .with_default = "transient", .with_names = '
     'prsm_io_r_dynamics_names0, .allowed = prsm_io_r_dynamics_names1, .code = "not_used", .message = "belongs to '
     'the vibration analyses'),
    ('... the name lists they use', None, 0,
     'static const char *const prsm_io_r_dynamics_names1[] = {"linear", "vibration", "sweep", '
     '"frequency_response", "basins", NULL};'),
    ('... "{member}" is each member\'s name, "if" a sibling that must be there', None, 0,
     '{.member = "inertia", .with = "analysis", .with_default = "transient", .with_names = '
     'prsm_io_r_dynamics_names0, .allowed = prsm_io_r_dynamics_names2, .code = "not_used", .message = "a gear pair '
     'is dimensionless and has every parameter in gear_pair: inertia is the reduced model\'s (with a design)", '
     '.present = "gear_pair"}'),
    ('... "keep" the members the rule spares, "unless" a sibling that must be absent', None, 0,
     '"the vibration model\'s load is constant: axial_load_N", .absent = "gear_pair", .keep = '
     'prsm_io_r_dynamics_names4}'),
    ('... "value" a member\'s value and the values it may hold', None, 0,
     '.absent = "gear_pair", .sub = "shape", .sub_values = prsm_io_r_dynamics_names5}'),
    ('... and the table of them', None, 0,
     'const prsm_io_rules prsm_io_r_dynamics = {prsm_io_r_dynamics_rules, sizeof prsm_io_r_dynamics_rules / '
     'sizeof prsm_io_r_dynamics_rules[0]};'),
    ('a rule "with" a sibling that is no enum with a default is refused', lambda s: rule(s, 2).update({'with': 'time'}),
     1, '"rules"[2]: "with" names time, which is no string enum with a default here'),
    ('a rule with a value the sibling does not have is refused',
     lambda s: rule(s, 2).update({'is': ['transient', 'calibrate']}), 1, '"rules"[2]: "is" lists values of analysis'),
    ('a rule on a member the object does not have is refused', lambda s: rule(s, 2)['members'].append('outputs'), 1,
     '"members" names outputs, which is no member here'),
    ('a rule keeping a member its object does not have is refused', lambda s: rule(s, 1)['keep'].append('step_s'), 1,
     '"rules"[1]: "keep" lists members of time'),
    ('a rule on a value its member cannot hold is refused', lambda s: rule(s, 6)['values'].append('square'), 1,
     '"rules"[6]: "values" lists values of load.shape'),
    ('a rule "if" a sibling the object does not have is refused', lambda s: rule(s, 4).update({'if': 'pair'}), 1,
     '"rules"[4]: "if" names pair, which is no member here'),
    ('a rule without its message is refused', lambda s: rule(s, 3).pop('message'), 1,
     '"rules"[3]: a rule is {"members", "with", "is", "code", "message"}'),
]
for name, edit, rc, text in RULE_CHECKS:
    doc_check('dynamics', name, edit, rc, text)
# ---- the analyze request's errors: "divide" as a C expression, "direction" -------------------
with open(os.path.join(src, 'schemas', 'analyze-request.schema.json'), encoding='utf-8') as f:
    docs['analyze-request'] = json.load(f)
doc_check('analyze-request', '"divide" may be a C expression, written as it is', None, 0,
          '.offset = offsetof(prsm_body_errors, runout_phase_rad), .kind = PRSM_IO_NUMBER, .min = -3600.0, '
          '.max = 3600.0, .min_exclusive = 0, .max_exclusive = 0, .divide = (180.0 / M_PI)}')
doc_check('analyze-request', '"direction": a magnitude names its direction', None, 0,
          '.divide = 1000.0, .direction = "runout_phase_deg"}')
doc_check('analyze-request', '"direction" naming no number of the object is refused',
          lambda s: s['$defs']['body']['properties']['runout_um']['x-prsm'].update(direction='start_index_mrad'),
          1, '"direction" names start_index_mrad, which is no number of this object')
sys.exit(1 if failed else 0)
