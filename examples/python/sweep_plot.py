"""A small sweep to a DataFrame-ready column dict, and plots.

Runs models/tasks/isometric_steps.json over dT x estimator x seeds with recruit.sweep (all
cores, the GIL released), aggregates the runs per grid cell with recruit.aggregate (the columns
of `recruit sweep`'s table.csv) and one run with recruit.simulate for its per-step trace, then
writes two PNGs into OUT:

    sweep.png   mean step overshoot and tracking RMSE against dT, one line per estimator
    trace.png   one run: force against the reference, and true vs estimated on-count

    python examples/python/sweep_plot.py OUT [--seeds 2] [--duration 30]

pandas is optional: with it the tables are printed as DataFrames (pandas.DataFrame takes the
column dicts directly); without it as plain text.
"""
import argparse
import pathlib

import numpy as np

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402

import recruit  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
TASK = ROOT / "models" / "tasks" / "isometric_steps.json"


def show(columns, keys):
    """Prints a column dict as a table (pandas when installed)."""
    try:
        import pandas as pd
    except ImportError:
        print("  ".join(f"{k:>18}" for k in keys))
        for i in range(len(columns[keys[0]])):
            cells = (columns[k][i] for k in keys)
            print("  ".join(f"{c:>18.4g}" if isinstance(c, (float, np.floating)) else f"{c!s:>18}"
                            for c in cells))
        return
    print(pd.DataFrame(columns)[list(keys)].to_string(index=False))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="folder for the PNGs (created)")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--duration", type=float, default=30.0)
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    dTs = [0.25, 0.5, 1.0, 2.0]
    estimators = ["output", "kalman2"]
    runs = recruit.sweep(TASK, dT=dTs, lam=[0.2], estimator=estimators, seeds=args.seeds,
                         duration=args.duration)
    print(f"{len(runs['dT'])} runs")
    cells = recruit.aggregate(runs)
    show(cells, ["dT", "estimator", "seeds", "overshoot_mean", "settled_fraction",
                 "tracking_rmse_mean", "estimator_rmse_mean"])

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(9, 3.5))
    est = np.array(cells["estimator"])
    for e in estimators:
        sel = est == e
        ax1.plot(cells["dT"][sel], 100 * cells["overshoot_mean"][sel], "o-", label=e)
        ax2.plot(cells["dT"][sel], cells["tracking_rmse_mean"][sel], "o-", label=e)
    ax1.set(xscale="log", xlabel="dT (s)", ylabel="mean step overshoot (%)")
    ax2.set(xscale="log", xlabel="dT (s)", ylabel="tracking RMSE (N)")
    for ax in (ax1, ax2):
        ax.set_xticks(dTs)
        ax.set_xticklabels([f"{d:g}" for d in dTs])
        ax.minorticks_off()
    ax1.legend()
    fig.tight_layout()
    fig.savefig(out / "sweep.png", dpi=100)
    plt.close(fig)

    run = recruit.simulate(TASK, estimator="kalman2", dT=0.5, duration=args.duration, seed=1,
                           trace_every=10)
    tr = run["trace"]
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5))
    ax1.plot(tr["time"], tr["reference"], "k--", label="reference")
    ax1.plot(tr["time"], tr["bundle.force"], label="force")
    ax1.set(ylabel="force (N)")
    ax1.legend()
    ax2.plot(tr["time"], tr["bundle.true_on"], label="true on-count")
    ci = tr["control_instant"]
    ax2.plot(tr["time"][ci], tr["bundle.estimated_on"][ci], ".", label="estimate (kalman2)")
    ax2.set(xlabel="time (s)", ylabel="units on")
    ax2.legend()
    fig.tight_layout()
    fig.savefig(out / "trace.png", dpi=100)
    plt.close(fig)
    print(f"trace: {len(tr['time'])} rows, tracking RMSE {run['metrics']['tracking_rmse']:.3f} N")
    print("wrote", out / "sweep.png", "and", out / "trace.png")


if __name__ == "__main__":
    main()
