#!/usr/bin/env bash
# Configures and builds Recruit in ./build (Release, Ninja) against the pinned MuJoCo wheel in
# .venv/ (scripts/install-deps.sh). Arguments are build targets (default: everything), e.g.
#   scripts/build.sh recruit          # only the command-line program and what it links
#   scripts/build.sh --demo           # the demo's configuration: `recruit` and its modules only,
#                                     # without the tests, benchmarks and Python package (so their
#                                     # dependencies need not be installed: install-deps.sh --demo)
set -euo pipefail
cd "$(dirname "$0")/.."
PARTS=ON
if [ "${1:-}" = --demo ]; then
  PARTS=OFF
  shift
  set -- recruit
fi
# The Python package is built too, so that ctest runs its pytest suite (python_pytest).
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DRECRUIT_BUILD_PYTHON=$PARTS \
  -DRECRUIT_BUILD_TESTS=$PARTS -DRECRUIT_BUILD_BENCH=$PARTS >/dev/null
if [ $# -eq 0 ]; then
  cmake --build build -j"$(nproc)"
else
  cmake --build build -j"$(nproc)" --target "$@"
fi
