"""`lagbench train-target --split --runs`: runs on the test split read only its held-out draw, use disjoint
init seeds, resume from finished runs of the same inputs, refuse a folder of other inputs, and summarise
the time to held-out L1 0.069 in distribution.csv / distribution.json."""
import contextlib
import io
import json
import shutil

import numpy as np
import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.replication.run import splits
from lagbench.replication.training import data as datamod
from lagbench.speedstudy import target_distribution as TD
from lagbench.speedstudy import train_target as TT

TINY = ["--budget", "4000", "--hidden", "8,8", "--heldout-states", "64", "--quiet"]
HELDOUT, WIDTHS = 64, (8, 8)
PROTOCOLS = ["variant", "restarts_halved"]
RUNS = 2


def _command(out, *extra):
    return ["train-target", *TINY, "--protocols", ",".join(PROTOCOLS), "--split", "test", "--runs", str(RUNS),
            "--out", str(out), *extra]


@pytest.fixture(scope="module")
def test_runs(tmp_path_factory):
    """Two test-split runs of variant and restarts_halved, recording every held-out draw's generator seed."""
    out, seen = tmp_path_factory.mktemp("tt") / "out", []
    real = datamod.heldout

    def heldout(protocol, seed=datamod.HELDOUT_SEED, **kw):
        seen.append(seed)
        return real(protocol, seed, **kw)
    printed = io.StringIO()
    with pytest.MonkeyPatch.context() as mp, contextlib.redirect_stdout(printed):
        mp.setattr(datamod, "heldout", heldout)
        assert main(_command(out)) == 0
    return out, seen, printed.getvalue()


def _copy(test_runs, tmp_path):
    shutil.copytree(test_runs[0], tmp_path / "out")
    return tmp_path / "out"


def test_a_test_split_run_reads_only_the_test_heldout_draw(test_runs):
    out, seen, _ = test_runs
    assert seen and set(seen) == {splits.TEST.heldout_seed}   # every evaluation and the Hessian error
    for r in range(RUNS):
        inputs = json.loads((out / "train_target" / f"run{r}" / "inputs.json").read_text())
        assert inputs["split"] == "test" and inputs["heldout_seed"] == splits.TEST.heldout_seed


def test_runs_use_disjoint_init_seeds_of_the_split(test_runs):
    out = test_runs[0] / "train_target"
    logs = [pd.read_csv(out / f"run{r}" / "train_target_log.csv") for r in range(RUNS)]
    for name in PROTOCOLS:
        k = TD.inits_per_run(name)
        per_run = [set(log.loc[log["protocol"] == name, "seed"]) for log in logs]
        assert [min(s) for s in per_run] == [splits.TEST.first_seed + r * k for r in range(RUNS)]
        assert all(len(s) == k for s in per_run) and not per_run[0] & per_run[1]
        assert all(splits.TEST.holds(s) for run in per_run for s in run)
    assert TD.inits_per_run("restarts_halved") == TT.HALVED_SEEDS and TD.inits_per_run("variant") == 1


def test_the_distribution_files_hold_one_row_per_run_and_protocol(test_runs):
    out, _, printed = test_runs
    table = pd.read_csv(out / "train_target" / "distribution.csv")
    assert list(table.columns) == TD.DIST_COLUMNS and len(table) == RUNS * len(PROTOCOLS)
    assert set(zip(table["protocol"], table["run"], strict=True)) == {(p, r) for p in PROTOCOLS for r in range(RUNS)}
    assert (table["split"] == "test").all() and np.allclose(table["threshold"], TT.CODE_HELDOUT_L1)
    assert (table["reached"] == table["samples_to_reach"].notna()).all()
    assert (table["cpus"] >= 1).all() and (table["load_15min_end"] >= 0).all()
    assert all((out / "train_target" / f"run{r}" / "load.json").exists() for r in range(RUNS))
    summary = json.loads((out / "train_target" / "distribution.json").read_text())
    assert summary["split"] == "test" and summary["budget"] == 4000 and summary["threshold"] == TT.CODE_HELDOUT_L1
    for name in PROTOCOLS:
        p, rows = summary["protocols"][name], table[table["protocol"] == name]
        assert p["runs"] == RUNS and p["reached"] == int(rows["reached"].sum()) and p["split"] == "test"
        assert p["note"] == f"median over the runs that reached it; {p['reached']} of {RUNS} reached"
        assert p["init_seeds"] == list(rows["init_seed"]) and p["budget"] == int(rows["budget"].iloc[0])
        assert p["protocol_hash"] == TD.protocol_hash(name, 4000, HELDOUT, WIDTHS)
        hit = rows.loc[rows["reached"], "wall_s_to_reach"]
        assert p["wall_s_to_reach"]["median"] == (float(hit.median()) if len(hit) else None)
    assert "restarts_halved" in printed and f"of {RUNS}" in printed
    hashes = {summary["protocols"][n]["protocol_hash"] for n in PROTOCOLS}
    assert len(hashes) == 2 and TD.protocol_hash("variant", 8000, HELDOUT, WIDTHS) not in hashes   # budget counts


def test_rerunning_the_command_reuses_the_finished_runs(test_runs, tmp_path, monkeypatch):
    out = _copy(test_runs, tmp_path)
    before = (out / "train_target" / "distribution.csv").read_text()

    def no_training(*a, **kw):
        raise AssertionError("a finished run was trained again")
    monkeypatch.setattr(TD, "run_study", no_training)
    monkeypatch.setattr(TT, "study", no_training)
    assert main(_command(out)) == 0
    assert (out / "train_target" / "distribution.csv").read_text() == before


def test_an_interrupted_command_trains_only_the_unfinished_run(test_runs, tmp_path, monkeypatch):
    out = _copy(test_runs, tmp_path)
    (out / "train_target" / "run1" / "train_target.csv").unlink()   # run1 stopped before its end
    trained, real = [], TD.run_study
    monkeypatch.setattr(TD, "run_study", lambda folder, *a, **kw: trained.append(folder.name) or real(folder, *a, **kw))
    assert main(_command(out)) == 0
    assert trained == ["run1"] and (out / "train_target" / "run1" / "train_target.csv").exists()


def test_a_run_folder_of_other_inputs_is_a_one_line_error(test_runs, tmp_path, capsys):
    out = _copy(test_runs, tmp_path)
    inputs = (out / "train_target" / "run0" / "inputs.json").read_text()
    assert main([*_command(out), "--budget", "2000"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "run0" in err and "differs in budget" in err
    assert (out / "train_target" / "run0" / "inputs.json").read_text() == inputs   # nothing overwritten


def test_one_development_run_keeps_the_single_folder_layout(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["train-target", *TINY, "--protocols", "variant", "--seed", "2", "--out", str(out)]) == 0
    folder = out / "train_target"
    assert set(pd.read_csv(folder / "train_target.csv")["seed"]) == {2}
    assert (folder / "train_target_log.csv").exists() and (folder / "variant.npz").exists()
    assert not any((folder / n).exists() for n in ("run0", "inputs.json", "distribution.csv", "distribution.json"))


def test_the_heldout_draw_never_steers_training():
    """The same init on the development and the test draw: the same training, other held-out numbers."""
    dev, test = (TT.study(1024, [8], 64, names=["variant"], seed=1000, heldout_seed=s.heldout_seed)[1]
                 for s in (splits.DEV, splits.TEST))
    assert [r["train_loss"] for r in dev] == pytest.approx([r["train_loss"] for r in test], nan_ok=True)
    assert [r["heldout_l1"] for r in dev] != [r["heldout_l1"] for r in test]


@pytest.mark.parametrize("args, message", [(["--runs", "0"], "--runs takes an integer >= 1"),
                                           (["--split", "val"], "--split: unknown 'val'"),
                                           (["--seed", "990", "--runs", "2", "--protocols", "restarts"],
                                            "past the 1000 seeds of the dev split")])
def test_bad_runs_split_or_seeds_are_one_line_errors(tmp_path, capsys, args, message):
    assert main(["train-target", *TINY, *args, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and not (tmp_path / "out").exists()
