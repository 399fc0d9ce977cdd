"""Recruit: SMA muscle bundles under stochastic recruitment control, from Python.

Works beside the official ``mujoco`` bindings: ``import recruit`` registers the MuJoCo engine
plugin ``recruit.sma`` (the shipped ``librecruit_sma.so``), after which
``mujoco.MjModel.from_xml_path`` opens bundle models. docs/python.md has the guide.

Contents:
    FilterModel        filter model files (docs/formats/filter.md) and models from arrays
    KalmanFilter       the population Kalman filter (all covariance modes; the fixed-size
                       C++ filter for m = 2, 3, 20 with r = 1, the dynamic one otherwise)
    ExactFilter        the exact Bayesian filter over every count vector (the reference)
    ParticleFilter     the bootstrap particle filter over count vectors (seeded)
    filter_log         an offline run of any estimator over a recorded log -> column arrays
    Bundles            the SMA bundles of a user's mujoco.MjModel / MjData
    Controller         the broadcast recruitment controller (estimator + expectation law)
    expectation_law    the law alone
    simulate           one closed-loop run of a task file -> summary dict with the per-step
                       trace (a column dict of NumPy arrays)
    sweep              a grid of runs on all cores -> column dict, one row per run
    aggregate          a sweep's runs per grid cell -> column dict (`recruit sweep`'s table)
    attach             a model's muscles become sized SMA bundles (`recruit attach`) -> report

Errors in arguments or files raise ValueError carrying the C++ message.
"""

import ctypes as _ctypes
import io as _io
import json as _json
import os as _os
import tempfile as _tempfile
from typing import Any, Dict, Mapping, Optional, Sequence, Tuple, Union

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

from ._version import __version__  # noqa: E402  (the CMake project version)
from ._version import _DATA_DIR  # noqa: E402

# The shipped models/identified/ are found under this folder (RECRUIT_DATA_DIR overrides it).
if _os.path.isdir(_DATA_DIR):
    _recruit.set_data_dir(_DATA_DIR)

_h = _recruit.mujoco_header_version()  # mjVERSION_HEADER: major * 1e6 + minor * 1e3 + patch
MUJOCO_BUILD_VERSION = f"{_h // 1000000}.{_h // 1000 % 1000}.{_h % 1000}"
"""The MuJoCo release whose headers recruit was compiled against."""
MUJOCO_VERSION = _mujoco.mj_versionString()
"""The MuJoCo release running (the libmujoco loaded; equal to mujoco.__version__)."""

PathLike = Union[str, "_os.PathLike[str]"]

FilterModel = _recruit.FilterModel
KalmanFilter = _recruit.KalmanFilter
ExactFilter = _recruit.ExactFilter
ParticleFilter = _recruit.ParticleFilter
Bundles = _recruit.Bundles
Controller = _recruit.Controller
attach = _recruit.attach

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

_STEPS = """
    predict(A)                  time update with an m x m column-stochastic A
    predict_broadcast(p_on, p_off)
                                time update with the model's broadcast transition
    update(y)                   measurement update; y None or all-NaN = missing sample, skipped
                                (returns False), else returns True
    run(ys, p_on=None, p_off=None, A=None) -> (X, V)
                                the whole log: for k = 0..T-1 predict with input k-1 (k > 0)
                                and update with ys[k] unless missing; X, V are T x m (estimates
                                and covariance diagonals). The GIL is released meanwhile.
    Properties: x (m,), P (m, m), model, N, num_states, num_outputs.
"""

KalmanFilter.__doc__ = """The population Kalman filter (Odhner and Asada 2010, eqs. 15-27).

    KalmanFilter(model, mode="extended", x0=None, P0=None, fixed_size=True)
        mode: "extended" (Qz at the estimate), "conservative" (Qz at N 1) or "plain" (no Qz:
        the standard Kalman filter). x0, P0 default to the model's initial belief.
        fixed_size: the fixed-size C++ filter PopulationKalmanFilterT<m, 1> for m = 2, 3 or 20
        states with r = 1 output (what `recruit filter` runs; no heap in the steps), else the
        dynamic-size one. The property fixed_size says which one runs.
""" + _STEPS + """
    reset(x0=None, P0=None)     back to a belief (default: the model's)
    set_output(H, R)            a new output model for the next updates (e.g. H at the
                                measured tendon length)
    Also: innovation (r,), K (m, r), H (r, m), mode, fixed_size.
    """

ExactFilter.__doc__ = """The exact Bayesian filter over every count vector (the accuracy reference).

    ExactFilter(model, max_states=200000, cache_bytes=256 MiB)
        The belief is one probability per count vector X (sum X = N): C(N + m - 1, m - 1) of
        them, refused above max_states. Prediction is the exact multinomial transition, the
        update the Gaussian likelihood. The model must have no process noise (G empty).
        Prior: a point mass at x0 when P0 = 0, else N(x0, P0) on the count vectors.
""" + _STEPS + """
    Also: probabilities (S,), states (S x m), num_count_vectors, set_probabilities(p).
    """

ParticleFilter.__doc__ = """The bootstrap particle filter over integer count vectors.

    ParticleFilter(model, particles=1000, resample_threshold=0.5, seed=1)
        Particles move by the chain itself (multinomial draws) and are weighted by the Gaussian
        likelihood; systematic resampling when ESS < resample_threshold * particles. One
        random stream seeded with `seed` draws the initial particles, then every step: the same
        seed and inputs give the same estimates as `recruit filter --estimator particle`.
""" + _STEPS + """
    Also: ess, num_particles, particles (num_particles x m).
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
                                          per-unit ndarrays (ground truth)
    b.state_counts(data, bundle) -> ndarray [off, on]
                                          true counts, in FilterModel.two_state's state order
    b.cohorts(data, bundle) -> dict       the units grouped by identical state: count, on,
                                          temperature, xi arrays; b.num_cohorts(data, bundle)
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


def expectation_law(target_on: float, estimated_on: float, num_units: float,
                    lam: float) -> Tuple[float, float]:
    """The expectation law -> (p_on, p_off) (docs/controller.md).

    recruit: p_on = lam (target - est) / (N - est), p_off = 0;
    release: p_off = lam (est - target) / est, p_on = 0. Inputs are clamped to [0, N] and lam to
    [0, 1]; a NaN input or N <= 0 broadcasts nothing (0, 0).
    """
    return _recruit.expectation_law(float(target_on), float(estimated_on), float(num_units),
                                    float(lam))


def filter_log(model_path: PathLike, log_path: PathLike, estimator: str = "extended",
               particles: int = 1000, seed: int = 1) -> Dict[str, _np.ndarray]:
    """Runs an estimator over a recorded log (docs/formats/filter.md) like `recruit filter`.

    estimator: "extended", "conservative", "plain", "exact" or "particle".
    Returns a dict of NumPy arrays, one per output column: "step", ("t",) "updated",
    "x_<state>", "var_<state>"; np.column_stack(...) gives a T x k array.
    """
    text = _recruit.filter_log(str(model_path), str(log_path), estimator, int(particles), int(seed))
    header = text.split("\n", 1)[0].split(",")
    data = _np.loadtxt(_io.StringIO(text), delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, i] for i, name in enumerate(header)}


def simulate(task_path: PathLike, *, estimator: Optional[str] = None,
             filter_model: Optional[PathLike] = None, dT: Optional[float] = None,
             lam: Optional[float] = None, force_noise_std: Optional[float] = None,
             duration: Optional[float] = None, seed: int = 1,
             trace_every: int = 1) -> Dict[str, Any]:
    """One closed-loop run of a task file (models/tasks/*.json), as `recruit simulate`.

    Unset options keep the task's values. Returns the run summary as a dict (the CLI's summary
    JSON: task, estimator, dT, lambda, seed, duration, unit, physics_steps, control_instants,
    wall_seconds, metrics, bundles, steps, ...) plus "trace": the columns of the CLI's per-step
    CSV (the same names and rows as `--csv-every trace_every`: every trace_every-th physics step
    and every control instant) as a dict of NumPy arrays at full precision;
    pandas.DataFrame(result["trace"]) takes it directly. trace_every=0: no trace.
    Same seed -> same result. The GIL is released during the run.
    """
    text, trace = _recruit.simulate_run(str(task_path), estimator,
                                        None if filter_model is None else str(filter_model), dT,
                                        lam, force_noise_std, duration, int(seed),
                                        int(trace_every))
    summary = _json.loads(text)
    if trace is not None:
        summary["trace"] = trace
    return summary


# The run metrics (C++ sim::kMetricFields): the keys of a summary's "metrics" and the metric
# columns of sweep(...), in the order of the sweep table's columns.
METRICS: Tuple[str, ...] = tuple(f["name"] for f in _recruit.METRIC_FIELDS)
_INTEGER_METRICS = frozenset(f["name"] for f in _recruit.METRIC_FIELDS if f["integer"])


def _as_list(x, kind):
    return [kind(v) for v in (x if isinstance(x, (list, tuple, _np.ndarray)) else [x])]


def sweep(task_path: Optional[PathLike] = None, *,
          dT: Optional[Union[float, Sequence[float]]] = None,
          lam: Optional[Union[float, Sequence[float]]] = None,
          estimator: Optional[Union[str, Sequence[str]]] = None, seeds: Optional[int] = None,
          base_seed: Optional[int] = None, duration: Optional[float] = None,
          filter_model: Optional[PathLike] = None, sweep_file: Optional[PathLike] = None,
          threads: int = 0) -> Dict[str, Any]:
    """A grid of closed-loop runs (plant points x dT x lam x estimator x seeds), as `recruit sweep`.

    Prepared as `recruit sweep --task ... --sweep ...` prepares it (C++ sweep::Prepare): a
    `sweep_file` (docs/sweep.md) gives the task, plant axes and controller values; an argument
    given here overrides the file's, and one given in neither takes its default here: lam 0.2,
    estimator ("output", "kalman-augmented"), seeds 1, base_seed 1 (dT has none: give it here or
    in the file). Runs on `threads` threads (0: all cores) with the GIL released. Seed index s
    runs with seed Rng::DeriveSeed(base_seed, s), as the CLI: the same arguments give the same
    results. Returns a column dict, one row per run in grid order (plant point outermost, then
    dT, lam, estimator, seed index): with plant axes first plant (the point's index) and one
    column per axis, then dT, lambda, estimator, seed_index, seed, duration, wall_seconds,
    physics_steps and one column per name in METRICS (tracking_rmse, overshoot, ...; mean_nees
    is NaN without a variance, num_steps is an integer). pandas.DataFrame(...) takes it
    directly; aggregate(...) gives the per-cell table. Not resumable: every call runs every
    point.
    """
    if dT is None and sweep_file is None:
        raise ValueError("dT: required without a sweep file (its controller.dT)")
    given = [name for name, v in (("task", task_path), ("dT", dT), ("lambda", lam),
                                  ("estimator", estimator), ("seeds", seeds),
                                  ("base-seed", base_seed)) if v is not None]
    with _tempfile.TemporaryDirectory(prefix="recruit-sweep-") as out:
        text = _recruit.sweep_json(
            "" if task_path is None else str(task_path),
            None if sweep_file is None else str(sweep_file),
            [] if dT is None else _as_list(dT, float),
            [0.2] if lam is None else _as_list(lam, float),
            ["output", "kalman-augmented"] if estimator is None else _as_list(estimator, str),
            1 if seeds is None else int(seeds), 1 if base_seed is None else int(base_seed), given,
            None if duration is None else float(duration),
            None if filter_model is None else str(filter_model), int(threads), out)
    runs = _json.loads(text)

    def col(key, dtype=float, get=None):
        get = get or (lambda r: r[key])
        return _np.array([get(r) for r in runs], dtype=dtype)

    out = {}
    if runs and runs[0]["plant_values"]:
        out["plant"] = col("plant", _np.int64)
        for a, (name, _) in enumerate(runs[0]["plant_values"]):
            out[name] = col(name, get=lambda r, a=a: r["plant_values"][a][1])
    out.update({
        "dT": col("dT"),
        "lambda": col("lambda"),
        "estimator": [r["estimator"] for r in runs],
        "seed_index": col("seed_index", _np.int64),
        "seed": col("seed", _np.uint64),
        "duration": col("duration"),
        "wall_seconds": col("wall_seconds"),
        "physics_steps": col("physics_steps", _np.int64),
    })
    for k in METRICS:
        # JSON has no NaN: a missing value (mean_nees of an estimator without variance) is null.
        out[k] = col(k, _np.int64 if k in _INTEGER_METRICS else float,
                     lambda r, k=k: _np.nan if r["metrics"][k] is None else r["metrics"][k])
    return out


def aggregate(runs: Mapping[str, Any], max_overshoot: float = 0.10,
              min_settled: float = 0.90) -> Dict[str, Any]:
    """The runs of sweep(...) (or any subset of its rows) per grid cell (dT, lambda, estimator).

    Returns a column dict with the columns of `recruit sweep`'s table.csv, in its order: dT,
    lambda, estimator, seeds, the seeds' mean of each metric the table shows (overshoot_mean,
    overshoot_sd, settling_time_mean, settled_fraction, tracking_rmse_mean, ...),
    meets_criterion, margin. A cell meets the criterion when its mean overshoot <= max_overshoot
    and its settled fraction >= min_settled. Runs with plant axes (a "plant" column, then the
    axis columns up to "dT", as sweep(...) returns them) give cells per plant point, with those
    columns first, as table.csv.
    """
    keys = list(runs.keys())
    axes = []
    if "plant" in keys and "dT" in keys:
        axes = keys[keys.index("plant") + 1:keys.index("dT")]
    return _recruit.aggregate(dict(runs), float(max_overshoot), float(min_settled), axes)


__all__ = ["FilterModel", "KalmanFilter", "ExactFilter", "ParticleFilter", "Bundles",
           "Controller", "expectation_law", "filter_log", "simulate", "sweep", "aggregate",
           "attach", "METRICS", "PLUGIN_LIBRARY", "MUJOCO_BUILD_VERSION", "MUJOCO_VERSION"]
