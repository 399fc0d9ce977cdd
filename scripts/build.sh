#!/usr/bin/env bash
# Configures and builds Recruit in ./build (Release, Ninja) against the pinned MuJoCo wheel in
# .venv/ (scripts/install-deps.sh). Arguments are build targets (default: everything), e.g.
#   scripts/build.sh recruit        # only the command-line program and what it links
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ $# -eq 0 ]; then
  cmake --build build -j"$(nproc)"
else
  cmake --build build -j"$(nproc)" --target "$@"
fi
