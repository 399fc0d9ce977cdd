#!/usr/bin/env bash
# Builds the libFuzzer targets of the input parsers (tests/fuzz) in the suite's sanitized tree
# (scripts/build-sanitized.sh: clang, AddressSanitizer + UndefinedBehaviorSanitizer with no
# recovery, libFuzzer's coverage instrumentation in the targets and the parsers' own sources;
# build-asan/, where scripts/sanitize.sh has built them already), then runs each for a fixed time
# from its checked-in seed corpus with a fixed seed, JOBS targets at a time.
# Fails if any target crashes, hangs (-timeout), leaks or trips a sanitizer; the input that did it
# is written to <build>/artifacts/.
# Usage:
#   scripts/fuzz.sh [target...]     targets: task filter_model filter_log bundle_config mjcf_config
#                                   sil_packet
#                                   (default: all)
# Environment: FUZZ_SECONDS per target (default 30), FUZZ_SEED (default 1), COVERAGE=ON for the
# targets' own tree with the coverage instrumentation in every library they link (build-fuzz/),
# BUILD_DIR (default build-asan, with COVERAGE=ON build-fuzz), JOBS (default: nproc; also the
# targets fuzzing at once). Reproduce a crash: <build>/tests/fuzz/fuzz_<target> FILE.
# Keep one found crash as a regression test: copy it to tests/fuzz/corpus/<target>/regress-<what>
# (ctest's fuzz_<target>_corpus replays every corpus file with the normal build).
set -euo pipefail
cd "$(dirname "$0")/.."
COVERAGE=${COVERAGE:-OFF}
if [ "$COVERAGE" = ON ]; then BUILD_DIR=${BUILD_DIR:-build-fuzz}; else BUILD_DIR=${BUILD_DIR:-build-asan}; fi
JOBS=${JOBS:-$(nproc)}
FUZZ_SECONDS=${FUZZ_SECONDS:-30}
FUZZ_SEED=${FUZZ_SEED:-1}
TARGETS=("$@")
if [ ${#TARGETS[@]} -eq 0 ]; then TARGETS=(task filter_model filter_log bundle_config mjcf_config sil_packet); fi

export BUILD_DIR JOBS COVERAGE
if ! "${CXX:-clang++}" --version | grep -q clang; then
  echo "fuzz: libFuzzer needs clang (CXX=${CXX:-clang++})" >&2
  exit 2
fi
./scripts/build-sanitized.sh "${TARGETS[@]/#/fuzz_}"

export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# libFuzzer's link puts libstdc++ before the shared ASan runtime (scripts/build-sanitized.sh), which
# must come first: preload it.
ASAN_RUNTIME="$("${CXX:-clang++}" -print-runtime-dir)/libclang_rt.asan-x86_64.so"
mkdir -p "$BUILD_DIR/artifacts"
# One target: exit status 0 when it ran its time without a finding; its log in artifacts/.
fuzz_one() {
  local t=$1 work="$BUILD_DIR/corpus/$1"
  # New inputs go to a scratch corpus (first folder); the checked-in seeds are only read.
  mkdir -p "$work"
  LD_PRELOAD="$ASAN_RUNTIME" "$BUILD_DIR/tests/fuzz/fuzz_$t" -seed="$FUZZ_SEED" \
    -max_total_time="$FUZZ_SECONDS" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$BUILD_DIR/artifacts/$t-" "$work" "tests/fuzz/corpus/$t" \
    >"$BUILD_DIR/artifacts/$t.log" 2>&1
}
# JOBS targets at a time (each is one process on one core), reported in the order given.
failed=()
for ((i = 0; i < ${#TARGETS[@]}; i += JOBS)); do
  batch=("${TARGETS[@]:i:JOBS}")
  pids=()
  for t in "${batch[@]}"; do
    echo "fuzz: $t for ${FUZZ_SECONDS}s (seed $FUZZ_SEED)"
    fuzz_one "$t" &
    pids+=($!)
  done
  for k in "${!batch[@]}"; do
    t=${batch[$k]}
    if ! wait "${pids[$k]}"; then
      failed+=("$t")
      tail -n 60 "$BUILD_DIR/artifacts/$t.log"
    fi
    grep -E '^stat::(number_of_executed_units|new_units_added)|^Done ' "$BUILD_DIR/artifacts/$t.log" \
      | sed "s/^/fuzz: $t: /" || true
  done
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]}; inputs in $BUILD_DIR/artifacts/ (see docs/reliability.md)" >&2
  exit 1
fi
echo "fuzz: ${#TARGETS[@]} targets, ${FUZZ_SECONDS}s each, no crash"
