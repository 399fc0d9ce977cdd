#!/usr/bin/env bash
# Remakes every committed picture made from the arm tasks (models/tasks/arm_*.json), e.g. after a
# change to the tasks, their self-tuned loop or the renderer (1-4 minutes on two shared cores):
#   renders/demo.mp4, demo.gif, demo_t0038.000.png   scripts/render_demo.sh (renders/README.md)
#   docs/img/repro_arm_*.png                         scripts/reproduce_paper.sh --arm
#   docs/img/plot_arm_count_320.png                  docs/plotting.md's commands
#   docs/img/replay_arm_push_current0.145.png        docs/replay.md's commands
# Same build, same pictures. The numbers the docs quote from these tasks have their own commands
# (printed at the end). Needs a build (scripts/build.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
R=./build/src/cli/recruit
tmp=$(mktemp -d /tmp/recruit_arm_figures.XXXXXX)
trap 'rm -rf "$tmp"' EXIT

bash scripts/render_demo.sh
bash scripts/reproduce_paper.sh --arm "$tmp/repro" > /dev/null

"$R" simulate --task models/tasks/arm_reach_hold.json --seed 1 --out "$tmp/arm" > /dev/null
"$R" plot --csv "$tmp/arm/arm_reach_hold_steps.csv" --summary "$tmp/arm/arm_reach_hold_summary.json" \
  --out "$tmp/arm/fig" --name plot_arm --width 320 --height 240 > /dev/null
cp "$tmp/arm/fig/plot_arm_count.png" docs/img/plot_arm_count_320.png

python3 tests/replay/calibrate.py --seeds 11 --variants current=0.145 --tasks arm_push \
  --out "$tmp/val" --recruit "$R" > /dev/null
"$R" simulate --task "$tmp/val/models/current0.145_arm_push.json" --seed 11 --estimator output \
  --out "$tmp/bench_weak" > /dev/null
"$R" replay --log "$tmp/bench_weak/arm_push_steps.csv" --task models/tasks/arm_push.json \
  --out "$tmp/rep_weak" --prefix arm_push_current0.145 > /dev/null
cp "$tmp/rep_weak/arm_push_current0.145_replay.png" docs/img/replay_arm_push_current0.145.png

echo "wrote renders/demo.*, docs/img/repro_arm_*.png, plot_arm_count_320.png, replay_arm_push_current0.145.png"
echo "the docs' numbers from the arm tasks come from: python3 scripts/dev/arm_tasks_table.py"
echo "  (docs/paper-reproduction.md), python3 scripts/dev/eval_tasks.py --seeds 301-310"
echo "  models/tasks/arm_*.json tests/export/data/arm_*_hand.json (docs/controller.md), the"
echo "  calibrate.py and replay commands of docs/replay.md, the tune commands of docs/sweep.md"
echo "  (the arm tasks), python3 scripts/dev/arm_loop_cpu.py (README.md)"
