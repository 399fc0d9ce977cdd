#!/usr/bin/env bash
# cmake/SourceHash.cmake on a scratch tree: the hash is SHA-256 (first 12 hex digits) over
# "<path> <sha256 of the file>\n" lines in path order (computed here with sha256sum); an
# unchanged tree leaves the header untouched; an edit, committed or not, changes it.
set -euo pipefail
SCRIPT=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/src/a" "$tmp/plugin"
echo 'int a;' >"$tmp/src/a/a.cc"
echo '#pragma once' >"$tmp/src/a/a.h"
echo 'int p;' >"$tmp/plugin/p.cc"
echo 'not a source' >"$tmp/src/a/notes.txt"
expected() {
  (cd "$tmp" && for f in plugin/p.cc src/a/a.cc src/a/a.h; do
    echo "$f $(sha256sum "$f" | cut -c1-64)"
  done) | sha256sum | cut -c1-12
}
run() { cmake -DROOT="$tmp" -DOUT="$tmp/out/source_hash.h" -P "$SCRIPT"; }
got() { sed -n 's/#define RECRUIT_SOURCE_HASH "\(.*\)"/\1/p' "$tmp/out/source_hash.h"; }
mkdir -p "$tmp/out"
run
[ "$(got)" = "$(expected)" ] || { echo "hash $(got) != $(expected)"; exit 1; }
first=$(got)
touch -d '2001-01-01' "$tmp/out/source_hash.h"
echo 'edited' >>"$tmp/src/a/notes.txt"
run
[ "$(stat -c %Y "$tmp/out/source_hash.h")" = "$(date -d 2001-01-01 +%s)" ] ||
  { echo "an unchanged tree rewrote the header"; exit 1; }
echo 'int b;' >>"$tmp/src/a/a.cc"
run
[ "$(got)" != "$first" ] || { echo "an edited source kept the hash"; exit 1; }
[ "$(got)" = "$(expected)" ] || { echo "hash after the edit $(got) != $(expected)"; exit 1; }
echo ok
