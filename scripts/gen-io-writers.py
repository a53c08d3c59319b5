#!/usr/bin/python3
"""Generate the C writer tables of the result documents from the annotated JSON Schemas.

Usage: gen-io-writers.py --out-dir DIR --src SRC SCHEMA...   (Python standard library only)

The result schemas (schemas/analysis.schema.json and the *-result ones) carry "x-prsm" writer
annotations; prsm_io_write (src/io/write.h) writes a struct by the generated table, its members
in the schema's property order, so each result field is stated once, in its schema.

An object whose "x-prsm" names "write" is a table, prsm_io_w_<write>, of the C struct "struct"
declared in "header" (under src/; the project headers it includes are read too). Every property
of a written object then says how it is written (the build fails when one says nothing, or names
a member the struct lacks):

  "field": "a_mm"               the member; a path: "terms.bending", "quantile[2]", through one
                                pointer "a->geometry.lead_mm", "[]" a row (see "count"); "p[].m":
                                member m of element i of what the pointer p points to (an
                                array's item i, or a row)
  "scale": 1000 | "(180.0 / M_PI)"   numbers: written = member x scale (an expression is written
                                into the table as it is); "divide": 1000: then / divide; either
                                {"field": "m"}: the double member m of the table's struct, as it is
                                when written (a factor the run decides); array items too
  the member's C type decides: double, int, long, size_t, uint64_t and int-sized enums are numbers, an
  int is a boolean for "type": "boolean" ("mask": "C_FLAG": true when that bit is set), a char
  array or a const char * a string
  "values": ["C_CONST", ...]    a string enum: the C constants of the schema's enum names, in
                                order (taken from the referenced reader schema when it gives them);
                                a null among them, or "other": "name", names any other value; a
                                null in the schema's enum is left to "when" and "else"
  a "const" string is written as it is (no annotation needed); "text": "C_MACRO" writes a C
                                string constant; "value": false writes that boolean
  "hook": "name"                written by hand: prsm_io_whook_<name>(w, obj, key, at), at the
                                member "field" names (through it when it is a pointer) or the
                                table's struct; for derived values and shapes no table says
  "skip": true                  not written by the table (a document field the result does not
                                echo, or a member the composing code adds)
  "when": "member"              written only when the int member is nonzero (a double: not NaN,
                                a char array: not empty); "!member": when it is zero; {"field": m, "is": "C"} / {"field": m,
                                "not": "C"}: when the int is (is not) that constant; {"row": 1}:
                                from row 1 on. "else": null writes null instead of leaving it out
  objects: without "field" a section of the same struct; with it the member (a struct, or a
                                pointer to one) is written by the object's table, its own
                                properties, or the table of the $defs entry it refers to
  arrays: "count": 3 | "member" the item count (a fixed number, or an int or size_t member; a C
                                array's length when left out);
                                "field" names the items (a C array or a pointer to them: numbers,
                                booleans (ints, "mask" as above), strings, or structs written by
                                the items' table; or "p[].m", the member of each); without "field"
                                the items are rows: their properties' fields are paths with "[]",
                                item i taking element i; "tuple": [{"field": ...}, ...] writes
                                those members as the array; items of a string enum with "field"
                                and "values" are the names of the bits set in an int, or, when
                                "field" is a C array or a pointer, the names of its ints' values;
                                "every": K (a number or a member) on a row's "p[].m" numbers or
                                booleans: item i is element row + i x K (rows that interleave);
                                "is": "C_CONST": boolean items true when the int is that constant;
                                "columns": C on an array of arrays of numbers: "count" rows of C
                                numbers from a row-major C array or pointer; "grid": {"from": m,
                                "to": m} (and "count", no "field"): numbers evenly spaced between
                                two double members, from + (to - from) * i / (count - 1);
                                "slice": true: a row's "count" numbers of a row-major C array or
                                pointer, element row x count + i (a matrix written row by row)
  "index": N                    an integer: the row's number + N (an item's position in a rows
                                table: a stage's number, an eigenvalue's index)

A written object's "view": {"a": "const prsm_analysis *", "F": "double"} has the generator
declare its struct, prsm_io_<write>_view, in the generated header: the hand code fills it with
the parts of the document and the values derived from them, and the paths go through it.

References ($ref) may cross files: a referenced node of a schema that is not a result schema gives
the types (and an enum's "values"), never the writer annotations; the referring node lists its
properties (with their annotations, in the written order) next to the $ref.

Output: DIR/prsm_io_writers.h and DIR/prsm_io_writers.c.
"""
import argparse
import importlib.util
import json
import os
import re
import sys

_spec = importlib.util.spec_from_file_location('gen_io_tables', os.path.join(os.path.dirname(
    os.path.abspath(__file__)), 'gen-io-tables.py'))
_tables = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_tables)
c_string, c_double = _tables.c_string, _tables.c_double


class GenError(Exception):
    pass


# ---- the C structs ---------------------------------------------------------------------------

class Member:
    def __init__(self, ctype, ptr, dims):
        self.ctype, self.ptr, self.dims = ctype, ptr, dims


STRUCT_RE = re.compile(r'typedef\s+struct\s*\w*\s*\{(.*?)\}\s*(\w+)\s*;', re.S)
QUALIFIERS = {'const', 'volatile', 'struct', 'enum'}


def parse_structs(text):
    """{struct: {member: Member}} of the typedef'd structs of a C header, pointers and array
    dimensions kept; a struct whose members cannot be read is left out."""
    text = re.sub(r'/\*.*?\*/', ' ', text, flags=re.S)
    text = re.sub(r'//[^\n]*', ' ', text)
    out = {}
    for body, name in STRUCT_RE.findall(text):
        members = {}
        for decl in body.split(';'):
            decl = ' '.join(decl.split())
            if not decl:
                continue
            fp = re.search(r'\(\s*\*\s*(\w+)\s*\)', decl)
            if fp:
                members[fp.group(1)] = Member('function pointer', 1, [])
                continue
            parts = decl.split(',')
            m = re.match(r'^(.*[\s*])(\w+)\s*((?:\[[^\]]*\])*)$', parts[0])
            if not m:
                members = None
                break
            words = m.group(1).replace('*', ' * ').split()
            base = ' '.join(x for x in words if x not in QUALIFIERS and x != '*')
            decls = [(m.group(1).count('*'), m.group(2), m.group(3))]
            for p in parts[1:]:
                d = re.match(r'^\s*((?:\*\s*(?:const\s*)?)*)(\w+)\s*((?:\[[^\]]*\])*)\s*$', p)
                if not d:
                    members = None
                    break
                decls.append((d.group(1).count('*'), d.group(2), d.group(3)))
            if members is None:
                break
            for ptr, mname, dims in decls:
                members[mname] = Member(base, ptr, re.findall(r'\[([^\]]*)\]', dims))
        if members is not None:
            out[name] = members
    return out


NUMERIC = {'double': 'PRSM_IO_W_DOUBLE', 'int': 'PRSM_IO_W_INT', 'size_t': 'PRSM_IO_W_SIZE', 'long': 'PRSM_IO_W_LONG',
           'uint64_t': 'PRSM_IO_W_U64', 'unsigned long long': 'PRSM_IO_W_U64', 'unsigned long': 'PRSM_IO_W_ULONG'}


class Ref:
    """Where a member is (prsm_io_wref) and what it is."""

    def __init__(self):
        self.offset, self.offset2, self.stride = None, None, None
        self.after = None  # "p[].member": the member's offset in what p points to
        self.deref = self.pointer = False
        self.ctype, self.ptr, self.dims, self.row = None, 0, [], False
        self.desig, self.struct = '', None

    def c(self):
        parts = [f'.offset = {self.offset}']
        if self.deref:
            parts += ['.deref = 1', f'.offset2 = {self.offset2}']
        if self.pointer:
            parts.append('.pointer = 1')
        if self.stride:
            parts.append(f'.stride = {self.stride}')
        if self.after:
            parts.append(f'.after = {self.after}')
        return '{' + ', '.join(parts) + '}'

    def through(self):
        """Through the pointer the member is (an object's or a hook's)."""
        if self.ptr == 1 and not self.dims and not self.pointer:
            self.pointer, self.ptr = True, 0
        return self

    def items(self, where):
        """The member as the items of an array: a C array or a pointer to them."""
        if self.dims:
            self.dims = self.dims[1:]
            self.stride = f'sizeof((({self.struct} *)0)->{self.desig}[0])'
        elif self.ptr == 1 and not self.pointer:
            self.pointer, self.ptr = True, 0
            self.stride = f'sizeof(*(({self.struct} *)0)->{self.desig})'
        else:
            raise GenError(f'{where}: the items\' member is no C array or pointer')
        return self


# ---- the schemas -----------------------------------------------------------------------------

class Gen:
    def __init__(self, paths, src_root):
        self.dir = os.path.dirname(os.path.abspath(paths[0])) if paths else '.'
        self.files = {}
        for p in paths:
            self.load(os.path.basename(p), p)
        self.writers = {f for f, s in self.files.items() if self.has_write(s)}
        self.structs, self.enums, self.headers = {}, set(), []
        for f in sorted(self.writers):
            for note in self.notes(self.files[f]):
                if 'header' in note and note['header'] not in self.headers:
                    self.headers.append(note['header'])
                    self.read_header(src_root, note['header'], set())
        self.tables, self.done, self.hooks, self.asserts = [], {}, set(), []
        self.enum_arrays, self.views = [], []
        for f in sorted(self.writers):
            for note in self.notes(self.files[f]):
                if 'view' in note:
                    self.view(note, f)

    def view(self, note, file):
        """A "view": the struct the hand code fills for the table (its parts, derived values),
        declared in the generated header: {"member": "C type", ...}."""
        name = f'prsm_io_{note["write"]}_view'
        if note.get('struct', name) != name:
            raise GenError(f'{file}: {note["write"]} names a "struct" and a "view"')
        note['struct'] = name
        def member(m, t):  # "double[N]": an array
            t, _, dims = t.partition('[')
            t = t.strip()
            return f'\t{t}{"" if t.endswith("*") else " "}{m}{"[" + dims if dims else ""};\n'
        decl = 'typedef struct {\n' + ''.join(member(m, t) for m, t in note['view'].items()) + f'}} {name};'
        members = parse_structs(decl).get(name)
        if members is None or len(members) != len(note['view']):
            raise GenError(f'{file}: cannot read the view of {note["write"]}')
        self.structs[name] = members
        self.views.append(decl)

    def load(self, name, path=None):
        if name not in self.files:
            with open(path or os.path.join(self.dir, name), encoding='utf-8') as f:
                self.files[name] = json.load(f)
        return self.files[name]

    def has_write(self, node):
        return any('write' in n for n in self.notes(node))

    def notes(self, node):
        if isinstance(node, dict):
            if isinstance(node.get('x-prsm'), dict):
                yield node['x-prsm']
            for v in node.values():
                yield from self.notes(v)
        elif isinstance(node, list):
            for v in node:
                yield from self.notes(v)

    def read_header(self, src_root, rel, seen):
        if rel in seen:
            return
        seen.add(rel)
        path = os.path.join(src_root, rel)
        if not os.path.exists(path):
            return
        with open(path, encoding='utf-8') as f:
            text = f.read()
        for k, v in parse_structs(text).items():
            self.structs.setdefault(k, v)
        self.enums |= set(re.findall(r'typedef\s+enum\s*\w*\s*\{[^}]*\}\s*(\w+)\s*;', text))
        for inc in re.findall(r'#include\s+"([^"]+)"', text):
            self.read_header(src_root, inc, seen)

    # -- layers: a node and what its $ref chain adds, each with its file

    def lookup(self, file, ref):
        doc, _, ptr = ref.partition('#')
        file = doc or file
        node = self.load(file)
        for part in [p for p in ptr.split('/') if p]:
            part = part.replace('~1', '/').replace('~0', '~')
            node = node[int(part)] if isinstance(node, list) else node[part]
        return file, node

    def expand(self, layers):
        out = []
        for file, node in layers:
            while isinstance(node, dict):
                out.append((file, node))
                if '$ref' not in node:
                    break
                file, node = self.lookup(file, node['$ref'])
        return out

    def note(self, layers):
        """The writer annotation: a result schema's, the nearest first; of another schema only an
        enum's C "values"."""
        note = {}
        for file, node in reversed(self.branches(layers)):
            x = node.get('x-prsm')
            if not isinstance(x, dict):
                continue
            if file in self.writers:
                note.update(x)
            elif 'values' in x:
                note['values'] = x['values']
        return note

    def first(self, layers, key):
        for _, node in layers:
            if key in node:
                return node[key]
        return None

    def branches(self, layers):
        """The layers with the object branches of a oneOf / anyOf (an object or null)."""
        out = list(layers)
        for file, node in layers:
            for b in node.get('oneOf', []) + node.get('anyOf', []):
                if isinstance(b, dict) and b.get('type') != 'null':
                    out += self.expand([(file, b)])
        return out

    def props(self, layers):
        props = {}
        for file, node in self.branches(layers):
            for k, v in node.get('properties', {}).items():
                props.setdefault(k, []).append((file, v))
        return {k: self.expand(v) for k, v in props.items()}

    def stype(self, layers):
        t = self.first(layers, 'type')
        if isinstance(t, list):
            t = [x for x in t if x != 'null']
            t = t[0] if len(t) == 1 else None
        if t is None and any('properties' in n or n.get('type') == 'object' for _, n in self.branches(layers)):
            t = 'object'
        return t

    # -- C members

    def ref(self, sname, path, where):
        r = Ref()
        toks = re.findall(r'(->|\.|^)(\w+)((?:\[[^\]]*\])*)', path)
        if ''.join(''.join(t) for t in toks) != path:
            raise GenError(f'{where}: cannot read the member path "{path}"')
        struct, outer, cur, last = sname, None, sname, None
        elem, after = None, ''  # after "p[]" (p a pointer): the element's struct and the path in it
        for sep, name, idx in toks:
            if sep == '->':
                if outer or elem or last is None or last.ptr != 1 or last.dims:
                    raise GenError(f'{where}: "{path}": "->" follows one pointer member, once')
                outer = (struct, r.desig)
                struct, r.desig = last.ctype, ''
            elif sep == '.' and (last is None or last.ptr or last.dims):
                raise GenError(f'{where}: "{path}": "." follows a struct member')
            if cur not in self.structs:
                raise GenError(f'{where}: "{path}": {cur} is no struct the headers declare')
            if name not in self.structs[cur]:
                raise GenError(f'{where}: struct {cur} has no member "{name}" (of "{path}")')
            m = self.structs[cur][name]
            last = Member(m.ctype, m.ptr, list(m.dims))
            if elem:
                after += ('.' if after else '') + name
            else:
                r.desig += ('.' if r.desig else '') + name
            for i in re.findall(r'\[([^\]]*)\]', idx):
                if i == '' and r.row:
                    raise GenError(f'{where}: "{path}": one "[]" at most')
                if last.dims:
                    last.dims.pop(0)
                    if elem:
                        after += f'[{i or 0}]'
                        continue
                    r.desig += f'[{i or 0}]'
                    if i == '':
                        r.row, r.stride = True, f'sizeof((({struct} *)0)->{r.desig})'
                elif last.ptr == 1 and i == '' and not elem:
                    r.row, r.pointer, last.ptr = True, True, 0
                    r.stride = f'sizeof(*(({struct} *)0)->{r.desig})'
                    if (sep, name, idx) != toks[-1]:  # "p[].member": element i's member
                        elem = last.ctype
                else:
                    raise GenError(f'{where}: "{path}": [{i}] indexes no array')
            cur = last.ctype
        if elem:
            r.after = f'offsetof({elem}, {after})'
        r.struct = struct
        if outer:
            r.deref = True
            r.offset, r.offset2 = f'offsetof({outer[0]}, {outer[1]})', f'offsetof({struct}, {r.desig})'
        else:
            r.offset = f'offsetof({struct}, {r.desig})'
        r.ctype, r.ptr, r.dims = last.ctype, last.ptr, last.dims
        return r

    def ctype_kind(self, ctype, where):
        if ctype in NUMERIC:
            return NUMERIC[ctype]
        if ctype in self.enums:
            self.asserts.append((f'sizeof({ctype}) == sizeof(int)', f'{ctype} is int-sized'))
            return 'PRSM_IO_W_INT'
        raise GenError(f'{where}: a member of type {ctype} is no number')

    def scalar(self, r, where):
        if r.ptr or r.dims:
            raise GenError(f'{where}: the member is an array or a pointer')
        return r

    # -- tables

    def cname(self, base, key):
        return base + '_' + re.sub(r'[^A-Za-z0-9]+', '_', key).strip('_')

    def table(self, layers, sname, cname, export=False):
        """Emit the table writing the object of layers from struct sname; returns its C name."""
        fields = []
        for key, play in self.props(layers).items():
            where = f'{layers[0][0]}: {cname}/{key}'
            f = self.field(key, play, sname, cname, where)
            if f is not None:
                fields.append(f)
        if not fields:
            raise GenError(f'{layers[0][0]}: {cname} writes nothing')
        used = {n for t, _, _ in self.tables for n in (t, t + '_fields')}
        base, n = cname, 1
        while cname in used or cname + '_fields' in used:  # a property "fields" of a table's X is X_fields
            if export:
                raise GenError(f'{layers[0][0]}: the table {cname} is named twice')
            cname, n = f'{base}_{n}', n + 1
        self.tables.append((cname, fields, export))
        return cname

    def named(self, layers, note, where):
        """The table of a "write" $defs entry (made once)."""
        name = note['write']
        if name not in self.done:
            sname = note.get('struct')
            if sname not in self.structs:
                raise GenError(f'{where}: "write": {name} names no struct the headers declare ({sname})')
            self.done[name] = (sname, None)
            layers = self.branches(layers)
            top = [(f, n) for f, n in layers if isinstance(n.get('x-prsm'), dict) and n['x-prsm'].get('write') == name]
            start = layers.index(top[0]) if top else 0
            self.done[name] = (sname, self.table(self.expand([layers[start]]), sname, f'prsm_io_w_{name}', True))
        return self.done[name]

    def when(self, f, note, sname, where):
        w = note['when']
        if isinstance(w, dict) and 'row' in w:
            f['when'], f['when_value'] = 'PRSM_IO_W_IF_ROW', str(int(w['row']))
        else:
            if isinstance(w, str):
                op = 'PRSM_IO_W_IF_NOT' if w.startswith('!') else 'PRSM_IO_W_IF'
                path = w.lstrip('!')
            elif isinstance(w, dict) and 'field' in w and ('is' in w) != ('not' in w):
                op = 'PRSM_IO_W_IF_IS' if 'is' in w else 'PRSM_IO_W_IF_ISNT'
                path, f['when_value'] = w['field'], str(w.get('is', w.get('not')))
            else:
                raise GenError(f'{where}: "when" is "member", "!member", {{"field", "is" | "not"}} or {{"row"}}')
            r = self.ref(sname, path, where)
            if r.ctype == 'char' and len(r.dims) == 1 and op != 'PRSM_IO_W_IF_IS' and op != 'PRSM_IO_W_IF_ISNT':
                f['when'], f['when_at'], f['when_type'] = op, r.c(), 'PRSM_IO_W_CHARS'  # a text: not empty
            else:
                r = self.scalar(r, where)
                f['when'], f['when_at'], f['when_type'] = op, r.c(), self.ctype_kind(r.ctype, where)
        if 'else' in note:
            if note['else'] is not None:
                raise GenError(f'{where}: "else" can only be null')
            f['else_null'] = '1'

    def count(self, f, note, sname, where, key='count', to='count'):
        """A count (note[key]: a number, or an int or size_t member) into f[to], or f[to_type]
        and f[to_at]."""
        c = note.get(key)
        if isinstance(c, int) and not isinstance(c, bool) and c >= 0:
            f[to] = str(c)
        elif isinstance(c, str):
            r = self.scalar(self.ref(sname, c, where), where)
            if r.ctype not in ('int', 'size_t'):
                raise GenError(f'{where}: the {key} {c} is an int or a size_t')
            f[to + '_type'], f[to + '_at'] = NUMERIC[r.ctype], r.c()
        elif key == 'count':
            raise GenError(f'{where}: an array needs "count" (a number or a member)')
        else:
            raise GenError(f'{where}: "{key}" is a number or an int or size_t member')

    def grid(self, f, note, sname, where):
        """"grid": {"from": m, "to": m}: "count" numbers evenly spaced between two doubles."""
        g = note['grid']
        if 'field' in note or not isinstance(g, dict) or set(g) != {'from', 'to'}:
            raise GenError(f'{where}: "grid" is {{"from": member, "to": member}}, without "field"')
        ends = [self.scalar(self.ref(sname, g[k], where), where) for k in ('from', 'to')]
        if any(r.ctype != 'double' for r in ends):
            raise GenError(f'{where}: a grid runs between two double members')
        self.count(f, note, sname, where)
        f.update({'shape': 'PRSM_IO_W_GRID', 'type': 'PRSM_IO_W_DOUBLE', 'at': ends[0].c(),
                  'step_type': 'PRSM_IO_W_DOUBLE', 'step_at': ends[1].c()})
        self.scale(f, note, sname, where)
        return f

    def enum(self, f, names, note, where):
        values = note.get('values')
        if values is None or len(values) != len(names) or not all(isinstance(n, str) for n in names):
            raise GenError(f'{where}: "values" must give one C constant per name of the string enum')
        other = [n for n, v in zip(names, values) if v is None]
        if len(other) > 1 or (other and 'other' in note):
            raise GenError(f'{where}: one name at most stands for the other values (a null in "values", or "other")')
        pairs = [(n, v) for n, v in zip(names, values) if v is not None]
        same = [b for b, n, v in self.enum_arrays if (n, v) == ([n for n, _ in pairs], [v for _, v in pairs])]
        base = same[0] if same else f'w_names_{len(self.enum_arrays)}'
        if not same:
            self.enum_arrays.append((base, [n for n, _ in pairs], [v for _, v in pairs]))
        f.update({'names': base + '_names', 'values': base + '_values', 'n_values': str(len(pairs))})
        if other or 'other' in note:
            f['text'] = c_string(note.get('other', other[0] if other else None))

    def field(self, key, layers, sname, cname, where, tuple_item=False):
        note = self.note(layers)
        if note.get('skip'):
            return None
        f = {'name': 'NULL' if tuple_item else c_string(key)}
        if 'when' in note or 'else' in note:
            self.when(f, note, sname, where)
        const = self.first(layers, 'const')
        stype = self.stype(layers)
        r = None
        if 'field' in note:
            r = self.ref(sname, note['field'], where)
            f['at'] = r.c()
        if 'hook' in note:
            f['kind'], f['hook'] = 'PRSM_IO_W_HOOK', f'prsm_io_whook_{note["hook"]}'
            self.hooks.add(note['hook'])
            if r is not None:
                f['at'] = r.through().c()
            return f
        if 'index' in note:  # the row's number (+ index): an item's position in a rows table
            if r is not None or stype != 'integer' or isinstance(note['index'], bool) or \
                    not isinstance(note['index'], int) or note['index'] < 0:
                raise GenError(f'{where}: "index": N (0 or more) writes the row\'s number + N as an integer, '
                               'without "field"')
            f['kind'], f['count'] = 'PRSM_IO_W_INDEX', str(note['index'])
            return f
        if r is None and (const is not None or 'text' in note or 'value' in note):
            value = note.get('value', const)
            if 'text' in note:
                f['kind'], f['text'] = 'PRSM_IO_W_TEXT', note['text']
            elif isinstance(value, str):
                f['kind'], f['text'] = 'PRSM_IO_W_TEXT', c_string(value)
            elif isinstance(value, bool):
                f['kind'], f['mask'] = 'PRSM_IO_W_BOOL', str(int(value))
            else:
                raise GenError(f'{where}: a constant is a string or a boolean')
            return f
        if stype == 'object':
            child = note.get('write')
            if r is not None:
                r.through()
                f['at'] = r.c()
                if r.ptr or r.dims or r.ctype not in self.structs:
                    raise GenError(f'{where}: {note["field"]} is no struct (or pointer to one)')
                csname = r.ctype
            else:
                csname = sname
            if child:
                tsname, tname = self.named(layers, note, where)
                if tsname != csname:
                    raise GenError(f'{where}: the table {child} writes a {tsname}, the member is a {csname}')
            else:
                tname = self.table(layers, csname, self.cname(cname, key))
            f['kind'], f['child'] = 'PRSM_IO_W_OBJECT', '&' + tname
            return f
        if stype == 'array':
            return self.array(f, key, layers, note, r, sname, cname, where)
        if r is None:
            raise GenError(f'{where} has no "x-prsm" annotation (which member, hook or constant writes it?)')
        names = self.first(layers, 'enum')
        if names is not None:  # null in an enum: written by "when" and "else"
            names = [n for n in names if n is not None]
            if not (all(isinstance(n, str) for n in names) or all(isinstance(n, (int, float)) for n in names)):
                raise GenError(f'{where}: an enum of strings or of numbers (and null)')
        if names is not None and r.ctype == 'char':
            stype = 'string'  # a name the struct holds as text
        if names is not None and all(isinstance(n, str) for n in names) and stype != 'string':
            self.scalar(r, where)
            if r.ctype != 'int' and r.ctype not in self.enums:
                raise GenError(f'{where}: a string enum is written from an int, not {r.ctype}')
            f['kind'] = 'PRSM_IO_W_ENUM'
            self.enum(f, names, note, where)
        elif stype == 'string':
            if r.ctype != 'char' or not ((len(r.dims) == 1 and not r.ptr) or (r.ptr == 1 and not r.dims)):
                raise GenError(f'{where}: a string is a char array or a const char *, not {r.ctype}')
            f['kind'], f['type'] = 'PRSM_IO_W_STRING', 'PRSM_IO_W_CSTR' if r.ptr else 'PRSM_IO_W_CHARS'
        elif stype == 'boolean':
            self.scalar(r, where)
            if r.ctype != 'int':
                raise GenError(f'{where}: a boolean is written from an int, not {r.ctype}')
            f['kind'], f['type'] = 'PRSM_IO_W_BOOL', 'PRSM_IO_W_INT'
            if 'mask' in note:
                f['mask'] = str(note['mask'])
        elif stype in ('number', 'integer') or names is not None:
            self.scalar(r, where)
            f['kind'], f['type'] = 'PRSM_IO_W_NUMBER', self.ctype_kind(r.ctype, where)
            if stype == 'integer' and f['type'] == 'PRSM_IO_W_DOUBLE':
                raise GenError(f'{where}: an integer is written from an integer member, not a double')
            self.scale(f, note, sname, where)
        else:
            raise GenError(f'{where}: cannot write a {stype} from a member (a hook can)')
        return f

    def scale(self, f, note, sname=None, where=''):
        for k in ('scale', 'divide'):
            if k in note:
                v = note[k]
                if isinstance(v, dict):  # {"field": m}: the double member m, read as it is written
                    r = self.scalar(self.ref(sname, v.get('field', ''), where), where)
                    if r.ctype != 'double' or r.row:
                        raise GenError(f'{where}: "{k}": {{"field"}} names a double member, not a row')
                    f[k + '_by'], f[k + '_at'] = '1', r.c()
                else:
                    f[k] = v if isinstance(v, str) else c_double(v)

    def array(self, f, key, layers, note, r, sname, cname, where):
        f['kind'] = 'PRSM_IO_W_ARRAY'
        items = self.expand([(f, n['items']) for f, n in layers if isinstance(n.get('items'), dict)])
        if 'tuple' in note:
            tname = self.cname(cname, key)
            fields = [self.field(key, [(layers[0][0], {'x-prsm': n, 'type': 'number'})] + items, sname, tname,
                                 where, True) for n in note['tuple']]
            self.tables.append((tname, fields, False))
            f.update({'shape': 'PRSM_IO_W_TUPLE', 'child': '&' + tname})
            f.pop('at', None)
            return f
        itype = self.stype(items)
        if 'grid' in note:
            if itype not in ('number', 'integer'):
                raise GenError(f'{where}: a grid\'s items are numbers')
            return self.grid(f, note, sname, where)
        if itype == 'array' or 'columns' in note:  # a matrix: rows of "columns" numbers
            inner = self.expand([(fl, n['items']) for fl, n in items if isinstance(n.get('items'), dict)])
            if itype != 'array' or 'columns' not in note or r is None or self.stype(inner) not in ('number', 'integer'):
                raise GenError(f'{where}: an array of arrays of numbers names the elements\' "field" (a C array '
                               'or a pointer) and its "columns"')
            self.count(f, note, sname, where)
            self.count(f, note, sname, where, 'columns', 'step')
            r.items(where)
            self.scalar(r, where)
            f.update({'at': r.c(), 'shape': 'PRSM_IO_W_MATRIX', 'type': self.ctype_kind(r.ctype, where)})
            self.scale(f, note, sname, where)
            return f
        inames = self.first(items, 'enum')
        if r is not None and inames is not None and 'values' in note and not (r.dims or r.ptr or r.after):
            f['kind'] = 'PRSM_IO_W_FLAGS'
            self.enum(f, inames, note, where)
            return f
        if 'count' in note or r is None or not r.dims:
            self.count(f, note, sname, where)
        else:  # the whole C array
            f['count'] = f'(int)(sizeof((({r.struct} *)0)->{r.desig}) / sizeof((({r.struct} *)0)->{r.desig}[0]))'
        if note.get('slice'):  # the row's "count" elements of a row-major C array
            if itype not in ('number', 'integer') or r is None or r.row or 'every' in note or 'count' not in note:
                raise GenError(f'{where}: "slice" takes a row\'s "count" numbers of a C array or pointer (no "[]")')
            r.items(where)
            f['at'], f['shape'] = r.c(), 'PRSM_IO_W_SLICE'
            self.scalar(r, where)
            f['type'] = self.ctype_kind(r.ctype, where)
            self.scale(f, note, sname, where)
            return f
        if 'every' in note:  # element row + i x every: one of the rows that interleave
            if itype not in ('number', 'integer', 'boolean') or r is None or not r.row:
                raise GenError(f'{where}: "every" steps through the elements of a row\'s numbers or '
                               'booleans ("p[].m")')
            self.count(f, note, sname, where, 'every', 'step')
        if 'is' in note and itype != 'boolean':
            raise GenError(f'{where}: "is" makes boolean items')
        if itype == 'object':
            inote = self.note(items)
            if r is None:  # rows: the items' fields are paths with "[]"
                f['shape'] = 'PRSM_IO_W_ROWS'
                f['child'] = '&' + self.table(items, sname, self.cname(cname, key))
                return f
            r.items(where)
            f['at'] = r.c()
            if r.ptr or r.dims or r.ctype not in self.structs:
                raise GenError(f'{where}: the items are no structs')
            f['shape'] = 'PRSM_IO_W_STRUCTS'
            if 'write' in inote:
                tsname, tname = self.named(items, inote, where)
                if tsname != r.ctype:
                    raise GenError(f'{where}: the table {inote["write"]} writes a {tsname}, the items are {r.ctype}')
            else:
                tname = self.table(items, r.ctype, self.cname(cname, key))
            f['child'] = '&' + tname
            return f
        if r is None:
            raise GenError(f'{where}: an array of {itype} names its items\' "field"')
        if not r.after:  # "p[].member": item i is element i's member
            r.items(where)
        f['at'] = r.c()
        if itype == 'boolean':
            self.scalar(r, where)
            if r.ctype != 'int':
                raise GenError(f'{where}: boolean items are written from ints, not {r.ctype}')
            if 'is' in note:  # true when the int is that constant
                if 'mask' in note:
                    raise GenError(f'{where}: boolean items take "mask" or "is", not both')
                f['type'], f['is_set'], f['is_value'] = 'PRSM_IO_W_INT', '1', str(note['is'])
            else:
                f['type'], f['mask'] = 'PRSM_IO_W_INT', str(note.get('mask', -1))
        elif inames is not None and 'values' in note:  # ints: the names of their values
            self.scalar(r, where)
            if r.ctype != 'int' and r.ctype not in self.enums:
                raise GenError(f'{where}: string enum items are written from ints, not {r.ctype}')
            f['type'] = 'PRSM_IO_W_INT'
            self.enum(f, inames, note, where)
        elif itype == 'string':
            if r.ctype != 'char' or not ((len(r.dims) == 1 and not r.ptr) or (r.ptr == 1 and not r.dims)):
                raise GenError(f'{where}: string items are char arrays or const char *')
            f['type'] = 'PRSM_IO_W_CSTR' if r.ptr else 'PRSM_IO_W_CHARS'
        else:
            self.scalar(r, where)
            f['type'] = self.ctype_kind(r.ctype, where)
            self.scale(f, note, sname, where)
        return f

    def run(self):
        def walk(file, node):
            if isinstance(node, dict):
                note = node.get('x-prsm')
                if isinstance(note, dict) and 'write' in note:
                    self.named(self.expand([(file, node)]), note, f'{file}: {note["write"]}')
                for k, v in node.items():
                    if k != 'x-prsm':
                        walk(file, v)
            elif isinstance(node, list):
                for v in node:
                    walk(file, v)
        for file in sorted(self.writers):
            walk(file, self.files[file])


def emit(g, out_dir):
    h = ['/* Generated by scripts/gen-io-writers.py from schemas/: do not edit. */',
         '#ifndef PRSM_IO_WRITERS_H', '#define PRSM_IO_WRITERS_H', '', '#include "io/write.h"']
    h += [f'#include "{i}"' for i in g.headers] + ['']
    c = ['/* Generated by scripts/gen-io-writers.py from schemas/: do not edit. */',
         '#include "prsm_io_writers.h"', '', '#include <math.h>', '#include <stddef.h>', '#include <stdint.h>', '']
    h += g.views + ([''] if g.views else [])
    for name in sorted(g.hooks):
        h.append(f'void prsm_io_whook_{name}(prsm_jw *w, cJSON *obj, const char *key, const void *at);')
    for cond, what in sorted(set(g.asserts)):
        c.append(f'_Static_assert({cond}, "{what}");')
    for base, names, values in g.enum_arrays:
        c.append(f'static const char *const {base}_names[] = {{' + ', '.join(c_string(n) for n in names) + '};')
        c.append(f'static const int {base}_values[] = {{' + ', '.join(values) + '};')
    # The fields hold no address: name, text, names, values, child and hook become indices into
    # the arrays emitted last (entry 0: none), so the tables need no relocation at start-up.
    pools = {k: ['NULL'] for k in ('strings', 'names', 'values', 'tables', 'hooks')}
    index = {k: {} for k in pools}
    pool_of = {'name': 'strings', 'text': 'strings', 'names': 'names', 'values': 'values', 'child': 'tables',
               'hook': 'hooks'}

    def indexed(key, value):
        pool = pool_of[key]
        if value == 'NULL':
            return '0 /* NULL */'
        shown = value
        if value.startswith('&'):
            value = value[1:]
        if value not in index[pool]:
            index[pool][value] = len(pools[pool])
            pools[pool].append(value)
        # the index, and what it names (for the reader of the generated file and the tests)
        comment = shown.replace('*/', '*\\/').replace('/*', '/\\*')
        return f'{index[pool][value]} /* {comment} */'

    for cname, fields, export in g.tables:
        if not export:
            c.append(f'static const prsm_io_wtable {cname};')
    for cname, fields, export in g.tables:
        c.append(f'static const prsm_io_wfield {cname}_fields[] = {{')
        for f in fields:
            c.append('\t{' + ', '.join(f'.{k}_i = {indexed(k, v)}' if k in pool_of else f'.{k} = {v}'
                                       for k, v in f.items()) + '},')
        c.append('};')
        c.append(f'{"" if export else "static "}const prsm_io_wtable {cname} = {{{cname}_fields, '
                 f'sizeof {cname}_fields / sizeof {cname}_fields[0]}};')
        if export:
            h.append(f'extern const prsm_io_wtable {cname};')
    for pool, ctype in (('strings', 'const char *const'), ('names', 'const char *const *const'),
                        ('values', 'const int *const'), ('tables', 'const prsm_io_wtable *const'),
                        ('hooks', 'const prsm_io_whook')):
        if len(pools[pool]) > 65535:
            raise GenError(f'more than 65535 {pool} for the tables\' unsigned short indices')
        refs = [v if v == 'NULL' or pool != 'tables' else '&' + v for v in pools[pool]]
        c.append(f'{ctype} prsm_io_wgen_{pool}[] = {{' + ', '.join(refs) + '};')
    h += ['', '#endif', '']
    os.makedirs(out_dir, exist_ok=True)
    for name, lines in (('prsm_io_writers.h', h), ('prsm_io_writers.c', c)):
        with open(os.path.join(out_dir, name), 'w', encoding='utf-8') as f:
            f.write('\n'.join(lines) + '\n')


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--out-dir', required=True)
    ap.add_argument('--src', required=True, help='the source tree\'s src/ (headers named by "header")')
    ap.add_argument('schemas', nargs='+')
    a = ap.parse_args(argv[1:])
    try:
        g = Gen(a.schemas, a.src)
        g.run()
        emit(g, a.out_dir)
    except GenError as e:
        print(f'gen-io-writers: {e}', file=sys.stderr)
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
