#!/usr/bin/env python3
"""Whole-process CPU of short `recruit simulate` runs (start-up and finish), several variants
alternated run by run.

Each variant is a binary, optionally with RECRUIT_COMPILED_CACHE set for it (the cache of compiled
models, src/common/compiled_model_cache.h): BINARY or BINARY@CACHE, CACHE a folder or "off". Every
variant runs `simulate --task models/tasks/TASK.json --duration D --csv F --summary F` N times, in
rotating order, and the median CPU time of the child (user + sys, getrusage) is printed per
variant, with its ratio to the first variant's median. One untimed run of each variant first
fills its cache.

Usage, from the repository root:
    python3 bench/process/short_run_cpu.py TASK D N VARIANT [VARIANT ...]
"""
import os
import resource
import statistics
import subprocess
import sys
import tempfile


def run(variant, task, duration, out):
    binary, _, cache = variant.partition("@")
    env = dict(os.environ)
    if cache:
        env["RECRUIT_COMPILED_CACHE"] = cache
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([binary, "simulate", "--task", f"models/tasks/{task}.json", "--duration",
                    str(duration), "--csv", f"{out}/y.csv", "--summary", f"{out}/y.json"],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main(argv):
    if len(argv) < 5:
        sys.exit(__doc__)
    task, duration, runs, variants = argv[1], float(argv[2]), int(argv[3]), argv[4:]
    cpu = {v: [] for v in variants}
    with tempfile.TemporaryDirectory() as out:
        for v in variants:
            run(v, task, duration, out)
        for i in range(runs):
            k = i % len(variants)
            for v in variants[k:] + variants[:k]:
                cpu[v].append(run(v, task, duration, out))
    ref = statistics.median(cpu[variants[0]])
    print(f"{task}, {duration} s simulated, {runs} runs each, median CPU:")
    for v in variants:
        med = statistics.median(cpu[v])
        print(f"  {v}: {1e3 * med:.2f} ms ({med / ref:.3f} x the first)")


if __name__ == "__main__":
    main(sys.argv)
