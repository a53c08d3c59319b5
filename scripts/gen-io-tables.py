#!/usr/bin/python3
"""Generate the C field tables of the document readers from the annotated JSON Schemas.

Usage: gen-io-tables.py --out-dir DIR --src SRC SCHEMA...   (Python standard library only)

A schema whose root, or an object under its $defs, carries an "x-prsm" object with a "table"
name is a document (or part of one) the C code reads: prsm_io_t_<table>. The annotation names
the C struct it fills ("struct"), the header that declares it ("header", under src/; the
project headers it includes are read too) and the members the document does not set
("computed": filled by the model or by a hook). Every property then carries its own "x-prsm":

  "field": "pitch_mm"            the struct member (a path: "losses.spin", "screw_material")
  "scale": 1000 | "(M_PI / 180.0)"  stored = JSON value x scale (numbers; an expression is
                                 written into the C table as it is)
  "divide": 1000 | "(180.0 / M_PI)"  stored = JSON value / divide (for bit-identical unit changes;
                                 an expression is written into the C table as it is)
  "direction": "runout_phase_deg"  the number is a magnitude whose direction is that sibling: a
                                 negative value is refused with a problem that says so
  "limits": {"maximum": "PRSM_X_MAX"}   the C constant must equal the schema (static assert;
                                 the root's "includes" names the headers that define them;
                                 arrays: "maxItems")
  a table root's "init" names the function that sets the struct's defaults: the generated
  prsm_io_defaults_<table>() compares it with every "default" of the schema; {"generate":
  "name", "set": [{"field", "value"}]} has the generator write that function: every member
  zero, each schema default as the reader stores it, then the members "set" names (no default
  the reader can state: "NAN" for "not given", what a hook's default writes)
  "values": ["PRSM_HAND_RIGHT", ...]   C constants of an enum, in the schema's enum order (into
                                 an int or an int-sized typedef'd enum)
  "constants": {"prefix": "PRSM_IO_DYN_", "count": "PRSM_IO_DYN_ANALYSES", "name": "fn"}
                                 the C constants of a string enum are generated (prsm_io_enums.h):
                                 prefix + each name in capitals, numbered in the schema's order,
                                 "count" of them, and const char *fn(int) their names ("unknown"
                                 out of range); "values" may then be left out (else it must be those)
  integers fill an int, a long (within an int's range), or a size_t (from 0 up); a string with
  a "field" fills a char array
  (copied whole, cut on a character boundary when it does not fit)
  a bound of +-1.7976931348623157e+308 (the largest double: "any finite number") is no bound
  "set": {"field": "thinning_rule", "value": "PRSM_THINNING_GIVEN"}   when present and valid
  "conflict": {"with": "thinning", "message": "..."}   both present: a problem at this property
  "hook": {"name": "engagement", "writes": ["engaged_threads"]}   read by hand-written C,
                                 prsm_io_hook_<name>(base, obj, pointer, problems)
  "covered": "engaged_threads"   read by that property's hook (or a step); "writes": [...] the
                                 members it sets there
  "by": "distribution"           a field or section (its member, limits, enum) read only when the
                                 hand-written step named asks for it (prsm_io_get); "required": true
                                 makes it required then (what a oneOf branch requires)
  "skip": true                   checked (type, length) and not stored (names, descriptions)
  "missing": "..."               a required member's own problem when it is absent (instead of
                                 "is required (...)"; an array's "{min}", "{max}" are the schema's)
  "only": {"with": "kind", "is": "torque", "code": "input_kind", "message": "...", "required": "..."}
                                 the member belongs with that value of its sibling enum: present
                                 while the sibling holds another, a problem (code, message) at it;
                                 "required": its problem when absent while the sibling holds it
                                 (checked once the object is read, the required ones first; not
                                 when the sibling itself has a problem)
  "when": "!is_study"            a member of its object (a key, and read) only when that int of the
                                 document's struct is nonzero ("!": zero); otherwise the allowed
                                 keys are the others (one condition per object)
  on objects: "field" + "struct" (a member of another struct type: its own table), "init"
  ([{"field", "value"}]: a member of the holder set when the section is present, before it is
  read; or a string: the function that sets
  the section's defaults, run at its turn whether it is present or not, and checked against
  the schema's defaults by prsm_io_defaults_<table>_<key>()), "computed" (the section's members
  no property fills), "after" (a hook run on the section once its properties are read), "order"
  (properties read first, in this order, and their problems reported so; the rest follow in the
  schema's order). An entry of "order" may be a step, {"step": "name", "writes": [...]}: the
  hand-written prsm_io_step_<name>(at, problems) runs there (at: the object, its struct, the
  document's root struct, which fields were read); nonzero stops reading the object. The keys
  of an object are its properties and those its oneOf / anyOf branches add.
  arrays: "message" (the problem, at the array, when it is not an array of minItems to maxItems
  items or, required, missing; "{min}" and "{max}" are the schema's numbers), "code" (default
  "bad_array"), "field" + "count" (a C array member, of exactly maxItems, and the member counting
  the items; "compact": true stores the items a step kept without gaps; "count" alone: the number
  of items not stored, once the array's shape is valid), "each" (a step run on
  each item once read: objects by the items' table, whose x-prsm names their "struct" when
  there is no "field"; strings checked against maxLength), "after" (a step run once the array
  is read, present or not). Numbers (with their limits) fill a double array. A step's
  annotation may be {"name", "writes"}.
  a table root's "rules" (checked by prsm_io_check_rules once the object is read, where the
  caller places the pass; each in its turn): [{"members": [...], "with": "analysis", "is": [...],
  "code", "message"}, ...]: each member belongs with those values of the sibling enum "with"
  (absent: its default); present while the sibling holds another, a problem at it ("{member}" in
  the message is its name, "{value}" the sibling's value); "if" / "unless": a sibling that must
  be present / absent for the rule to hold; "keep": [...]: the rule is on each member of the
  (object) member but those; "value": "shape", "values": [...]: on that member's string value
  unless it is one of those
  maps (an object with "additionalProperties" and no properties): "key" (prsm_io_key_<name>
  picks the struct a member fills, or refuses its name) and "each"; the items' x-prsm names
  their "struct".

Limits come from the schema itself (minimum, maximum, exclusive*, maxLength, maxItems, required),
so the schema is the single source of truth and the C reader cannot disagree with it. The
generator fails, and with it the build, when a property has no annotation, when an annotation
names no member of the struct, or when a member of a struct a table fills (the document's, an
array's or a map's items) is neither read nor listed as computed.

A $defs string vocabulary whose x-prsm names "vocabulary" (a oneOf of "const" names, each with
its C constant in "values"; a "deprecated" one an older name) becomes plain C in prsm_vocab.h.

Output: DIR/prsm_io_tables.h, DIR/prsm_io_tables.c, DIR/prsm_io_enums.h and DIR/prsm_vocab.h.
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


def c_divide(v):
    """A divisor: a number, or a C expression written as it is ("(180.0 / M_PI)")."""
    return v if isinstance(v, str) else c_double(v)


def c_double(v):
    if v == float('inf'):
        return 'INFINITY'
    if v == float('-inf'):
        return '-INFINITY'
    return repr(float(v))


# ---- the C structs (members a document must cover) --------------------------------------------

STRUCT_RE = re.compile(r'typedef\s+struct\s*\w*\s*\{(.*?)\}\s*(\w+)\s*;', re.S)


def parse_structs(text, strict=True):
    """{struct name: [(type, member, is_array)]} of the typedef'd structs in a C header (strict
    False: a struct whose members cannot be read is left out)."""
    text = re.sub(r'/\*.*?\*/', ' ', text, flags=re.S)
    text = re.sub(r'//[^\n]*', ' ', text)
    out = {}
    for body, name in STRUCT_RE.findall(text):
        members = []
        try:
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
        except GenError:
            if strict:
                raise
            continue
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


DBL_MAX = 1.7976931348623157e+308


def bounds(prop):
    """(min, max, min exclusive, max exclusive) of a number or integer; for a number the largest
    double bounds nothing but finiteness (JSON cannot say infinity)."""
    lo, hi, lo_x, hi_x = float('-inf'), float('inf'), 0, 0
    if 'minimum' in prop:
        lo = prop['minimum']
    if 'exclusiveMinimum' in prop:
        lo, lo_x = prop['exclusiveMinimum'], 1
    if 'maximum' in prop:
        hi = prop['maximum']
    if 'exclusiveMaximum' in prop:
        hi, hi_x = prop['exclusiveMaximum'], 1
    if prop.get('type') == 'number':
        lo = float('-inf') if lo == -DBL_MAX and not lo_x else lo
        hi = float('inf') if hi == DBL_MAX and not hi_x else hi
    return lo, hi, lo_x, hi_x


def c_bounds(lo, hi, lo_x, hi_x):
    return {'min': c_double(lo), 'max': c_double(hi), 'min_exclusive': str(lo_x), 'max_exclusive': str(hi_x)}


class Scope:
    """A struct whose members a table (with its sections) must cover: the document's, or an
    array's or a map's items."""

    def __init__(self, sname, computed, what):
        self.sname, self.computed, self.what = sname, set(computed), what
        self.written = set()


# ---- schema walk -----------------------------------------------------------------------------

class Gen:
    def __init__(self, schema, path, src_root, node=None):
        self.schema = schema
        self.path = path
        self.node = schema if node is None else node
        self.root_note = self.node['x-prsm']
        self.doc = self.root_note['table']
        self.structs, self.enums = {}, set()
        self.read_header(src_root, self.root_note['header'], True, set())
        self.tables = []      # (c name, struct, [field initialisers], [keys])
        self.hooks = set()    # prsm_io_hook_<name>
        self.steps = set()    # prsm_io_step_<name>
        self.keys = set()     # prsm_io_key_<name>
        self.by = set()       # steps that fields name in "by"
        self.asserts = []
        self.limit_asserts = []  # a schema limit against its C constant: a floating comparison
        self.inits = []       # (scope name, struct, init function, [(member path, C value, pointer, kind)])
        self.wrappers = []    # (wrapper name, struct, init function)
        self.generated_init = None  # (function, struct, [(member path, C value)]): "init": {"generate"}
        self.section_init = {}  # member path -> the value its section's "init" sets
        self.rule_list = []   # the root's "rules": one dict per member each names

    def read_header(self, src_root, rel, strict, seen):
        """The structs and enums of header rel, and of the project headers it includes."""
        if rel in seen:
            return
        seen.add(rel)
        path = os.path.join(src_root, rel)
        if not os.path.exists(path):
            return
        with open(path, encoding='utf-8') as f:
            text = f.read()
        for k, v in parse_structs(text, strict).items():
            self.structs.setdefault(k, v)
        # typedef'd enums fill like an int (the generated file asserts they are int-sized)
        self.enums |= set(re.findall(r'typedef\s+enum\s*\w*\s*\{[^}]*\}\s*(\w+)\s*;', text))
        for inc in re.findall(r'#include\s+"([^"]+)"', text):
            self.read_header(src_root, inc, False, seen)

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

    def member_info(self, sname, path):
        """(C type, is an array) of a member path of struct sname (checks that it exists)."""
        ctype, is_array = sname, False
        for part in path.split('.'):
            found = [m for m in self.structs.get(ctype, []) if m[1] == part]
            if not found:
                raise GenError(f'{self.path}: struct {ctype} has no member "{part}" (of "{path}")')
            ctype, is_array = found[0][0], found[0][2]
        return ctype, is_array

    def member_type(self, sname, path):
        return self.member_info(sname, path)[0]

    def write(self, scope, sname, prefix, paths):
        for w in paths:
            self.member_type(sname, w)
            scope.written.add(prefix + w)

    def step(self, spec, scope, sname, prefix, kind='step'):
        """A step's annotation, "name" or {"name", "writes"}: its C function."""
        if isinstance(spec, str):
            spec = {'name': spec}
        self.write(scope, sname, prefix, spec.get('writes', []))
        (self.keys if kind == 'key' else self.steps).add(spec['name'])
        return f'prsm_io_{kind}_{spec["name"]}'

    def item_scope(self, items, sname, where):
        note = items.get('x-prsm', {})
        scope = Scope(sname, note.get('computed', []), where)
        for c in scope.computed:
            self.member_type(sname, c)
        return scope

    def check_scope(self, scope):
        def covered(m):
            return any(m == w or m.startswith(w + '.') for w in scope.written | scope.computed)
        missing = [m for m in leaf_members(self.structs, scope.sname) if not covered(m)]
        if missing:
            raise GenError(f'{self.path}: members of {scope.sname} that no property '
                           f'fills and "computed" does not list: {", ".join(missing)}')

    def table(self, node, ptr, sname, prefix, scope, init=None, iprefix=''):
        """Emit the table of object node (schema pointer ptr) read into struct sname; prefix is
        the member path of sname inside scope's struct (for the coverage check), init the
        section whose defaults function sets it (iprefix: the path inside that section)."""
        cname = 'prsm_io_t_' + re.sub(r'[^a-z0-9]+', '_', (self.doc + ptr).lower()).strip('_')
        required = set(node.get('required', []))
        fields = []
        props = node.get('properties', {})
        keys = list(props)  # the schema's order: the unknown-key message lists them so
        # the members the object's oneOf / anyOf branches add (each occurrence annotated)
        extra = []
        for branch in node.get('oneOf', []) + node.get('anyOf', []):
            for k, v in branch.get('properties', {}).items():
                if k not in props:
                    extra.append((k, v))
                    if k not in keys:
                        keys.append(k)
        order = node.get('x-prsm', {}).get('order')
        seq = [(k, v) for k, v in props.items()]
        if order is not None:
            names = [o for o in order if isinstance(o, str)]
            if len(set(names)) != len(names) or not set(names) <= set(props):
                raise GenError(f'{self.path}: {ptr or "/"} "order" must name properties, each once')
            # the listed ones (and steps) in that order, then the others in the schema's
            seq = [(o, props[o]) if isinstance(o, str) else (None, o) for o in order]
            seq += [(k, v) for k, v in props.items() if k not in names]
        when = {}  # the condition of the fields with "when" (one per table) -> their keys
        for key, raw in seq + extra:
            if key is None:  # a step
                fields.append({'name': 'NULL', 'required': '0', 'kind': 'PRSM_IO_STEP',
                               'step': self.step({'name': raw['step'], 'writes': raw.get('writes', [])},
                                                 scope, sname, prefix)})
                continue
            where = f'{self.path}: {ptr}/{key}'
            note = raw.get('x-prsm')
            init_ = {'name': c_string(key), 'required': '1' if key in required else '0'}
            if note is not None and 'constants' in note:
                self.constants(raw, note, cname, key, where)
            if note is not None and 'covered' in note and not note.keys() - {'covered', 'writes', 'missing', 'when'}:
                init_['kind'] = 'PRSM_IO_COVERED'  # (a reference need not be local then)
                self.write(scope, sname, prefix, note.get('writes', []))
                self.presence(init_, note, key, when, where)
                fields.append(init_)
                continue
            prop = self.resolve(raw)
            note = prop.get('x-prsm')
            if note is None and (prop.get('type') == 'object' or 'properties' in prop):
                note = {}  # a section of the same struct
            if note is None:
                raise GenError(f'{where} has no "x-prsm" annotation (which C member does it fill?)')
            self.presence(init_, note, key, when, where)
            if 'only' in note:
                self.only(init_, note['only'], props, sname, where)
            ptype = prop.get('type')
            if 'hook' in note:
                h = note['hook']
                init_['kind'] = 'PRSM_IO_HOOK'
                init_['hook'] = 'prsm_io_hook_' + h['name']
                self.hooks.add(h['name'])
                self.write(scope, sname, prefix, h.get('writes', []))
                fields.append(init_)
                continue
            if ptype == 'array':
                fields.append(self.array(init_, prop, note, ptr, key, sname, prefix, scope, where))
                continue
            if ptype == 'object' and 'properties' not in prop and isinstance(prop.get('additionalProperties'), dict):
                fields.append(self.map(init_, prop, note, ptr, key, sname, prefix, scope, where))
                continue
            if ptype == 'object' or 'properties' in prop:
                sec_init = note.get('init', [])
                if isinstance(sec_init, str):
                    sec_init = []
                for f0 in sec_init:
                    # a member the section sets when present: its schema default is that value
                    self.section_init[iprefix + f0['field']] = str(f0['value'])
                child_init, child_iprefix = init, iprefix
                if 'field' in note:
                    child_struct = note['struct']
                    if self.member_type(sname, note['field']) != child_struct:
                        raise GenError(f'{where}: member {note["field"]} is not a {child_struct}')
                    init_['offset'] = f'offsetof({sname}, {note["field"]})'
                    for c in note.get('computed', []):
                        self.member_type(child_struct, c)
                        scope.computed.add(prefix + note['field'] + '.' + c)
                    child_iprefix = iprefix + note['field'] + '.'
                    if isinstance(note.get('init'), str):
                        # the section's defaults function: run at its turn, its defaults checked
                        wrapper = f'prsm_io_init_{self.doc}_{key}'
                        self.wrappers.append((wrapper, child_struct, note['init']))
                        init_['init'] = wrapper
                        child_init, child_iprefix = (f'{self.doc}_{key}', child_struct, note['init'], []), ''
                        self.inits.append(child_init)
                    child = self.table(prop, f'{ptr}/{key}', child_struct, prefix + note['field'] + '.', scope,
                                       child_init, child_iprefix)
                else:
                    init_['offset'] = '0'
                    child = self.table(prop, f'{ptr}/{key}', sname, prefix, scope, init, iprefix)
                init_['kind'] = 'PRSM_IO_OBJECT'
                init_['child'] = '&' + child
                self.deferred(init_, note, where)
                if sec_init:
                    if len(sec_init) != 1:
                        raise GenError(f'{where}: one "init" member at most')
                    f0 = sec_init[0]
                    self.write(scope, sname, prefix, [f0['field']])
                    init_['has_set'] = '1'
                    init_['set_offset'] = f'offsetof({sname}, {f0["field"]})'
                    init_['set_value'] = str(f0['value'])
                if 'after' in note:
                    init_['hook'] = 'prsm_io_hook_' + note['after']['name']
                    self.hooks.add(note['after']['name'])
                    self.write(scope, sname, prefix, note['after'].get('writes', []))
                fields.append(init_)
                continue
            if note.get('skip'):
                init_['kind'] = 'PRSM_IO_STRING'
                init_['offset'] = '0'
                if 'maxLength' in prop:
                    init_['max_chars'] = str(prop['maxLength'])
                fields.append(init_)
                continue
            if 'covered' in note:
                init_['kind'] = 'PRSM_IO_COVERED'
                fields.append(init_)
                continue
            field = note.get('field')
            if field is None:
                raise GenError(f'{where}: "x-prsm" names no "field", "hook", "covered" or "skip"')
            ctype, is_array = self.member_info(sname, field)
            scope.written.add(prefix + field)
            init_['offset'] = f'offsetof({sname}, {field})'
            if 'enum' in prop:
                values = note.get('values')
                if values is None or len(values) != len(prop['enum']):
                    raise GenError(f'{where}: "values" must give one C constant per enum name')
                if not all(isinstance(e, str) for e in prop['enum']):
                    raise GenError(f'{where}: only string enums are tables (numbers need a hook)')
                base = f'{cname}_{key}'
                self.enum_arrays.append((base, prop['enum'], values))
                init_['kind'] = 'PRSM_IO_ENUM'
                init_['names'] = base + '_names'
                init_['values'] = base + '_values'
                if ctype != 'int' and ctype not in self.enums:
                    raise GenError(f'{where}: an enum fills an int or an enum type, not {ctype}')
                if ctype != 'int':
                    self.asserts.append((f'sizeof({ctype})', 'sizeof(int)', f'{ptr}/{key}: {ctype} is int-sized'))
            elif ptype == 'string':
                if ctype != 'char' or not is_array:
                    raise GenError(f'{where}: a string fills a char array, but {sname}.{field} is {ctype}')
                init_['kind'] = 'PRSM_IO_STRING'
                init_['capacity'] = f'sizeof((({sname} *)0)->{field})'
                if 'maxLength' in prop:
                    init_['max_chars'] = str(prop['maxLength'])
            else:
                if ptype not in KINDS:
                    raise GenError(f'{where}: type {ptype!r} needs a hook')
                init_['kind'] = KINDS[ptype]
                want = {'number': 'double', 'integer': 'int', 'boolean': 'int'}.get(ptype)
                if ptype == 'integer' and ctype in ('size_t', 'long'):
                    init_['kind'], want = f'PRSM_IO_{ctype.split("_")[0].upper()}', ctype
                if want and ctype != want:
                    raise GenError(f'{where}: {ptype} fills a {want}, but {sname}.{field} is {ctype}')
                lo, hi, lo_x, hi_x = bounds(prop)
                if ptype == 'integer' and (lo_x or hi_x or lo == float('-inf') or hi == float('inf')):
                    raise GenError(f'{where}: an integer needs inclusive minimum and maximum')
                if init_['kind'] == 'PRSM_IO_SIZE' and lo < 0:
                    raise GenError(f'{where}: a size_t member needs a minimum of 0 or more')
                init_.update(c_bounds(lo, hi, lo_x, hi_x))
                if 'scale' in note:
                    init_['scale'] = str(note['scale'])
                if 'divide' in note:
                    init_['divide'] = c_divide(note['divide'])
                if 'direction' in note:
                    self.direction(init_, note['direction'], props, where)
                self.limits(note, prop, ptr, key, where)
            if 'set' in note:
                self.write(scope, sname, prefix, [note['set']['field']])
                init_['has_set'] = '1'
                init_['set_offset'] = f'offsetof({sname}, {note["set"]["field"]})'
                init_['set_value'] = str(note['set']['value'])
            if 'conflict' in note:
                init_['conflict_with'] = c_string(note['conflict']['with'])
                init_['conflict_message'] = c_string(note['conflict']['message'])
            self.deferred(init_, note, where)
            if 'default' in prop and init is not None:
                self.default_check(prop, note, init_['kind'], iprefix + field, f'{ptr}/{key}', where, init)
            fields.append(init_)
        if len(fields) > 64:  # prsm_io_at.read has a bit per field
            raise GenError(f'{self.path}: {ptr or "/"} has more than 64 fields and steps: split it into sections')
        cond = None
        if when:
            if len(when) > 1:
                raise GenError(f'{self.path}: {ptr or "/"}: its fields\' "when" must name one condition')
            ((member, negated), governed), = when.items()
            cond = ([c_string(k) for k in keys if k not in governed],
                    f'offsetof({self.root_note["struct"]}, {member})', '1' if negated else '0')
        self.tables.append((cname, sname, fields, keys, cond))
        return cname

    def constants(self, prop, note, cname, key, where):
        """"constants": the C enum of a string enum's names, generated (emit_constants), so no
        header restates the schema's list; "values" defaults to those constants."""
        spec, names = note['constants'], prop.get('enum')
        if set(spec) - {'prefix', 'count', 'name'} or not {'prefix', 'count'} <= set(spec) or \
                not names or not all(isinstance(n, str) for n in names):
            raise GenError(f'{where}: "constants" is {{"prefix", "count", "name"}} on a string enum')
        consts = [spec['prefix'] + re.sub(r'[^A-Za-z0-9]+', '_', n).upper() for n in names]
        if note.setdefault('values', consts) != consts:
            raise GenError(f'{where}: "values" must be the constants "constants" makes ({", ".join(consts)})')
        self.constant_sets.append((where, f'{cname}_{key}', names, consts, spec))

    def presence(self, init_, note, key, when, where):
        """"missing": the problem when a required member is absent; "when": "[!]member", a
        member of the object (a key, and read) only when that int of the document's struct is
        nonzero (zero)."""
        if 'missing' in note:
            if init_['required'] == '0' and not note.get('required'):
                raise GenError(f'{where}: "missing" is the problem of a required member')
            init_['missing'] = c_string(note['missing'])
        if 'when' in note:
            member = note['when'].lstrip('!')
            if self.member_type(self.root_note['struct'], member) != 'int':
                raise GenError(f'{where}: "when" names {member}, not an int member of {self.root_note["struct"]}')
            when.setdefault((member, note['when'].startswith('!')), set()).add(key)
            init_['when'] = '1'

    def deferred(self, init_, note, where):
        """"by": read when that step asks; "required" then (what a oneOf branch requires)."""
        if 'by' in note:
            init_['deferred'] = '1'
            self.by.add((note['by'], where))
            if note.get('required'):
                init_['required'] = '1'

    def limits(self, note, prop, ptr, key, where):
        for bound, cname_c in note.get('limits', {}).items():
            v = prop.get(bound)
            if v is None:
                raise GenError(f'{where}: "limits" names {bound}, which the schema lacks')
            self.limit_asserts.append((cname_c, c_double(v), f'{ptr}/{key} {bound}'))

    def array(self, init_, prop, note, ptr, key, sname, prefix, scope, where):
        """An array: its items one by one, objects by their table, strings checked."""
        items = self.resolve(prop.get('items', {}))
        lo, hi = prop.get('minItems', 0), prop.get('maxItems')
        if 'message' not in note:
            raise GenError(f'{where}: an array needs "message" (the problem when it is not one)')
        msg = note['message'].replace('{min}', str(lo)).replace('{max}', str(hi))
        if 'missing' in note:
            init_['missing'] = c_string(note['missing'].replace('{min}', str(lo)).replace('{max}', str(hi)))
        init_.update({'kind': 'PRSM_IO_ARRAY', 'min_items': str(lo), 'max_items': 'INT_MAX' if hi is None else str(hi),
                      'code': c_string(note.get('code', 'bad_array')), 'message': c_string(msg)})
        self.limits(note, prop, ptr, key, where)
        item_struct = None
        if 'field' in note:
            field, count = note['field'], note.get('count')
            item_struct, is_array = self.member_info(sname, field)
            if not is_array or count is None or hi is None:
                raise GenError(f'{where}: "field" names a C array, with "count" and the schema\'s maxItems')
            ctype = self.member_type(sname, count)
            if ctype not in ('int', 'size_t'):
                raise GenError(f'{where}: the count {count} is an int or a size_t, not {ctype}')
            self.write(scope, sname, prefix, [field, count])
            init_.update({'offset': f'offsetof({sname}, {field})', 'stored': '1', 'item_size': f'sizeof({item_struct})',
                          'count_offset': f'offsetof({sname}, {count})', 'count_size': f'sizeof({ctype})'})
            if note.get('compact'):
                init_['compact'] = '1'
            self.asserts.append((f'sizeof((({sname} *)0)->{field}) / sizeof({item_struct})', str(hi),
                                 f'{ptr}/{key}: the C array holds maxItems'))
        elif 'count' in note:  # items not stored: their count once the array's shape is valid
            ctype = self.member_type(sname, note['count'])
            if ctype not in ('int', 'size_t'):
                raise GenError(f'{where}: the count {note["count"]} is an int or a size_t, not {ctype}')
            self.write(scope, sname, prefix, [note['count']])
            init_.update({'count_offset': f'offsetof({sname}, {note["count"]})', 'count_size': f'sizeof({ctype})'})
        if items.get('type') == 'object' or 'properties' in items:
            scratch = item_struct is None
            if scratch:  # read into a scratch struct, one item at a time
                item_struct = items.get('x-prsm', {}).get('struct')
                if item_struct is None or item_struct not in self.structs:
                    raise GenError(f'{where}: the items\' x-prsm names no "struct" (or the array no "field")')
                init_['item_size'] = f'sizeof({item_struct})'
                self.asserts.append((f'(sizeof({item_struct}) <= PRSM_IO_SCRATCH_MAX)', '1',
                                     f'{ptr}/{key}: a scratch item fits'))
            iscope = self.item_scope(items, item_struct, where)
            init_['child'] = '&' + self.table(items, f'{ptr}/{key}', item_struct, '', iscope)
            if 'each' in note:  # what it writes: in the item, or (scratch items) in the holder
                init_['step'] = (self.step(note['each'], scope, sname, prefix) if scratch
                                 else self.step(note['each'], iscope, item_struct, ''))
            self.check_scope(iscope)
        elif items.get('type') == 'string' and item_struct is None:
            init_['items'] = 'PRSM_IO_STRING'
            if 'maxLength' in items:
                init_['max_chars'] = str(items['maxLength'])
            if 'each' in note:
                init_['step'] = self.step(note['each'], scope, sname, prefix)
        elif items.get('type') == 'number' and item_struct == 'double' and 'each' not in note:
            init_['items'] = 'PRSM_IO_NUMBER'
            init_.update(c_bounds(*bounds(items)))
        else:
            raise GenError(f'{where}: arrays of objects, of strings a step takes, or of numbers into a double array')
        self.deferred(init_, note, where)
        if 'after' in note:
            init_['after'] = self.step(note['after'], scope, sname, prefix)
        return init_

    def map(self, init_, prop, note, ptr, key, sname, prefix, scope, where):
        """An object of named items: the key step picks each one's struct, its table reads it."""
        items = self.resolve(prop['additionalProperties'])
        item_struct = items.get('x-prsm', {}).get('struct')
        if 'key' not in note or item_struct not in self.structs:
            raise GenError(f'{where}: a map needs "key" and its items\' x-prsm a "struct"')
        init_['kind'] = 'PRSM_IO_MAP'
        init_['key'] = self.step(note['key'], scope, sname, prefix, 'key')
        iscope = self.item_scope(items, item_struct, where)
        init_['child'] = '&' + self.table(items, f'{ptr}/{key}', item_struct, '', iscope)
        if 'each' in note:
            init_['step'] = self.step(note['each'], iscope, item_struct, '')
        self.check_scope(iscope)
        return init_

    def direction(self, init_, sibling, props, where):
        """"direction": "runout_phase_deg": the number is a magnitude whose direction is that sibling
        number; a negative value is refused with a problem saying so (prsm_io_read)."""
        sib = self.resolve(props[sibling]) if isinstance(sibling, str) and sibling in props else None
        if sib is None or sib.get('type') != 'number':
            raise GenError(f'{where}: "direction" names {sibling}, which is no number of this object')
        init_['direction'] = c_string(sibling)

    def only(self, init_, only, props, sname, where):
        """"only": {"with": "kind", "is": "torque", "code", "message", "required"}: the member belongs
        with that value of its sibling enum "with": present while the sibling holds another, a
        problem (code, message); "required": its problem when absent while the sibling holds it."""
        if not isinstance(only, dict) or not {'with', 'is', 'code', 'message'} <= set(only) or \
                set(only) - {'with', 'is', 'code', 'message', 'required'}:
            raise GenError(f'{where}: "only" is {{"with", "is", "code", "message"}} (and "required")')
        sib = self.resolve(props[only['with']]) if only['with'] in props else None
        snote = (sib or {}).get('x-prsm') or {}
        if sib is None or 'enum' not in sib or 'values' not in snote or 'field' not in snote:
            raise GenError(f'{where}: "only" names {only["with"]}, which is no enum member of this object')
        if only['is'] not in sib['enum']:
            raise GenError(f'{where}: "only": {only["with"]} has no value {only["is"]!r}')
        init_.update({'only_key': c_string(only['with']), 'only_offset': f'offsetof({sname}, {snote["field"]})',
                      'only_value': snote['values'][sib['enum'].index(only['is'])],
                      'only_code': c_string(only['code']), 'only_message': c_string(only['message'])})
        if 'required' in only:
            init_['only_required'] = c_string(only['required'])

    def default_check(self, prop, note, kind, path, pointer, where, init):
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
        elif kind in ('PRSM_IO_INT', 'PRSM_IO_SIZE', 'PRSM_IO_LONG'):
            value = str(int(d))
        elif kind == 'PRSM_IO_NUMBER':
            v = c_double(d)
            if 'divide' in note:
                value = f'({v} / {c_divide(note["divide"])})'
            elif 'scale' in note:
                value = f'({v} * {note["scale"]})'
            else:
                value = v
        else:
            return
        init[3].append((path, value, pointer, kind))

    def run(self):
        self.enum_arrays = []
        self.constant_sets = []  # "constants": (schema pointer, names base, names, C constants, spec)
        st = self.root_note['struct']
        scope = Scope(st, self.root_note.get('computed', []), st)
        for c in scope.computed:
            self.member_type(st, c)
        init = None
        made = self.root_note.get('init')
        if isinstance(made, dict):  # {"generate": "name", "set": [...]}: made from the schema's defaults
            if set(made) - {'generate', 'set'} or not isinstance(made.get('generate'), str):
                raise GenError(f'{self.doc}: "init" is a function\'s name or {{"generate": "name", "set": [...]}}')
        if made is not None:
            init = (self.doc, st, made['generate'] if isinstance(made, dict) else made, [])
            self.inits.append(init)
        root = self.table(self.node, '', st, '', scope, init)
        self.rules(self.node)
        self.check_scope(scope)
        if isinstance(made, dict):
            self.generate_init(st, init, made.get('set', []))
        return root

    def rules(self, node):
        """The root's "rules" (prsm_io_check_rules): one prsm_io_rule per member of each, in order."""
        rules = node['x-prsm'].get('rules', [])
        props = node.get('properties', {})
        where = f'{self.path}: "rules"'
        keys = {'members', 'with', 'is', 'if', 'unless', 'keep', 'value', 'values', 'code', 'message'}
        for k, rule in enumerate(rules):
            w = f'{where}[{k}]'
            if not isinstance(rule, dict) or not {'members', 'with', 'is', 'code', 'message'} <= set(rule) or \
                    set(rule) - keys or ('keep' in rule and 'value' in rule) or ('value' in rule) != ('values' in rule):
                raise GenError(f'{w}: a rule is {{"members", "with", "is", "code", "message"}} (and "if", '
                               f'"unless", "keep" or "value" with "values")')
            sib = self.resolve(props[rule['with']]) if rule['with'] in props else {}
            names = sib.get('enum')
            if not names or not all(isinstance(e, str) for e in names) or sib.get('default') not in names:
                raise GenError(f'{w}: "with" names {rule["with"]}, which is no string enum with a default here')
            if not rule['is'] or set(rule['is']) - set(names):
                raise GenError(f'{w}: "is" lists values of {rule["with"]} ({", ".join(names)})')
            for c in ('if', 'unless'):
                if c in rule and rule[c] not in props:
                    raise GenError(f'{w}: "{c}" names {rule[c]}, which is no member here')
            for m in rule['members']:
                if m not in props:
                    raise GenError(f'{w}: "members" names {m}, which is no member here')
                sub = self.resolve(props[m]).get('properties', {})
                if 'keep' in rule and (not sub or set(rule['keep']) - set(sub)):
                    raise GenError(f'{w}: "keep" lists members of {m}')
                if 'value' in rule:
                    en = self.resolve(sub[rule['value']]).get('enum') if rule['value'] in sub else None
                    if not en or set(rule['values']) - set(en):
                        raise GenError(f'{w}: "values" lists values of {m}.{rule["value"]}')
                r = {'member': c_string(m), 'with': c_string(rule['with']),
                     'with_default': c_string(sib['default']), 'with_names': names, 'allowed': rule['is'],
                     'code': c_string(rule['code']), 'message': c_string(rule['message'].replace('{member}', m))}
                if 'if' in rule:
                    r['present'] = c_string(rule['if'])
                if 'unless' in rule:
                    r['absent'] = c_string(rule['unless'])
                if 'keep' in rule:
                    r['keep'] = rule['keep']
                if 'value' in rule:
                    r['sub'], r['sub_values'] = c_string(rule['value']), rule['values']
                self.rule_list.append(r)

    def generate_init(self, st, init, extra):
        """The struct's init function made from the schema: every member zero, then each
        "default" as the reader would store it, then the members "set" names (those without a
        default the reader can state: NAN for "not given", the writes of a hook)."""
        if self.section_init:
            raise GenError(f'{self.doc}: a generated "init" with sections that set members when present')
        body = [(path, value) for path, value, _, _ in init[3]]
        for e in extra:
            if not isinstance(e, dict) or set(e) != {'field', 'value'}:
                raise GenError(f'{self.doc}: "set" lists {{"field", "value"}}')
            self.member_type(st, e['field'])
            if e['field'] in dict(body):
                raise GenError(f'{self.doc}: "set" gives {e["field"]}, which has a schema default')
            body.append((e['field'], str(e['value'])))
        self.generated_init = (init[2], st, body)


class Pools:
    """The fields hold no address: their strings, enum arrays, child tables, hooks, inits, steps
    and keys are indices into arrays emitted after every table (entry 0: none), so the field
    tables need no relocation when the program starts (doc.h)."""
    POOL_OF = {'name': 'strings', 'conflict_with': 'strings', 'conflict_message': 'strings',
               'missing': 'strings', 'code': 'strings', 'message': 'strings', 'names': 'names',
               'values': 'values', 'child': 'tables', 'hook': 'hooks', 'init': 'inits', 'step': 'steps',
               'after': 'steps', 'key': 'keys', 'only_key': 'strings', 'only_code': 'strings',
               'only_message': 'strings', 'only_required': 'strings', 'direction': 'strings',
               'member': 'strings', 'sub': 'strings', 'with': 'strings', 'with_default': 'strings',
               'present': 'strings', 'absent': 'strings', 'with_names': 'names', 'allowed': 'names',
               'keep': 'names', 'sub_values': 'names'}
    TYPES = (('strings', 'const char *const prsm_io_gen_strings[]'),
             ('names', 'const char *const *const prsm_io_gen_names[]'),
             ('values', 'const int *const prsm_io_gen_values[]'),
             ('tables', 'const prsm_io_table *const prsm_io_gen_tables[]'),
             ('hooks', 'const prsm_io_hook prsm_io_gen_hooks[]'),
             ('inits', 'void (*const prsm_io_gen_inits[])(void *)'),
             ('steps', 'const prsm_io_step prsm_io_gen_steps[]'),
             ('keys', 'const prsm_io_key prsm_io_gen_keys[]'))

    def __init__(self):
        self.items = {k: ['NULL'] for k, _ in self.TYPES}
        self.index = {k: {} for k, _ in self.TYPES}

    def ref(self, key, value):
        pool = self.POOL_OF.get(key)
        if pool is None:
            return value
        if value == 'NULL':
            return '0 /* NULL */'
        if value not in self.index[pool]:
            if len(self.items[pool]) >= 65535:
                raise GenError(f'more than 65535 {pool} for the fields\' unsigned short indices')
            self.index[pool][value] = len(self.items[pool])
            self.items[pool].append(value)
        # the index, and what it names (for the reader of the generated file and the tests)
        comment = value.replace('*/', '*\\/').replace('/*', '/\\*')
        return f'{self.index[pool][value]} /* {comment} */'

    def arrays(self):
        return [f'{decl} = {{' + ', '.join(self.items[pool]) + '};' for pool, decl in self.TYPES]


def emit(gens, out_dir):
    pools = Pools()
    every_defaults = []
    limit_checks = []  # (C constant, schema value, message): exact, at run time
    h = ['/* Generated by scripts/gen-io-tables.py from schemas/: do not edit. */',
         '#ifndef PRSM_IO_TABLES_H', '#define PRSM_IO_TABLES_H', '', '#include "io/doc.h"', '']
    c = ['/* Generated by scripts/gen-io-tables.py from schemas/: do not edit. */',
         '#include "prsm_io_tables.h"', '', '#include <limits.h>', '#include <math.h>', '#include <stddef.h>',
         '#include <stdlib.h>', '#include <string.h>', '']
    includes = sorted({g.root_note['header'] for g in gens})
    h[5:5] = [f'#include "{i}"' for i in includes] + ['#include "prsm_vocab.h"']
    extra = sorted({i for g in gens for i in g.root_note.get('includes', [])})
    c[6:6] = [f'#include "{i}"' for i in extra]
    for g in gens:
        for name in sorted(g.hooks):
            h.append(f'void prsm_io_hook_{name}(void *base, const cJSON *obj, const char *obj_pointer, '
                     f'prsm_problems *problems);')
        for name in sorted(g.steps):
            h.append(f'int prsm_io_step_{name}(prsm_io_at *at, prsm_problems *problems);')
        for name in sorted(g.keys):
            h.append(f'void *prsm_io_key_{name}(const prsm_io_at *at, const char *key, prsm_problems *problems);')
        for cname_c, value, what in g.asserts:
            c.append(f'_Static_assert({cname_c} == {value}, "{cname_c} differs from the schema ({what})");')
        for cname_c, value, what in g.limit_asserts:
            # no floating comparison is an integer constant expression: GCC folds one as an
            # extension, clang refuses it, so the build checks it with GCC, and
            # prsm_io_defaults_all() (test_io_defaults) with any compiler
            message = f'"{cname_c} differs from the schema ({what})"'
            limit_checks.append((cname_c, value, message))
            c.append(f'#if defined(__GNUC__) && !defined(__clang__)\n'
                     f'_Static_assert({cname_c} == {value}, {message});\n#endif')
        for base, names, values in g.enum_arrays:  # the names, for the C code that writes them too
            h.append(f'extern const char *const {base}_names[]; /* {len(names)} and NULL */')
            c.append(f'const char *const {base}_names[] = {{' +
                     ', '.join(c_string(n) for n in names) + ', NULL};')
            c.append(f'static const int {base}_values[] = {{' + ', '.join(values) + '};')
        for wrapper, st, fn in g.wrappers:
            c.append(f'static void {wrapper}(void *p)\n{{\n\t{fn}(p);\n}}')
        for cname, sname, fields, keys, cond in g.tables:
            c.append(f'static const char *const {cname}_keys[] = {{' +
                     ', '.join(c_string(k) for k in keys) + ', NULL};')
            if cond:
                c.append(f'static const char *const {cname}_keys_else[] = {{' + ', '.join(cond[0] + ['NULL']) + '};')
            c.append(f'static const prsm_io_field {cname}_fields[] = {{')
            for f in fields:
                c.append('\t{' + ', '.join(f'.{k} = {pools.ref(k, v)}' for k, v in f.items()) + '},')
            c.append('};')
            export = cname == f'prsm_io_t_{g.doc}'
            tail = f', .keys_else = {cname}_keys_else, .when_offset = {cond[1]}, .when_not = {cond[2]}' if cond else ''
            c.append(f'{"" if export else "static "}const prsm_io_table {cname} = {{.struct_name = {c_string(sname)}, '
                     f'.fields = {cname}_fields, .n_fields = sizeof {cname}_fields / sizeof {cname}_fields[0], '
                     f'.keys = {cname}_keys{tail}}};')
            c.append('')
            if export:
                h.append(f'extern const prsm_io_table {cname};')
        if g.generated_init:
            fn, st, body = g.generated_init
            h.append(f'/* Sets the schema\'s defaults (generated: "init": {{"generate"}}). */')
            h.append(f'void {fn}({st} *s);')
            c.append(f'void {fn}({st} *s)')
            c.append('{')
            c.append('\tmemset(s, 0, sizeof *s);')
            c += [f'\ts->{path} = {value};' for path, value in body]
            c.append('}')
            c.append('')
        for name, st, fn, defaults in g.inits:
            every_defaults.append(name)
            h.append(f'/* The schema\'s defaults against what {fn}() sets: one problem each that differs; returns')
            h.append(' * their count, or -1 when out of memory. */')
            h.append(f'int prsm_io_defaults_{name}(prsm_problems *problems);')
            c.append(f'int prsm_io_defaults_{name}(prsm_problems *problems)')
            c.append('{')
            c.append(f'\t{st} *s = calloc(1, sizeof *s);')
            c.append('\tif (s == NULL)\n\t\treturn -1;')
            c.append(f'\t{fn}(s);')
            c.append('\tint bad = 0;')
            for path, value, pointer, kind in defaults:
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
        if g.rule_list:  # the root's "rules": prsm_io_r_<table> (their name lists first)
            lists = {}
            for r in g.rule_list:
                for k in ('with_names', 'allowed', 'keep', 'sub_values'):
                    if k in r:
                        key = tuple(r[k])
                        if key not in lists:
                            lists[key] = f'prsm_io_r_{g.doc}_names{len(lists)}'
                            c.append(f'static const char *const {lists[key]}[] = {{' +
                                     ', '.join(c_string(n) for n in key) + ', NULL};')
                        r[k] = lists[key]
            c.append(f'static const prsm_io_rule prsm_io_r_{g.doc}_rules[] = {{')
            for r in g.rule_list:
                c.append('\t{' + ', '.join(f'.{k} = {pools.ref(k, v)}' for k, v in r.items()) + '},')
            c.append('};')
            c.append(f'const prsm_io_rules prsm_io_r_{g.doc} = {{prsm_io_r_{g.doc}_rules, '
                     f'sizeof prsm_io_r_{g.doc}_rules / sizeof prsm_io_r_{g.doc}_rules[0]}};')
            c.append('')
            h.append(f'extern const prsm_io_rules prsm_io_r_{g.doc};')
        # the sections other code reads on their own (e.g. an operating point in a study)
        for cname, sname, fields, keys, cond in g.tables:
            for sec in g.root_note.get('export', []):
                if cname == f'prsm_io_t_{g.doc}_{sec}':
                    c.append(f'const prsm_io_table *const {cname}_table = &{cname};')
                    h.append(f'extern const prsm_io_table *const {cname}_table;')
    # every table's defaults check at once (direct calls: no table of addresses to relocate)
    h.append('/* Every prsm_io_defaults_<table>() above, in turn, then the floating limits the build cannot compare '
             'exactly: the problems of all, their count or -1. */')
    h.append('int prsm_io_defaults_all(prsm_problems *problems);')
    c.append('int prsm_io_defaults_all(prsm_problems *problems)')
    c.append('{')
    c.append('\tint bad = 0, r;')
    for name in every_defaults:
        c.append(f'\tif ((r = prsm_io_defaults_{name}(problems)) < 0)\n\t\treturn -1;')
        c.append('\tbad += r;')
    for cname_c, value, message in limit_checks:
        c.append(f'\tif (!((double)({cname_c}) == {value})) {{\n'
                 f'\t\tprsm_problems_add(problems, "", "limit", "%s", {message});\n\t\tbad++;\n\t}}')
    c.append('\treturn bad;')
    c.append('}')
    c.append('')
    e = emit_constants(gens, h, c)
    c += pools.arrays()
    h += ['', '#endif', '']
    os.makedirs(out_dir, exist_ok=True)
    for name, lines in (('prsm_io_tables.h', h), ('prsm_io_tables.c', c), ('prsm_io_enums.h', e)):
        write_if_changed(os.path.join(out_dir, name), '\n'.join(lines) + '\n')


def write_if_changed(path, text):
    """Write text to path unless it holds it already (so that make rebuilds nothing)."""
    old = None
    if os.path.exists(path):
        with open(path, encoding='utf-8') as f:
            old = f.read()
    if old != text:
        with open(path, 'w', encoding='utf-8') as f:
            f.write(text)


def emit_constants(gens, h, c):
    """The enums of "constants": prsm_io_enums.h (no includes, so that the header of a struct
    may include it) and their name functions in prsm_io_tables.c. Returns the header's lines."""
    e = ['/* Generated by scripts/gen-io-tables.py from schemas/: do not edit. */',
         '#ifndef PRSM_IO_ENUMS_H', '#define PRSM_IO_ENUMS_H', '']
    h.insert(h.index('#include "io/doc.h"') + 1, '#include "prsm_io_enums.h"')
    for g in gens:
        arrays = {base for base, _, _ in g.enum_arrays}
        for where, base, names, consts, spec in g.constant_sets:
            e.append(f'/* {where}, named by {base}_names */')
            e.append('enum {')
            e += [f'\t{k} = {i}, /* {c_string(n)} */' for i, (n, k) in enumerate(zip(names, consts))]
            e.append('};')
            e.append(f'#define {spec["count"]} {len(names)}')
            if base not in arrays:  # a covered enum: its names for the step that reads it
                h.append(f'extern const char *const {base}_names[]; /* {len(names)} and NULL */')
                c.append(f'const char *const {base}_names[] = {{' + ', '.join(c_string(n) for n in names) +
                         ', NULL};')
            if 'name' in spec:
                e.append(f'/* The schema\'s name of a {spec["prefix"]}* ("unknown" out of range). */')
                e.append(f'const char *{spec["name"]}(int v);')
                c.append(f'const char *{spec["name"]}(int v)\n{{\n\treturn v >= 0 && v < {spec["count"]} ? '
                         f'{base}_names[v] : "unknown";\n}}')
            e.append('')
    return e + ['#endif', '']


def vocabulary(schema, doc, key, node):
    """A $defs string vocabulary ("oneOf" of "const"s) whose x-prsm names "vocabulary" (a C
    prefix), "header", "count" and "values" (each name's C constant, in the schema's order): the
    lines of prsm_vocab.h that give code without JSON (src/mc) its names, by constant, and the
    names as one text for messages. A "deprecated" name is an older one the readers still take."""
    note, where = node['x-prsm'], f'{doc}: $defs/{key}'
    if set(note) != {'vocabulary', 'header', 'count', 'values'}:
        raise GenError(f'{where}: a vocabulary is {{"vocabulary", "header", "count", "values"}}')
    names = [(b.get('const'), b.get('deprecated', False)) for b in node.get('oneOf', [])]
    if not names or any(not isinstance(n, str) for n, _ in names) or len(note['values']) != len(names):
        raise GenError(f'{where}: a vocabulary is a oneOf of "const" names, one C constant each in "values"')
    current = [(n, v) for (n, old), v in zip(names, note['values']) if not old]
    older = [(n, v) for (n, old), v in zip(names, note['values']) if old]
    if len({v for _, v in current}) != len(current) or {v for _, v in older} - {v for _, v in current}:
        raise GenError(f'{where}: each C constant has one name (a "deprecated" one names a constant '
                       f'another name has)')
    p, count = note['vocabulary'], note['count']
    lines = [f'/* {doc} $defs/{key}: {count} names */', f'#include "{note["header"]}"',
             f'_Static_assert({count} == {len(current)}, "{count} differs from the names of {doc} $defs/{key}");',
             f'#define {p}_NAMES {{ \\']
    lines += [f'\t[{v}] = {c_string(n)}, \\' for n, v in current] + ['}']
    lines.append(f'#define {p}_NAMES_TEXT {c_string(", ".join(n for n, _ in current))}')
    if older:
        lines.append(f'#define {p}_OLDER_NAMES {{' + ', '.join(c_string(n) for n, _ in older) + ', NULL}')
        lines.append(f'#define {p}_OLDER_VALUES {{' + ', '.join(v for _, v in older) + '}')
    return lines + vocabulary_attributes(node, note, where) + ['']


def vocabulary_attributes(node, note, where):
    """What a vocabulary's names carry in their own x-prsm ({"needs_load": true, "low": 0}): one
    initialiser by constant per attribute, <prefix>_<ATTRIBUTE>: true is 1 (absent 0), a string a C
    string (absent NULL), a number a double (absent NAN: not given)."""
    attrs = {}
    for b, v in zip(node['oneOf'], note['values']):
        if b.get('deprecated') and 'x-prsm' in b:
            raise GenError(f'{where}: a "deprecated" name has the attributes of its constant\'s name')
        for a, x in b.get('x-prsm', {}).items():
            attrs.setdefault(a, {})[v] = x
    def kind(x):
        if x is True or isinstance(x, str):
            return type(x)
        return float if isinstance(x, (int, float)) and not isinstance(x, bool) else None

    lines = []
    for a, given in attrs.items():
        kinds = {kind(x) for x in given.values()}
        if len(kinds) != 1 or None in kinds:
            raise GenError(f'{where}: the attribute "{a}" is true, a string or a number on every name that has it')
        if kinds == {float}:  # every current name, NAN where not given
            items = [(v, c_double(given[v]) if v in given else 'NAN')
                     for v, b in zip(note['values'], node['oneOf']) if not b.get('deprecated')]
        else:
            items = [(v, '1' if x is True else c_string(x)) for v, x in given.items()]
        lines.append(f'#define {note["vocabulary"]}_{a.upper()} {{ \\')
        lines += [f'\t[{v}] = {x}, \\' for v, x in items] + ['}']
    return lines


def emit_vocabularies(parts, out_dir):
    """prsm_vocab.h: every vocabulary (plain C: src/mc includes it, and prsm_io_tables.h)."""
    lines = ['/* Generated by scripts/gen-io-tables.py from schemas/: do not edit. */',
             '#ifndef PRSM_VOCAB_H', '#define PRSM_VOCAB_H', '', '#include <math.h>', ''] + parts + ['#endif', '']
    write_if_changed(os.path.join(out_dir, 'prsm_vocab.h'), '\n'.join(lines))


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--out-dir', required=True)
    ap.add_argument('--src', required=True, help='the source tree\'s src/ (headers named by "header")')
    ap.add_argument('schemas', nargs='+')
    a = ap.parse_args(argv[1:])
    gens, vocabs = [], []
    try:
        for path in a.schemas:
            with open(path, encoding='utf-8') as f:
                schema = json.load(f)
            for key, d in schema.get('$defs', {}).items():
                if 'vocabulary' in d.get('x-prsm', {}):
                    vocabs += vocabulary(schema, os.path.basename(path), key, d)
            # a document's root, or a part of it under $defs, that names its table
            nodes = [None] if 'table' in schema.get('x-prsm', {}) else []
            nodes += [d for d in schema.get('$defs', {}).values() if 'table' in d.get('x-prsm', {})]
            for node in nodes:
                g = Gen(schema, os.path.basename(path), a.src, node)
                g.run()
                gens.append(g)
        steps = {s for g in gens for s in g.steps | g.hooks}
        for g in gens:
            for name, where in g.by:
                if name not in steps:
                    raise GenError(f'{where}: "by" names {name}, which is no step or hook')
        emit(gens, a.out_dir)
        emit_vocabularies(vocabs, a.out_dir)
    except GenError as e:
        print(f'gen-io-tables: {e}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
