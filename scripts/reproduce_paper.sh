#!/usr/bin/env bash
# Reproduces the paper's Figs. 5 and 9 with the project's own runs (docs/paper-reproduction.md):
#   1. one run each (seed 1) of the isometric paper task: output only at dT = 2.0 s and 0.5 s,
#      the Kalman filter on the augmented model at dT = 0.5 s; plots in docs/img/repro_*.png;
#   2. 20 seeds of each at lambda = 0.2 (recruit sweep), and the claims checked on them;
#   3. a dT x lambda sweep of output only and of the filter: stability map docs/img/sweep_*.png;
#   4. the three arm tasks (seed 1): docs/img/repro_arm_*.png.
# Usage: scripts/reproduce_paper.sh [--arm] [OUT_DIR]   (default renders/out/repro; resumable)
#   --arm: step 4 only (the arm tasks' figures, about 10 s; remake them after a change to the arm
#   tasks or their loop).
set -euo pipefail
cd "$(dirname "$0")/.."
ARM_ONLY=0
if [ "${1:-}" = --arm ]; then
  ARM_ONLY=1
  shift
fi
RECRUIT=${RECRUIT:-./build/src/cli/recruit}
OUT=${1:-renders/out/repro}
TASK=models/tasks/isometric_paper.json
SEEDS=${SEEDS:-20}
# FILTER_MODEL=FILE uses that filter model for kalman-augmented instead of models/identified/'s.
FM=()
[ -n "${FILTER_MODEL:-}" ] && FM=(--filter-model "$FILTER_MODEL")
mkdir -p "$OUT" docs/img
[ -x "$RECRUIT" ] || { echo "build first: bash scripts/build.sh" >&2; exit 1; }

arm_figures() {
  echo "== arm tasks (seed 1, the tasks' Kalman filter and self-tuned loop)"
  for t in arm_reach_hold arm_lift arm_push; do
    "$RECRUIT" simulate --task "models/tasks/$t.json" --seed 1 --out "$OUT" --csv-every 5
    "$RECRUIT" plot --csv "$OUT/${t}_steps.csv" --summary "$OUT/${t}_summary.json" --out docs/img \
      --name "repro_$t" --figure all --width 900 --height 640
  done
}
if [ "$ARM_ONLY" = 1 ]; then
  arm_figures
  echo "done: $OUT, docs/img/repro_arm_*.png"
  exit 0
fi

run() {  # run NAME ESTIMATOR DT
  local fm=()
  [ "$2" = kalman-augmented ] && fm=("${FM[@]}")
  "$RECRUIT" simulate --task "$TASK" --estimator "$2" --dT "$3" --lambda 0.2 --seed 1 \
    --out "$OUT" --csv "$OUT/$1.csv" --summary "$OUT/$1.json" --csv-every 5 "${fm[@]}"
}
echo "== single runs (seed 1)"
run fig5_top output 2.0
run fig5_bottom output 0.5
run fig9 kalman-augmented 0.5
for f in fig5_top fig5_bottom fig9; do
  "$RECRUIT" plot --csv "$OUT/$f.csv" --summary "$OUT/$f.json" --out docs/img --name "repro_$f" \
    --figure all --width 900 --height 640
done

echo "== $SEEDS seeds at lambda = 0.2"
"$RECRUIT" sweep --task "$TASK" --out "$OUT/seeds_output" --dT 0.5,2.0 --lambda 0.2 \
  --estimator output --seeds "$SEEDS"
"$RECRUIT" sweep --task "$TASK" --out "$OUT/seeds_kalman" --dT 0.5 --lambda 0.2 \
  --estimator kalman-augmented --seeds "$SEEDS" "${FM[@]}"

# The claims, from the sweeps' table.csv (columns: dT,lambda,estimator,seeds,overshoot_mean,
# overshoot_sd,settling_time_mean,settled_fraction,...,estimator_within3_mean = 15).
cell() {  # cell FILE DT COLUMN
  awk -F, -v dt="$2" -v c="$3" 'NR > 1 && $1 == dt { print $c }' "$1"
}
os_o05=$(cell "$OUT/seeds_output/table.csv" 0.5 5)
os_o2=$(cell "$OUT/seeds_output/table.csv" 2 5)
st_o2=$(cell "$OUT/seeds_output/table.csv" 2 7)
os_k05=$(cell "$OUT/seeds_kalman/table.csv" 0.5 5)
st_k05=$(cell "$OUT/seeds_kalman/table.csv" 0.5 7)
w3_k05=$(cell "$OUT/seeds_kalman/table.csv" 0.5 15)
awk -v a="$os_o05" -v b="$os_o2" -v c="$os_k05" -v s2="$st_o2" -v sk="$st_k05" -v w="$w3_k05" \
  -v n="$SEEDS" 'BEGIN {
  printf "mean step overshoot over %d seeds: output dT=0.5: %.1f %%, output dT=2.0: %.1f %%, kalman dT=0.5: %.1f %%\n", n, 100*a, 100*b, 100*c
  printf "mean settling time (10 %% band): output dT=2.0: %.2f s, kalman dT=0.5: %.2f s (ratio %.2f)\n", s2, sk, s2/sk
  printf "kalman dT=0.5: estimated on-count within 3 units of the truth in %.1f %% of control instants\n", 100*w
  printf "claim 1 (output dT=0.5 overshoots >= 10 %% and >= 3x dT=2.0): %s\n", (a >= 0.10 && a >= 3*b) ? "holds" : "FAILS"
  printf "claim 2 (kalman dT=0.5 overshoot <= output dT=2.0): %s\n", (c <= b) ? "holds" : "FAILS"
  printf "claim 3 (kalman dT=0.5 settles >= 1.5x faster than output dT=2.0): %s\n", (s2 >= 1.5*sk) ? "holds" : "FAILS"
  printf "claim 4 (within 3 units in >= 90 %% of samples): %s\n", (w >= 0.9) ? "holds" : "FAILS"
}' | tee "$OUT/claims.txt"

echo "== dT x lambda sweeps (stability maps)"
"$RECRUIT" sweep --task "$TASK" --out "$OUT/map_output" --dT 0.25,0.5,1.0,2.0 \
  --lambda 0.1,0.2,0.35,0.5 --estimator output --seeds "${MAP_SEEDS:-5}"
"$RECRUIT" plot --stability-map "$OUT/map_output/stability.dat" --out docs/img \
  --name sweep_stability_output --width 920 --height 420 \
  --title "isometric_paper, output only: mean step overshoot (%), ring = meets criterion"
"$RECRUIT" sweep --task "$TASK" --out "$OUT/map_kalman" --dT 0.5,2.0 \
  --lambda 0.1,0.2,0.35,0.5 --estimator kalman-augmented --seeds "${MAP_SEEDS:-5}" "${FM[@]}"
"$RECRUIT" plot --stability-map "$OUT/map_kalman/stability.dat" --out docs/img \
  --name sweep_stability_kalman --width 920 --height 420 \
  --title "isometric_paper, Kalman filter: mean step overshoot (%), ring = meets criterion"
arm_figures
echo "done: $OUT, docs/img/repro_*.png, docs/img/sweep_*.png"
