#!/usr/bin/python3
"""api/openapi.yaml -> api/openapi.json (what `prsm serve` serves as /v1/openapi.json).
Run after editing the YAML: /usr/bin/python3 api/make-json.py. Needs Debian's python3-yaml.
The contract suite fails when the two differ."""
import json
import os
import yaml

here = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(here, "openapi.yaml"), encoding="utf-8") as f:
    doc = yaml.safe_load(f)
with open(os.path.join(here, "openapi.json"), "w", encoding="utf-8") as f:
    json.dump(doc, f, indent=1, ensure_ascii=False)
    f.write("\n")
