"""recruit.attach (`recruit attach` from Python): the written model, read back with the official
mujoco bindings, has the designed bundles on the original tendons and every other element as
before; the returned report is the one --report writes; bad input raises and writes nothing."""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

import mujoco
import recruit  # registers the recruit.sma plugin

from conftest import ROOT

ARM = str(ROOT / "models" / "arm2j_muscle.xml")


def _name(m, kind, i):
    return mujoco.mj_id2name(m, kind, i)


def _tendon_muscles(m):
    """The original's muscles on tendons, read from the compiled model (an independent list)."""
    return {_name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a) for a in range(m.nu)
            if m.actuator_dyntype[a] == mujoco.mjtDyn.mjDYN_MUSCLE
            and m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_TENDON}


@pytest.fixture(scope="module")
def attached(tmp_path_factory):
    d = tmp_path_factory.mktemp("attach")
    out, task, rep = d / "arm2j_sma.xml", d / "task.json", d / "report.json"
    report = recruit.attach(ARM, "all", output=out, task=task, report=rep)
    return report, out, task, rep


def test_replaced_actuators_are_plugin_actuators_on_the_same_tendons(attached):
    report, out, _, _ = attached
    before = mujoco.MjModel.from_xml_path(ARM)
    after = mujoco.MjModel.from_xml_path(str(out))
    names = [b["name"] for b in report["bundles"]]
    assert set(names) == _tendon_muscles(before)
    for b in report["bundles"]:
        a = mujoco.mj_name2id(after, mujoco.mjtObj.mjOBJ_ACTUATOR, b["name"])
        a0 = mujoco.mj_name2id(before, mujoco.mjtObj.mjOBJ_ACTUATOR, b["name"])
        assert a >= 0 and a0 >= 0
        assert after.actuator_plugin[a] >= 0, b["name"]
        assert after.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_TENDON
        assert after.actuator_trnid[a, 0] == before.actuator_trnid[a0, 0], b["name"]
        assert _name(after, mujoco.mjtObj.mjOBJ_TENDON, after.actuator_trnid[a, 0]) == b["tendon"]
        assert after.actuator_dyntype[a] == mujoco.mjtDyn.mjDYN_NONE  # no inherited muscle
        assert after.actuator_gear[a, 0] == pytest.approx(b["gear"])
        s = mujoco.mj_name2id(after, mujoco.mjtObj.mjOBJ_SENSOR, b["sensor"])
        assert s >= 0
    # The plugin host reads the designed unit counts from the written plugin config.
    bundles = recruit.Bundles(after)
    assert sorted(bundles.names) == sorted(names)
    for b in report["bundles"]:
        assert bundles.num_units(b["name"]) == int(b["config"]["units"])
        assert bundles.tendon_id(b["name"]) == after.actuator_trnid[
            mujoco.mj_name2id(after, mujoco.mjtObj.mjOBJ_ACTUATOR, b["name"]), 0]


def test_everything_else_is_unchanged(attached):
    _, out, _, _ = attached
    before = mujoco.MjModel.from_xml_path(ARM)
    after = mujoco.MjModel.from_xml_path(str(out))
    for n in ("nbody", "njnt", "ngeom", "nsite", "ntendon", "nu", "nq", "nv"):
        assert getattr(after, n) == getattr(before, n), n
    np.testing.assert_array_equal(after.body_mass, before.body_mass)
    np.testing.assert_array_equal(after.geom_type, before.geom_type)
    np.testing.assert_array_equal(after.jnt_type, before.jnt_type)
    # mj_saveXML writes 6 significant digits (the compiled radians of a degree model).
    np.testing.assert_allclose(after.jnt_range, before.jnt_range, atol=1e-5)
    np.testing.assert_allclose(after.geom_size, before.geom_size, rtol=1e-5)
    np.testing.assert_array_equal(after.dof_damping, before.dof_damping)
    assert after.opt.timestep == before.opt.timestep
    for kind, count in ((mujoco.mjtObj.mjOBJ_BODY, before.nbody),
                        (mujoco.mjtObj.mjOBJ_JOINT, before.njnt),
                        (mujoco.mjtObj.mjOBJ_TENDON, before.ntendon)):
        assert [_name(after, kind, i) for i in range(count)] == \
               [_name(before, kind, i) for i in range(count)]
    # One truth sensor per bundle is the only addition.
    assert after.nsensor == before.nsensor + after.nu


def test_report_is_what_the_report_file_holds(attached):
    report, out, task, rep = attached
    with open(rep) as f:
        assert report == json.load(f)
    assert report["output"] == str(out) and report["task"] == str(task)
    assert [b["replaced"] for b in report["bundles"]] == ["muscle"] * len(report["bundles"])
    with open(task) as f:
        t = json.load(f)
    assert t["bundles"] == [b["name"] for b in report["bundles"]]


@pytest.mark.skipif(not os.environ.get("RECRUIT_CLI"), reason="RECRUIT_CLI not set")
def test_bundles_match_the_cli_report(attached, tmp_path):
    report = attached[0]
    rep = tmp_path / "cli.json"
    subprocess.run([os.environ["RECRUIT_CLI"], "attach", ARM, "--muscles", "all", "-o",
                    str(tmp_path / "out.xml"), "--report", str(rep)], check=True,
                   capture_output=True)
    with open(rep) as f:
        cli = json.load(f)
    assert cli["bundles"] == report["bundles"]


def test_size_only_writes_nothing_and_designs_the_same(attached, tmp_path):
    report = recruit.attach(ARM, ["EF", "EE"], size_only=True)
    assert os.listdir(tmp_path) == []
    assert report["output"] == ""
    full = {b["name"]: b for b in attached[0]["bundles"]}
    for b in report["bundles"]:
        assert b["config"] == full[b["name"]]["config"]


def test_sizing_options_are_the_clis(tmp_path):
    """stroke_use and units_per_holding_force design what the CLI's options of the same names
    design: the same config keys, bundle by bundle."""
    rep = tmp_path / "cli.json"
    subprocess.run([os.environ["RECRUIT_CLI"], "attach", ARM, "--muscles", "all", "--size-only",
                    "--stroke-use", "0.5", "--units-per-holding-force", "0", "--report", str(rep)],
                   check=True, capture_output=True)
    with open(rep) as f:
        cli = json.load(f)
    report = recruit.attach(ARM, "all", size_only=True, stroke_use=0.5,
                            units_per_holding_force=0)
    assert [b["config"] for b in report["bundles"]] == [b["config"] for b in cli["bundles"]]
    default = recruit.attach(ARM, "all", size_only=True)
    assert [b["config"] for b in report["bundles"]] != [b["config"] for b in default["bundles"]]


def test_damping_ratio_is_the_clis(tmp_path):
    """damping_ratio gives the dampers --damping-ratio gives, bundle by bundle and joint by joint;
    0 gives none."""
    rep = tmp_path / "cli.json"
    subprocess.run([os.environ["RECRUIT_CLI"], "attach", ARM, "--muscles", "all", "--size-only",
                    "--damping-ratio", "0.9", "--report", str(rep)], check=True,
                   capture_output=True)
    with open(rep) as f:
        cli = json.load(f)
    report = recruit.attach(ARM, "all", size_only=True, damping_ratio=0.9)
    assert [b["damper"] for b in report["bundles"]] == [b["damper"] for b in cli["bundles"]]
    assert report["joints"] == cli["joints"]
    assert min(j["damping_ratio"][1] for j in report["joints"]) == pytest.approx(0.9)
    none = recruit.attach(ARM, "all", size_only=True, damping_ratio=0)
    assert all(b["damper"] == 0 for b in none["bundles"])


def test_bad_input_raises_naming_the_muscle_and_writes_nothing(tmp_path):
    out, task, rep = tmp_path / "out.xml", tmp_path / "task.json", tmp_path / "r.json"
    with pytest.raises(ValueError, match="'biceps' does not exist"):
        recruit.attach(ARM, ["EF", "biceps"], output=out, task=task, report=rep)
    with pytest.raises(ValueError, match="--lock wrist"):
        recruit.attach(ARM, "all", output=out, task=task, lock="wrist")
    with pytest.raises(ValueError, match="refusing to overwrite"):
        recruit.attach(ARM, "all", output=ARM)
    with pytest.raises(ValueError, match="no output model"):
        recruit.attach(ARM, "all")
    with pytest.raises(ValueError, match="force"):
        recruit.attach(ARM, "all", output=out, force=-1.0)
    with pytest.raises(ValueError, match="stroke_use"):
        recruit.attach(ARM, "all", output=out, stroke_use=1.5)
    with pytest.raises(ValueError, match="units_per_holding_force"):
        recruit.attach(ARM, "all", output=out, units_per_holding_force=-1)
    with pytest.raises(ValueError, match="damping_ratio"):
        recruit.attach(ARM, "all", output=out, damping_ratio=-0.1)
    with pytest.raises(ValueError, match="cannot open model"):
        recruit.attach(tmp_path / "missing.xml", "all", output=out)
    assert os.listdir(tmp_path) == []


def test_unwritable_output_is_an_os_error_and_leaves_nothing(tmp_path):
    out = tmp_path / "no_such_dir" / "out.xml"
    with pytest.raises(OSError, match="cannot"):
        recruit.attach(ARM, "all", output=out, report=tmp_path / "r.json")
    assert os.listdir(tmp_path) == []


def test_lock_holds_the_joint_in_mujocos_own_simulation(tmp_path):
    """lock=["elbow"]: the written model holds the elbow with a joint equality, which MuJoCo's
    own solver keeps (1 s under gravity with the bundles idle); the bundles' sizing and the
    starter task leave the elbow out."""
    out, task = tmp_path / "locked.xml", tmp_path / "task.json"
    report = recruit.attach(ARM, "all", output=out, task=task, lock=["elbow"])
    m = mujoco.MjModel.from_xml_path(str(out))
    elbow = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "elbow")
    assert m.neq == 1
    assert m.eq_type[0] == mujoco.mjtEq.mjEQ_JOINT
    assert m.eq_obj1id[0] == elbow and m.eq_obj2id[0] == -1
    d = mujoco.MjData(m)
    q = m.jnt_qposadr[elbow]
    worst = 0.0
    for _ in range(int(1.0 / m.opt.timestep)):
        mujoco.mj_step(m, d)
        worst = max(worst, abs(d.qpos[q] - m.qpos0[q]))
    assert worst < 0.02
    for b in report["bundles"]:
        assert all(j["joint"] != "elbow" for j in b["joints"]), b["name"]
    with open(task) as f:
        assert [j["joint"] for j in json.load(f)["joints"]] == ["shoulder"]


def test_mujocos_warnings_go_to_stderr_not_into_the_working_folder(tmp_path, monkeypatch,
                                                                   capfd):
    """A model whose tendon path jumps makes the plugin warn while attach compiles it: the
    warning goes to stderr (at most once per process: an earlier test may have printed it), and
    no MUJOCO_LOG.TXT (MuJoCo's default handler's file) appears in the working folder."""
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    recruit.attach(str(ROOT / "tests/attach/data/jump_arm.xml"), muscles=["all"],
                   output=str(out / "m.xml"))
    assert capfd.readouterr().err.count("tendon path jumps") <= 1
    assert sorted(os.listdir(tmp_path)) == ["out"]
