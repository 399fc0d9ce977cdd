#!/usr/bin/env bash
# The whole suite (every test program, the recruit program, the plugin and the Python module)
# built with AddressSanitizer + UndefinedBehaviorSanitizer by scripts/build-sanitized.sh
# (build-asan/, clang, -O1 -DNDEBUG), then ctest over it with no recovery: the first report fails
# its test. CI runs it (scripts/test.sh).
# Usage:
#   scripts/sanitize.sh [ctest arguments...]      e.g. scripts/sanitize.sh -R 'common|sim_'
# Environment: BUILD_DIR (default build-asan), JOBS (default nproc), TARGETS (default: all), and
# those of scripts/build-sanitized.sh (OPT, BENCH, CC/CXX).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build-asan}
JOBS=${JOBS:-$(nproc)}
export BUILD_DIR JOBS
# shellcheck disable=SC2086
./scripts/build-sanitized.sh ${TARGETS:-}
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
  if "$cxx" --version | grep -q clang; then
    runtime="$("$cxx" -print-runtime-dir)/libclang_rt.asan-x86_64.so"
  else
    runtime=$("$cxx" -print-file-name=libasan.so)
  fi
  # libstdc++ too: the interpreter does not link it, and ASan's __cxa_throw interceptor must find
  # it at start-up (else the first C++ exception aborts: "real___cxa_throw != 0").
  LD_PRELOAD="$runtime $("$cxx" -print-file-name=libstdc++.so)" \
    ctest "${args[@]}" -R '^python_pytest$'
fi
