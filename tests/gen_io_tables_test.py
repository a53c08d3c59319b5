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

src = os.path.abspath(sys.argv[1])
gen = os.path.join(src, 'scripts', 'gen-io-tables.py')
with open(os.path.join(src, 'schemas', 'design.schema.json'), encoding='utf-8') as f:
    design = json.load(f)
failed = 0


def run(schema, header_edit=None):
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, 'design.schema.json')
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
        out = os.path.join(tmp, 'out', 'prsm_io_tables.c')
        text = ''
        if os.path.exists(out):
            with open(out, encoding='utf-8') as f:
                text = f.read()
        return r.returncode, r.stderr + text


def check(name, schema, want_rc, want_text='', header_edit=None):
    global failed
    rc, err = run(schema, header_edit)
    ok = rc == want_rc and want_text in err
    print(('ok   ' if ok else 'FAIL ') + name + ('' if ok else f': rc {rc}, stderr {err.strip()!r}'))
    failed += not ok


def props(s, *path):
    node = s
    for k in path:
        node = node['properties'][k]
    return node


check('the project schema generates', design, 0)
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
      '_Static_assert(PRSM_DESIGN_STARTS_MAX == 13.0')
s = copy.deepcopy(design)
props(s, 'geometry', 'hand')['x-prsm']['values'] = ['PRSM_HAND_RIGHT']
check('an enum with a C constant missing is refused', s, 1, 'one C constant per enum name')

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
sys.exit(1 if failed else 0)
