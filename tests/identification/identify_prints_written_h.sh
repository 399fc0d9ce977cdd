#!/bin/sh
# `recruit identify` prints the H it writes: the H column of its table, read as numbers, equals
# the written model file's H exactly, state by state, from the bench (H carried onto the force
# law and clamped to >= 0) and from a switching log (clamped to >= 0).
# Usage: identify_prints_written_h.sh RECRUIT SOURCE_DIR WORK_DIR
set -eu
R=$1
W=$3
cd "$2"
rm -rf "$W"
mkdir -p "$W"
# 60 s: 84 training samples, enough for 20 states (40 s is refused: too few), and the fits
# still clamp some states' H to 0 (heat1, cool6, cool7 and cool9 at seed 1); the
# check is about the printing, not the fit, so the shortest recording that fits will do.
"$R" identify --dt 0.5 --duration 60 --save-log "$W/bench_log.csv" -o "$W/bench.json" \
  > "$W/bench.out" 2> "$W/bench.err"
"$R" identify --log "$W/bench_log.csv" --units 60 -o "$W/log.json" > "$W/log.out"
python3 - "$W" <<'PY'
import json
import sys

w = sys.argv[1]
for name in ("bench", "log"):
    with open(f"{w}/{name}.json") as f:
        model = json.load(f)
    with open(f"{w}/{name}.out") as f:
        lines = f.read().splitlines()
    head = next(i for i, l in enumerate(lines) if l.split()[:3] == ["state", "on", "H"])
    rows = [l.split() for l in lines[head + 1 : head + 1 + len(model["states"])]]
    assert [r[0] for r in rows] == model["states"], (name, rows)
    printed = [float(r[2]) for r in rows]
    written = model["H"][0]
    bad = [(s, p, h) for s, p, h in zip(model["states"], printed, written) if p != h]
    assert not bad, f"{name}: printed != written (state, printed, written): {bad}"
    assert min(written) >= 0, (name, written)
    print(f"{name}: the {len(printed)} printed H equal the written H")
PY
