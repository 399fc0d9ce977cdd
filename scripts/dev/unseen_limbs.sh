#!/usr/bin/env bash
# Issue 24's "limbs the tests never saw": the user's flow (docs/howto-own-model.md) on MuJoCo's
# arm26 and two MyoSuite limbs that no test, doc example or dev script uses. For each case:
# `recruit attach` (its printout kept), then the starter task at dT 1 and 0.5 (lambda 0.2, the
# task's Kalman estimator) on SEEDS, scored by scripts/dev/eval_tasks.py; every run's summary is
# kept and tabled (settled steps, worst overshoot, NEES, count within band, warnings, datasheet
# limits, run and identification time).
# Usage: scripts/dev/unseen_limbs.sh OUT_DIR [SEEDS] [CASE...]   (SEEDS like 601-603)
# Cases (default: all): arm26_elbow (EF, EE; shoulder locked), arm26_all (six bundles, both
# joints), arm26_all_f150 (the same at --force 150: every bundle of 0.127 mm wire, none of the
# 0.51 mm wire F0 gives SF and BF), myoelbow2_all (MyoSuite's 2-dof elbow, six bundles, shoulder
# and elbow driven), myoelbow2_elbow (the same, shoulder locked), myolegs_ankle (OSL legs model,
# left ankle: soleus and tibialis anterior, subtalar locked), myolegs_ankle_pinned (the same with
# the pelvis held by a hand edit).
# arm26.xml is taken from the mujoco-mjx wheel on PyPI (mujoco/mjx/test_data/actuator/arm26.xml;
# the mujoco wheel has no model/ folder), downloaded to a temporary folder; ARM26=PATH skips that.
# MyoSuite's models are used where myo-sim 0.2.3 installed them (.venv), never copied.
# About 15 min on one core (the legs model's two identifications take 6.5 min of it).
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$(mkdir -p "$1" && cd "$1" && pwd)
SEEDS=${2:-601-603}
shift $(($# < 2 ? $# : 2))
CASES=${*:-arm26_elbow arm26_all arm26_all_f150 myoelbow2_all myoelbow2_elbow myolegs_ankle myolegs_ankle_pinned}
ROOT=$PWD
R=$ROOT/build/src/cli/recruit
PY=$ROOT/.venv/bin/python
M=$($PY -c "import myo_sim, os; print(os.path.dirname(myo_sim.__file__))")/models

if [ -z "${ARM26:-}" ]; then
  TMP=$(mktemp -d)
  trap 'rm -rf "$TMP"' EXIT
  $PY -m pip download --quiet --no-deps mujoco-mjx==3.17.0 -d "$TMP" >/dev/null
  unzip -q -o -j "$TMP"/mujoco_mjx-3.17.0-*.whl mujoco/mjx/test_data/actuator/arm26.xml -d "$OUT"
  ARM26=$OUT/arm26.xml
fi

# Identified filter models go to OUT (RECRUIT_MODEL_CACHE), so that the first run of each case
# and dT identifies them, as a new user's does, and the table's identification time is real.
export RECRUIT_MODEL_CACHE=${RECRUIT_MODEL_CACHE:-$OUT/identified}

# A stand-in for `recruit` that eval_tasks.py runs: it runs the real one and keeps each run's
# summary, stderr and wall time (identification included) under OUT/runs/.
mkdir -p "$OUT/runs"
cat >"$OUT/runs/recruit_keep.sh" <<EOF
#!/usr/bin/env bash
args=("\$@"); task= seed= dT= sum=
while [ \$# -gt 0 ]; do
  case \$1 in --task) task=\$2 ;; --seed) seed=\$2 ;; --dT) dT=\$2 ;; --summary) sum=\$2 ;; esac
  shift
done
key="$OUT/runs/\$(basename "\$task" .json)_dT\${dT}_s\${seed}"
t0=\$(date +%s.%N)
"$R" "\${args[@]}" 2>"\$key.log"; rc=\$?
echo "\$(date +%s.%N) - \$t0" | bc >"\$key.time"
cat "\$key.log" >&2
[ \$rc -eq 0 ] && cp "\$sum" "\$key.json"
exit \$rc
EOF
chmod +x "$OUT/runs/recruit_keep.sh"

# attach NAME MODEL ARGS...: the user's command; its printout (stdout and stderr) and exit code.
attach() {
  local name=$1 model=$2
  shift 2
  local rc=0
  (cd "$OUT" && "$R" attach "$model" "$@" -o "$name.xml" --task "${name}_task.json" \
    --report "${name}_report.json") >"$OUT/${name}_attach.txt" 2>&1 || rc=$?
  echo "attach $name: exit $rc ($OUT/${name}_attach.txt)"
  return $rc
}

for c in $CASES; do
  case $c in
    arm26_elbow)
      # As a user would: first without --lengthrange-from-joints (the kept muscles fail
      # MuJoCo's lengthrange computation), then with it.
      attach arm26_elbow_nolr "$ARM26" --muscles EF,EE --lock shoulder || true
      attach arm26_elbow "$ARM26" --muscles EF,EE --lock shoulder --lengthrange-from-joints ;;
    arm26_all) attach arm26_all "$ARM26" --muscles all ;;
    arm26_all_f150) attach arm26_all_f150 "$ARM26" --muscles all --force 150 ;;
    myoelbow2_all)
      attach myoelbow2_all "$M/legacy/elbow/myoelbow_2dof6muscles.xml" --muscles all ;;
    myoelbow2_elbow)
      attach myoelbow2_elbow "$M/legacy/elbow/myoelbow_2dof6muscles.xml" --muscles all \
        --lock r_shoulder_elev ;;
    myolegs_ankle)
      # The left (biological) ankle of the OSL legs model: soleus and tibialis anterior, the
      # subtalar joint they also cross held.
      attach myolegs_ankle "$M/legacy/osl/myolegs_osl.xml" --muscles soleus_l,tibant_l \
        --lock subtalar_angle_l ;;
    myolegs_ankle_pinned)
      # The same with the pelvis held (a hand edit attach cannot make: --lock takes hinges and
      # slides only): the root free joint and the keyframes deleted through mjSpec, else the
      # body falls and the ankle is stepped lying on the floor.
      attach myolegs_ankle "$M/legacy/osl/myolegs_osl.xml" --muscles soleus_l,tibant_l \
        --lock subtalar_angle_l
      (cd "$OUT" && $PY - "$ROOT/build/plugin/librecruit_sma.so" <<'PIN'
import json, sys
import mujoco
mujoco.mj_loadPluginLibrary(sys.argv[1])
s = mujoco.MjSpec.from_file("myolegs_ankle.xml")
s.delete(s.joint("root"))
for k in list(s.keys):
    s.delete(k)
s.compile()
open("myolegs_ankle_pinned.xml", "w").write(s.to_xml())
t = json.load(open("myolegs_ankle_task.json"))
t["model"], t["name"] = "myolegs_ankle_pinned.xml", "myolegs_ankle_pinned_steps"
json.dump(t, open("myolegs_ankle_pinned_task.json", "w"), indent=2)
PIN
      ) ;;
    *) echo "unknown case $c" >&2; exit 2 ;;
  esac
  python3 scripts/dev/eval_tasks.py --recruit "$OUT/runs/recruit_keep.sh" --seeds "$SEEDS" \
    --dT 1,0.5 "$OUT/${c}_task.json" 2>&1 | tee "$OUT/${c}_eval.txt"
done

# The table: one row per case and dT over the seeds' runs.
$PY - "$OUT" "$SEEDS" $CASES <<'EOF' | tee "$OUT/table.md"
import glob, json, os, sys
out, seeds, cases = sys.argv[1], sys.argv[2], sys.argv[3:]
lo, hi = (int(x) for x in seeds.split("-"))
print("| case | bundles | dT (s) | settled | worst overshoot | NEES | count within band (min) "
      "| within 3 units (min) | peak T (C) / stress (MPa) | limits exceeded | summary warnings "
      "| run s (sim) | identification s (first run) |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for c in cases:
    for dT in ("1", "0.5"):
        runs = []
        for s in range(lo, hi + 1):
            f = os.path.join(out, "runs", f"{c}_task_dT{dT}_s{s}.json")
            if os.path.exists(f):
                runs.append(json.load(open(f)))
        if not runs:
            print(f"| {c} | | {dT} | no run | | | | | | | | | |")
            continue
        steps = [st for r in runs for st in r["steps"]]
        b = [x for r in runs for x in r["bundles"]]
        nees = [x["mean_nees"] for x in b if x["mean_nees"] is not None]
        over = [f'{x["actuator"]} {x["peak_temperature"]:.0f} C {x["peak_wire_stress"]/1e6:.0f} MPa'
                for x in b if x["peak_temperature"] > x["max_temperature"]
                or x["peak_wire_stress"] > x["max_wire_stress"]]
        warns = sorted({w for r in runs for w in r["warnings"]})
        print(f'| {c} | {len(runs[0]["bundles"])} | {dT} | '
              f'{sum(st["settled"] for st in steps)}/{len(steps)} | '
              f'{100*max(st["overshoot"] for st in steps):.1f} % | '
              f'{min(nees):.2f}..{max(nees):.2f} | '
              f'{min(x["estimator_within_band"] for x in b):.3f} | '
              f'{min(x["estimator_within3"] for x in b):.3f} | '
              f'{max(x["peak_temperature"] for x in b):.1f} / '
              f'{max(x["peak_wire_stress"] for x in b)/1e6:.0f} | '
              f'{"; ".join(sorted(set(over))) or "none"} | {len(warns)} | '
              f'{min(r["wall_seconds"] for r in runs):.2f}..{max(r["wall_seconds"] for r in runs):.2f} | '
              f'{max(r["identification_seconds"] for r in runs):.1f} |')
print()
print("Per bundle (worst over seeds; NEES range, least fraction within band):")
for c in cases:
    for dT in ("1", "0.5"):
        per = {}
        for f in sorted(glob.glob(os.path.join(out, "runs", f"{c}_task_dT{dT}_s*.json"))):
            for x in json.load(open(f))["bundles"]:
                per.setdefault(x["actuator"], []).append(x)
        print(f"  {c} dT {dT}: " + ", ".join(
            f'{a} {min(x["mean_nees"] for x in v):.2f}..{max(x["mean_nees"] for x in v):.2f}'
            f'/{min(x["estimator_within_band"] for x in v):.3f}' for a, v in per.items()))
print()
print("Per joint (settled steps, worst overshoot, tracking RMSE range):")
for c in cases:
    for dT in ("1", "0.5"):
        per = {}
        for f in sorted(glob.glob(os.path.join(out, "runs", f"{c}_task_dT{dT}_s*.json"))):
            for j in json.load(open(f))["joints"]:
                per.setdefault(j["joint"], []).append(j)
        print(f"  {c} dT {dT}: " + ", ".join(
            f'{n} {round(sum(j["settled_fraction"] * j["num_steps"] for j in v))}/'
            f'{sum(j["num_steps"] for j in v)} {100*max(j["max_overshoot"] for j in v):.0f} % '
            f'{min(j["tracking_rmse"] for j in v)*57.2958:.1f}..'
            f'{max(j["tracking_rmse"] for j in v)*57.2958:.1f} deg' for n, v in per.items()))
times = sorted(glob.glob(os.path.join(out, "runs", "*.time")))
if times:
    print()
    print("Wall time per run, identification included (s): " + ", ".join(
        f'{os.path.basename(t)[:-5]} {float(open(t).read()):.1f}' for t in times))
print()
print("Designs (recruit attach --report):")
for c in cases:
    if not os.path.exists(os.path.join(out, f"{c}_report.json")):
        continue
    rep = json.load(open(os.path.join(out, f"{c}_report.json")))
    for x in rep["bundles"]:
        k = {key: float(v) for key, v in x["config"].items()}  # MJCF config values: text
        print(f'  {c} {x["name"]}: F {x["peak_force"]:.0f} N, {k["units"]:.0f} units x {k["parallel"]:.0f}'
              f' x {k["series"]:.0f} of {k["wire_diameter"]*1e3:.3f} mm x {k["wire_length"]*1e3:.0f} mm, '
              f'gear {x["gear"]:.2f}, tau {x["time_constant"]:.1f} s, {x["wire_total"]:.0f} m, '
              f'{x["mass"]*1e3:.0f} g, {x["power"]:.0f} W all on')
EOF
