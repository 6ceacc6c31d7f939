"""Guards against silent nonsense (issue 86, item 3): `evaluate` refuses a data file that is the fit's training
file (or holds only its training rows) and warns about one that holds some (`replication.fit.rows`); an error
beyond the data's own scale reads "diverged", never as a number (`replication.evaluation.diverged`)."""
import json
import shutil
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.replication.evaluation.diverged import (
    DIVERGED,
    diverged_trajectories,
    flagged,
    is_diverged,
    note,
    shown,
)
from lagbench.replication.fit.cli import evaluation_line
from lagbench.reports.sections_fit import _rollout_table


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A tiny fit of 4 simulated pendulum trajectories (one held out) and a file of 3 other trajectories."""
    d = tmp_path_factory.mktemp("guards")
    for name, seed, n in (("train.csv", 0, 4), ("other.csv", 1, 3)):
        assert main(["simulate", "--system", "pendulum", "--trajectories", str(n), "--duration", "2", "--rate", "20",
                     "--seed", str(seed), "--out", str(d / name)]) == 0
    assert main(["fit", "--data", str(d / "train.csv"), "--model", "baseline", "--steps", "3", "--hidden", "8",
                 "--restarts", "0", "--quiet", "--out", str(d / "fit")]) == 0
    unit = d / "fit" / "units" / "fit" / "jax" / "baseline" / "seed0"
    prepared = pd.read_csv(next((d / "fit" / "data").glob("train-fit-*.csv")))
    return SimpleNamespace(dir=d, fit=d / "fit", unit=unit, result=json.loads((unit / "result.json").read_text()),
                           train_ids=sorted(prepared.loc[prepared["split"] == "train", "traj"].unique()))


def _evaluate(fitted, data, out, capsys):
    rc = main(["evaluate", "--fitted", str(fitted.fit), "--data", str(data), "--out", str(out), "--quiet"])
    return (rc, *capsys.readouterr())


def test_the_training_file_itself_is_refused_naming_both_files(fitted, tmp_path, capsys):
    rc, out, err = _evaluate(fitted, fitted.dir / "train.csv", tmp_path / "e", capsys)
    assert rc == 2 and out == "" and err.count("\n") == 1, err
    assert "the same file as the training data of the fit" in err and err.count("train.csv") == 2, err
    assert not (tmp_path / "e").exists()   # refused before anything is written
    shutil.copy(fitted.dir / "train.csv", tmp_path / "renamed.csv")
    rc, _, err = _evaluate(fitted, tmp_path / "renamed.csv", tmp_path / "e", capsys)
    assert rc == 2 and "renamed.csv: byte for byte the same as the training data" in err and "train.csv" in err, err


def test_a_file_of_only_training_trajectories_is_refused(fitted, tmp_path, capsys):
    df = pd.read_csv(fitted.dir / "train.csv")
    only = df[df["traj"].isin(fitted.train_ids)].assign(traj=lambda x: x["traj"] + 100)   # relabelled: other bytes
    only.to_csv(tmp_path / "only.csv", index=False)
    rc, _, err = _evaluate(fitted, tmp_path / "only.csv", tmp_path / "e", capsys)
    n = len(fitted.train_ids)
    assert rc == 2 and f"{n} of its {n} trajectories" in err and "are training rows of the fit" in err, err


def test_a_file_partly_of_training_trajectories_is_evaluated_with_a_warning_on_record(fitted, tmp_path, capsys):
    df, other = pd.read_csv(fitted.dir / "train.csv"), pd.read_csv(fitted.dir / "other.csv")
    part = pd.concat([df[df["traj"] == fitted.train_ids[0]], other.assign(traj=other["traj"] + 10)])
    part.to_csv(tmp_path / "part.csv", index=False)
    rc, out, err = _evaluate(fitted, tmp_path / "part.csv", tmp_path / "e", capsys)
    assert rc == 0 and "warning: --data" in err and "1 of its 4 trajectories" in err, err
    r = json.loads(next((tmp_path / "e" / "units" / "evaluate").glob("*/*/seed0/result.json")).read_text())
    shared = r["eval_config"]["training_rows"]
    assert shared["trajectories"] == 1 and shared["of_trajectories"] == 4 and 0 < shared["rows"] < shared["of_rows"]
    from lagbench.reports.build import build_sections

    text = " ".join(getattr(b, "text", "") for s in build_sections(tmp_path / "e", tmp_path / "rep") for b in s.blocks)
    assert "WARNING: 1 of its 4 trajectories" in text
    rc, out, err = _evaluate(fitted, fitted.dir / "other.csv", tmp_path / "o", capsys)   # other trajectories: silent
    assert rc == 0 and "warning" not in err
    r = json.loads(next((tmp_path / "o" / "units" / "evaluate").glob("*/*/seed0/result.json")).read_text())
    assert "training_rows" not in r["eval_config"]


def test_each_rollout_set_records_how_many_of_its_rollouts_diverged(fitted):
    m = fitted.result["metrics"]
    assert m["heldout_n_trajectories"] == 4 - len(fitted.train_ids)
    assert 0 <= m["heldout_n_diverged"] <= m["heldout_n_trajectories"]
    err = np.array([[0.1, 0.2, 0.3], [0.1, np.inf, np.nan], [0.1, 2 * DIVERGED, 0.1], [0.0, DIVERGED, DIVERGED]])
    assert diverged_trajectories(err).tolist() == [False, True, True, False]


def test_an_error_beyond_the_datas_scale_reads_diverged_never_as_a_number():
    m = {"test_l1": 0.25, "test_rollout_gmean_err": 0.97, "test_learned_energy_drift": 0.5,
         "test_energy_err_final": 9.9e59, "test_n_diverged": 2, "test_n_trajectories": 4}
    line = evaluation_line(m, "test", "test_l1")
    assert "test_energy_err_final diverged" in line and "e+59" not in line and "9.9" not in line, line
    assert "test_learned_energy_drift 0.5" in line and "(DIVERGED: 2 of 4 rollouts diverged)" in line, line
    assert is_diverged(float("nan")) and is_diverged(-2 * DIVERGED) and not is_diverged(DIVERGED) and not is_diverged(None)
    assert shown(0.5) == "0.5" and shown(float("inf")) == "diverged"
    assert flagged({**m, "test_n_diverged": 0}, "test") == "test_energy_err_final diverged"
    assert flagged({"test_energy_err_final": 0.1, "test_n_diverged": 0, "test_n_trajectories": 4}, "test") is None
    assert note({"heldout_n_diverged": 1, "heldout_n_trajectories": 1}) == " (DIVERGED: 1 of 1 rollouts diverged)"
    assert note({"heldout_n_diverged": 0, "heldout_n_trajectories": 1}) == ""
    u = SimpleNamespace(claim="evaluate", model="lnn", framework="jax", seed=0, metric=lambda k: m.get(k))
    row = _rollout_table([u]).iloc[0]
    assert row["true energy error at the end"] == "diverged" and row["learned energy drift (max over time)"] == "0.5"
    assert row.filter(like="rollouts diverged").iloc[0] == "2 of 4"


def test_a_fit_whose_test_file_is_its_training_data_is_refused_before_any_work(fitted, tmp_path, capsys):
    shutil.copy(fitted.dir / "train.csv", tmp_path / "copy.csv")
    rc = main(["fit", "--data", str(fitted.dir / "train.csv"), "--test", str(tmp_path / "copy.csv"), "--model",
               "baseline", "--steps", "3", "--hidden", "8", "--quiet", "--out", str(tmp_path / "f")])
    err = capsys.readouterr().err
    assert rc == 2 and "copy.csv: byte for byte the training data" in err, err
    assert not (tmp_path / "f").exists()   # the folder it made for its output is gone with its lock
    (tmp_path / "mine").mkdir()            # a folder the user made stays, as it was
    rc = main(["fit", "--data", str(fitted.dir / "train.csv"), "--test", str(tmp_path / "copy.csv"), "--model",
               "baseline", "--steps", "3", "--hidden", "8", "--quiet", "--out", str(tmp_path / "mine")])
    assert rc == 2 and (tmp_path / "mine").is_dir()
    rc = main(["fit", "--data", str(fitted.dir / "train.csv"), "--test", str(tmp_path / "copy.csv"), "--model",
               "baseline", "--steps", "3", "--hidden", "8", "--quiet", "--out", str(tmp_path / "a" / "b")])
    assert rc == 2 and not (tmp_path / "a").exists()   # the parents it made too
