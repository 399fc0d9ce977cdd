#!/usr/bin/env bash
# Quick start, command 1: install dependencies, build, and run the default demo.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
mkdir -p renders/out
echo "demo: the default demo is being built (issues 3-5); the toolkit's commands:"
./build/src/cli/recruit --help
