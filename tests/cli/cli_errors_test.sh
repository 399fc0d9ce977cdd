#!/bin/sh
# End-to-end checks of the error policy of `recruit` (docs/reliability.md), one case per call:
#   cli_errors_test.sh RECRUIT SOURCE_DIR WORK_DIR CASE
# Each case runs the real binary and checks its exit code, its message and the files it left.
set -u
RECRUIT=$1
SRC=$2
WORK=$3/$4
CASE=$4
rm -rf "$WORK" && mkdir -p "$WORK" || exit 1
cd "$WORK" || exit 1
TASK=$SRC/models/tasks/isometric_steps.json
MODEL=$SRC/models/isometric_bench.xml

fail() { echo "FAIL [$CASE]: $*"; echo "--- stderr:"; head -c 2000 err 2>/dev/null; exit 1; }
# expect CODE COMMAND...: runs the command, stderr into ./err, checks the exit code.
expect() {
  want=$1; shift
  "$@" > out 2> err
  got=$?
  [ "$got" -eq "$want" ] || fail "exit $got, expected $want: $(echo "$*" | cut -c1-300)"
}
# A copy of the test task with one field replaced (python3 edits the JSON).
task_with() {
  python3 - "$TASK" "$MODEL" "$1" "$2" > "$3" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))
t["model"] = sys.argv[2]
t[sys.argv[3]] = json.loads(sys.argv[4])
print(json.dumps(t))
PY
}

case $CASE in
usage_range)  # range errors: exit 2, say what is allowed, never print DBL_MAX
  for bad in "--dT -1" "--dT nan" "--dT inf" "--lambda 2" "--duration 0"; do
    expect 2 "$RECRUIT" simulate --task "$TASK" $bad --out o
    grep -q "1.79769e+308\|1.7976931348623157e+308" err && fail "DBL_MAX printed for $bad"
    grep -q "must be" err || fail "no 'must be' for $bad"
  done
  expect 2 "$RECRUIT" sweep --task "$TASK" --seeds 0 --out o
  expect 2 "$RECRUIT" sweep --task "$TASK" --estimator bogus --out o
  for bad in -0.5 2000; do  # the controller's rule for dT (control/sampling_period.h)
    expect 2 "$RECRUIT" identify --dt $bad
    grep -q "1.79769e+308" err && fail "DBL_MAX printed by identify"
    grep -q "must be a finite number > 0 and <= 1000" err || fail "identify --dt $bad: no rule"
  done
  for bad in "--stroke-use 0.1" "--stroke-use 1" "--units-per-holding-force -1" \
    "--damping-ratio -0.5" "--damping-ratio nan"; do
    expect 2 "$RECRUIT" attach "$SRC/models/arm2j_muscle.xml" --muscles all $bad -o o
    grep -q "must be\|not in range\|allowed" err || fail "attach $bad: no rule"
  done
  [ ! -e o ] || fail "a usage error created --out"
  ;;
usage_same_code_everywhere)  # an unknown option and a missing input: 2 for every command
  for c in simulate sweep render identify filter plot replay; do
    expect 2 "$RECRUIT" $c --no-such-option
  done
  expect 2 "$RECRUIT" simulate --task /no/such/task.json
  expect 2 "$RECRUIT" filter --model /no/such.json --log /no/such.csv --out x.csv
  expect 0 "$RECRUIT"  # no command: the help (cli_version checks its text)
  expect 0 "$RECRUIT" --help
  ;;
filter_plant_mismatch)  # filter --plant: a model identified on another plant is refused (3)
  BENCH_MODEL=$SRC/models/identified/bundle_903e47abb54d0604_dt0.5_m20.json
  awk -F, 'NR==1{print "t,p_on,p_off,y"; next} NR<=200{print $1","$2","$3","$4}' \
    "$SRC/models/identified/bench_n60_dt0.5_log.csv" > log.csv
  expect 3 "$RECRUIT" filter --model "$BENCH_MODEL" --log log.csv --out f.csv \
    --plant "$SRC/models/elbow_arm.xml" --actuator flexor
  grep -q "identified on another plant" err || fail "no plant mismatch message"
  grep -q "series 1 vs 6" err || fail "the differing unit parameters are not named"
  [ ! -e f.csv ] || fail "filter wrote on a refused model"
  expect 0 "$RECRUIT" filter --model "$BENCH_MODEL" --log log.csv --out f.csv \
    --plant "$SRC/models/isometric_bench.xml"
  [ -s f.csv ] || fail "no output on the matching plant"
  ;;
long_value_shortened)  # a huge option value is not echoed whole
  big=$(python3 -c "print('9x' * 50000)")
  expect 2 "$RECRUIT" simulate --task "$TASK" --dT "$big" --out o
  [ "$(wc -c < err)" -lt 400 ] || fail "message of $(wc -c < err) bytes"
  ;;
bad_input_code)  # bad file content: exit 3 (task and filter model), message names the field
  task_with controller '{"estimator": "output", "dT": 1.0, "lambda": 7}' bad.json
  expect 3 "$RECRUIT" simulate --task bad.json --out o
  grep -q "lambda" err || fail "field not named"
  printf '{"states": [' > model.json
  printf 't,y\n0,1\n' > log.csv
  expect 3 "$RECRUIT" filter --model model.json --log log.csv --out f.csv
  [ ! -e f.csv ] || fail "filter wrote on error"
  # A filter model's fields are checked in the words of task and sweep files: file.key, the
  # value, what is allowed (src/common/json_fields.h).
  good='"states": ["off", "on"], "H": [[0, 0.45]], "R": [[0.09]], "transition": {"type": "explicit"}'
  for bad in '"N": 60, "Hx": 1|model.json: unknown field '"'"'Hx'"'"'; allowed: G, H, N' \
             '"N": -3|model.json.N: -3; allowed: a whole number of agents >= 1' \
             '"N": "60"|model.json.N: "60"; allowed: a whole number of agents >= 1'; do
    printf '{%s, %s}' "$good" "${bad%%|*}" > model.json
    expect 3 "$RECRUIT" filter --model model.json --log log.csv --out f.csv
    grep -qF "${bad#*|}" err || fail "no '${bad#*|}'"
  done
  [ ! -e f.csv ] || fail "filter wrote on error"
  ;;
io_code)  # an output that cannot be written, an input that cannot be read: exit 4
  expect 4 "$RECRUIT" simulate --task "$TASK" --duration 2 --out o --summary /proc/nonexistent/s.json
  # A socket exists (so the options' existence checks pass) but cannot be opened, even by root.
  python3 -c "import socket; socket.socket(socket.AF_UNIX).bind('sock')" || fail "no socket"
  expect 4 "$RECRUIT" simulate --task sock --out o
  expect 4 "$RECRUIT" filter --model sock --log sock --out f.csv
  expect 4 "$RECRUIT" identify --log sock -o m.json
  expect 4 "$RECRUIT" replay --log sock --task "$TASK" --out r  # was 3: the class was lost
  grep -q "cannot open 'sock'" err || fail "replay does not say it cannot open the log"
  expect 4 "$RECRUIT" export --task "$TASK" --estimator kalman-augmented --filter-model sock \
    --out ex  # was 3: the class was lost
  [ ! -e ex ] || fail "export wrote on an I/O error"
  ;;
name_escape)  # a task name with .., / or an absolute path never writes outside --out
  for name in '"../escaped"' '"/tmp/recruit_abs_escape"' '"a/b"' '"x\u001b[2J"'; do
    task_with name "$name" t.json
    expect 3 "$RECRUIT" simulate --task t.json --duration 2 --out od
    grep -q "cannot be used in a file name" err || fail "unclear message for $name"
  done
  [ ! -e escaped_steps.csv ] && [ ! -e escaped_summary.json ] || fail "wrote outside --out"
  [ ! -e /tmp/recruit_abs_escape_steps.csv ] || fail "wrote to an absolute path"
  [ ! -e od ] || fail "created or wrote into --out on error"
  ;;
input_not_overwritten)  # --csv / --summary / render --out equal to an input are refused
  cp "$TASK" task.json
  sed -i "s|\"../isometric_bench.xml\"|\"$MODEL\"|" task.json
  cp task.json before.json
  expect 2 "$RECRUIT" simulate --task task.json --duration 2 --csv task.json
  expect 2 "$RECRUIT" simulate --task task.json --duration 2 --summary ./task.json
  ln -s task.json link.json
  expect 2 "$RECRUIT" simulate --task task.json --duration 2 --csv link.json
  grep -q "refusing to overwrite an input" err || fail "unclear message"
  expect 2 "$RECRUIT" render --task task.json --duration 1 --out task.json
  cmp -s task.json before.json || fail "the task file changed"
  ;;
sigterm_cleans_up)  # a killed simulate leaves no temporary files and dies of SIGTERM
  "$RECRUIT" simulate --task "$TASK" --duration 3000 --out o > out 2> err &
  pid=$!
  i=0
  while [ -z "$(ls o 2>/dev/null | grep '\.tmp\.')" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i+1)); done
  [ -n "$(ls o | grep '\.tmp\.')" ] || fail "no temporary file appeared to test with"
  kill -TERM $pid
  wait $pid
  rc=$?
  [ $rc -eq 143 ] || fail "exit status $rc, expected 143 (killed by SIGTERM)"
  [ -z "$(ls o | grep '\.tmp\.')" ] || fail "left $(ls o)"
  ;;
no_render_libs)  # only the commands that draw load the drawing libraries (cairo, libav, GL)
  # LD_DEBUG=files lists every shared object the loader maps, linked or opened later.
  libs() { grep -o 'file=[^ ]*' err | sed 's/file=//' | sort -u; }
  drawing='cairo|libav|OSMesa|libGL|libEGL|pixman|png16|freetype'
  LD_DEBUG=files expect 0 "$RECRUIT" --help
  libs | grep -E "$drawing" && fail "--help maps drawing libraries"
  LD_DEBUG=files expect 0 "$RECRUIT" simulate --task "$TASK" --duration 2 --dT 0.5 --estimator output --out s
  libs | grep -E "$drawing" && fail "simulate maps drawing libraries"
  cut -d, -f1-4 s/isometric_steps_steps.csv | head -200 > log.csv
  LD_DEBUG=files "$RECRUIT" filter --model /no/such.json --log log.csv --out f.csv > out 2> err
  libs | grep -E "$drawing" && fail "filter maps drawing libraries"
  # The control: a sweep draws its figures (the plot module maps cairo), and its stability map
  # is made without gnuplot (PATH without it).
  PATH=/nonexistent LD_DEBUG=files expect 0 "$RECRUIT" sweep --task "$TASK" --duration 2 --dT 0.5,1 --estimator output --seeds 1 --threads 1 --out w
  libs | grep -q cairo || fail "the sweep's figures did not load cairo (is the check blind?)"
  [ -s w/stability.png ] && [ -s w/margin.png ] || fail "sweep figures missing: $(ls w)"
  ;;
sweep_lock)  # a second sweep into a locked folder fails at once with a clear message
  mkdir s
  expect 4 flock s/sweep.lock "$RECRUIT" sweep --task "$TASK" --duration 4 --dT 1 \
    --estimator output --seeds 1 --out s
  grep -q "another sweep is writing into this folder" err || fail "unclear message"
  [ ! -e s/runs ] || fail "the locked-out sweep wrote runs"
  ;;
sweep_edited_task_reruns)  # resume reuses runs only when the task content is unchanged
  sed "s|\"../isometric_bench.xml\"|\"$MODEL\"|" "$TASK" > task.json
  args="sweep --task task.json --duration 4 --dT 1 --estimator output --seeds 2 --out s"
  expect 0 "$RECRUIT" $args
  grep -q "2 runs made, 0 reused" out || fail "first sweep: $(cat out)"
  expect 0 "$RECRUIT" $args
  grep -q "0 runs made, 2 reused" out || fail "unchanged task not reused: $(cat out)"
  sed -i 's/"lambda": 0.2/"lambda": 0.3/' task.json
  expect 0 "$RECRUIT" $args
  grep -q "2 runs made, 0 reused" out || fail "edited task served stale runs: $(cat out)"
  [ -z "$(find s -name '*.tmp.*')" ] || fail "temporary files left"
  ;;
replay_errors)  # replay: bad log content 3, outputs that would replace an input or escape 2
  printf 'time,bundle.p_on,bundle.p_off,bundle.sensed_force\n0,0.2,0,0\n1,0.2,0,nan\n' > b.csv
  expect 3 "$RECRUIT" replay --log b.csv --task "$TASK" --out o
  grep -q "b.csv:3: column 'bundle.sensed_force': 'nan'" err || fail "cell not named"
  printf 'time,flexor.p_on,flexor.p_off,flexor.sensed_force\n0,0.2,0,0\n1,0.2,0,1\n' > f.csv
  expect 3 "$RECRUIT" replay --log f.csv --task "$TASK" --out o
  grep -q "no columns for the task's bundle 'bundle'" err || fail "missing bundle not named"
  [ ! -e o ] || fail "replay created --out on error"
  printf 'time,bundle.p_on,bundle.p_off,bundle.sensed_force\n0,0.2,0,0\n1,0.2,0,1\n2,0,0,2\n' > r_replay.csv
  cp r_replay.csv before.csv
  expect 2 "$RECRUIT" replay --log r_replay.csv --task "$TASK" --prefix r --out .
  grep -q "refusing to overwrite an input" err || fail "unclear message"
  cmp -s r_replay.csv before.csv || fail "the log changed"
  expect 2 "$RECRUIT" replay --log r_replay.csv --task "$TASK" --prefix ../x --out o
  expect 2 "$RECRUIT" replay --log r_replay.csv --task "$TASK" --seeds 2 --out o
  [ ! -e o ] && [ ! -e ../x_replay.json ] || fail "wrote on a usage error"
  expect 0 "$RECRUIT" replay --log r_replay.csv --task "$TASK" --seeds 3 --out o
  [ "$(ls o | wc -l)" -eq 3 ] || fail "outputs: $(ls o)"
  ;;
mujoco_warnings)  # MuJoCo's warnings on stderr, each once, never into MUJOCO_LOG.TXT here
  mkdir written
  expect 0 "$RECRUIT" attach "$SRC/tests/attach/data/jump_arm.xml" --muscles all -o written/m.xml
  [ "$(grep -c "^WARNING: recruit.sma actuator 'ext': tendon path jumps" err)" -eq 1 ] ||
    fail "the fit warning not printed exactly once"
  [ ! -e MUJOCO_LOG.TXT ] || fail "MUJOCO_LOG.TXT written in the working folder"
  [ "$(ls | tr '\n' ' ')" = "err out written " ] || fail "files left: $(ls | tr '\n' ' ')"
  ;;
*)
  echo "unknown case $CASE"; exit 1 ;;
esac
echo "ok [$CASE]"
