#!/bin/sh
# `recruit --version` and `recruit` alone, against versions read independently of the build:
#   cli_version_test.sh RECRUIT SOURCE_DIR
# The project version is parsed from CMakeLists.txt's project(recruit VERSION ...) line and the
# MuJoCo version from its pinned RECRUIT_MUJOCO_VERSION (the release whose header the build
# compiles against and whose libmujoco.so.<version> the binary links by soname).
set -u
RECRUIT=$1
SRC=$2
fail() { echo "FAIL: $*"; exit 1; }
project=$(sed -n 's/^project(recruit VERSION \([0-9.]*\).*/\1/p' "$SRC/CMakeLists.txt")
mujoco=$(sed -n 's/^set(RECRUIT_MUJOCO_VERSION \([0-9.]*\))/\1/p' "$SRC/CMakeLists.txt")
[ -n "$project" ] && [ -n "$mujoco" ] || fail "versions not found in $SRC/CMakeLists.txt"
out=$("$RECRUIT" --version 2>/dev/null) || fail "--version exited $?"
first=$(echo "$out" | sed -n 1p)
case $first in
"recruit $project ($project+"*")") ;;
*) fail "first line '$first', expected 'recruit $project ($project+<commit>)'" ;;
esac
second=$(echo "$out" | sed -n 2p)
major=${mujoco%%.*}; rest=${mujoco#*.}; minor=${rest%%.*}; patch=${rest#*.}
header=$((major * 1000000 + minor * 1000 + patch))
want="MuJoCo built against $mujoco (mjVERSION_HEADER $header), running $mujoco"
[ "$second" = "$want" ] || fail "second line '$second', expected '$want'"
# No subcommand: the help on stdout, exit 0, nothing on stderr.
"$RECRUIT" > out.txt 2> err.txt || fail "recruit alone exited $?"
[ -s err.txt ] && fail "recruit alone wrote to stderr: $(head -c 300 err.txt)"
grep -q "^Usage: recruit \[OPTIONS\] SUBCOMMAND" out.txt || fail "no usage line"
for c in filter identify simulate sweep render plot; do
  grep -q "^  $c " out.txt || fail "help does not list '$c'"
done
grep -q -- "--version" out.txt || fail "help does not list --version"
echo "ok: recruit $project, MuJoCo $mujoco"
