#!/usr/bin/env bash
# Makes docs/img/fig4_step.png: runs the Fig. 4 step on models/isometric_bench.xml and plots it
# with `recruit plot --panel` (no gnuplot). The step figures (peak, 75 %, settling, relaxation)
# are printed on stderr.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build --target sma_fig4_step recruit >/dev/null
csv=$(mktemp /tmp/fig4.XXXXXX.csv)
trap 'rm -f "$csv"' EXIT
./build/plugin/sma_fig4_step models/isometric_bench.xml 12 20 > "$csv"
./build/src/cli/recruit plot --csv "$csv" --out docs/img --name fig4_step --width 900 \
  --height 420 \
  --title "Isometric bench, 60 SMA units: all switched on at t = 1 s, off at t = 12 s" \
  --panel "force (N)=tension,load_cell_force,on*0.5" \
  --panel "mean temperature (C)=mean_temperature" \
  --panel "mean martensite fraction=mean_xi" >/dev/null
echo "wrote docs/img/fig4_step.png" >&2
