#!/usr/bin/env python3
"""The arm tasks' estimator table of docs/paper-reproduction.md ("Arm tasks"): runs each task
over seeds with its own estimator (the Kalman filter) and with output only, and prints per task
the share of steps settled, the tracking RMSE, and per bundle the range of each run's mean NEES
(median), count RMSE and the lowest share of control instants within 3 units; then the runs
below issue 10's bar (mean NEES < 0.3 or > 2, within 3 units < 95 %), the peak temperature and
wire stress against their limits, and any warning. Usage (from the repository root, after
`bash scripts/build.sh recruit`):
  python3 scripts/dev/arm_tasks_table.py [--seeds 101-110] [TASK.json...]
"""
import argparse, json, os, statistics, subprocess, sys, tempfile

TASKS = ["models/tasks/arm_reach_hold.json", "models/tasks/arm_lift.json",
         "models/tasks/arm_push.json"]


def run(recruit, task, seed, estimator, tmp):
    out = os.path.join(tmp, "s.json")
    cmd = [recruit, "simulate", "--task", task, "--seed", str(seed), "--csv",
           os.path.join(tmp, "s.csv"), "--summary", out]
    if estimator:
        cmd += ["--estimator", estimator]
    subprocess.run(cmd, check=True, capture_output=True)
    return json.load(open(out))


def rng(v, digits=2):
    return f"{min(v):.{digits}f}-{max(v):.{digits}f}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("tasks", nargs="*", default=TASKS)
    ap.add_argument("--seeds", default="101-110")
    ap.add_argument("--recruit", default="build/src/cli/recruit")
    a = ap.parse_args()
    lo, hi = (int(x) for x in a.seeds.split("-"))
    seeds = range(lo, hi + 1)
    print("| task | bundle | Kalman: NEES (median) | Kalman: count RMSE | Kalman: within 3 (min) "
          "| output only: count RMSE | output only: within 3 (min) |")
    print("|---|---|---|---|---|---|---|")
    notes = []
    with tempfile.TemporaryDirectory() as tmp:
        for task in a.tasks:
            name = os.path.splitext(os.path.basename(task))[0]
            kal = [run(a.recruit, task, s, "", tmp) for s in seeds]
            out = [run(a.recruit, task, s, "output", tmp) for s in seeds]
            for i, b in enumerate(kal[0]["bundles"]):
                nees = [r["bundles"][i]["mean_nees"] for r in kal]
                row = [name if i == 0 else "", b["actuator"],
                       f"{rng(nees)} ({statistics.median(nees):.2f})",
                       rng([r["bundles"][i]["estimator_rmse"] for r in kal]),
                       f"{100 * min(r['bundles'][i]['estimator_within3'] for r in kal):.1f} %",
                       rng([r["bundles"][i]["estimator_rmse"] for r in out]),
                       f"{100 * min(r['bundles'][i]['estimator_within3'] for r in out):.1f} %"]
                print("| " + " | ".join(row) + " |")
                for s, r in zip(seeds, kal):
                    bb = r["bundles"][i]
                    if not 0.3 <= bb["mean_nees"] <= 2 or bb["estimator_within3"] < 0.95:
                        notes.append(f"{name} seed {s} {bb['actuator']}: mean NEES "
                                     f"{bb['mean_nees']:.2f}, count RMSE {bb['estimator_rmse']:.2f}, "
                                     f"within 3 {100 * bb['estimator_within3']:.1f} %")
            settled = [statistics.mean(r["metrics"]["settled_fraction"] for r in x)
                       for x in (kal, out)]
            rmse = [r["metrics"]["tracking_rmse"] for r in kal]
            os_k = [r["metrics"]["max_overshoot"] for r in kal]
            temp = max(b["peak_temperature"] for r in kal + out for b in r["bundles"])
            stress = max(b["peak_wire_stress"] for r in kal + out for b in r["bundles"])
            warns = sorted({w for r in kal + out for w in r["warnings"]})
            notes.append(f"{name}: steps settled (mean over seeds) Kalman {settled[0]:.2f} / output "
                         f"{settled[1]:.2f}; tracking RMSE (Kalman) {rng(rmse, 3)} rad; worst "
                         f"overshoot (Kalman) {100 * max(os_k):.1f} %; peak {temp:.1f} C, "
                         f"{stress / 1e6:.1f} MPa; warnings: {warns if warns else 'none'}")
    print()
    for n in notes:
        print(n)


if __name__ == "__main__":
    sys.exit(main())
