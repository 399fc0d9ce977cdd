"""The metric names and sweep columns of the package come from the C++ table of run metrics
(src/sim/run_metrics.h): recruit.METRICS are the keys of a summary's "metrics", sweep(...) has a
column for each, and aggregate(...) has exactly the columns of `recruit sweep`'s table.csv."""
import csv
import os
import pathlib
import subprocess

import numpy as np
import pytest

import recruit
from recruit import _recruit

from conftest import ROOT

TASK = str(ROOT / "models" / "tasks" / "isometric_steps.json")


def test_metrics_are_the_summary_keys():
    r = recruit.simulate(TASK, duration=4.0, trace_every=0)
    assert sorted(recruit.METRICS) == sorted(r["metrics"])
    assert len(set(recruit.METRICS)) == len(recruit.METRICS)
    fields = {f["name"]: f for f in _recruit.METRIC_FIELDS}
    for name, v in r["metrics"].items():
        if fields[name]["integer"]:
            assert isinstance(v, int), name
        elif v is None:
            assert fields[name]["may_be_nan"], name


def test_sweep_and_aggregate_columns_follow_the_table():
    runs = recruit.sweep(TASK, dT=[1.0], estimator=["output"], seeds=2, duration=4.0, threads=1)
    for name in recruit.METRICS:
        assert len(runs[name]) == 2, name
    integer = {f["name"] for f in _recruit.METRIC_FIELDS if f["integer"]}
    assert integer == {"num_steps"}
    assert runs["num_steps"].dtype == np.int64
    cells = recruit.aggregate(runs)
    assert tuple(cells) == _recruit.CELL_COLUMNS
    # Each metric's cell column is the mean of its two seeds (settled_fraction keeps its name).
    for name in recruit.METRICS:
        col = name if name == "settled_fraction" else name + "_mean"
        if col in cells:
            v = runs[name]
            want = np.nanmean(v) if np.isfinite(v).any() else np.nan
            np.testing.assert_allclose(cells[col][0], want, rtol=1e-12, err_msg=name)
    np.testing.assert_allclose(cells["overshoot_sd"][0], np.std(runs["overshoot"], ddof=1),
                               rtol=1e-12)


def test_cell_columns_are_the_cli_table_header(tmp_path):
    cli = os.environ.get("RECRUIT_CLI")
    if not cli and os.environ.get("RECRUIT_PYTHONPATH"):
        cli = str(pathlib.Path(os.environ["RECRUIT_PYTHONPATH"]).parent / "src" / "cli" / "recruit")
    if not cli or not os.access(cli, os.X_OK):
        pytest.skip("the recruit CLI is not built (set RECRUIT_CLI)")
    subprocess.run([cli, "sweep", "--task", TASK, "--out", str(tmp_path), "--dT", "1",
                    "--estimator", "output", "--seeds", "1", "--duration", "4", "--threads", "1"],
                   check=True, capture_output=True, cwd=ROOT)
    with open(tmp_path / "table.csv") as f:
        header = next(csv.reader(f))
    assert tuple(header) == _recruit.CELL_COLUMNS
