#!/usr/bin/env python3
"""The replay criterion's calibration and check (docs/replay.md, "Criterion").

Makes bench logs with `recruit simulate` on the project's tasks, on their own plant ("same") or on
a copy whose every bundle has one unit parameter changed, replays each against the project's task
with `recruit replay` (default settings), and prints per log the largest normalised RMSE ratio of
the level and of the increments over its signals, and whether it was flagged.

    python3 tests/replay/calibrate.py --seeds 1-10 --variants same --out /tmp/cal
    python3 tests/replay/calibrate.py --seeds 11-13 --variants same,current=0.153,current=0.145 \\
        --out /tmp/val

Run from the repository root after `bash scripts/build.sh recruit`.
"""
import argparse, json, os, re, subprocess, sys

TASKS = ["isometric_steps", "arm_lift", "arm_reach_hold", "arm_push"]


def seeds(spec):
    out = []
    for part in spec.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    return out


def variant_task(root, out, task, variant):
    """The task file for `variant` ("same" or "key=value")."""
    path = f"{root}/models/tasks/{task}.json"
    if variant == "same":
        return path
    key, value = variant.split("=")
    j = json.load(open(path))
    model = os.path.normpath(os.path.join(os.path.dirname(path), j["model"]))
    text = open(model).read()
    text = re.sub(r'(<config key="units" value="[0-9]+"/>)', rf'\1<config key="{key}" value="{value}"/>', text)
    os.makedirs(f"{out}/models", exist_ok=True)
    j["model"] = f"{out}/models/{key}{value}_{os.path.basename(model)}"
    open(j["model"], "w").write(text)
    p = f"{out}/models/{key}{value}_{task}.json"
    json.dump(j, open(p, "w"))
    return p


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="1-3")
    ap.add_argument("--variants", default="same")
    ap.add_argument("--tasks", default=",".join(TASKS))
    ap.add_argument("--estimator", default="output", help="the controller that made the logs")
    ap.add_argument("--out", required=True)
    ap.add_argument("--recruit", default="build/src/cli/recruit")
    a = ap.parse_args()
    root = os.getcwd()
    for task in a.tasks.split(","):
        for variant in a.variants.split(","):
            tp = variant_task(root, a.out, task, variant)
            for s in seeds(a.seeds):
                d = f"{a.out}/{task}_{variant}_s{s}"
                subprocess.run([a.recruit, "simulate", "--task", tp, "--seed", str(s), "--estimator",
                                a.estimator, "--out", d, "--csv-every", "1000"], check=True,
                               capture_output=True)
                subprocess.run([a.recruit, "replay", "--log", f"{d}/{task}_steps.csv", "--task",
                                f"{root}/models/tasks/{task}.json", "--out", d, "--prefix", "r"],
                               check=True, capture_output=True)
                j = json.load(open(f"{d}/r_replay.json"))
                level = max(x["rmse_ratio"] for x in j["signals"])
                step = max(x["step_ratio"] for x in j["signals"])
                print(f"{task:16s} {variant:16s} seed {s:3d}  level {level:6.2f}  increments "
                      f"{step:5.2f}  flagged {j['flagged']}", flush=True)


if __name__ == "__main__":
    sys.exit(main())
