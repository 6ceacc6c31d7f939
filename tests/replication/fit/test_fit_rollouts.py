"""A fit's rollouts: to `--horizon` seconds when given (recorded, inherited by `evaluate`, refused when
shorter than a trajectory's first interval), with progress reported per evaluation set (issue 58, item 6)."""
import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.replication.fit.evaluate_file import evaluate
from lagbench.replication.fit.task import fit

FAST = {"model": "lnn", "steps": 4, "hidden": (8,), "batch": 16}


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("rollouts")
    for name, seed in (("train.csv", 0), ("test.csv", 1)):
        assert main(["simulate", "--system", "pendulum", "--trajectories", "3", "--duration", "3", "--rate", "20",
                     "--seed", str(seed), "--out", str(d / name)]) == 0
    return d


def test_horizon_cuts_the_rollouts_and_progress_counts_their_intervals(files, tmp_path):
    seen = []
    r = fit(files / "train.csv", out=tmp_path / "o", test=files / "test.csv", horizon=1.0,
            on_progress=lambda *a: seen.append(a), **FAST)
    assert r["status"] == "ok" and r["eval_config"]["horizon"] == 1.0
    folder = tmp_path / "o" / "units" / "fit" / "jax" / "lnn" / "seed0"
    series = pd.read_csv(folder / "timeseries.csv")
    test = series[series["set"] == "test"]
    assert 0.95 <= test["t"].max() <= 1.0 and test["traj"].nunique() == 3
    last = {label: (done, total) for label, done, total in seen}
    assert last["test"] == (20, 20)   # 3 trajectories on one grid: the 20 intervals to 1 s, once
    whole = fit(files / "train.csv", out=tmp_path / "w", test=files / "test.csv", **FAST)
    assert "horizon" not in whole["eval_config"]   # fits without a horizon keep their keys
    wseries = pd.read_csv(tmp_path / "w" / "units" / "fit" / "jax" / "lnn" / "seed0" / "timeseries.csv")
    assert wseries[wseries["set"] == "test"]["t"].max() > 2.0   # to the end (the filter trims 7 samples a side)
    again = evaluate(folder, files / "test.csv", out=tmp_path / "e")
    assert again[0]["eval_config"]["horizon"] == 1.0   # evaluate inherits the fit's


def test_a_horizon_shorter_than_the_first_interval_is_refused_by_name(files, tmp_path):
    with pytest.raises(ValueError, match=r"--horizon 0\.01: shorter than the first sample interval"):
        fit(files / "train.csv", out=tmp_path / "o", test=files / "test.csv", horizon=0.01, **FAST)
