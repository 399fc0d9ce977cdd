#!/usr/bin/env bash
# Quick start, command 2: install dependencies, build, run every test.
#   bash scripts/test.sh             the README's command and CI's (.ci/run): the whole suite (C++
#                                    and Python) built with AddressSanitizer + UndefinedBehavior-
#                                    Sanitizer in build-asan/, then each parser's libFuzzer target
#                                    for FUZZ_SECONDS (default 10), built in the same tree
#   bash scripts/test.sh --release   the same suite in the Release build (build/), no fuzzing
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
case "${1:-}" in
  "")
    ./scripts/sanitize.sh
    FUZZ_SECONDS=${FUZZ_SECONDS:-10} ./scripts/fuzz.sh
    ;;
  --release)
    ./scripts/build.sh
    ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 300
    ;;
  *)
    echo "usage: scripts/test.sh [--release]" >&2
    exit 2
    ;;
esac
