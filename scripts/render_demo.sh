#!/usr/bin/env bash
# Renders the default demo (the elbow arm reaching and holding angles, first 32 s) into
# renders/: demo.mp4, demo.gif and the still demo_t0031.000.png shown in renders/README.md.
# Same seed, same frames. Needs a build (scripts/build.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
./build/src/cli/recruit render --task models/tasks/arm_reach_hold.json --duration 32 \
  --out renders/demo.mp4 --gif renders/demo.gif --gif-fps 5 --gif-width 320 \
  --stills 31 --stills-prefix renders/demo_ --crf 28 \
  --tendon-width 0.003 --transparent --azimuth 90 --elevation -10 --distance 0.9 \
  --lookat 0.05,0,0.4 "$@"
