#!/usr/bin/env bash
# Makes docs/img/fig4_step.png: runs the Fig. 4 step on models/isometric_bench.xml and plots it.
# The step figures (peak, 75 %, settling, relaxation) are printed on stderr.
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --build build --target sma_fig4_step >/dev/null
csv=$(mktemp /tmp/fig4.XXXXXX.csv)
trap 'rm -f "$csv"' EXIT
./build/plugin/sma_fig4_step models/isometric_bench.xml 12 20 > "$csv"
tmp=docs/img/.fig4_step.png.tmp
gnuplot -e "csv='$csv'; out='$tmp'" scripts/plot_fig4.gp
mv "$tmp" docs/img/fig4_step.png
echo "wrote docs/img/fig4_step.png" >&2
