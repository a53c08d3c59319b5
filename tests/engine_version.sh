#!/usr/bin/env bash
# engine_version.sh: the engine build identity (cmake/EngineVersion.cmake) follows the sources
# that determine results, so a cache written by an older engine is never served.
#   - the binary's build (prsm --version) is the hash of the source tree it was built from;
#   - a change to a model, engine, optimiser, dynamics, reader/writer, application, utility or schema
#     source, or a new source file there, changes it; a change to a front end does not.
# Usage: engine_version.sh PRSM SOURCE_DIR "COMPILER_ID VERSION"
set -euo pipefail
prsm=$1
src=$2
compiler=$3
script="$src/cmake/EngineVersion.cmake"
pass=0
fail=0
check() { # check NAME CONDITION...
	local name=$1
	shift
	if "$@"; then pass=$((pass + 1)); else fail=$((fail + 1)); echo "FAIL: $name"; fi
}
hash_of() { cmake -DSOURCE_DIR="$1" "-DCOMPILER=$compiler" -P "$script" 2>&1; }

binary_build=$("$prsm" --version | sed -n 's/.*"build": "\([0-9a-f]*\)".*/\1/p')
tree_build=$(hash_of "$src")
check "prsm --version names a 16-digit build ($binary_build)" test "${#binary_build}" -eq 16
check "the binary's build is its source tree's ($binary_build vs $tree_build)" test "$binary_build" = "$tree_build"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/t"
cp -r "$src/src" "$src/schemas" "$src/scripts" "$tmp/t/"
base=$(hash_of "$tmp/t")
check "a copy of the tree has the tree's build" test "$base" = "$tree_build"

changed() { # changed FILE: append a comment, hash, restore
	cp "$tmp/t/$1" "$tmp/saved"
	printf '\n/* a change */\n' >>"$tmp/t/$1"
	local h
	h=$(hash_of "$tmp/t")
	cp "$tmp/saved" "$tmp/t/$1"
	echo "$h"
}
for f in src/model/hertz.c src/model/assembly.h src/mc/engine.c src/opt/optimize.c src/io/study_json.c \
	src/app/optimize.c src/util/rng.c; do
	h=$(changed "$f")
	check "a change to $f changes the build" test "$h" != "$base"
done
for f in src/cli/main.c src/http/server.c src/job/jobs.c src/store/store.c; do
	h=$(changed "$f")
	check "a change to $f (a front end, the queue, the store) keeps the build" test "$h" = "$base"
done
cp "$tmp/t/schemas/study.schema.json" "$tmp/saved"
sed -i 's/"title"/"title" /' "$tmp/t/schemas/study.schema.json"
h=$(hash_of "$tmp/t")
check "a change to a schema changes the build" test "$h" != "$base"
cp "$tmp/saved" "$tmp/t/schemas/study.schema.json"
mkdir -p "$tmp/t/src/dyn"
echo '/* new */' >"$tmp/t/src/dyn/new.c"
h=$(hash_of "$tmp/t")
check "a new dynamics source changes the build" test "$h" != "$base"
rm "$tmp/t/src/dyn/new.c"
check "restored, the build is the tree's again" test "$(hash_of "$tmp/t")" = "$base"
h=$(cmake -DSOURCE_DIR="$tmp/t" "-DCOMPILER=another compiler" -P "$script" 2>&1)
check "another compiler changes the build" test "$h" != "$base"

echo "engine_version: $pass passed, $fail failed"
echo "$pass passed, $fail failed"
test "$fail" -eq 0
