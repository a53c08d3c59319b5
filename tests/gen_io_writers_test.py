#!/usr/bin/python3
"""The result-writer table generator (scripts/gen-io-writers.py) refuses what would let a
result and its schema disagree: a property of a written object without an annotation, an
annotation naming no member, a type that does not fit the member; and it writes what the
annotations say (order, scale, conditions, cross-file references).

Usage: gen_io_writers_test.py SOURCE_DIR"""
import copy
import json
import os
import shutil
import subprocess
import sys
import tempfile
import re

INDEXED = re.compile(r'(\.\w+?)(?:_i)? = \d+ /\* (.*?) \*/(?=[,}])')

src = os.path.abspath(sys.argv[1])
gen = os.path.join(src, 'scripts', 'gen-io-writers.py')
schemas = os.path.join(src, 'schemas')
RESULTS = ['analysis.schema.json', 'study-result.schema.json', 'optimization-result.schema.json',
           'allocation-result.schema.json', 'measured-result.schema.json', 'dynamics-result.schema.json']
failed = 0


def load(name):
    with open(os.path.join(schemas, name), encoding='utf-8') as f:
        return json.load(f)


def run(edits):
    """The generator over a copy of schemas/ with edits {file name: schema}: (rc, stderr + the
    generated C)."""
    with tempfile.TemporaryDirectory() as tmp:
        sdir = os.path.join(tmp, 'schemas')
        shutil.copytree(schemas, sdir)
        for name, schema in edits.items():
            with open(os.path.join(sdir, name), 'w', encoding='utf-8') as f:
                json.dump(schema, f)
        paths = sorted(os.path.join(sdir, n) for n in os.listdir(sdir) if n.endswith('.schema.json'))
        r = subprocess.run(['/usr/bin/python3', gen, '--out-dir', os.path.join(tmp, 'out'), '--src',
                            os.path.join(src, 'src')] + paths, capture_output=True, text=True)
        text = ''
        for name in ('prsm_io_writers.h', 'prsm_io_writers.c'):
            p = os.path.join(tmp, 'out', name)
            if os.path.exists(p):
                with open(p, encoding='utf-8') as f:
                    text += f.read()
        # the fields name strings, tables and hooks by index, with what the index names in a
        # comment (".name_i = 7 /* "approach_um" */"): the checks below read the named form
        text = INDEXED.sub(r'\1 = \2', text)
        return r.returncode, r.stderr + text


def check(name, edits, want_rc, *want_texts, absent=()):
    global failed
    rc, out = run(edits)
    ok = rc == want_rc and all(t in out for t in want_texts) and not any(t in out for t in absent)
    print(('ok   ' if ok else 'FAIL ') + name + ('' if ok else f': rc {rc}, output {out[:600]!r}'))
    failed += not ok


def table(out, cname):
    """The field initialisers of table cname in the generated C."""
    start = out.index(f'static const prsm_io_wfield {cname}_fields[] = {{')
    return out[start:out.index('};', start)]


a = load('analysis.schema.json')
D = a['$defs']

# the project's schemas generate, with the documents' tables and hooks
rc, out = run({})
print(('ok   ' if rc == 0 else 'FAIL ') + 'the project schemas generate')
failed += rc != 0
for t in ('prsm_io_w_analysis', 'prsm_io_w_multistage', 'prsm_io_w_assembly', 'prsm_io_w_resolved_design',
          'prsm_io_w_output', 'prsm_io_w_solver', 'prsm_io_w_cost_model', 'prsm_io_w_spec'):
    ok = f'extern const prsm_io_wtable {t};' in out
    print(('ok   ' if ok else 'FAIL ') + f'{t} is exported')
    failed += not ok

# the written order is the schema's: a reordered property moves in the table
h = table(out, 'prsm_io_w_hertz')
ok = h.index('"normal_load_N"') < h.index('"sum_rho_per_mm"') < h.index('"p_max_MPa"')
print(('ok   ' if ok else 'FAIL ') + 'the table follows the schema\'s order')
failed += not ok
s = copy.deepcopy(a)
hp = s['$defs']['hertz_contact']['properties']
s['$defs']['hertz_contact']['properties'] = {k: hp[k] for k in reversed(list(hp))}
rc, out2 = run({'analysis.schema.json': s})
h = table(out2, 'prsm_io_w_hertz')
ok = rc == 0 and h.index('"p_max_MPa"') < h.index('"normal_load_N"')
print(('ok   ' if ok else 'FAIL ') + 'a reordered schema reorders the table')
failed += not ok

# what the annotations say reaches the table
check('scale, pointer paths and conditions', {}, 0,
      '.name = "approach_um", .at = {.offset = offsetof(prsm_hertz, delta_mm)}, .kind = PRSM_IO_W_NUMBER, '
      '.type = PRSM_IO_W_DOUBLE, .scale = 1000.0',
      '.at = {.offset = offsetof(prsm_io_analysis_view, a), .deref = 1, .offset2 = offsetof(prsm_analysis, geometry)}',
      '.when = PRSM_IO_W_IF_IS, .when_at = {.offset = offsetof(prsm_design_stiffness, width_rule)}',
      '_values[] = {PRSM_HAND_RIGHT, PRSM_HAND_LEFT};')

# a property of a written object without an annotation
s = copy.deepcopy(a)
del s['$defs']['hertz_contact']['properties']['ellipticity_a_over_b']['x-prsm']
check('a property without x-prsm is refused', {'analysis.schema.json': s}, 1,
      'prsm_io_w_hertz/ellipticity_a_over_b has no "x-prsm" annotation')
# ... also one a cross-file $ref brings in (the design schema's annotations are the reader's)
s = copy.deepcopy(a)
del s['$defs']['resolved_design']['properties']['geometry']['properties']['nut_length_mm']
check('a referenced property the result does not say how to write is refused', {'analysis.schema.json': s}, 1,
      'prsm_io_w_resolved_design_geometry/nut_length_mm has no "x-prsm"')
# a member the struct lacks
s = copy.deepcopy(a)
s['$defs']['hertz_contact']['properties']['semi_major_a_mm']['x-prsm']['field'] = 'a_um'
check('an annotation naming no member is refused', {'analysis.schema.json': s}, 1, 'struct prsm_hertz has no member "a_um"')
s = copy.deepcopy(a)
s['$defs']['contact']['properties']['x_mm']['x-prsm']['field'] = 'c->x_um'
check('... through a pointer too', {'analysis.schema.json': s}, 1, 'struct prsm_contact has no member "x_um"')
# types that do not fit
s = copy.deepcopy(a)
s['$defs']['hertz_contact']['properties']['p_max_MPa']['type'] = 'integer'
check('an integer from a double is refused', {'analysis.schema.json': s}, 1, 'an integer is written from an integer member')
s = copy.deepcopy(a)
s['$defs']['hertz_contact']['properties']['p_max_MPa']['type'] = 'string'
check('a string from a double is refused', {'analysis.schema.json': s}, 1, 'a string is a char array')
s = copy.deepcopy(a)
s['$defs']['contact']['properties']['edge_contact']['x-prsm']['field'] = 'c->gap_mm'
check('a boolean from a double is refused', {'analysis.schema.json': s}, 1, 'a boolean is written from an int')
s = copy.deepcopy(a)
del s['$defs']['analysis']['properties']['thinning']['properties']['rule']['x-prsm']['values']
check('a string enum without its C values is refused', {'analysis.schema.json': s}, 1, '"values" must give one C constant')
s = copy.deepcopy(a)
s['$defs']['contact']['properties']['normal_radial_tangential_axial']['x-prsm']['field'] = 'c->x_mm'
check('array items from a scalar are refused', {'analysis.schema.json': s}, 1, 'no C array or pointer')
s = copy.deepcopy(a)
s['$defs']['analysis']['properties']['geometry']['x-prsm']['field'] = 'a->backlash_mm'
check('an object from a number is refused', {'analysis.schema.json': s}, 1, 'is no struct')
s = copy.deepcopy(a)
s['$defs']['analysis']['properties']['contacts']['properties']['screw_roller']['x-prsm']['field'] = 'screw_side'
check('an object whose table writes another struct is refused', {'analysis.schema.json': s}, 1,
      'the table contact writes a prsm_io_contact_view, the member is a prsm_io_side_view')
s = copy.deepcopy(a)
s['$defs']['analysis']['properties']['load_distribution']['properties']['roller_load_N']['x-prsm']['when'] = 'nothing'
check('a condition on no member is refused', {'analysis.schema.json': s}, 1, 'has no member "nothing"')

# a new result field is one schema edit: the table grows by it
s = copy.deepcopy(a)
s['$defs']['analysis']['properties']['kinematics']['properties']['carrier_ratio_min_slip'] = {
    'description': 'k*.', 'type': 'number', 'x-prsm': {'field': 'a->kinematics.carrier_ratio_min_slip'}}
s['$defs']['analysis']['properties']['kinematics']['properties']['roller_spin_ratio_ideal'] = {
    'description': 'gone', 'type': 'number', 'x-prsm': {'skip': True}}
check('a field added (and one skipped) in the schema reaches the table', {'analysis.schema.json': s}, 0,
      '{.name = "carrier_ratio_min_slip", .at = {.offset = offsetof(prsm_io_analysis_view, a), .deref = 1, '
      '.offset2 = offsetof(prsm_analysis, kinematics.carrier_ratio_min_slip)}',
      absent=('"roller_spin_ratio_ideal"',))

# the calibration and dynamics results: a member of each element a pointer points to ("p[].m"),
# boolean and enum-name items, long integers, factors the run decides ({"field"}), a property
# "fields" whose table name would collide with its parent's field list
for t in ('prsm_io_w_calibration_result', 'prsm_io_w_dyn_result', 'prsm_io_w_vib_result', 'prsm_io_w_vib_sweep_point',
          'prsm_io_w_vib_gear_pair', 'prsm_io_w_vib_te_line'):
    ok = f'extern const prsm_io_wtable {t};' in out
    print(('ok   ' if ok else 'FAIL ') + f'{t} is exported')
    failed += not ok
check('the new shapes reach the tables', {}, 0,
      '.offset2 = offsetof(prsm_dyn_result, point), .pointer = 1, .stride = sizeof(*((prsm_dyn_result *)0)->point), '
      '.after = offsetof(prsm_dyn_point, time_s)}, .kind = PRSM_IO_W_ARRAY',
      '.after = offsetof(prsm_dyn_point, stuck)}, .kind = PRSM_IO_W_ARRAY, .count_type = PRSM_IO_W_SIZE, '
      '.count_at = {.offset = offsetof(prsm_io_dyn_result_view, r), .deref = 1, .offset2 = offsetof(prsm_dyn_result, points)}, '
      '.type = PRSM_IO_W_INT, .mask = -1}',
      '.offset2 = offsetof(prsm_dyn_result, steps)}, .kind = PRSM_IO_W_NUMBER, .type = PRSM_IO_W_LONG}',
      '.divide_by = 1, .divide_at = {.offset = offsetof(prsm_io_vib_result_view, wref)}}',
      'prsm_io_w_calibration_result_calibration_1 = ')
ok = '.type = PRSM_IO_W_INT, .names = ' in table(out, 'prsm_io_w_calibration_result_calibration_1')
print(('ok   ' if ok else 'FAIL ') + 'an array of ints with "values" writes their names')
failed += not ok
m = load('measured-result.schema.json')
dr = load('dynamics-result.schema.json')
s = copy.deepcopy(dr)
s['$defs']['vib_linear']['properties']['half_power']['properties']['peak_frequency_Hz']['x-prsm']['scale'] = {'field': 'failed'}
check('a factor from a member that is no double is refused', {'dynamics-result.schema.json': s}, 1,
      '"scale": {"field"} names a double member')
s = copy.deepcopy(dr)
s['$defs']['transient']['properties']['stuck']['x-prsm']['field'] = 'r->point[].efficiency'
check('boolean items from doubles are refused', {'dynamics-result.schema.json': s}, 1,
      'boolean items are written from ints, not double')
s = copy.deepcopy(dr)
s['$defs']['transient']['properties']['time_s']['x-prsm']['field'] = 'r->point[].time_z'
check('"p[].m" naming no member of the element is refused', {'dynamics-result.schema.json': s}, 1,
      'struct prsm_dyn_point has no member "time_z"')
s = copy.deepcopy(m)
s['properties']['calibration']['properties']['dropped_lines']['x-prsm']['field'] = 'line->lag'
check('enum items from no member are refused', {'measured-result.schema.json': s}, 1, 'has no member "lag"')
s = copy.deepcopy(m)
s['properties']['calibration']['properties']['dropped_lines']['x-prsm']['field'] = 'line->amplitude_um'
check('enum items from doubles are refused', {'measured-result.schema.json': s}, 1,
      'string enum items are written from ints, not double')

# the series and grids of the dynamics result: a row's elements taken every K ("every": a chain's
# stages interleave, K per output time), booleans from an int equal to a constant ("is"), a
# row-major C array as an array of arrays ("columns"), an evenly spaced grid between two members
SP = ['$defs', 'transient', 'properties', 'stages', 'items', 'properties']


def node(d, path):
    for k in path:
        d = d[k]
    return d


check('"every", "is", "columns" and "grid" reach the tables', {}, 0,
      '.after = offsetof(prsm_dyn_stage_point, carrier_ratio)}, .kind = PRSM_IO_W_ARRAY, .count_type = PRSM_IO_W_SIZE, '
      '.count_at = {.offset = offsetof(prsm_io_dyn_result_view, r), .deref = 1, .offset2 = offsetof(prsm_dyn_result, points)}, '
      '.step_type = PRSM_IO_W_INT, .step_at = {.offset = offsetof(prsm_io_dyn_result_view, r), .deref = 1, '
      '.offset2 = offsetof(prsm_dyn_result, stages)}, .type = PRSM_IO_W_DOUBLE}',
      '.after = offsetof(prsm_dyn_stage_point, flank)}, .kind = PRSM_IO_W_ARRAY',
      '.type = PRSM_IO_W_INT, .is_set = 1, .is_value = PRSM_DYN_FLANK_UPPER}',
      '.offset2 = offsetof(prsm_io_vib_result, basins.label), .pointer = 1, '
      '.stride = sizeof(*((prsm_io_vib_result *)0)->basins.label)}, .kind = PRSM_IO_W_ARRAY',
      '.offset2 = offsetof(prsm_io_vib_result, basins.nv)}, .shape = PRSM_IO_W_MATRIX, .type = PRSM_IO_W_INT}',
      '.offset2 = offsetof(prsm_io_vib_result, steady.poincare_size)}, .shape = PRSM_IO_W_MATRIX, .type = PRSM_IO_W_DOUBLE}',
      '{.name = "deflection", .kind = PRSM_IO_W_ARRAY, .count_type = PRSM_IO_W_INT, ',
      '.shape = PRSM_IO_W_GRID, .type = PRSM_IO_W_DOUBLE, .at = {.offset = offsetof(prsm_io_vib_result_view, r), '
      '.deref = 1, .offset2 = offsetof(prsm_io_vib_result, basins.x_min)}, .step_type = PRSM_IO_W_DOUBLE, '
      '.step_at = {.offset = offsetof(prsm_io_vib_result_view, r), .deref = 1, '
      '.offset2 = offsetof(prsm_io_vib_result, basins.x_max)}}')
s = copy.deepcopy(dr)
node(s, SP + ['carrier_ratio', 'x-prsm'])['every'] = 'r->max_power_balance_relative'
check('"every" naming no integer member is refused', {'dynamics-result.schema.json': s}, 1,
      'the every r->max_power_balance_relative is an int or a size_t')
s = copy.deepcopy(dr)
node(s, ['$defs', 'transient', 'properties', 'time_s', 'x-prsm'])['every'] = 'r->stages'
s['$defs']['transient']['properties']['time_s']['x-prsm']['field'] = 'r->settled.efficiency'
check('"every" outside a row is refused', {'dynamics-result.schema.json': s}, 1,
      '"every" steps through the elements of a row')
s = copy.deepcopy(dr)
node(s, SP + ['upper_flank', 'x-prsm'])['mask'] = 1
check('boolean items with "mask" and "is" are refused', {'dynamics-result.schema.json': s}, 1,
      'boolean items take "mask" or "is", not both')
s = copy.deepcopy(dr)
node(s, SP + ['carrier_ratio', 'x-prsm'])['is'] = 'PRSM_DYN_FLANK_UPPER'
check('"is" on number items is refused', {'dynamics-result.schema.json': s}, 1, '"is" makes boolean items')
s = copy.deepcopy(dr)
del node(s, ['$defs', 'vib_basins', 'properties', 'labels', 'x-prsm'])['columns']
check('an array of arrays without "columns" is refused', {'dynamics-result.schema.json': s}, 1,
      'an array of arrays of numbers names the elements\' "field" (a C array or a pointer) and its "columns"')
s = copy.deepcopy(dr)
node(s, ['$defs', 'vib_basins', 'properties', 'labels', 'x-prsm'])['field'] = 'r->basins.nx'
check('a matrix from a scalar is refused', {'dynamics-result.schema.json': s}, 1, 'no C array or pointer')
s = copy.deepcopy(dr)
node(s, ['$defs', 'vib_basins', 'properties', 'deflection', 'x-prsm'])['grid']['to'] = 'r->basins.nv'
check('a grid to an int is refused', {'dynamics-result.schema.json': s}, 1, 'a grid runs between two double members')
s = copy.deepcopy(dr)
node(s, ['$defs', 'vib_basins', 'properties', 'deflection', 'x-prsm'])['field'] = 'r->basins.x_min'
check('a grid with "field" is refused', {'dynamics-result.schema.json': s}, 1,
      '"grid" is {"from": member, "to": member}, without "field"')
check('"slice" and "index" reach the tables (a mode shape: its row of each matrix, its index)', {}, 0,
      '{.name = "eigenvalue", .kind = PRSM_IO_W_INDEX, .count = 0}',
      '{.name = "stage", .kind = PRSM_IO_W_INDEX, .count = 1}',
      '.offset2 = offsetof(prsm_io_vib_result, linear.shape_im), .pointer = 1, '
      '.stride = sizeof(*((prsm_io_vib_result *)0)->linear.shape_im)}, .kind = PRSM_IO_W_ARRAY, .count_type = '
      'PRSM_IO_W_INT, .count_at = {.offset = offsetof(prsm_io_vib_result_view, r), .deref = 1, '
      '.offset2 = offsetof(prsm_io_vib_result, linear.shape_size)}, .shape = PRSM_IO_W_SLICE, .type = PRSM_IO_W_DOUBLE}')
MP = ['$defs', 'vib_linear', 'properties', 'modes', 'properties', 'shapes', 'items', 'properties']
s = copy.deepcopy(dr)
node(s, MP + ['re', 'x-prsm'])['field'] = 'r->linear.eig_re[]'
check('a slice of a row\'s element ("[]") is refused', {'dynamics-result.schema.json': s}, 1,
      '"slice" takes a row\'s "count" numbers of a C array or pointer (no "[]")')
s = copy.deepcopy(dr)
node(s, MP + ['eigenvalue', 'x-prsm'])['field'] = 'r->linear.eigenvalues'
check('"index" with a "field" is refused', {'dynamics-result.schema.json': s}, 1,
      '"index": N (0 or more) writes the row\'s number + N as an integer, without "field"')
s = copy.deepcopy(dr)
node(s, MP + ['eigenvalue'])['type'] = 'string'
check('"index" on a string is refused', {'dynamics-result.schema.json': s}, 1, '"index": N (0 or more)')

print('gen-io-writers:', 'FAILED' if failed else 'all ok')
sys.exit(1 if failed else 0)
