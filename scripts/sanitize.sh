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
# Every test in one ctest run, the Python tests too (their test preloads the ASan runtime into
# the interpreter: tests/python/CMakeLists.txt), the longest first (recruit_test_cost,
# tests/CMakeLists.txt): both cores stay busy to the end.
args=(--test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" --timeout 600 "$@")
exec ctest "${args[@]}"
