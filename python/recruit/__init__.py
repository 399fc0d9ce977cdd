"""Recruit: SMA muscle bundles under stochastic recruitment control, from Python.

Works beside the official ``mujoco`` bindings: ``import recruit`` registers the MuJoCo engine
plugin ``recruit.sma`` (the shipped ``librecruit_sma.so``), after which
``mujoco.MjModel.from_xml_path`` opens bundle models. docs/python.md has the guide.

Contents:
    FilterModel        filter model files (docs/formats/filter.md) and models from arrays
    KalmanFilter       the population Kalman filter (dynamic size, all covariance modes)
    filter_log         an offline run of any estimator over a recorded log -> column arrays
    Bundles            the SMA bundles of a user's mujoco.MjModel / MjData
    Controller         the broadcast recruitment controller (estimator + expectation law)
    expectation_law    the law alone
    simulate           one closed-loop run of a task file -> summary dict

Errors in arguments or files raise ValueError carrying the C++ message.
"""

import ctypes as _ctypes
import io as _io
import json as _json
import os as _os

# One libmujoco per process: the official bindings load the wheel's libmujoco.so.<version>
# first; the plugin library and the extension link it by soname, so the loader reuses it.
import mujoco as _mujoco
import numpy as _np

_HERE = _os.path.dirname(_os.path.abspath(__file__))
_SHIPPED = _os.path.join(_HERE, "librecruit_sma.so")

# The plugin is registered from one file only: the shipped library, loaded globally before the
# extension (which links the same file by soname, so it is not loaded twice). In a build tree
# the extension finds build/plugin/librecruit_sma.so through its build rpath instead.
PLUGIN_HANDLE = None
if _os.path.exists(_SHIPPED):
    PLUGIN_HANDLE = _ctypes.CDLL(_SHIPPED, mode=_ctypes.RTLD_GLOBAL)

from . import _recruit  # noqa: E402

PLUGIN_LIBRARY = _recruit.plugin_library()
"""Path of the librecruit_sma.so that registered the recruit.sma plugin."""

if PLUGIN_HANDLE is not None and _os.path.realpath(PLUGIN_LIBRARY) != _os.path.realpath(_SHIPPED):
    raise ImportError(
        f"recruit: the extension uses {PLUGIN_LIBRARY}, not the shipped {_SHIPPED}; "
        "two copies of the plugin cannot be registered in one process")
if _recruit.mujoco_version() != _mujoco.mj_versionString():
    raise ImportError(
        f"recruit: built for MuJoCo {_recruit.mujoco_version()}, but mujoco "
        f"{_mujoco.mj_versionString()} is imported; install the mujoco version recruit was "
        "built with")

__version__ = "0.2.0"

FilterModel = _recruit.FilterModel
KalmanFilter = _recruit.KalmanFilter
Bundles = _recruit.Bundles
Controller = _recruit.Controller

FilterModel.__doc__ = """What a population filter knows about the units and the sensor.

    FilterModel.load(path)                  a model file (docs/formats/filter.md), e.g. one
                                            written by `recruit identify`
    FilterModel.two_state(N, dt, unit_force, noise_std)
                                            the off/on model with a force sensor
    FilterModel.linear(H, R, N, x0=None, P0=None, A=None, G=None, Qw=None, state_names=None)
                                            from arrays: y = H X + v, v ~ N(0, R); A given =
                                            constant transition, else pass A at every predict;
                                            process noise G Qw G^T must have zero column sums

    Properties (NumPy arrays): H, R, G, Qw, process_noise, A, x0, P0; N, dt, state_names,
    is_on, transition ("broadcast", "explicit", "constant"), num_states, num_outputs.
    Methods: save(path), with_population(N), broadcast_matrix(p_on, p_off).
    """

KalmanFilter.__doc__ = """The population Kalman filter (Odhner and Asada 2010, eqs. 15-27).

    KalmanFilter(model, mode="extended", x0=None, P0=None)
        mode: "extended" (Qz at the estimate), "conservative" (Qz at N 1) or "plain" (no Qz:
        the standard Kalman filter). x0, P0 default to the model's initial belief.

    predict(A)                  time update with an m x m column-stochastic A
    predict_broadcast(p_on, p_off)
                                time update with the model's broadcast transition
    update(y)                   measurement update; y None or all-NaN = missing sample, skipped
                                (returns False), else returns True
    run(ys, p_on=None, p_off=None, A=None) -> (X, V)
                                the whole log: for k = 0..T-1 predict with input k-1 (k > 0)
                                and update with ys[k] unless missing; X, V are T x m (estimates
                                and covariance diagonals). The GIL is released meanwhile.
    reset(x0=None, P0=None)     back to a belief (default: the model's)

    Properties: x (m,), P (m, m), innovation (r,), K (m, r), mode, N, num_states,
    num_outputs, model.
    """

Bundles.__doc__ = """The recruit.sma bundles of a mujoco.MjModel (actuator order).

    b = recruit.Bundles(model)
    b.reset(data, seed)                   every unit off and cold; per-bundle seeded streams
    b.broadcast(data, bundle, p_on, p_off)
                                          each unit switches off->on with p_on, on->off with
                                          p_off (call at control instants, then mujoco.mj_step)
    b.on_count(data, bundle) -> int       true number of units whose heater is on
    b.force(data, bundle) -> float        tension (N) at the current tendon length
    b.mean_temperature(data, bundle), b.heat(data, bundle)
    b.unit_temperatures(data, bundle), b.unit_xi(data, bundle), b.units_on(data, bundle)
                                          per-unit ndarrays
    b.num_bundles, b.names, b.index(name), b.num_units(bundle), b.settled_unit_force(bundle),
    b.actuator_id(bundle), b.tendon_id(bundle)

    `bundle` is an index or the actuator's name. `data` must be an MjData of this model.
    Keeps a reference to the model.
    """

Controller.__doc__ = """One bundle's broadcast recruitment controller (docs/controller.md).

    Controller(num_units, unit_force, dT, lam=0.2, estimator="kalman-augmented",
               covariance="extended", model_file="", num_states=20, force_noise_std=0.0)
        estimator: "output", "kalman2" or "kalman-augmented" (an identified model file; empty =
        the shipped models/identified/ file for dT and num_states).

    step(reference_force, measured_force) -> (p_on, p_off)
        once per sampling period dT: observe the force, apply the expectation law, predict.
    reset()   back to all units off.
    Properties: target_on, estimated_on, estimated_on_variance, state_estimate, state_names,
    num_units, unit_force, dT, lam.
    """


def expectation_law(target_on, estimated_on, num_units, lam):
    """The expectation law -> (p_on, p_off) (docs/controller.md).

    recruit: p_on = lam (target - est) / (N - est), p_off = 0;
    release: p_off = lam (est - target) / est, p_on = 0. Inputs are clamped to [0, N] and lam to
    [0, 1]; a NaN input or N <= 0 broadcasts nothing (0, 0).
    """
    return _recruit.expectation_law(float(target_on), float(estimated_on), float(num_units),
                                    float(lam))


def filter_log(model_path, log_path, estimator="extended", particles=1000, seed=1):
    """Runs an estimator over a recorded log (docs/formats/filter.md) like `recruit filter`.

    estimator: "extended", "conservative", "plain", "exact" or "particle".
    Returns a dict of NumPy arrays, one per output column: "step", ("t",) "updated",
    "x_<state>", "var_<state>"; np.column_stack(...) gives a T x k array.
    """
    text = _recruit.filter_log(str(model_path), str(log_path), estimator, int(particles), int(seed))
    header = text.split("\n", 1)[0].split(",")
    data = _np.loadtxt(_io.StringIO(text), delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, i] for i, name in enumerate(header)}


def simulate(task_path, *, estimator=None, filter_model=None, dT=None, lam=None,
             force_noise_std=None, duration=None, seed=1):
    """One closed-loop run of a task file (models/tasks/*.json), as `recruit simulate`.

    Unset options keep the task's values. Returns the run summary as a dict: task, estimator,
    dT, lambda, seed, duration, unit, physics_steps, control_instants, wall_seconds,
    metrics (dict) and steps (list of dicts). Same seed -> same result. The GIL is released
    during the run.
    """
    text = _recruit.simulate_json(str(task_path), estimator, filter_model, dT, lam,
                                  force_noise_std, duration, int(seed))
    return _json.loads(text)


__all__ = ["FilterModel", "KalmanFilter", "Bundles", "Controller", "expectation_law",
           "filter_log", "simulate", "PLUGIN_LIBRARY"]
