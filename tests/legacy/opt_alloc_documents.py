#!/usr/bin/python3
"""The optimisation and allocation documents tests/schema_test.py builds (its optimisation and
allocation sections: the invalid documents both the schema and the C reader refuse, and the
batch section's), one a line as JSON text, for tests/test_io_doc.c's side-by-side proof of the
two readers (issue 24). The examples they start from (studies/optimize-*.json,
studies/allocate-*.json) come first.

Usage: opt_alloc_documents.py SOURCE_DIR optimization|allocation

The lists of mistakes are taken from schema_test.py itself (every `for bad_name, ... in [...]`
list of the two sections, and mutated_copy by name), so the documents follow that file.
"""
import ast
import copy
import glob
import json
import os
import sys

src, kind = sys.argv[1], sys.argv[2]
with open(os.path.join(src, 'tests', 'schema_test.py'), encoding='utf-8') as f:
    tree = ast.parse(f.read())
DELETE = object()
ns = {'copy': copy, 'DELETE': DELETE}
for node in tree.body:
    if isinstance(node, ast.FunctionDef) and node.name == 'mutated_copy':
        exec(compile(ast.Module(body=[node], type_ignores=[]), 'schema_test.py', 'exec'), ns)


def load(path):
    with open(path, encoding='utf-8') as f:
        return json.load(f)


def mistakes(section):
    """The lists of (bad_name, ...) the loops of a section run over, in the file's order: the
    optimisation's use `prsm("optimize"`, the allocation's mutated_copy."""
    out = []
    for node in ast.walk(tree):
        if not (isinstance(node, ast.For) and isinstance(node.target, ast.Tuple) and
                isinstance(node.iter, ast.List) and node.target.elts and
                getattr(node.target.elts[0], 'id', '') == 'bad_name'):
            continue
        text = ast.unparse(node)
        if section == 'optimization' and '"optimize"' not in text and "'optimize'" not in text:
            continue
        if section == 'allocation' and 'mutated_copy' not in text:
            continue
        out.append(eval(compile(ast.Expression(node.iter), 'schema_test.py', 'eval'), ns))
    return out


studies = sorted(glob.glob(os.path.join(src, 'studies', '*.json')))
docs = []
if kind == 'optimization':
    examples = [load(p) for p in studies if os.path.basename(p).startswith('optimize-')]
    docs += examples
    lists = mistakes('optimization')
    plain = [d for d in examples if 'multi_objective' not in d and 'robust' not in d][0]
    for entries in lists:
        robust = len(entries[0]) == 4  # (name, mutate, pointer, by_schema): on each robust example
        for base in ([d for d in examples if 'robust' in d] if robust else [plain]):
            for entry in entries:
                bad = copy.deepcopy(base)
                entry[1](bad)
                docs.append(bad)
    batch = copy.deepcopy(plain)
    batch['solver']['max_evaluations'] = 300
    docs.append(batch)
else:
    examples = [load(p) for p in studies if os.path.basename(p).startswith('allocate-')]
    docs += examples
    base = load(os.path.join(src, 'studies', 'allocate-ls1.json'))
    for entries in mistakes('allocation'):
        for entry in entries:
            docs.append(ns['mutated_copy'](base, entry[1], entry[2]))
    docs.append({'allocate': 1})  # the batch section's invalid allocation
for d in docs:
    print(json.dumps(d))
