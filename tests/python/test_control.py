"""The expectation law, the controller object and simulate()."""
import math

import numpy as np
import pytest

import recruit

from conftest import ROOT


@pytest.mark.parametrize("target,est,N,lam", [(30, 10, 60, 0.2), (5, 40, 60, 0.5),
                                              (60, 12.5, 60, 1.0), (0, 3, 60, 0.3)])
def test_expectation_law_closed_form(target, est, N, lam):
    p_on, p_off = recruit.expectation_law(target, est, N, lam)
    if target > est:  # recruit: expected switches = lam (target - est)
        assert p_on == pytest.approx(lam * (target - est) / (N - est), rel=1e-15)
        assert p_off == 0
    else:
        assert p_off == pytest.approx(lam * (est - target) / est, rel=1e-15)
        assert p_on == 0


def test_expectation_law_guards():
    assert recruit.expectation_law(80, 60, 60, 0.2) == (0.0, 0.0)  # target clamped to N = est
    assert recruit.expectation_law(-5, 0, 60, 0.2) == (0.0, 0.0)  # nobody to release
    assert recruit.expectation_law(30, 10, 60, 3.0) == recruit.expectation_law(30, 10, 60, 1.0)
    assert recruit.expectation_law(math.nan, 10, 60, 0.2) == (0.0, 0.0)
    assert recruit.expectation_law(30, 10, 0, 0.2) == (0.0, 0.0)


def test_output_controller_is_force_over_unit_force():
    # The "output" estimator: count = force / unit force (docs/controller.md); the controller
    # applies the law to target = reference / unit force.
    c = recruit.Controller(60, 0.45, 0.5, lam=0.3, estimator="output")
    p_on, p_off = c.step(9.0, 2.25)
    assert c.estimated_on == pytest.approx(5.0)
    assert c.target_on == pytest.approx(20.0)
    assert (p_on, p_off) == pytest.approx(recruit.expectation_law(20.0, 5.0, 60, 0.3))
    assert math.isnan(c.estimated_on_variance)


def test_kalman_controller_predicts_the_broadcast():
    # kalman2, no units on: the first step's estimate is ~0, the law recruits; the next
    # estimate without new information is the prediction N p_on (the binomial mean).
    c = recruit.Controller(60, 0.45, 0.5, lam=0.2, estimator="kalman2", covariance="extended")
    p_on, _ = c.step(13.5, 0.0)
    assert p_on == pytest.approx(0.2 * 30 / 60, abs=1e-3)
    assert c.state_estimate.sum() == pytest.approx(60)
    c.reset()
    assert c.state_estimate[0] == pytest.approx(60)


def test_controller_bad_inputs():
    with pytest.raises(ValueError, match="lambda"):
        recruit.Controller(60, 0.45, 0.5, lam=2.0, estimator="output")
    with pytest.raises(ValueError, match="unit_force"):
        recruit.Controller(60, 0.0, 0.5, estimator="output")
    with pytest.raises(ValueError, match="nope"):
        recruit.Controller(60, 0.45, 0.5, estimator="nope")
    c = recruit.Controller(60, 0.45, 0.5, estimator="output")
    with pytest.raises(ValueError, match="finite"):
        c.step(float("nan"), 1.0)


TASK = str(ROOT / "models" / "tasks" / "isometric_steps.json")


def test_simulate_summary_and_reproducibility():
    a = recruit.simulate(TASK, duration=10.0, seed=3)
    b = recruit.simulate(TASK, duration=10.0, seed=3)
    assert a["task"] == "isometric_steps"
    assert a["duration"] == pytest.approx(10.0)
    assert a["control_instants"] == 10  # dT = 1 s over 10 s
    assert a["physics_steps"] == 5000  # timestep 0.002 s
    a.pop("wall_seconds"), b.pop("wall_seconds")
    ta, tb = a.pop("trace"), b.pop("trace")
    assert a == b
    assert ta.keys() == tb.keys()
    for k in ta:
        np.testing.assert_array_equal(ta[k], tb[k])
    c = recruit.simulate(TASK, duration=10.0, seed=4)
    assert c["metrics"] != a["metrics"]


def test_simulate_bad_inputs():
    with pytest.raises(ValueError, match="no_such_task.json"):
        recruit.simulate(str(ROOT / "no_such_task.json"))
    with pytest.raises(ValueError):
        recruit.simulate(TASK, estimator="nope", duration=1.0)
    with pytest.raises(ValueError):
        recruit.simulate(TASK, lam=-1.0, duration=1.0)


def _cli():
    import os
    path = os.environ.get("RECRUIT_CLI", str(ROOT / "build" / "src" / "cli" / "recruit"))
    return path if os.path.exists(path) else None


@pytest.mark.skipif(_cli() is None, reason="no recruit CLI (set RECRUIT_CLI or build build/)")
def test_simulate_equals_the_cli_bit_for_bit(tmp_path):
    # The same task and seed through `recruit simulate` and recruit.simulate: every number of
    # the summary is the same double (JSON keeps 17 digits). Keys only one side has (a newer
    # CLI) are ignored.
    import json
    import subprocess
    out = subprocess.run([_cli(), "simulate", "--task", TASK, "--duration", "10", "--seed", "3",
                          "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    cli = json.loads((tmp_path / "isometric_steps_summary.json").read_text())
    py = recruit.simulate(TASK, duration=10.0, seed=3)
    common = (set(cli) & set(py)) - {"wall_seconds"}
    assert {"metrics", "steps", "physics_steps", "seed"} <= common
    assert {k: py[k] for k in common} == {k: cli[k] for k in common}
