#!/usr/bin/python3
"""The study documents tests/schema_test.py builds (section 9: the studies it runs, the invalid
ones, those beyond the schema, the valid ones, the known bugs), one a line as JSON text, for
tests/test_io_doc.c's side-by-side proof of the study reader (issue 24). Documents written as
raw text (NaN, 1e999, a duplicate key) are printed as that text.

Usage: study_documents.py SOURCE_DIR

The definitions are taken from schema_test.py itself (its module-level assignments and helper
functions by name, run without the rest of the script), so the list follows that file.
"""
import ast
import copy
import json
import math
import os
import sys

src = sys.argv[1]
with open(os.path.join(src, 'tests', 'schema_test.py'), encoding='utf-8') as f:
    tree = ast.parse(f.read())

# what section 9 builds its documents from, in the file's order
WANTED = {'DELETE', 'CASE_A', 'PI', 'ISHIGAMI', 'LS1_TOL', 'LS1', 'EARLY', 'EARLY_RUN', 'FAILING',
          'CONSTANT', 'ECHO', 'UNLOADED', 'SBASE', 'BBASE', 'sv', 'bv', 'shorthand_key', 'raw_with',
          'STUDY_INVALID', 'ALL_DESIGN', 'ALL_OUTPUTS', 'PER_ROLLER', 'STUDY_BEYOND', 'STUDY_VALID',
          'SHOULD_REFUSE', 'MANY'}
body = []
for node in tree.body:
    names = set()
    if isinstance(node, ast.Assign):
        names = {t.id for t in node.targets if isinstance(t, ast.Name)}
    elif isinstance(node, ast.FunctionDef):
        names = {node.name}
    if names & WANTED:
        body.append(node)


def load_json(path):
    with open(path, encoding='utf-8') as f:
        return json.load(f)


with open(os.path.join(src, 'schemas', 'study.schema.json'), encoding='utf-8') as f:
    schemas = {'study.schema.json': json.load(f)}
ns = {'copy': copy, 'json': json, 'math': math, 'os': os, 'SRC': src, 'load_json': load_json,
      'schemas': schemas}
exec(compile(ast.Module(body=body, type_ignores=[]), 'schema_test.py', 'exec'), ns)

docs = [ns[k] for k in ('ISHIGAMI', 'LS1', 'EARLY', 'EARLY_RUN', 'FAILING', 'CONSTANT', 'ECHO', 'UNLOADED',
                        'SBASE', 'BBASE', 'MANY')]
docs += [entry[1] for k in ('STUDY_INVALID', 'STUDY_BEYOND', 'STUDY_VALID', 'SHOULD_REFUSE') for entry in ns[k]]
for d in docs:
    print(d if isinstance(d, str) else json.dumps(d))
