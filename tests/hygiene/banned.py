#!/usr/bin/python3
"""banned.py: no banned C library function is called in the project's C sources.

    /usr/bin/python3 tests/hygiene/banned.py [SOURCE_DIR]     # the check (a CTest test)
    /usr/bin/python3 tests/hygiene/banned.py --self-test      # the matcher on its own cases

Scans every .c and .h file under src/ and tests/ of SOURCE_DIR (default: this script's
project; hidden and node_modules directories are skipped). A call is the function's name as a whole identifier followed by '(' (spaces and line
breaks allowed), not after '.' or '->' (a struct member), once comments, string literals and
character literals are removed, so a comment or a message that names a function does not count.
Every hit is printed as file:line: name: what to use instead; the exit status is 1 when there is
one, else 0.

The list follows git's banned.h (strcpy strcat strncpy strncat sprintf vsprintf gmtime
localtime ctime ctime_r asctime asctime_r) and adds what curl's checksrc and the CERT C rules
refuse:
  - unbounded writes: sprintf, vsprintf, strcpy, strcat, gets. snprintf and "%s" copies are
    the project's way;
  - strncpy and strncat too (as git): strncpy leaves the copy unterminated when the source is
    as long as the buffer and pads the rest with zeros, strncat's bound is the room left, not the
    buffer's size; both are misused more often than not. snprintf(dst, size, "%s", src) says what
    is meant and always terminates;
  - no error reporting: atoi, atol, atoll, atof (undefined on overflow, 0 for garbage). strtol,
    strtoll, strtoul, strtod with an end pointer and errno, as the readers do;
  - hidden global state, not thread-safe (the service runs jobs on threads): rand, srand (and a
    poor generator: the engine's streams are util/rng.h), strtok (strtok_r), gmtime, localtime,
    ctime, asctime (the _r forms with a caller's buffer; ctime_r and asctime_r are banned too, as
    in git: their buffer size is unchecked and the format is locale-blind; use strftime);
  - race-prone temporary names: tmpnam, tempnam, mktemp (mkstemp, tmpfile);
  - non-local jumps: setjmp, longjmp, sigsetjmp, siglongjmp. Nothing here needs them, and a jump
    skips the goto-cleanup that frees what a function owns (cmocka's own use is inside its
    headers, which are not scanned).
"""
import os
import re
import sys

BANNED = {
    'sprintf': 'snprintf',
    'vsprintf': 'vsnprintf',
    'strcpy': 'snprintf(dst, size, "%s", src)',
    'strcat': 'snprintf at the end of what is written',
    'strncpy': 'snprintf(dst, size, "%s", src) (strncpy may leave no terminator)',
    'strncat': 'snprintf at the end of what is written',
    'gets': 'fgets',
    'atoi': 'strtol with an end pointer and errno',
    'atol': 'strtol with an end pointer and errno',
    'atoll': 'strtoll with an end pointer and errno',
    'atof': 'strtod with an end pointer and errno',
    'rand': 'the counter-based streams of util/rng.h (or getrandom for ids)',
    'srand': 'the counter-based streams of util/rng.h',
    'strtok': 'strtok_r, or a scan with strchr/strcspn',
    'tmpnam': 'mkstemp or tmpfile',
    'tempnam': 'mkstemp or tmpfile',
    'mktemp': 'mkstemp',
    'gmtime': 'gmtime_r',
    'localtime': 'localtime_r',
    'ctime': 'strftime on localtime_r',
    'ctime_r': 'strftime on localtime_r',
    'asctime': 'strftime',
    'asctime_r': 'strftime',
    'setjmp': 'return codes and goto cleanup',
    'longjmp': 'return codes and goto cleanup',
    'sigsetjmp': 'return codes and goto cleanup',
    'siglongjmp': 'return codes and goto cleanup',
}

# Functions only one file may call: switching GSL's process-wide error handler races with every
# other thread, so prsm_global_init (src/io/global.c) does it once and everything else calls that.
RESTRICTED = {
    'gsl_set_error_handler_off': ('src/io/global.c', 'prsm_global_init() (io/global.h)'),
    'gsl_set_error_handler': ('src/io/global.c', 'prsm_global_init() (io/global.h)'),
}

SCANNED_DIRS = ('src', 'tests')
SUFFIXES = ('.c', '.h')

CALL = re.compile(r'(?<![\w.])(?<!->)(' + '|'.join(sorted(list(BANNED) + list(RESTRICTED), key=len, reverse=True)) + r')\s*\(')


def strip(text):
    """text with comments, string literals and character literals blanked out: every removed
    character but a newline becomes a space, so offsets and line numbers stay where they were."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == '/' and text.startswith('/*', i):
            end = text.find('*/', i + 2)
            end = n if end < 0 else end + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:end]))
            i = end
        elif c == '/' and text.startswith('//', i):
            # a line comment goes on past a backslash-newline
            j = i
            while j < n and text[j] != '\n':
                j += 2 if text[j] == '\\' and j + 1 < n else 1
            out.append(re.sub(r'[^\n]', ' ', text[i:j]))
            i = j
        elif c in '"\'':
            j = i + 1
            while j < n and text[j] != c and text[j] != '\n':
                j += 2 if text[j] == '\\' else 1
            j = min(j + 1, n)
            out.append(c + re.sub(r'[^\n]', ' ', text[i + 1:j - 1]) + (c if j - 1 > i else ''))
            i = j
        else:
            out.append(c)
            i += 1
    return ''.join(out)


def calls(text):
    """(line, name) of every banned call in C source text."""
    code = strip(text)
    for m in CALL.finditer(code):
        yield code.count('\n', 0, m.start()) + 1, m.group(1)


def scan(root):
    hits = []
    for top in SCANNED_DIRS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(root, top)):
            dirnames[:] = sorted(d for d in dirnames if not d.startswith('.') and d != 'node_modules')
            for name in sorted(filenames):
                if not name.endswith(SUFFIXES):
                    continue
                path = os.path.join(dirpath, name)
                with open(path, encoding='utf-8', errors='replace') as f:
                    text = f.read()
                rel = os.path.relpath(path, root)
                for line, fn in calls(text):
                    if fn in RESTRICTED and rel == RESTRICTED[fn][0]:
                        continue
                    hits.append((rel, line, fn))
    return hits


SELF_TEST = r'''
/* sprintf(buf, "x") in a comment, strcpy( too */
// atoi(s) in a line comment \
   rand() on its continuation
static const char *m = "use snprintf, not sprintf(buf, ...)";
static const char q = '"'; static const char *t = "atof(\"1\")";
int my_atoi(const char *s);           /* a name that ends in a banned one */
int x = p->rand(3) + s.srand(4);       /* members */
int y = strtol(s, &e, 10);            /* allowed */
void f(void) { sprintf(buf, "%d", 1); strncpy (a, b, 3);
  char *w = strtok
     (s, ",");
  int k = atoi(s); gmtime_r(&t, &tm); localtime(&t); }
'''
SELF_TEST_WANT = [(10, 'sprintf'), (10, 'strncpy'), (11, 'strtok'), (13, 'atoi'), (13, 'localtime')]


def self_test():
    got = list(calls(SELF_TEST))
    if got != SELF_TEST_WANT:
        print(f'banned.py self-test: got {got}, want {SELF_TEST_WANT}')
        return 1
    print('banned.py self-test: ok')
    return 0


def main(argv):
    if len(argv) > 1 and argv[1] == '--self-test':
        return self_test()
    root = argv[1] if len(argv) > 1 else os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    if self_test():
        return 1
    hits = scan(root)
    for path, line, fn in hits:
        if fn in RESTRICTED:
            print(f'{path}:{line}: {fn}() only in {RESTRICTED[fn][0]}: use {RESTRICTED[fn][1]}')
        else:
            print(f'{path}:{line}: {fn}() is banned: use {BANNED[fn]}')
    dirs = ' and '.join(f'{d}/' for d in SCANNED_DIRS)
    if hits:
        print(f'banned.py: {len(hits)} call(s) of banned or restricted functions in {dirs} (list and reasons: tests/hygiene/banned.py)')
        return 1
    print(f'banned.py: no banned function is called in {dirs}')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
