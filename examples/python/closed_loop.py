"""A closed loop written in plain Python with the official MuJoCo bindings.

The user's own loop: mujoco.mj_step drives the isometric bench (models/isometric_bench.xml);
every dT seconds the bundle force is measured (with sensor noise), Recruit's population Kalman
filter estimates how many units are on, the expectation law picks (p_on, p_off), and the
bundle receives the broadcast. The filter is the identified 20-state model
(models/identified/bench_n60_dt0.5_m20.json); recruit.Controller packages the same steps.

    python examples/python/closed_loop.py [--duration 40] [--seed 1]
"""
import argparse
import pathlib

import mujoco
import numpy as np

import recruit

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=40.0, help="simulated seconds")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--lam", type=float, default=0.3, help="expectation-law gain")
    args = ap.parse_args()

    m = mujoco.MjModel.from_xml_path(str(ROOT / "models" / "isometric_bench.xml"))
    d = mujoco.MjData(m)
    bundles = recruit.Bundles(m)
    bundles.reset(d, args.seed)
    N = bundles.num_units("bundle")

    model = recruit.FilterModel.load(str(ROOT / "models" / "identified" /
                                         "bench_n60_dt0.5_m20.json")).with_population(N)
    kf = recruit.KalmanFilter(model, "extended")
    on_states = np.array(model.is_on)
    unit_force = bundles.settled_unit_force("bundle")
    dT = model.dt
    noise_std = float(np.sqrt(model.R[0, 0]))
    rng = np.random.default_rng(args.seed)

    def reference(t):  # N: 0 -> 12 -> 24 -> 8
        return 0.0 if t < 2 else 12.0 if t < 12 else 24.0 if t < 22 else 8.0

    steps_per_instant = int(round(dT / m.opt.timestep))
    rows = []
    while d.time < args.duration - 1e-9:
        measured = bundles.force(d, "bundle") + noise_std * rng.standard_normal()
        kf.update([measured])
        est_on = float(kf.x[on_states].sum())
        p_on, p_off = recruit.expectation_law(reference(d.time) / unit_force, est_on, N, args.lam)
        bundles.broadcast(d, "bundle", p_on, p_off)
        kf.predict_broadcast(p_on, p_off)
        rows.append((d.time, reference(d.time), measured, est_on, bundles.on_count(d, "bundle")))
        for _ in range(steps_per_instant):
            mujoco.mj_step(m, d)

    rows = np.array(rows)
    print("   t(s)   ref(N) force(N)  est_on  true_on")
    for r in rows[:: max(1, len(rows) // 15)]:
        print(f"{r[0]:7.1f} {r[1]:8.1f} {r[2]:8.2f} {r[3]:7.1f} {r[4]:8.0f}")
    late = rows[:, 0] >= rows[-1, 0] - 5.0
    print(f"last 5 s: mean |force - ref| = {np.abs(rows[late, 2] - rows[late, 1]).mean():.2f} N, "
          f"estimator RMSE (on units, all instants) = "
          f"{np.sqrt(np.mean((rows[:, 3] - rows[:, 4] + 0.0) ** 2)):.2f}")


if __name__ == "__main__":
    main()
