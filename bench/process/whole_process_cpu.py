#!/usr/bin/env python3
"""Whole-process CPU of two `recruit` binaries, alternated run by run.

For each task, runs `BINARY simulate --task models/tasks/TASK.json --seed 3 --out TMP` N times
with each binary in turn, which one goes first alternating, and prints a Markdown row: the median
CPU time of the child (user + sys, getrusage), the simulated seconds per CPU second (x real time)
at the median and at the fastest run, and OLD / NEW as the ratio of the medians and as the median
of the pairs' ratios. Alternating the two binaries makes the ratio robust to the shared
machine's drift (docs/benchmarks.md, "Issue 15, session 5"), and alternating their order to the
second run's ~1 % penalty ("Issue 15, session 6").

With --fresh each run writes into a new empty folder; by default every run of a task writes
over the previous run's outputs, as a user repeating a run does (replacing a 2-5 MB CSV costs
2-5 %: docs/benchmarks.md, "Issue 15, session 6").

Usage, from the repository root:
    python3 bench/process/whole_process_cpu.py [--fresh] OLD NEW N TASK [TASK ...]
"""
import json
import resource
import statistics
import subprocess
import sys
import tempfile


def child_cpu(binary, task, out, fresh=False):
    """CPU seconds (user + sys) of one `simulate` run of `task` (into a new subfolder if fresh)."""
    if fresh:
        out = tempfile.mkdtemp(dir=out)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([binary, "simulate", "--task", f"models/tasks/{task}.json", "--seed", "3",
                    "--out", out], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(argv):
    fresh = "--fresh" in argv
    argv = [a for a in argv if a != "--fresh"]
    if len(argv) < 5:
        sys.exit(__doc__)
    old, new, runs, tasks = argv[1], argv[2], int(argv[3]), argv[4:]
    print("| task | simulated | before: CPU (x real time), fastest | "
          "after: CPU (x real time), fastest | before / after: medians, pairs |")
    print("|---|---|---|---|---|")
    for task in tasks:
        with open(f"models/tasks/{task}.json") as f:
            duration = json.load(f)["duration"]
        old_cpu, new_cpu = [], []
        with tempfile.TemporaryDirectory() as out:
            for i in range(runs):
                # ABBA order: the binary run second in a pair measured ~1 % slower, whichever it
                # was (docs/benchmarks.md, "Issue 15, session 6"); alternating cancels that.
                if i % 2 == 0:
                    old_cpu.append(child_cpu(old, task, out, fresh))
                    new_cpu.append(child_cpu(new, task, out, fresh))
                else:
                    new_cpu.append(child_cpu(new, task, out, fresh))
                    old_cpu.append(child_cpu(old, task, out, fresh))
        a, b = statistics.median(old_cpu), statistics.median(new_cpu)
        # The host's speed drifts run to run: a pair's two runs are a second apart, so the median
        # of the pairs' ratios follows the drift more closely than the ratio of the medians.
        pairs = statistics.median(o / n for o, n in zip(old_cpu, new_cpu))
        print(f"| {task} | {duration:.0f} s | {a * 1000:.1f} ms ({duration / a:.0f}x), "
              f"{duration / min(old_cpu):.0f}x | {b * 1000:.1f} ms ({duration / b:.0f}x), "
              f"{duration / min(new_cpu):.0f}x | {a / b:.3f}, {pairs:.3f} |")


if __name__ == "__main__":
    main(sys.argv)
