#!/usr/bin/python3
"""Generate the C field tables of the document readers from the annotated JSON Schemas.

Usage: gen-io-tables.py --out-dir DIR SCHEMA...   (Python standard library only)

A schema whose root, or an object under its $defs, carries an "x-prsm" object with a "table"
name is a document (or part of one) the C code reads: prsm_io_t_<table>. The annotation names
the C struct it fills ("struct"), the header that declares it ("header", under src/) and the
members the document does not set ("computed": filled by the model or by a hook). Every property then carries its own "x-prsm":

  "field": "pitch_mm"            the struct member (a path: "losses.spin", "screw_material")
  "scale": 1000 | "(M_PI / 180.0)"  stored = JSON value x scale (numbers; an expression is
                                 written into the C table as it is)
  "divide": 1000                 stored = JSON value / divide (for bit-identical unit changes)
  "limits": {"maximum": "PRSM_X_MAX"}   the C constant must equal the schema (static assert;
                                 the root's "includes" names the headers that define them)
  a table root's "init" names the function that sets the struct's defaults: the generated
  prsm_io_defaults_<table>() compares it with every "default" of the schema
  "values": ["PRSM_HAND_RIGHT", ...]   C constants of an enum, in the schema's enum order (into
                                 an int or an int-sized typedef'd enum)
  integers fill an int, or a size_t (from 0 up)
  "set": {"field": "thinning_rule", "value": "PRSM_THINNING_GIVEN"}   when present and valid
  "conflict": {"with": "thinning", "message": "..."}   both present: a problem at this property
  "hook": {"name": "engagement", "writes": ["engaged_threads"]}   read by hand-written C
  "covered": "engaged_threads"   read by that property's hook
  "skip": true                   checked (type, length) and not stored (names, descriptions)
  on objects: "field" + "struct" (a member of another struct type: its own table), "init"
  ([{"field", "value"}] set when the section is present), "after" (a hook run on the section
  once its properties are read), "order" (properties read first, in this order, and their
  problems reported so; the rest follow in the schema's order).

Limits come from the schema itself (minimum, maximum, exclusive*, maxLength, required), so the
schema is the single source of truth and the C reader cannot disagree with it. The generator
fails, and with it the build, when a property has no annotation, when an annotation names no
member of the struct, or when a member of the struct is neither read nor listed as computed.

Output: DIR/prsm_io_tables.h and DIR/prsm_io_tables.c.
"""
import argparse
import json
import os
import re
import sys

KINDS = {'number': 'PRSM_IO_NUMBER', 'integer': 'PRSM_IO_INT', 'boolean': 'PRSM_IO_BOOL',
         'string': 'PRSM_IO_STRING'}


class GenError(Exception):
    pass


def c_string(s):
    return '"' + s.replace('\\', '\\\\').replace('"', '\\"') + '"'


def c_double(v):
    if v == float('inf'):
        return 'INFINITY'
    if v == float('-inf'):
        return '-INFINITY'
    return repr(float(v))


# ---- the C structs (members a document must cover) --------------------------------------------

STRUCT_RE = re.compile(r'typedef\s+struct\s*\w*\s*\{(.*?)\}\s*(\w+)\s*;', re.S)


def parse_structs(text):
    """{struct name: [(type, member, is_array)]} of the typedef'd structs in a C header."""
    text = re.sub(r'/\*.*?\*/', ' ', text, flags=re.S)
    text = re.sub(r'//[^\n]*', ' ', text)
    out = {}
    for body, name in STRUCT_RE.findall(text):
        members = []
        for decl in body.split(';'):
            decl = ' '.join(decl.split())
            if not decl:
                continue
            fp = re.search(r'\(\s*\*\s*(\w+)\s*\)\s*\(', decl)
            if fp:  # a function pointer member
                members.append(('function pointer', fp.group(1), False))
                continue
            m = re.match(r'^((?:const\s+)?(?:unsigned\s+|signed\s+)?\w+(?:\s*\*)*)\s+(.*)$', decl)
            if not m:
                raise GenError(f'cannot read the member declaration "{decl}" of {name}')
            ctype, names = m.group(1).strip(), m.group(2)
            for part in names.split(','):
                part = part.strip().lstrip('*').strip()
                member = re.match(r'^(\w+)', part).group(1)
                members.append((ctype, member, '[' in part))
        out[name] = members
    return out


def leaf_members(structs, sname, prefix=''):
    """Every scalar or array member path of struct sname, nested structs expanded."""
    paths = []
    for ctype, member, is_array in structs[sname]:
        path = prefix + member
        if ctype in structs and not is_array:
            paths.extend(leaf_members(structs, ctype, path + '.'))
        else:
            paths.append(path)
    return paths


# ---- schema walk -----------------------------------------------------------------------------

class Gen:
    def __init__(self, schema, path, src_root, node=None):
        self.schema = schema
        self.path = path
        self.node = schema if node is None else node
        self.root_note = self.node['x-prsm']
        self.doc = self.root_note['table']
        header = os.path.join(src_root, self.root_note['header'])
        with open(header, encoding='utf-8') as f:
            text = f.read()
        self.structs = parse_structs(text)
        # typedef'd enums fill like an int (the generated file asserts they are int-sized)
        self.enums = set(re.findall(r'typedef\s+enum\s*\w*\s*\{[^}]*\}\s*(\w+)\s*;', text))
        self.tables = []      # (c name, struct, [field initialisers], [keys])
        self.hooks = set()
        self.written = set()  # member paths of the root struct the document sets
        self.asserts = []
        self.defaults = []    # (member path, C value, schema pointer, kind)
        self.section_init = {}  # member path -> the value its section's "init" sets

    def resolve(self, prop):
        if '$ref' in prop:
            ref = prop['$ref']
            if not ref.startswith('#/$defs/'):
                raise GenError(f'{self.path}: only local $defs references are supported ({ref})')
            target = dict(self.schema['$defs'][ref[len('#/$defs/'):]])
            merged = dict(target)
            merged.update({k: v for k, v in prop.items() if k != '$ref'})
            if 'x-prsm' in target and 'x-prsm' in prop:
                note = dict(target['x-prsm'])
                note.update(prop['x-prsm'])
                merged['x-prsm'] = note
            return merged
        return prop

    def member_type(self, sname, path):
        """The C type of a member path of struct sname (checks that it exists)."""
        ctype = sname
        for part in path.split('.'):
            found = [m for m in self.structs.get(ctype, []) if m[1] == part]
            if not found:
                raise GenError(f'{self.path}: struct {ctype} has no member "{part}" (of "{path}")')
            ctype = found[0][0]
        return ctype

    def table(self, node, ptr, sname, prefix):
        """Emit the table of object node (schema pointer ptr) read into struct sname; prefix is
        the member path of sname inside the root struct (for the coverage check)."""
        cname = 'prsm_io_t_' + re.sub(r'[^a-z0-9]+', '_', (self.doc + ptr).lower()).strip('_')
        required = set(node.get('required', []))
        fields, keys = [], []
        props = node.get('properties', {})
        keys = list(props)  # the schema's order: the unknown-key message lists them so
        order = node.get('x-prsm', {}).get('order')
        if order is not None:
            if len(set(order)) != len(order) or not set(order) <= set(props):
                raise GenError(f'{self.path}: {ptr or "/"} "order" must name properties, each once')
            # the listed ones in that order, then the others in the schema's
            props = {**{k: props[k] for k in order}, **{k: v for k, v in props.items() if k not in order}}
        for key, raw in props.items():
            prop = self.resolve(raw)
            note = prop.get('x-prsm')
            where = f'{self.path}: {ptr}/{key}'
            if note is None and (prop.get('type') == 'object' or 'properties' in prop):
                note = {}  # a section of the same struct
            if note is None:
                raise GenError(f'{where} has no "x-prsm" annotation (which C member does it fill?)')
            init = {'name': c_string(key), 'required': '1' if key in required else '0'}
            ptype = prop.get('type')
            if 'covered' in note:
                init['kind'] = 'PRSM_IO_COVERED'
                fields.append(init)
                continue
            if 'hook' in note:
                h = note['hook']
                init['kind'] = 'PRSM_IO_HOOK'
                init['hook'] = 'prsm_io_hook_' + h['name']
                self.hooks.add(h['name'])
                for w in h.get('writes', []):
                    self.member_type(sname, w)
                    self.written.add(prefix + w)
                fields.append(init)
                continue
            if ptype == 'object' or 'properties' in prop:
                for f0 in note.get('init', []):
                    # a member the section sets when present: its schema default is that value
                    self.section_init[prefix + f0['field']] = str(f0['value'])
                if 'field' in note:
                    child_struct = note['struct']
                    if self.member_type(sname, note['field']) != child_struct:
                        raise GenError(f'{where}: member {note["field"]} is not a {child_struct}')
                    init['offset'] = f'offsetof({sname}, {note["field"]})'
                    child = self.table(prop, f'{ptr}/{key}', child_struct, prefix + note['field'] + '.')
                else:
                    init['offset'] = '0'
                    child = self.table(prop, f'{ptr}/{key}', sname, prefix)
                init['kind'] = 'PRSM_IO_OBJECT'
                init['child'] = '&' + child
                inits = note.get('init', [])
                if inits:
                    if len(inits) != 1:
                        raise GenError(f'{where}: one "init" member at most')
                    f0 = inits[0]
                    self.member_type(sname, f0['field'])
                    init['has_set'] = '1'
                    init['set_offset'] = f'offsetof({sname}, {f0["field"]})'
                    init['set_value'] = str(f0['value'])
                if 'after' in note:
                    init['hook'] = 'prsm_io_hook_' + note['after']['name']
                    self.hooks.add(note['after']['name'])
                    for w in note['after'].get('writes', []):
                        self.member_type(sname, w)
                        self.written.add(prefix + w)
                fields.append(init)
                continue
            if note.get('skip'):
                init['kind'] = 'PRSM_IO_STRING'
                init['offset'] = '0'
                init['skip'] = '1'
                if 'maxLength' in prop:
                    init['max_chars'] = str(prop['maxLength'])
                fields.append(init)
                continue
            field = note.get('field')
            if field is None:
                raise GenError(f'{where}: "x-prsm" names no "field", "hook", "covered" or "skip"')
            ctype = self.member_type(sname, field)
            self.written.add(prefix + field)
            init['offset'] = f'offsetof({sname}, {field})'
            if 'enum' in prop:
                values = note.get('values')
                if values is None or len(values) != len(prop['enum']):
                    raise GenError(f'{where}: "values" must give one C constant per enum name')
                if not all(isinstance(e, str) for e in prop['enum']):
                    raise GenError(f'{where}: only string enums are tables (numbers need a hook)')
                base = f'{cname}_{key}'
                self.enum_arrays.append((base, prop['enum'], values))
                init['kind'] = 'PRSM_IO_ENUM'
                init['names'] = base + '_names'
                init['values'] = base + '_values'
                if ctype != 'int' and ctype not in self.enums:
                    raise GenError(f'{where}: an enum fills an int or an enum type, not {ctype}')
                if ctype != 'int':
                    self.asserts.append((f'sizeof({ctype})', 'sizeof(int)', f'{ptr}/{key}: {ctype} is int-sized'))
            else:
                if ptype not in KINDS:
                    raise GenError(f'{where}: type {ptype!r} needs a hook')
                init['kind'] = KINDS[ptype]
                want = {'number': 'double', 'integer': 'int', 'boolean': 'int'}.get(ptype)
                if ptype == 'integer' and ctype == 'size_t':
                    init['kind'], want = 'PRSM_IO_SIZE', 'size_t'
                if want and ctype != want:
                    raise GenError(f'{where}: {ptype} fills a {want}, but {sname}.{field} is {ctype}')
                lo, hi = float('-inf'), float('inf')
                lo_x = hi_x = 0
                if 'minimum' in prop:
                    lo = prop['minimum']
                if 'exclusiveMinimum' in prop:
                    lo, lo_x = prop['exclusiveMinimum'], 1
                if 'maximum' in prop:
                    hi = prop['maximum']
                if 'exclusiveMaximum' in prop:
                    hi, hi_x = prop['exclusiveMaximum'], 1
                if ptype == 'integer' and (lo_x or hi_x or lo == float('-inf') or hi == float('inf')):
                    raise GenError(f'{where}: an integer needs inclusive minimum and maximum')
                if init['kind'] == 'PRSM_IO_SIZE' and lo < 0:
                    raise GenError(f'{where}: a size_t member needs a minimum of 0 or more')
                init['min'], init['max'] = c_double(lo), c_double(hi)
                init['min_exclusive'], init['max_exclusive'] = str(lo_x), str(hi_x)
                if 'scale' in note:
                    init['scale'] = str(note['scale'])
                if 'divide' in note:
                    init['divide'] = c_double(note['divide'])
                for bound, cname_c in note.get('limits', {}).items():
                    v = prop.get(bound)
                    if v is None:
                        raise GenError(f'{where}: "limits" names {bound}, which the schema lacks')
                    self.asserts.append((cname_c, c_double(v), f'{ptr}/{key} {bound}'))
            if 'set' in note:
                self.member_type(sname, note['set']['field'])
                self.written.add(prefix + note['set']['field'])
                init['has_set'] = '1'
                init['set_offset'] = f'offsetof({sname}, {note["set"]["field"]})'
                init['set_value'] = str(note['set']['value'])
            if 'conflict' in note:
                init['conflict_with'] = c_string(note['conflict']['with'])
                init['conflict_message'] = c_string(note['conflict']['message'])
            if 'default' in prop:
                self.default_check(prop, note, init['kind'], prefix + field, f'{ptr}/{key}', where)
            fields.append(init)
        self.tables.append((cname, sname, fields, keys))
        return cname

    def default_check(self, prop, note, kind, path, pointer, where):
        """The schema's default of a member, as the C value the reader would store: checked
        against what the struct's init function sets (prsm_io_defaults_<table>)."""
        d = prop['default']
        if path in self.section_init:
            if str(d) != self.section_init[path]:
                raise GenError(f'{where}: default {d} but its section sets {self.section_init[path]}')
            return
        if kind == 'PRSM_IO_ENUM':
            value = note['values'][prop['enum'].index(d)]
        elif kind == 'PRSM_IO_BOOL':
            value = '1' if d else '0'
        elif kind in ('PRSM_IO_INT', 'PRSM_IO_SIZE'):
            value = str(int(d))
        elif kind == 'PRSM_IO_NUMBER':
            v = c_double(d)
            if 'divide' in note:
                value = f'({v} / {c_double(note["divide"])})'
            elif 'scale' in note:
                value = f'({v} * {note["scale"]})'
            else:
                value = v
        else:
            return
        self.defaults.append((path, value, pointer, kind))

    def run(self):
        self.enum_arrays = []
        root = self.table(self.node, '', self.root_note['struct'], '')
        members = leaf_members(self.structs, self.root_note['struct'])
        computed = set(self.root_note.get('computed', []))
        for c in computed:
            self.member_type(self.root_note['struct'], c)

        def covered(m):
            return any(m == w or m.startswith(w + '.') for w in self.written | computed)
        missing = [m for m in members if not covered(m)]
        if missing:
            raise GenError(f'{self.path}: members of {self.root_note["struct"]} that no property '
                           f'fills and "computed" does not list: {", ".join(missing)}')
        return root


def emit(gens, out_dir):
    h = ['/* Generated by scripts/gen-io-tables.py from schemas/: do not edit. */',
         '#ifndef PRSM_IO_TABLES_H', '#define PRSM_IO_TABLES_H', '', '#include "io/doc.h"', '']
    c = ['/* Generated by scripts/gen-io-tables.py from schemas/: do not edit. */',
         '#include "prsm_io_tables.h"', '', '#include <math.h>', '#include <stddef.h>', '#include <stdlib.h>', '']
    includes = sorted({g.root_note['header'] for g in gens})
    h[5:5] = [f'#include "{i}"' for i in includes]
    extra = sorted({i for g in gens for i in g.root_note.get('includes', [])})
    c[5:5] = [f'#include "{i}"' for i in extra]
    for g in gens:
        for name in sorted(g.hooks):
            h.append(f'void prsm_io_hook_{name}(void *base, const cJSON *obj, const char *obj_pointer, '
                     f'prsm_problems *problems);')
        for cname_c, value, what in g.asserts:
            c.append(f'_Static_assert({cname_c} == {value}, "{cname_c} differs from the schema ({what})");')
        for base, names, values in g.enum_arrays:
            c.append(f'static const char *const {base}_names[] = {{' +
                     ', '.join(c_string(n) for n in names) + ', NULL};')
            c.append(f'static const int {base}_values[] = {{' + ', '.join(values) + '};')
        for cname, sname, fields, keys in g.tables:
            c.append(f'static const char *const {cname}_keys[] = {{' +
                     ', '.join(c_string(k) for k in keys) + ', NULL};')
            c.append(f'static const prsm_io_field {cname}_fields[] = {{')
            for f in fields:
                c.append('\t{' + ', '.join(f'.{k} = {v}' for k, v in f.items()) + '},')
            c.append('};')
            export = cname == f'prsm_io_t_{g.doc}'
            c.append(f'{"" if export else "static "}const prsm_io_table {cname} = {{{c_string(sname)}, '
                     f'{cname}_fields, sizeof {cname}_fields / sizeof {cname}_fields[0], {cname}_keys}};')
            c.append('')
            if export:
                h.append(f'extern const prsm_io_table {cname};')
        if 'init' in g.root_note:
            st, fn = g.root_note['struct'], g.root_note['init']
            h.append(f'/* The schema\'s defaults against what {fn}() sets: one problem each that differs; returns')
            h.append(' * their count, or -1 when out of memory. */')
            h.append(f'int prsm_io_defaults_{g.doc}(prsm_problems *problems);')
            c.append(f'int prsm_io_defaults_{g.doc}(prsm_problems *problems)')
            c.append('{')
            c.append(f'\t{st} *s = calloc(1, sizeof *s);')
            c.append('\tif (s == NULL)\n\t\treturn -1;')
            c.append(f'\t{fn}(s);')
            c.append('\tint bad = 0;')
            for path, value, pointer, kind in g.defaults:
                cast = '(double)' if kind != 'PRSM_IO_NUMBER' else ''
                c.append(f'\tif (!(s->{path} == {value})) {{')
                c.append(f'\t\tprsm_problems_add(problems, {c_string(pointer)}, "default", "the schema\'s default is '
                         f'%.17g, {fn}() sets %.17g", (double)({value}), {cast}s->{path});')
                c.append('\t\tbad++;')
                c.append('\t}')
            c.append('\tfree(s);')
            c.append('\treturn bad;')
            c.append('}')
            c.append('')
        # the sections other code reads on their own (e.g. an operating point in a study)
        for cname, sname, fields, keys in g.tables:
            for sec in g.root_note.get('export', []):
                if cname == f'prsm_io_t_{g.doc}_{sec}':
                    c.append(f'const prsm_io_table *const {cname}_table = &{cname};')
                    h.append(f'extern const prsm_io_table *const {cname}_table;')
    h += ['', '#endif', '']
    os.makedirs(out_dir, exist_ok=True)
    for name, lines in (('prsm_io_tables.h', h), ('prsm_io_tables.c', c)):
        text = '\n'.join(lines) + '\n'
        path = os.path.join(out_dir, name)
        old = None
        if os.path.exists(path):
            with open(path, encoding='utf-8') as f:
                old = f.read()
        if old != text:
            with open(path, 'w', encoding='utf-8') as f:
                f.write(text)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--out-dir', required=True)
    ap.add_argument('--src', required=True, help='the source tree\'s src/ (headers named by "header")')
    ap.add_argument('schemas', nargs='+')
    a = ap.parse_args(argv[1:])
    gens = []
    try:
        for path in a.schemas:
            with open(path, encoding='utf-8') as f:
                schema = json.load(f)
            # a document's root, or a part of it under $defs, that names its table
            nodes = [None] if 'table' in schema.get('x-prsm', {}) else []
            nodes += [d for d in schema.get('$defs', {}).values() if 'table' in d.get('x-prsm', {})]
            for node in nodes:
                g = Gen(schema, os.path.basename(path), a.src, node)
                g.run()
                gens.append(g)
        emit(gens, a.out_dir)
    except GenError as e:
        print(f'gen-io-tables: {e}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
