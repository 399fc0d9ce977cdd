#!/usr/bin/env bash
# Issue 24 item 5's development cases: attach every muscle of the project's two-joint arm and
# of MyoSuite's elbow and finger (MCP driven, the other finger joints locked), then run each
# starter task and the project's arm tasks (their self-tuned loop) over seeds at dT 1 and 0.5.
# Usage: scripts/dev/dev_cases.sh OUT_DIR [SEEDS]     (SEEDS like 201-203)
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$1
SEEDS=${2:-201-203}
R=./build/src/cli/recruit
M=$(.venv/bin/python -c "import myo_sim, os; print(os.path.dirname(myo_sim.__file__))")/models/legacy
mkdir -p "$OUT"
$R attach models/arm2j_muscle.xml --muscles all -o "$OUT/arm2j.xml" --task "$OUT/arm2j_task.json" >"$OUT/arm2j_attach.txt"
$R attach "$M/elbow/myoelbow_1dof6muscles.xml" --muscles all -o "$OUT/myoelbow.xml" \
  --task "$OUT/myoelbow_task.json" >"$OUT/myoelbow_attach.txt"
$R attach "$M/finger/myofinger_v0.xml" --muscles all --lock IFadb,IFpip,IFdip -o "$OUT/finger.xml" \
  --force 40 --task "$OUT/finger_task.json" >"$OUT/finger_attach.txt"
python3 scripts/dev/eval_tasks.py --seeds "$SEEDS" "$OUT/arm2j_task.json" "$OUT/myoelbow_task.json" \
  "$OUT/finger_task.json"
python3 scripts/dev/eval_tasks.py --seeds "$SEEDS" models/tasks/arm_reach_hold.json \
  models/tasks/arm_lift.json models/tasks/arm_push.json
