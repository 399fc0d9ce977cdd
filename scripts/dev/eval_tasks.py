#!/usr/bin/env python3
"""Runs tasks over seeds and dT values and prints, per task and dT, what issue 24 item 5 asks:
the fraction of steps that settle, the worst overshoot, each bundle's mean NEES range and
the least fraction of control instants its count estimate is within 3 units (or 5 % of N),
how many bundle-runs have a mean NEES outside [0.3, 2], warnings; and how the steps' overshoot
spreads (mean, 90th percentile, steps above 20 %: the worst alone moves a lot from one seed to
the next). Usage:
  eval_tasks.py [--recruit BIN] [--seeds 101-110] [--dT 1,0.5] [--override-auto] TASK.json...
"""
import argparse, json, os, statistics, subprocess, sys, tempfile

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("tasks", nargs="+")
    ap.add_argument("--recruit", default="build/src/cli/recruit")
    ap.add_argument("--seeds", default="101-110")
    ap.add_argument("--dT", default="1,0.5")
    ap.add_argument("--override-auto", action="store_true", help="set outer_loop to auto")
    ap.add_argument("--lambda", dest="lam", default="0.2")
    a = ap.parse_args()
    lo, hi = (int(x) for x in a.seeds.split("-"))
    with tempfile.TemporaryDirectory() as tmp:
        for task in a.tasks:
            path = task
            if a.override_auto:
                t = json.load(open(task))
                t["outer_loop"] = "auto"
                t["model"] = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(task)), t["model"]))
                path = os.path.join(tmp, os.path.basename(task))
                json.dump(t, open(path, "w"))
            for dT in a.dT.split(","):
                steps = settled = 0
                worst_os = 0
                overshoots = []
                nees = {}
                within = {}
                warns = set()
                rows = []
                for seed in range(lo, hi + 1):
                    out = os.path.join(tmp, "s.json")
                    r = subprocess.run([a.recruit, "simulate", "--task", path, "--seed", str(seed),
                                        "--dT", dT, "--lambda", a.lam, "--csv", os.path.join(tmp, "s.csv"),
                                        "--summary", out], capture_output=True, text=True)
                    if r.returncode != 0:
                        print(task, dT, seed, "FAILED", r.stderr[-500:])
                        continue
                    s = json.load(open(out))
                    for st in s["steps"]:
                        steps += 1
                        settled += st["settled"]
                        worst_os = max(worst_os, st["overshoot"])
                        overshoots.append(st["overshoot"])
                    for b in s["bundles"]:
                        nees.setdefault(b["actuator"], []).append(b["mean_nees"])
                        within.setdefault(b["actuator"], []).append(b["estimator_within_band"])
                    warns.update(s["warnings"])
                    rows.append((seed, s["metrics"]["settled_fraction"], s["metrics"]["max_overshoot"]))
                print(f"{os.path.basename(task)} dT {dT}: settled {settled}/{steps} "
                      f"({100*settled/max(steps,1):.0f} %), worst overshoot {100*worst_os:.1f} %")
                if overshoots:
                    o = sorted(overshoots)
                    print(f"   steps: overshoot mean {statistics.mean(o):.3f} "
                          f"p90 {o[int(0.9 * len(o))]:.3f}, above 20 % {sum(x > 0.2 for x in o)}")
                outside = total = 0
                for b in nees:
                    v=[x for x in nees[b] if x is not None]; w=[x for x in within[b] if x is not None]
                    outside += sum(not 0.3 <= x <= 2 for x in v); total += len(v)
                    if v: print(f"   {b}: NEES {min(v):.2f}..{max(v):.2f}, within max(3, 5 % N) min {min(w):.3f}")
                if total: print(f"   bundle-runs with mean NEES outside [0.3, 2]: {outside} of {total}")
                if warns: print("   warnings:", sorted(warns)[:5])
                print("   per seed (settled, max os):", " ".join(f"{s}:{f:.2f}/{o:.2f}" for s, f, o in rows))

if __name__ == "__main__":
    main()
