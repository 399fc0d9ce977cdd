"""The plugin beside the official bindings, and the Bundles API on a user's MjModel/MjData."""
import os

import numpy as np
import pytest

import mujoco
import recruit

from conftest import ROOT

BENCH = str(ROOT / "models" / "isometric_bench.xml")


def _maps(word):
    with open("/proc/self/maps") as f:
        return {line.split()[-1] for line in f if word in line}


def test_one_libmujoco_and_one_plugin_file():
    # The official bindings, the extension and the plugin share one libmujoco; one plugin file.
    mujoco.MjModel.from_xml_path(BENCH)
    assert len(_maps("libmujoco")) == 1
    assert len(_maps("librecruit_sma")) == 1
    assert _maps("librecruit_sma") == {os.path.realpath(recruit.PLUGIN_LIBRARY)}


def test_fig4_step_with_ctrl_one_through_plain_mujoco():
    # The paper's Fig. 4 (PAPER.md sec. 5): 60 units at constant length held on reach 25-30 N,
    # 75 % of it in about 2 s. Only the official bindings drive the model here (ctrl = +1 =
    # p_on 1 at every step); the tension sensor is read, then compared with Bundles.force.
    m = mujoco.MjModel.from_xml_path(BENCH)
    d = mujoco.MjData(m)
    d.ctrl[0] = 1.0
    steps = int(round(10.0 / m.opt.timestep))
    tension = np.empty(steps)
    for i in range(steps):
        mujoco.mj_step(m, d)
        tension[i] = -d.sensor("tension").data[0]
    peak = tension[-1]
    t75 = (np.argmax(tension >= 0.75 * peak) + 1) * m.opt.timestep
    assert 25.0 <= peak <= 30.0
    assert 1.5 <= t75 <= 2.5
    b = recruit.Bundles(m)
    assert b.on_count(d, 0) == 60
    assert b.force(d, "bundle") == pytest.approx(peak, abs=0.05)


def _bench():
    m = mujoco.MjModel.from_xml_path(BENCH)
    return m, mujoco.MjData(m), recruit.Bundles(m)


def test_bundle_inventory():
    m, d, b = _bench()
    assert b.num_bundles == 1
    assert b.names == ["bundle"]
    assert b.index("bundle") == 0
    assert b.num_units(0) == 60
    assert b.actuator_id(0) == mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "bundle")
    assert b.tendon_id(0) == mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_TENDON, "bundle")


def test_broadcast_certain_probabilities_and_reset():
    m, d, b = _bench()
    b.reset(d, 7)
    assert b.on_count(d, 0) == 0
    b.broadcast(d, 0, 0.0, 0.0)
    assert b.on_count(d, 0) == 0
    b.broadcast(d, 0, 1.0, 0.0)  # p_on = 1: every off unit switches on
    assert b.on_count(d, 0) == 60
    assert b.units_on(d, 0).sum() == 60
    b.broadcast(d, 0, 1.0, 1.0)  # p_off = 1: every on unit switches off
    assert b.on_count(d, 0) == 0
    b.broadcast(d, 0, 1.0, 0.0)
    b.reset(d, 7)
    assert b.on_count(d, 0) == 0


def test_broadcast_is_binomial():
    # From all off, one broadcast p_on turns on Binomial(60, p_on) units. 400 seeds: the mean
    # fraction has sd sqrt(p q / 24000) = 0.003, band 0.015 (5 sd); the count variance 60 p q
    # = 12.6 within 25 % (sd of a 400-sample variance is about 7 %).
    m, d, b = _bench()
    p = 0.3
    counts = []
    for seed in range(400):
        b.reset(d, seed)
        b.broadcast(d, 0, p, 0.0)
        counts.append(b.on_count(d, 0))
    counts = np.array(counts)
    assert abs(counts.mean() / 60 - p) < 0.015
    assert abs(counts.var(ddof=1) / (60 * p * (1 - p)) - 1) < 0.25


def test_same_seed_same_units():
    m, d, b = _bench()
    runs = []
    for _ in range(2):
        b.reset(d, 42)
        b.broadcast(d, 0, 0.5, 0.0)
        runs.append(b.units_on(d, 0).copy())
    np.testing.assert_array_equal(runs[0], runs[1])


def test_temperatures():
    m, d, b = _bench()
    b.reset(d, 1)
    T0 = b.unit_temperatures(d, 0)
    assert T0.shape == (60,)
    assert np.all(T0 == T0[0])  # every unit cold, at ambient
    b.broadcast(d, 0, 0.5, 0.0)
    for _ in range(1000):
        mujoco.mj_step(m, d)
    T = b.unit_temperatures(d, 0)
    on = b.units_on(d, 0)
    assert np.all(T[on] > T0[0] + 10) and np.allclose(T[~on], T0[0])
    assert b.mean_temperature(d, 0) == pytest.approx(T.mean(), rel=1e-12)


def test_bad_inputs_raise_value_error():
    m, d, b = _bench()
    with pytest.raises(ValueError, match=r"p_on = 2.* must be a probability in \[0, 1\]"):
        b.broadcast(d, 0, 2.0, 0.0)
    with pytest.raises(ValueError, match=r"p_off .*probability"):
        b.broadcast(d, 0, 0.0, float("nan"))
    with pytest.raises(ValueError, match=r"index 3 out of range \[0, 1\)"):
        b.on_count(d, 3)
    with pytest.raises(ValueError, match="no recruit.sma actuator named 'biceps'"):
        b.force(d, "biceps")
    other = mujoco.MjModel.from_xml_path(BENCH)
    with pytest.raises(ValueError, match="another MjModel"):
        b.on_count(mujoco.MjData(other), 0)
    with pytest.raises(ValueError, match="must be a mujoco.MjData"):
        b.on_count(object(), 0)
    with pytest.raises(ValueError, match="must be a mujoco.MjModel"):
        recruit.Bundles(object())
    plain = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><joint/><geom size='.1'/></body></worldbody></mujoco>")
    with pytest.raises(ValueError):
        recruit.Bundles(plain)


def test_state_counts_and_cohorts_agree_with_the_units():
    # The per-state counts and the cohorts are two views of the per-unit ground truth.
    m, d, b = _bench()
    b.reset(d, 3)
    c = b.cohorts(d, 0)
    assert list(c["count"]) == [60] and not c["on"][0]  # one cohort: all off and cold
    np.testing.assert_array_equal(b.state_counts(d, 0), [60, 0])
    b.broadcast(d, 0, 0.4, 0.0)
    for _ in range(300):
        mujoco.mj_step(m, d)
    b.broadcast(d, 0, 0.3, 0.5)  # on units of two ages, off units cooling and cold
    for _ in range(200):
        mujoco.mj_step(m, d)
    on = b.units_on(d, 0)
    np.testing.assert_array_equal(b.state_counts(d, 0), [60 - on.sum(), on.sum()])
    assert b.state_counts(d, "bundle")[1] == b.on_count(d, 0)
    c = b.cohorts(d, 0)
    assert len(c["count"]) == b.num_cohorts(d, 0) >= 3
    assert c["count"].sum() == 60
    assert c["count"][c["on"]].sum() == on.sum()
    # Each cohort's temperature is carried by exactly `count` units.
    T = b.unit_temperatures(d, 0)
    for n, t in zip(c["count"], c["temperature"]):
        assert np.sum(T == t) >= n
    assert np.dot(c["count"], c["temperature"]) / 60 == pytest.approx(T.mean(), rel=1e-12)
    np.testing.assert_allclose(np.dot(c["count"], c["xi"]) / 60, b.unit_xi(d, 0).mean(),
                               rtol=1e-12)
