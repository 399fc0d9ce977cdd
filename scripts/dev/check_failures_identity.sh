#!/usr/bin/env bash
# Checks that the failure work leaves every existing output bit-identical: runs the four tasks
# with a baseline binary and this tree's, then compares the CSVs (cmp) and the summaries
# (apart from wall_seconds and identification_seconds).
#   scripts/dev/check_failures_identity.sh BASELINE_RECRUIT [OUT_DIR]
set -euo pipefail
base=$1
out=${2:-/tmp/failures-identity}
cd "$(dirname "$0")/../.."
for t in isometric_steps arm_lift arm_reach_hold arm_push; do
  "$base" simulate --task models/tasks/$t.json --seed 3 --out "$out/base/$t" >/dev/null
  build/src/cli/recruit simulate --task models/tasks/$t.json --seed 3 --out "$out/new/$t" >/dev/null
  cmp "$out/base/$t/${t}_steps.csv" "$out/new/$t/${t}_steps.csv"
  python3 - "$out/base/$t/${t}_summary.json" "$out/new/$t/${t}_summary.json" <<'PY'
import json, sys
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in ("wall_seconds", "identification_seconds")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
a, b = (strip(json.load(open(p))) for p in sys.argv[1:])
assert a == b, "summaries differ: " + sys.argv[1]
PY
  echo "$t: identical"
done
