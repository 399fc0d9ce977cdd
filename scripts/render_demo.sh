#!/usr/bin/env bash
# Renders the default demo (the elbow arm reaching and holding angles, first 40 s) into renders/:
#   demo.mp4              1280x720, 20 frames/s, and the README's still demo_t0038.000.png;
#   demo.gif              640x360 at 5 frames/s, a second run rendered at the GIF's own size
#                         so its text is drawn for that size (a downscaled 720p frame is not
#                         readable at 640 px).
# The task's estimator (the Kalman filter on each bundle's identified, length-dependent model;
# ESTIMATOR=name to show another): the plots carry its +-2 sd band. Same seed, same frames.
# Needs a build (scripts/build.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
RECRUIT=./build/src/cli/recruit
TASK=models/tasks/arm_reach_hold.json
EST=()
[ -n "${ESTIMATOR:-}" ] && EST=(--estimator "$ESTIMATOR")
"$RECRUIT" render --task "$TASK" "${EST[@]}" --duration 40 --width 1280 --height 720 --fps 20 \
  --out renders/demo.mp4 --stills 38 --stills-prefix renders/demo_ --crf 28 "$@"
tmp=$(mktemp -d /tmp/recruit_demo.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
"$RECRUIT" render --task "$TASK" "${EST[@]}" --duration 40 --width 640 --height 360 --fps 5 \
  --out "$tmp/gif_run.mp4" --gif renders/demo.gif --gif-fps 5 --gif-width 640 "$@"
