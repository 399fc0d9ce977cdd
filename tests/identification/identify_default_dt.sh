#!/bin/sh
# `recruit identify`'s dT: the bench's default is the controller's (control::kDefaultDT, 2 s), and
# a --log's is read from its time column, which also names the default output file.
# Usage: identify_default_dt.sh RECRUIT SOURCE_DIR WORK_DIR
set -eu
R=$1
SRC=$2
W=$3
rm -rf "$W"
mkdir -p "$W/models/identified"
cd "$W"
"$R" identify --help > help.txt
grep -q -- "--dt FLOAT:.*=2$" help.txt || { echo "the default --dt is not 2 s:"; grep -- --dt help.txt; exit 1; }
# A log recorded at dT = 2 s, fitted without --dt and without -o.
"$R" identify --log "$SRC/models/identified/bench_n60_dt2.0_log.csv" --states 4 > log.out
f=models/identified/bench_n60_dt2.0_m4.json
[ -s "$f" ] || { echo "no $f; wrote:"; ls models/identified; exit 1; }
python3 - "$f" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
assert m["transition"]["dt"] == 2.0 and m["identification"]["dT"] == 2.0, m["transition"]["dt"]
print("the log's dT (2 s) is the model's and names its file")
PY
