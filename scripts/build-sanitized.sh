#!/usr/bin/env bash
# Configures and builds the sanitized tree (build-asan/) that CI's tests and fuzzers share: clang,
# AddressSanitizer + UndefinedBehaviorSanitizer with no recovery, and libFuzzer's coverage
# instrumentation (fuzzer-no-link) in every library, so that scripts/sanitize.sh (the suite) and
# scripts/fuzz.sh (the libFuzzer targets) need one build, not two. -O1 -DNDEBUG: -O3 with the
# sanitizers compiles 2.5-3.4 times slower (docs/reliability.md "Sanitizers"). No LTO (pybind11
# adds -flto to the Python module unless told; with the coverage instrumentation GNU ld then
# rejects the module's constructors).
# Usage:
#   scripts/build-sanitized.sh [target...]     (default: every target but the benchmarks)
# Environment: BUILD_DIR (default build-asan), JOBS (default nproc), OPT (default -O1),
# BENCH=ON to build the benchmarks too, CC/CXX (default clang/clang++; with gcc the fuzz targets
# are not built).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build-asan}
JOBS=${JOBS:-$(nproc)}
CC=${CC:-clang}
CXX=${CXX:-clang++}
SAN="address,undefined"
FUZZ=OFF
LINK="-fsanitize=address,undefined"
if "$CXX" --version | grep -q clang; then
  SAN="$SAN,fuzzer-no-link"
  FUZZ=ON
  # The shared ASan runtime in every program, as GCC does: the Python tests preload it into the
  # interpreter, and the recruit programs they start must not carry a second, static copy
  # ("linked against incompatible ASan runtimes").
  LINK="$LINK -shared-libasan -Wl,-rpath,$("$CXX" -print-runtime-dir)"
fi
FLAGS="-fsanitize=$SAN -fno-sanitize-recover=all -fno-omit-frame-pointer"
cmake -G Ninja -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DRECRUIT_BUILD_PYTHON=ON \
  -DCMAKE_C_COMPILER="$CC" -DCMAKE_CXX_COMPILER="$CXX" \
  -DCMAKE_C_FLAGS_RELEASE="${OPT:--O1} -DNDEBUG" -DCMAKE_CXX_FLAGS_RELEASE="${OPT:--O1} -DNDEBUG" \
  -DRECRUIT_BUILD_BENCH="${BENCH:-OFF}" -DRECRUIT_BUILD_FUZZ="$FUZZ" \
  -DCMAKE_INTERPROCEDURAL_OPTIMIZATION=OFF \
  -DCMAKE_C_FLAGS="$FLAGS" -DCMAKE_CXX_FLAGS="$FLAGS" -DCMAKE_EXE_LINKER_FLAGS="$LINK" \
  -DCMAKE_SHARED_LINKER_FLAGS="$LINK" -DCMAKE_MODULE_LINKER_FLAGS="$LINK" >/dev/null
ninja -C "$BUILD_DIR" -j "$JOBS" "$@"
