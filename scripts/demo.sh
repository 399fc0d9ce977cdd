#!/usr/bin/env bash
# Quick start, command 1: install dependencies, build, run the default demo: the elbow arm
# task in closed loop, filmed while it runs; the video lands in renders/demo.mp4.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh recruit   # only what the demo runs
./scripts/render_demo.sh --progress
echo "demo: wrote renders/demo.mp4, renders/demo.gif and renders/demo_t0031.000.png"
