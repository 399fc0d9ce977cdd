#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build of the whole suite (every test program,
# the recruit program, the plugin and the Python module; -O1 -DNDEBUG: -O3 with the sanitizers
# compiles 2.5-3.4 times slower than Release, -O1 1.75 times, docs/reliability.md), then ctest
# over it with no recovery: the first report fails its test. CI runs it (scripts/test.sh
# --sanitize).
# Usage:
#   scripts/sanitize.sh [ctest arguments...]      e.g. scripts/sanitize.sh -R 'common|sim_'
# Environment: BUILD_DIR (default build-asan), JOBS (default nproc), TARGETS (default: all),
# OPT (default -O1), BENCH=ON to build the benchmarks too (ctest runs none of them).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build-asan}
JOBS=${JOBS:-$(nproc)}
FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
LINK="-fsanitize=address,undefined"
cmake -G Ninja -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DRECRUIT_BUILD_PYTHON=ON \
  -DCMAKE_C_FLAGS_RELEASE="${OPT:--O1} -DNDEBUG" -DCMAKE_CXX_FLAGS_RELEASE="${OPT:--O1} -DNDEBUG" \
  -DRECRUIT_BUILD_BENCH="${BENCH:-OFF}" \
  -DCMAKE_C_FLAGS="$FLAGS" -DCMAKE_CXX_FLAGS="$FLAGS" -DCMAKE_EXE_LINKER_FLAGS="$LINK" \
  -DCMAKE_SHARED_LINKER_FLAGS="$LINK" -DCMAKE_MODULE_LINKER_FLAGS="$LINK" >/dev/null
# shellcheck disable=SC2086
ninja -C "$BUILD_DIR" -j "$JOBS" ${TARGETS:-}
# detect_leaks=0: MuJoCo and OSMesa keep process-lifetime allocations; leaks are not the target.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1:detect_stack_use_after_return=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
args=(--test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" --timeout 600)
if [ $# -gt 0 ]; then
  exec ctest "${args[@]}" "$@"
fi
ctest "${args[@]}" -E '^python_pytest$'
# The Python interpreter is not instrumented: the sanitized extension module needs the ASan
# runtime loaded first, so pytest runs with it preloaded (and only pytest: other programs the
# tests start, e.g. gnuplot, stay as they are).
if grep -q '^RECRUIT_BUILD_PYTHON:BOOL=ON' "$BUILD_DIR/CMakeCache.txt"; then
  cxx=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$BUILD_DIR/CMakeCache.txt")
  # libstdc++ too: the interpreter does not link it, and ASan's __cxa_throw interceptor must find
  # it at start-up (else the first C++ exception aborts: "real___cxa_throw != 0").
  LD_PRELOAD="$("$cxx" -print-file-name=libasan.so) $("$cxx" -print-file-name=libstdc++.so)" \
    ctest "${args[@]}" -R '^python_pytest$'
fi
