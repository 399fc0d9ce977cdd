#!/usr/bin/env bash
# Quick start, command 1: install dependencies, build, run the default demo: the elbow arm
# task in closed loop, filmed while it runs; the video lands in renders/demo.mp4.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh --demo   # only what the demo needs (the tests install the rest)
./scripts/build.sh --demo          # only `recruit` and its render and plot modules
./scripts/render_demo.sh --progress
echo "demo: wrote renders/demo.mp4, renders/demo.gif and renders/demo_t0038.000.png"
