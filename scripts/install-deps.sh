#!/usr/bin/env bash
# Installs every build, test and render dependency of Recruit: Debian 12 packages, then a Python
# virtual environment at .venv/ with the pinned MuJoCo wheel (the only MuJoCo the build uses) and
# the Python test tools. Nothing else is downloaded. Safe to run again: skips what is present.
set -euo pipefail
cd "$(dirname "$0")/.."

MUJOCO_VERSION=4.0.0  # keep in step with RECRUIT_MUJOCO_VERSION in CMakeLists.txt
PY_PACKAGES=("mujoco==${MUJOCO_VERSION}" "numpy" "pytest" "filterpy" "pybind11" "scikit-build-core"
  "matplotlib")

PACKAGES=(
  build-essential cmake ninja-build pkg-config clang-format ccache
  python3 python3-venv python3-dev
  libosmesa6-dev libcairo2-dev
  libeigen3-dev libcli11-dev nlohmann-json3-dev libfmt-dev libtbb-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev ffmpeg
  liblodepng-dev libstb-dev
  clang libclang-rt-14-dev  # libFuzzer targets (tests/fuzz)
  slurm-wlm munge           # the single-node Slurm the sweep's job-array test runs on
)

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
if .venv/bin/python - "$MUJOCO_VERSION" <<'PY' 2>/dev/null; then
import sys, mujoco, numpy, pytest, filterpy, matplotlib
sys.exit(0 if mujoco.__version__ == sys.argv[1] else 1)
PY
  echo "install-deps: .venv has mujoco ${MUJOCO_VERSION} and the test tools"
else
  echo "install-deps: installing ${PY_PACKAGES[*]} into .venv"
  .venv/bin/python -m pip install -q --disable-pip-version-check "${PY_PACKAGES[@]}"
fi
