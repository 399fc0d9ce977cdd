#!/usr/bin/env bash
# Quick start, command 2: install dependencies, build, run every test.
#   bash scripts/test.sh              Release build in build/ (the README's command)
#   bash scripts/test.sh --sanitize   the same suite built with AddressSanitizer +
#                                     UndefinedBehaviorSanitizer in build-asan (CI; slower)
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
case "${1:-}" in
  "")
    ./scripts/build.sh
    ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 300
    ;;
  --sanitize)
    ./scripts/sanitize.sh
    ;;
  *)
    echo "usage: scripts/test.sh [--sanitize]" >&2
    exit 2
    ;;
esac
