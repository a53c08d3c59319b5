#!/usr/bin/python3
"""Run the shell blocks of README.md as printed, in a temporary directory that holds the build
(`build`) and the example documents (`studies`) as symbolic links.

Usage: readme_test.py SOURCE_DIR BUILD_DIR

The first block (make run, make test) is skipped: it is what runs this test. Every other block
must exit 0 and write nothing that looks like a failure on stderr."""
import os
import re
import subprocess
import sys
import tempfile

src, build = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
with open(os.path.join(src, 'README.md'), encoding='utf-8') as f:
    text = f.read()
blocks = re.findall(r'```sh\n(.*?)```', text, re.S)
failed = 0
with tempfile.TemporaryDirectory() as tmp:
    os.symlink(build, os.path.join(tmp, 'build'))
    os.symlink(os.path.join(src, 'studies'), os.path.join(tmp, 'studies'))
    for i, block in enumerate(blocks):
        if re.match(r'\s*make (run|test)', block):
            print(f'block {i + 1}: skipped (make run / make test)')
            continue
        r = subprocess.run(['bash', '-e', '-c', block], cwd=tmp, capture_output=True, text=True, timeout=300)
        bad = r.returncode != 0 or re.search(r'(?i)command not found|no such file|usage:', r.stderr)
        first = block.strip().splitlines()[0]
        print(f'block {i + 1} ({first[:60]}): {"FAIL" if bad else "ok"}')
        if bad:
            failed += 1
            print('--- stdout\n' + r.stdout[-1500:] + '--- stderr\n' + r.stderr[-1500:])
print(f'readme: {len(blocks)} blocks, {failed} failed')
sys.exit(1 if failed else 0)
