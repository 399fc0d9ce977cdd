#!/usr/bin/env bash
# `cmake --install` of the build into a temporary prefix, then a separate project (consumer/)
# configured with find_package(Recruit) against it, built and run. Usage: install_test.sh BUILD_DIR
set -euo pipefail
build=$1
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT INT TERM
cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
# The consumer is compiled and linked with the build's own flags (a sanitized build's libraries
# need the sanitizer runtime in the program too).
cache() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
cmake -S "$here/consumer" -B "$tmp/build" -DCMAKE_PREFIX_PATH="$tmp/prefix" \
  -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER="$(cache CMAKE_CXX_COMPILER)" \
  -DCMAKE_CXX_FLAGS="$(cache CMAKE_CXX_FLAGS)" \
  -DCMAKE_CXX_FLAGS_RELEASE="$(cache CMAKE_CXX_FLAGS_RELEASE)" \
  -DCMAKE_EXE_LINKER_FLAGS="$(cache CMAKE_EXE_LINKER_FLAGS)" >/dev/null
cmake --build "$tmp/build" >/dev/null
"$tmp/build/consumer"
