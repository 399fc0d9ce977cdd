#!/usr/bin/env python3
"""The project's own share of a whole process, from a callgrind profile.

MuJoCo's own work is the inclusive cost of every call made from outside libmujoco into it,
minus the calls it makes back into the SMA plugin (its callbacks: those are the project's); the
project's own share is everything else (the plugin, the program, the loader, libc and libstdc++
called from the project's code). Cost lines of `calls=` entries are inclusive in callgrind's
format, so one pass over them gives both sums.

Usage (the profile written without string or position compression):
    valgrind --tool=callgrind --compress-strings=no --compress-pos=no \
        --callgrind-out-file=cg.out build/src/cli/recruit simulate --task T.json --seed 3 --out D
    python3 bench/process/own_share.py cg.out [cg2.out ...]
"""
import sys


def shares(path):
    """(total, MuJoCo's own, plugin callbacks) instructions of one profile."""
    ob = cob = None
    total = into = back = 0
    pending = False
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith(("summary:", "totals:")):
                total = int(line.split()[1])
            elif line.startswith("ob="):
                ob, cob = line[3:].strip(), None
            elif line.startswith("fn="):
                cob = None
            elif line.startswith("cob="):
                cob = line[4:].strip()
            elif line.startswith("calls="):
                pending = True
            elif pending:
                pending = False
                fields = line.split()
                cost = int(fields[1]) if len(fields) > 1 else 0
                callee = cob if cob is not None else ob
                cob = None
                from_mujoco = "libmujoco" in (ob or "")
                to_mujoco = "libmujoco" in (callee or "")
                if to_mujoco and not from_mujoco:
                    into += cost
                elif from_mujoco and "librecruit_sma" in (callee or ""):
                    back += cost
    return total, into - back, back


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for path in sys.argv[1:]:
        total, mujoco, callbacks = shares(path)
        print(f"{path}: {total / 1e6:.1f} M instructions, MuJoCo's own {100 * mujoco / total:.1f} %, "
              f"plugin callbacks {100 * callbacks / total:.1f} %, "
              f"project's own {100 * (total - mujoco) / total:.1f} %")


if __name__ == "__main__":
    main()
