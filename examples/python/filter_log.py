"""Filtering a recorded log into a NumPy array.

Reads models/filter/three_state_log.csv (t, p_on, p_off, y: the force of a 60-unit bundle
sampled every 0.5 s, some samples missing), runs the population Kalman filter of
models/filter/three_state_model.json over it, and compares the estimates with the true counts
(three_state_truth.csv) and with the exact Bayesian filter run by recruit.filter_log.

    python examples/python/filter_log.py [--out estimates.npy]
"""
import argparse
import pathlib

import numpy as np

import recruit

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "models" / "filter"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="save the T x m estimates as .npy")
    ap.add_argument("--mode", default="extended", choices=["extended", "conservative", "plain"])
    args = ap.parse_args()

    model = recruit.FilterModel.load(str(DATA / "three_state_model.json"))
    log = np.genfromtxt(DATA / "three_state_log.csv", delimiter=",", names=True)
    ys = log["y"].reshape(-1, 1)  # empty cells read as NaN: missing samples, skipped
    X, V = recruit.KalmanFilter(model, args.mode).run(ys, log["p_on"], log["p_off"])

    truth = np.genfromtxt(DATA / "three_state_truth.csv", delimiter=",", names=True)
    n = np.column_stack([truth["n_" + s] for s in model.state_names])
    exact = recruit.filter_log(DATA / "three_state_model.json", DATA / "three_state_log.csv",
                               "exact")
    Xe = np.column_stack([exact["x_" + s] for s in model.state_names])

    print(f"{len(ys)} samples ({int(np.isnan(ys).sum())} missing), states {model.state_names}")
    print(f"estimates: array {X.shape}, variances {V.shape}")
    rmse = lambda a: np.sqrt(np.mean((a - n) ** 2, axis=0))  # noqa: E731
    print("RMSE vs truth per state, Kalman (" + args.mode + "):", np.round(rmse(X), 3))
    print("RMSE vs truth per state, exact filter:   ", np.round(rmse(Xe), 3))
    if args.out:
        np.save(args.out, X)
        print("wrote", args.out)


if __name__ == "__main__":
    main()
