#!/usr/bin/env bash
# Configures and builds a sanitized tree: AddressSanitizer + UndefinedBehaviorSanitizer with no
# recovery, -O1 -DNDEBUG (-O3 with the sanitizers compiles 2.5-3.4 times slower; docs/reliability.md
# "Sanitizers"). Two kinds:
#   - the suite (default, build-asan/): every test program, the recruit program, the plugin, the
#     Python module and, with clang, the libFuzzer targets of the input parsers (tests/fuzz,
#     scripts/fuzz.sh runs them); the tests and the module as unity batches (RECRUIT_UNITY_TESTS),
#     which halves a build from scratch; the targets the tests spend little time in
#     (RECRUIT_COLD_TARGETS and the test programs not marked HOT, CMakeLists.txt) with COLD_OPT
#     (default -O0), about half the compile CPU of -O1. libFuzzer's coverage instrumentation
#     (fuzzer-no-link) only in the fuzz targets' objects and the parsers' own sources
#     (tests/fuzz/coverage_allowlist.txt, each library's parsers in a unity batch of their own):
#     everywhere, its comparison callbacks made the suite's Monte Carlo tests 2.7 times slower.
#     The headers the test programs share precompiled once per level (RECRUIT_PCH_TESTS,
#     tests/CMakeLists.txt). scripts/sanitize.sh runs it.
#   - COVERAGE=ON (clang only, build-fuzz/): the libFuzzer targets and the libraries they link
#     alone, with the coverage instrumentation in every library (a second tree: CI does not build
#     it; docs/reliability.md "CI").
# No LTO (pybind11 adds -flto to the Python module unless told; with the coverage instrumentation GNU
# ld then rejects the module's constructors).
# Usage:
#   scripts/build-sanitized.sh [target...]     (default: every target of the tree's kind)
# Environment: BUILD_DIR (default build-asan, with COVERAGE=ON build-fuzz), JOBS (default nproc),
# OPT (default -O1), COLD_OPT (suite only, default -O0; "" = OPT everywhere), COVERAGE (OFF),
# BENCH=ON to build the benchmarks too (suite only), PCH (suite only, default ON), CC/CXX (default
# clang/clang++).
set -euo pipefail
cd "$(dirname "$0")/.."
COVERAGE=${COVERAGE:-OFF}
if [ "$COVERAGE" = ON ]; then BUILD_DIR=${BUILD_DIR:-build-fuzz}; else BUILD_DIR=${BUILD_DIR:-build-asan}; fi
JOBS=${JOBS:-$(nproc)}
CC=${CC:-clang}
CXX=${CXX:-clang++}
SAN="address,undefined"
LINK="-fsanitize=address,undefined"
if "$CXX" --version | grep -q clang; then
  # The shared ASan runtime in every program, as GCC does: the Python tests preload it into the
  # interpreter, and the recruit programs they start must not carry a second, static copy
  # ("linked against incompatible ASan runtimes").
  LINK="$LINK -shared-libasan -Wl,-rpath,$("$CXX" -print-runtime-dir)"
elif [ "$COVERAGE" = ON ]; then
  echo "build-sanitized: COVERAGE=ON needs clang (libFuzzer), CXX=$CXX" >&2
  exit 2
fi
FUZZ=OFF
COV=""
if "$CXX" --version | grep -q clang; then
  FUZZ=ON
  SAN="$SAN,fuzzer-no-link"
  COV="-fsanitize-coverage-allowlist=$PWD/tests/fuzz/coverage_allowlist.txt"
fi
KIND=(-DRECRUIT_BUILD_PYTHON=ON -DRECRUIT_UNITY_TESTS=ON -DRECRUIT_BUILD_FUZZ="$FUZZ"
  -DRECRUIT_BUILD_BENCH="${BENCH:-OFF}" -DRECRUIT_COLD_OPT="${COLD_OPT--O0}"
  -DRECRUIT_PCH_TESTS="${PCH:-ON}")
if [ "$COVERAGE" = ON ]; then
  COV=""
  KIND=(-DRECRUIT_BUILD_PYTHON=OFF -DRECRUIT_BUILD_TESTS=OFF -DRECRUIT_BUILD_FUZZ=ON
    -DRECRUIT_BUILD_BENCH=OFF -DRECRUIT_COLD_OPT=)
fi
FLAGS="-fsanitize=$SAN -fno-sanitize-recover=all -fno-omit-frame-pointer $COV"
cmake -G Ninja -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "${KIND[@]}" \
  -DCMAKE_C_COMPILER="$CC" -DCMAKE_CXX_COMPILER="$CXX" \
  -DCMAKE_C_FLAGS_RELEASE="${OPT:--O1} -DNDEBUG" -DCMAKE_CXX_FLAGS_RELEASE="${OPT:--O1} -DNDEBUG" \
  -DCMAKE_INTERPROCEDURAL_OPTIMIZATION=OFF \
  -DCMAKE_C_FLAGS="$FLAGS" -DCMAKE_CXX_FLAGS="$FLAGS" -DCMAKE_EXE_LINKER_FLAGS="$LINK" \
  -DCMAKE_SHARED_LINKER_FLAGS="$LINK" -DCMAKE_MODULE_LINKER_FLAGS="$LINK" >/dev/null
ninja -C "$BUILD_DIR" -j "$JOBS" "$@"
