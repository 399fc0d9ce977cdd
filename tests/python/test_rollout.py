"""mujoco.rollout over bundle models: several threads give serial stepping's states bit for bit.

Each unit's state and the random streams live in mjData.plugin_state, which mjSTATE_FULLPHYSICS
(the state rollout sets and records) includes; so a rollout on any thread continues exactly the
run it was forked from.
"""
import numpy as np
import pytest

import mujoco
from mujoco import rollout

import recruit

from conftest import ROOT

FULL = mujoco.mjtState.mjSTATE_FULLPHYSICS


def _serial(m, initial_state, control):
    """The reference: one MjData, mj_setState then mj_step, ctrl set before every step."""
    d = mujoco.MjData(m)
    nbatch, nstep = control.shape[:2]
    nstate = mujoco.mj_stateSize(m, FULL)
    state = np.empty((nbatch, nstep, nstate))
    sensordata = np.empty((nbatch, nstep, m.nsensordata))
    for b in range(nbatch):
        mujoco.mj_resetData(m, d)
        mujoco.mj_setState(m, d, initial_state[b], FULL)
        for k in range(nstep):
            d.ctrl[:] = control[b, k]
            mujoco.mj_step(m, d)
            mujoco.mj_getState(m, d, state[b, k], FULL)
            sensordata[b, k] = d.sensordata
    return state, sensordata


def _initial_states(m, bundles, nbatch, rng):
    """Different starting points: per-bundle seeds, then a random warm-up of broadcasts."""
    d = mujoco.MjData(m)
    states = np.empty((nbatch, mujoco.mj_stateSize(m, FULL)))
    for b in range(nbatch):
        mujoco.mj_resetData(m, d)
        bundles.reset(d, 100 + b)
        for _ in range(int(rng.integers(50, 400))):
            d.ctrl[:] = rng.uniform(-1, 1, m.nu)
            mujoco.mj_step(m, d)
        mujoco.mj_getState(m, d, states[b], FULL)
    return states


def _plugin_slice(m):
    """Where plugin_state sits in a FULLPHYSICS state vector (the last mjSTATE_PLUGIN part)."""
    n = mujoco.mj_stateSize(m, mujoco.mjtState.mjSTATE_PLUGIN)
    total = mujoco.mj_stateSize(m, FULL)
    return slice(total - n, total)


@pytest.mark.parametrize("model", ["isometric_bench.xml", "elbow_arm.xml"])
def test_threaded_rollout_equals_serial_steps_bit_for_bit(model):
    m = mujoco.MjModel.from_xml_path(str(ROOT / "models" / model))
    bundles = recruit.Bundles(m)
    assert bundles.num_bundles >= 1 and m.npluginstate > 0
    rng = np.random.default_rng(5)
    nbatch, nstep = 6, 250
    initial = _initial_states(m, bundles, nbatch, rng)
    # Broadcasts held for 25 steps each, as a controller with dT = 25 steps would send them.
    held = rng.uniform(-0.3, 0.3, (nbatch, nstep // 25, m.nu))
    control = np.repeat(held, 25, axis=1)

    want_state, want_sensor = _serial(m, initial, control)
    datas = [mujoco.MjData(m) for _ in range(3)]
    got_state, got_sensor = rollout.rollout(m, datas, initial, control)

    # Not vacuous: the plugin state is part of the compared vector and changes during the run.
    ps = _plugin_slice(m)
    assert ps.stop - ps.start == m.npluginstate
    assert not np.array_equal(want_state[:, 0, ps], want_state[:, -1, ps])
    assert not np.array_equal(want_state[0, -1, ps], want_state[1, -1, ps])
    # Bit for bit (NaN-safe: compared as raw 64-bit words).
    assert np.array_equal(got_state.view(np.uint64), want_state.view(np.uint64))
    assert np.array_equal(got_sensor.view(np.uint64), want_sensor.view(np.uint64))


def test_rollout_without_the_plugin_state_would_differ():
    # The control experiment: restarting from a state that lacks plugin_state (units reset
    # instead) gives another trajectory, so equality above depends on the plugin state.
    m = mujoco.MjModel.from_xml_path(str(ROOT / "models" / "isometric_bench.xml"))
    bundles = recruit.Bundles(m)
    rng = np.random.default_rng(9)
    initial = _initial_states(m, bundles, 1, rng)
    control = np.full((1, 200, m.nu), 0.2)
    want, _ = _serial(m, initial, control)
    blank = initial.copy()
    blank[0, _plugin_slice(m)] = mujoco.MjData(m).plugin_state
    other, _ = rollout.rollout(m, [mujoco.MjData(m), mujoco.MjData(m)], blank, control)
    assert not np.array_equal(other, want)
