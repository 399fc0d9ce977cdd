#!/usr/bin/env python3
"""How a task's steps spread over seeds: settled steps and the mean, 90th percentile and worst
overshoot, and the steps above 20 %, per task and dT (the worst alone, which eval_tasks.py
prints, moves a lot from one seed to the next). Usage:
  step_spread.py [--recruit BIN] [--seeds 711-730] [--dT 1,0.5] [--lambda 0.2] TASK.json...
"""
import argparse, json, os, statistics, subprocess, tempfile


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("tasks", nargs="+")
    ap.add_argument("--recruit", default="build/src/cli/recruit")
    ap.add_argument("--seeds", default="711-730")
    ap.add_argument("--dT", default="1,0.5")
    ap.add_argument("--lambda", dest="lam", default="0.2")
    a = ap.parse_args()
    lo, hi = (int(x) for x in a.seeds.split("-"))
    with tempfile.TemporaryDirectory() as tmp:
        for task in a.tasks:
            for dT in a.dT.split(","):
                over, settled = [], 0
                for seed in range(lo, hi + 1):
                    out = os.path.join(tmp, "s.json")
                    r = subprocess.run([a.recruit, "simulate", "--task", task, "--seed", str(seed),
                                        "--dT", dT, "--lambda", a.lam, "--csv",
                                        os.path.join(tmp, "s.csv"), "--summary", out],
                                       capture_output=True, text=True)
                    if r.returncode != 0:
                        print(task, dT, seed, "FAILED", r.stderr[-300:])
                        continue
                    for st in json.load(open(out))["steps"]:
                        over.append(st["overshoot"])
                        settled += st["settled"]
                if not over:
                    continue
                over.sort()
                print(f"{os.path.basename(task)} dT {dT}: settled {settled}/{len(over)}, overshoot "
                      f"mean {statistics.mean(over):.3f} p90 {over[int(0.9 * len(over))]:.3f} "
                      f"worst {over[-1]:.3f}, above 20 % {sum(o > 0.2 for o in over)}")


if __name__ == "__main__":
    main()
