#!/usr/bin/env python3
"""Whole-process CPU of the arm tasks with their self-tuned loop (models/tasks/) against the same
tasks with hand-set gains (tests/export/data/*_hand.json), alternated run by run: per task the
median CPU (user + sys) of `recruit simulate --task T --seed 3` and the simulated seconds per CPU
second. Usage, from the repository root after `bash scripts/build.sh recruit`:
  python3 scripts/dev/arm_loop_cpu.py [RUNS] [TASK...]     (default 15 arm_push arm_lift arm_reach_hold)
"""
import json, resource, statistics, subprocess, sys, tempfile


def cpu(task, out):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(["build/src/cli/recruit", "simulate", "--task", task, "--seed", "3", "--out",
                    out], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime


def main(argv):
    runs = int(argv[1]) if len(argv) > 1 else 15
    names = argv[2:] or ["arm_push", "arm_lift", "arm_reach_hold"]
    for name in names:
        auto, hand = f"models/tasks/{name}.json", f"tests/export/data/{name}_hand.json"
        duration = json.load(open(auto))["duration"]
        a, h = [], []
        with tempfile.TemporaryDirectory() as out:
            for i in range(runs):
                pair = [(auto, a), (hand, h)] if i % 2 == 0 else [(hand, h), (auto, a)]
                for task, times in pair:
                    times.append(cpu(task, out))
        ma, mh = statistics.median(a), statistics.median(h)
        print(f"{name} ({duration:g} s): self-tuned {1000 * ma:.0f} ms ({duration / ma:.0f}x real "
              f"time), hand-set {1000 * mh:.0f} ms ({duration / mh:.0f}x); ratio {ma / mh:.2f}")


if __name__ == "__main__":
    sys.exit(main(sys.argv))
