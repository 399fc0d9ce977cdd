#!/usr/bin/env bash
# Re-identifies the estimator models shipped in models/identified/ for the shipped tasks'
# bundles and sampling periods (docs/identification.md): each held at its longest tendon, checked
# at other lengths and in motion, and named as the model cache names it
# (<actuator>_<unit hash>_dt<dT>_m20.json), so that simulate and sweep find them without
# identifying. Other periods are identified on demand and cached (identification/model_cache.h).
# Usage: scripts/identify_models.sh   (from a build: bash scripts/build.sh recruit)
set -euo pipefail
cd "$(dirname "$0")/.."
RECRUIT=${RECRUIT:-./build/src/cli/recruit}
OUT=models/identified
identify() {  # identify MODEL ACTUATOR DT
  local tmp
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' RETURN
  "$RECRUIT" identify --bench "$1" --actuator "$2" --dt "$3" -o "$tmp/model.json" | tee "$tmp/out.txt"
  local name
  name=$(python3 -c "import json,sys; j=json.load(open('$tmp/model.json'))['identification']; \
print('%s_%s_dt%g_m20.json' % (j['plant']['actuator'], j['plant']['hash'], j['dT']))")
  mv "$tmp/model.json" "$OUT/$name"
  echo "-> $OUT/$name"
}
for dt in 0.5 1.0 2.0; do
  identify models/isometric_bench.xml bundle "$dt"
  identify models/elbow_arm.xml flexor "$dt"
  identify models/elbow_arm.xml extensor "$dt"
done
