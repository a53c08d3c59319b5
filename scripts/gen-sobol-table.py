#!/usr/bin/python3
"""gen-sobol-table.py: the Sobol direction numbers of src/mc/sobol.c as a C source.

The numbers are Joe and Kuo's new-joe-kuo-6.21201 (S. Joe, F. Y. Kuo, "Constructing Sobol
sequences with better two-dimensional projections", SIAM J. Sci. Comput. 30 (2008) 2635-2654):
for each dimension d = 2..21201 the degree s of its primitive polynomial over GF(2), the
polynomial's interior coefficients a (bit s-2 is the coefficient of x^(s-1), bit 0 that of x)
and the initial direction numbers m_1..m_s (m_i odd, m_i < 2^i). Dimension 1 is the van der
Corput sequence (every m_i = 1), stored with s = 0.

Debian's python3-scipy ships the table as scipy/stats/_sobol_direction_numbers.npz (arrays
`poly`, the whole polynomial x^s + a_1 x^(s-1) + ... + 1 as bits, and `vinit`, the m_i padded
with zeros, one row per dimension). This script reads it, checks it (the SHA-256 of its
arrays, rows of the published file, the structure of every row) and writes the C arrays.
Because the check pins the table's content, the engine's build identity (cmake/EngineVersion.cmake
hashes scripts/gen-*.py) covers the generated numbers too.

Usage (cmake/SobolTable.cmake runs it at build time; the output lives in the build tree):
  gen-sobol-table.py --out FILE.c     write the table
  gen-sobol-table.py --print-source   print the path of the .npz (a build dependency)
"""
import argparse
import hashlib
import os
import sys

DIMS = 21201
MAX_DEGREE = 18
# SHA-256 of poly then vinit, each as little-endian int64 (scipy 1.10's npz; the table is the
# published one and does not change between scipy releases).
ARRAYS_SHA256 = "4fb13a6891dd539f095ea6306eb6d180f4e0b5dc9b4546c8b9c9ca36518ecfc0"
# Rows of new-joe-kuo-6.21201 as published: d, s, a, m_1..m_s.
PUBLISHED = [
    (2, 1, 0, [1]),
    (3, 2, 1, [1, 3]),
    (4, 3, 1, [1, 3, 1]),
    (5, 3, 2, [1, 1, 1]),
    (6, 4, 1, [1, 1, 3, 3]),
    (7, 4, 4, [1, 3, 5, 13]),
    (8, 5, 2, [1, 1, 5, 5, 17]),
    (9, 5, 4, [1, 1, 5, 5, 5]),
    (10, 5, 7, [1, 1, 7, 11, 19]),
    (11, 5, 11, [1, 1, 5, 1, 1]),
    (12, 5, 13, [1, 1, 1, 3, 11]),
    (13, 5, 14, [1, 3, 5, 5, 31]),
    (14, 6, 1, [1, 3, 3, 9, 7, 49]),
    (15, 6, 13, [1, 1, 1, 15, 21, 21]),
    (16, 6, 16, [1, 3, 1, 13, 27, 49]),
    (17, 6, 19, [1, 1, 1, 15, 7, 5]),
    (18, 6, 22, [1, 3, 1, 15, 13, 25]),
    (19, 6, 25, [1, 1, 5, 5, 19, 61]),
    (20, 7, 1, [1, 3, 7, 11, 23, 15, 103]),
    (21201, 18, 131059, [1, 1, 7, 11, 15, 7, 37, 239, 337, 245, 1557, 3681, 7357, 9639, 27367,
                         26869, 114603, 86317]),
]


def fail(msg):
    sys.stderr.write("gen-sobol-table.py: %s\n" % msg)
    sys.exit(1)


def npz_path():
    try:
        import scipy.stats
    except ImportError:
        fail("needs Debian's python3-scipy (scripts/install-deps.sh installs it)")
    p = os.path.join(os.path.dirname(scipy.stats.__file__), "_sobol_direction_numbers.npz")
    if not os.path.isfile(p):
        fail("%s is missing: this scipy does not ship the Joe-Kuo table" % p)
    return p


def read_rows(path):
    import numpy as np
    z = np.load(path)
    poly, vinit = z["poly"], z["vinit"]
    if poly.shape != (DIMS,) or vinit.ndim != 2 or vinit.shape[0] != DIMS:
        fail("%s: unexpected shapes poly %s, vinit %s" % (path, poly.shape, vinit.shape))
    digest = hashlib.sha256(poly.astype("<i8").tobytes() + vinit.astype("<i8").tobytes()).hexdigest()
    if digest != ARRAYS_SHA256:
        fail("%s: the arrays' SHA-256 is %s, not the checked table's %s" % (path, digest, ARRAYS_SHA256))
    rows = []  # (s, a, [m]) per dimension, 0-based
    for d in range(DIMS):
        p = int(poly[d])
        v = [int(x) for x in vinit[d]]
        if d == 0:
            if p != 1 or v[0] != 1:
                fail("dimension 1 is not van der Corput's")
            rows.append((0, 0, []))
            continue
        s = p.bit_length() - 1
        if not (1 <= s <= MAX_DEGREE) or not (p & 1):
            fail("dimension %d: polynomial %d is not of degree 1..%d with a constant term" % (d + 1, p, MAX_DEGREE))
        a = (p >> 1) & ((1 << (s - 1)) - 1)
        m = v[:s]
        if any(x != 0 for x in v[s:]):
            fail("dimension %d: direction numbers beyond the degree" % (d + 1))
        for i, x in enumerate(m, start=1):
            if x % 2 == 0 or not (0 < x < (1 << i)):
                fail("dimension %d: m_%d = %d is not odd and below 2^%d" % (d + 1, i, x, i))
        rows.append((s, a, m))
    for d, s, a, m in PUBLISHED:
        if rows[d - 1] != (s, a, m):
            fail("dimension %d: %s differs from the published row %s" % (d, rows[d - 1], (s, a, m)))
    return rows


def c_array(ctype, name, size, values, per_line=16):
    out = ["const %s %s[%s] = {" % (ctype, name, size)]
    for i in range(0, len(values), per_line):
        out.append("\t" + ", ".join(str(x) for x in values[i:i + per_line]) + ",")
    out.append("};")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--out", help="the C source to write")
    g.add_argument("--print-source", action="store_true", help="print the path of scipy's .npz")
    args = ap.parse_args()
    path = npz_path()
    if args.print_source:
        print(path)
        return
    rows = read_rows(path)
    degree = [r[0] for r in rows]
    coef = [r[1] for r in rows]
    m = [x for r in rows for x in r[2]]
    text = (
        "/* Generated by scripts/gen-sobol-table.py from %s: do not edit.\n"
        " * Joe-Kuo new-joe-kuo-6.21201 direction numbers (see src/mc/sobol.h). */\n"
        "#include \"mc/sobol.h\"\n\n" % os.path.basename(path)
        + c_array("unsigned char", "prsm_sobol_table_degree", "PRSM_SOBOL_MAX_DIM", degree, 32)
        + c_array("uint32_t", "prsm_sobol_table_a", "PRSM_SOBOL_MAX_DIM", coef)
        + c_array("uint32_t", "prsm_sobol_table_m", "", m)
        + "const size_t prsm_sobol_table_m_count = %d;\n" % len(m)
    )
    tmp = args.out + ".tmp"
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, args.out)


if __name__ == "__main__":
    main()
