"""Benchmark: one filter step (predict + update) through Python, recruit vs filterpy.

The same plain linear problem for both (m states, r = 1 output, column-stochastic A, process
noise G Qw G^T with zero column sums, known total N), timed in one process with timeit; the
figure is the median over repeats of the per-step time, and the ratio is filterpy / recruit.
Rows: recruit.KalmanFilter.predict(A) + update(y), one Python call each per step (mode plain,
the same equations as filterpy, and mode extended), and KalmanFilter.run over the whole log
(one call, per-step time), each with the fixed-size C++ filter (the default for m = 2 and 20
with r = 1) and with the dynamic-size one (fixed_size=False).

    .venv/bin/python examples/python/bench_filter.py [--steps 2000] [--repeats 7]
"""
import argparse
import statistics
import timeit

import numpy as np
from filterpy.kalman import KalmanFilter as FilterpyKF

import recruit


def problem(m, seed=1):
    rng = np.random.default_rng(seed)
    A = rng.uniform(0.05, 1.0, (m, m))
    A /= A.sum(axis=0)
    H = rng.normal(size=(1, m))
    R = np.array([[2.0]])
    G = np.zeros((m, m - 1))
    for i in range(m - 1):
        G[i, i], G[i + 1, i] = 1.0, -1.0
    Qw = np.eye(m - 1) * 0.5
    N = 100
    x0 = np.full(m, N / m)
    ys = rng.normal(size=(4096, 1)) + H @ x0
    return A, H, R, G, Qw, N, x0, ys


def per_step(fn, steps, repeats):
    times = timeit.repeat(fn, number=1, repeat=repeats)
    return statistics.median(times) / steps


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    S = args.steps
    print(f"{'m':>3} {'variant':<34} {'us/step':>9} {'filterpy/this':>14}")
    for m in (2, 20):
        A, H, R, G, Qw, N, x0, ys = problem(m)
        model = recruit.FilterModel.linear(H, R, N, x0=x0, A=A, G=G, Qw=Qw)

        fp = FilterpyKF(dim_x=m, dim_z=1)
        fp.x, fp.P, fp.F, fp.H, fp.R, fp.Q = x0.copy(), np.zeros((m, m)), A, H, R, G @ Qw @ G.T

        def run_filterpy():
            for k in range(S):
                fp.predict()
                fp.update(ys[k % len(ys)])

        results = {}
        ys_run = ys[np.arange(S) % len(ys)]
        for fixed in (True, False):
            size = "fixed" if fixed else "dyn"
            for mode in ("plain", "extended"):
                kf = recruit.KalmanFilter(model, mode, fixed_size=fixed)
                assert kf.fixed_size == fixed

                def run_recruit(kf=kf):
                    for k in range(S):
                        kf.predict(A)
                        kf.update(ys[k % len(ys)])

                results[f"recruit p+u ({mode}, {size})"] = run_recruit
            kf_run = recruit.KalmanFilter(model, "plain", fixed_size=fixed)
            results[f"recruit run() (plain, {size})"] = lambda kf_run=kf_run: kf_run.run(ys_run)
        t_ref = per_step(run_filterpy, S, args.repeats)
        print(f"{m:>3} {'filterpy predict+update':<34} {t_ref * 1e6:9.2f} {1.0:14.2f}")
        for name, fn in results.items():
            t = per_step(fn, S, args.repeats)
            print(f"{m:>3} {name:<34} {t * 1e6:9.2f} {t_ref / t:14.2f}")


if __name__ == "__main__":
    main()
