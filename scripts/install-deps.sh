#!/usr/bin/env bash
# Installs every build, test and render dependency of Recruit: Debian 12 packages, then a Python
# virtual environment at .venv/ with the pinned MuJoCo wheel (the only MuJoCo the build uses) and
# the Python test tools. Nothing else is downloaded. Safe to run again: skips what is present.
#   scripts/install-deps.sh          everything (tests, benchmarks, Python package, fuzzers, Slurm)
#   scripts/install-deps.sh --demo   only what `recruit` and its render and plot modules need
#                                    (scripts/demo.sh): no test tools, clang, Slurm or ffmpeg CLI
set -euo pipefail
cd "$(dirname "$0")/.."
MODE=${1:-all}
case "$MODE" in
  all | --demo) ;;
  *)
    echo "usage: scripts/install-deps.sh [--demo]" >&2
    exit 2
    ;;
esac

MUJOCO_VERSION=4.0.0  # keep in step with RECRUIT_MUJOCO_VERSION in CMakeLists.txt
PY_PACKAGES=("mujoco==${MUJOCO_VERSION}" "numpy" "pytest" "filterpy" "pybind11" "scikit-build-core"
  "matplotlib"
  "myo-sim==0.2.3")  # test data: MyoSuite elbow and finger models (tests/attach); import myo_sim

DEMO_PACKAGES=(
  build-essential cmake ninja-build pkg-config ccache
  python3 python3-venv
  libosmesa6-dev libegl-dev libcairo2-dev
  libeigen3-dev libcli11-dev nlohmann-json3-dev libfmt-dev libtbb-dev
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev
  liblodepng-dev libstb-dev
)
PACKAGES=("${DEMO_PACKAGES[@]}"
  clang-format python3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  ffmpeg                    # the render tests decode the videos they write
  clang libclang-rt-14-dev  # the sanitized suite and the libFuzzer targets (tests/fuzz)
  slurm-wlm munge           # the single-node Slurm the sweep's job-array test runs on
  gcc-arm-none-eabi libnewlib-arm-none-eabi  # the exported controller built for Cortex-M4F
  qemu-system-arm                            # ... and run on an emulated MPS2 board (tests/export)
)
if [ "$MODE" = --demo ]; then
  PACKAGES=("${DEMO_PACKAGES[@]}")
  PY_PACKAGES=("mujoco==${MUJOCO_VERSION}")
fi

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} Debian packages present"
else
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# The pinned MuJoCo wheel and the Python tools, in .venv/ (cmake finds MuJoCo there).
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
if .venv/bin/python - "$MUJOCO_VERSION" "${PY_PACKAGES[@]}" <<'PY' 2>/dev/null; then
import importlib, sys
import mujoco
for package in sys.argv[3:]:
    importlib.import_module(package.split("==")[0].replace("-", "_"))
sys.exit(0 if mujoco.__version__ == sys.argv[1] else 1)
PY
  echo "install-deps: .venv has mujoco ${MUJOCO_VERSION} and ${#PY_PACKAGES[@]} Python packages"
else
  echo "install-deps: installing ${PY_PACKAGES[*]} into .venv"
  # --no-compile: no byte-code for the ~6700 modules installed (scipy, matplotlib, ...); Python
  # writes it for the few the tests import, when they import them. Half pip's CPU time
  # (docs/reliability.md "CI").
  .venv/bin/python -m pip install -q --no-compile --disable-pip-version-check "${PY_PACKAGES[@]}"
fi
