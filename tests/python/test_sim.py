"""simulate's per-step trace and sweep / aggregate against the CLI (`recruit simulate`,
`recruit sweep`) for the same task, options and seeds."""
import csv
import glob
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import recruit

from conftest import ROOT

TASK = str(ROOT / "models" / "tasks" / "isometric_steps.json")


def _cli():
    # ctest passes RECRUIT_CLI; otherwise the build tree next to RECRUIT_PYTHONPATH.
    path = os.environ.get("RECRUIT_CLI")
    if not path and os.environ.get("RECRUIT_PYTHONPATH"):
        path = str(pathlib.Path(os.environ["RECRUIT_PYTHONPATH"]).parent / "src" / "cli" / "recruit")
    if not path or not os.access(path, os.X_OK):
        pytest.skip("the recruit CLI is not built (set RECRUIT_CLI)")
    return path


# The CSV writer's number formats (src/sim/csv_writer.cc), by column suffix.
def _fmt(name, v):
    if name == "control_instant" or name.endswith(".true_on"):
        return str(int(v))
    if name in ("reference", "measured", "angle") or name.endswith((".force",
                                                                     ".force_reference",
                                                                     ".sensed_force")):
        return format(v, ".9g")
    if name.endswith((".estimated_on", ".estimated_on_std")) and not np.isfinite(v):
        return ""  # non-finite estimates are left empty
    return format(v, ".6g")


@pytest.mark.parametrize("estimator,every", [("output", 1), ("kalman-augmented", 7)])
def test_simulate_trace_is_the_cli_csv(tmp_path, monkeypatch, estimator, every):
    cli = _cli()
    monkeypatch.chdir(ROOT)  # the default identified models are found from the root
    csv_path, summary_path = tmp_path / "steps.csv", tmp_path / "summary.json"
    subprocess.run([cli, "simulate", "--task", TASK, "--duration", "12", "--seed", "5",
                    "--estimator", estimator, "--dT", "0.5", "--csv-every", str(every), "--out",
                    str(tmp_path), "--csv", str(csv_path), "--summary", str(summary_path)],
                   check=True, capture_output=True, cwd=ROOT)
    r = recruit.simulate(TASK, duration=12.0, seed=5, estimator=estimator, dT=0.5,
                         trace_every=every)
    trace = r.pop("trace")
    with open(csv_path) as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], rows[1:]
    assert list(trace.keys()) == header
    n = len(rows)
    assert all(len(v) == n for v in trace.values())
    # Every cell, formatted as the CLI formats it, is the CLI's text: the same numbers.
    for j, name in enumerate(header):
        assert [_fmt(name, v) for v in trace[name]] == [row[j] for row in rows], name
    assert trace["control_instant"].sum() == r["control_instants"]
    with open(summary_path) as f:
        cli_summary = json.load(f)
    cli_summary.pop("wall_seconds"), r.pop("wall_seconds")
    assert r == cli_summary


def test_simulate_without_trace_and_errors():
    r = recruit.simulate(TASK, duration=2.0, trace_every=0)
    assert "trace" not in r
    with pytest.raises(ValueError, match="trace_every"):
        recruit.simulate(TASK, duration=2.0, trace_every=-1)
    with pytest.raises(ValueError, match="no_such_task"):
        recruit.simulate(str(ROOT / "no_such_task.json"))


def test_sweep_and_aggregate_are_the_cli_sweep(tmp_path, monkeypatch):
    cli = _cli()
    monkeypatch.chdir(ROOT)
    args = dict(dT=[0.5, 2.0], lam=[0.2], estimator=["output", "kalman-augmented"], seeds=2,
                base_seed=3, duration=20.0)
    subprocess.run([cli, "sweep", "--task", TASK, "--out", str(tmp_path), "--dT", "0.5,2",
                    "--lambda", "0.2", "--estimator", "output,kalman-augmented", "--seeds", "2",
                    "--base-seed", "3", "--duration", "20", "--threads", "2"],
                   check=True, capture_output=True, cwd=ROOT)
    runs = recruit.sweep(TASK, threads=2, **args)
    assert len(runs["dT"]) == 8
    assert all(len(v) == 8 for v in runs.values())
    # Grid order: dT outermost, then lambda, estimator, seed index.
    assert list(runs["dT"]) == [0.5] * 4 + [2.0] * 4
    assert runs["estimator"][:4] == ["output", "output", "kalman-augmented", "kalman-augmented"]
    assert list(runs["seed_index"]) == [0, 1] * 4
    # The CLI's per-run records: the same seeds and metrics, bit for bit.
    records = {}
    for p in glob.glob(str(tmp_path / "runs" / "*.json")):
        with open(p) as f:
            j = json.load(f)
        records[(j["dT"], j["estimator"], j["seed"])] = j
    assert len(records) == 8
    for i in range(8):
        j = records[(runs["dT"][i], runs["estimator"][i], int(runs["seed"][i]))]
        for k, v in j["metrics"].items():
            got = runs[k][i]
            if v is None:
                assert np.isnan(got), k
            else:
                assert got == v, k
    # aggregate == table.csv, formatted as the CLI writes it.
    cells = recruit.aggregate(runs)
    with open(tmp_path / "table.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == len(cells["dT"]) == 4
    for i, row in enumerate(table):
        assert format(cells["dT"][i], "g") == row["dT"]
        assert cells["estimator"][i] == row["estimator"]
        assert str(cells["seeds"][i]) == row["seeds"]
        assert str(int(cells["meets_criterion"][i])) == row["meets_criterion"]
        for k in ("overshoot_mean", "overshoot_sd", "settling_time_mean", "settled_fraction",
                  "tracking_rmse_mean", "iae_mean", "oscillation_mean", "switching_rate_mean",
                  "estimator_rmse_mean", "mean_nees_mean", "estimator_within3_mean", "margin"):
            # The table writes the shortest text that reads back as the double: exact.
            got = float(row[k])
            assert got == cells[k][i] or (np.isnan(got) and np.isnan(cells[k][i])), k
    # Another base seed: other runs.
    other = recruit.sweep(TASK, threads=2, **dict(args, base_seed=4, dT=[2.0]))
    assert not np.array_equal(other["tracking_rmse"], runs["tracking_rmse"][4:])


def test_sweep_with_a_sweep_file_is_the_cli_sweep(tmp_path):
    """A sweep file (plant axes, controller values) is prepared as `recruit sweep --sweep`
    prepares it: the same grid, seeds and metrics, and aggregate gives table.csv's cells per
    plant point; an argument given to sweep() overrides the file's as a CLI option does."""
    cli = _cli()
    spec = tmp_path / "noise.json"
    spec.write_text(json.dumps({
        "task": TASK,
        "duration": 10,
        "controller": {"dT": [2], "lambda": [0.3], "estimator": ["output"], "seeds": 2,
                       "base_seed": 5},
        "plant": {"axes": [{"name": "noise_std", "path": "/sensor/noise_std",
                            "values": [0.02, 0.5]}]},
    }))
    out = tmp_path / "cli"
    subprocess.run([cli, "sweep", "--sweep", str(spec), "--out", str(out), "--threads", "2"],
                   check=True, capture_output=True)
    runs = recruit.sweep(sweep_file=spec, threads=2)
    assert list(runs)[:3] == ["plant", "noise_std", "dT"]
    assert list(runs["plant"]) == [0, 0, 1, 1]
    assert list(runs["noise_std"]) == [0.02, 0.02, 0.5, 0.5]
    assert list(runs["lambda"]) == [0.3] * 4
    assert np.allclose(runs["duration"], 10.0, rtol=1e-12)  # the simulated time
    for i in range(4):
        key = "p{:04d}_dT2_l0.3_output_s{}".format(runs["plant"][i], runs["seed_index"][i])
        with open(out / "runs" / (key + ".json")) as f:
            j = json.load(f)
        assert j["seed"] == runs["seed"][i]
        for k, v in j["metrics"].items():
            assert (np.isnan(runs[k][i]) if v is None else runs[k][i] == v), (key, k)
    # The louder load cell changes the runs: the axis was applied.
    assert runs["estimator_rmse"][0] != runs["estimator_rmse"][2]
    cells = recruit.aggregate(runs)
    with open(out / "table.csv") as f:
        table = list(csv.DictReader(f))
    assert list(cells)[:3] == ["plant", "noise_std", "dT"] and len(table) == 2
    for i, row in enumerate(table):
        assert str(cells["plant"][i]) == row["plant"]
        assert float(row["noise_std"]) == cells["noise_std"][i]
        for k in ("overshoot_mean", "tracking_rmse_mean", "margin"):
            assert float(row[k]) == cells[k][i], k
    # Given here, a value overrides the file's (as --seeds and --lambda do).
    more = recruit.sweep(sweep_file=spec, seeds=1, lam=0.2, threads=2)
    assert list(more["seed_index"]) == [0, 0] and list(more["lambda"]) == [0.2, 0.2]


def test_sweep_errors_are_value_errors(tmp_path):
    with pytest.raises(ValueError, match="lambda"):
        recruit.sweep(TASK, dT=1.0, lam=2.0, duration=2.0)
    with pytest.raises(ValueError, match="seeds"):
        recruit.sweep(TASK, dT=1.0, seeds=0, duration=2.0)
    with pytest.raises(ValueError, match="dT: required"):
        recruit.sweep(TASK, duration=2.0)
    with pytest.raises(ValueError, match="duration"):
        recruit.sweep(TASK, dT=1.0, duration=0.0)
    with pytest.raises(ValueError, match="unknown field 'colour'"):  # the sweep file's checks
        bad = tmp_path / "bad.json"
        bad.write_text('{"colour": 1}')
        recruit.sweep(TASK, dT=1.0, sweep_file=bad)
    with pytest.raises(ValueError, match="no column"):
        recruit.aggregate({"dT": [1.0]})
