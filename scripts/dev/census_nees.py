#!/usr/bin/env python3
"""docs/failures.md 'In a task file': tests/sim/data/census_loss.json (the bench holds 15 N, units
fail open at 60.25 s) with 6 and 18 of 60 units lost and a census every 0.5 s (every control
instant), 2.5 s and never, seeds 500-599: the per-run mean on-count NEES (the summary's) and how
many runs have it in [0.3, 2]. Usage, from the repository root after `bash scripts/build.sh
recruit`: python3 scripts/dev/census_nees.py
"""
import json, os, statistics, subprocess, tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def main():
    base = json.load(open(os.path.join(ROOT, "tests/sim/data/census_loss.json")))
    base["model"] = os.path.join(ROOT, "models/isometric_bench.xml")
    with tempfile.TemporaryDirectory() as tmp:
        task = os.path.join(tmp, "cl.json")
        for count in [6, 18]:
            for period in [0.5, 2.5, 0]:
                t = json.loads(json.dumps(base))
                t["controller"]["census_period"] = period
                t["failures"]["bundle"]["schedule"][0]["count"] = count
                json.dump(t, open(task, "w"))
                nees = []
                for seed in range(500, 600):
                    subprocess.run([os.path.join(ROOT, "build/src/cli/recruit"), "simulate", "--task",
                                    task, "--seed", str(seed), "--out", tmp], check=True,
                                   capture_output=True)
                    s = json.load(open(os.path.join(tmp, "census_loss_summary.json")))
                    nees.append(s["bundles"][0]["mean_nees"])
                inside = sum(0.3 <= x <= 2 for x in nees)
                print(f"loss {count}/60, census every {period} s: mean NEES per run median "
                      f"{statistics.median(nees):.2f}, in [0.3, 2]: {inside}/100", flush=True)


if __name__ == "__main__":
    main()
