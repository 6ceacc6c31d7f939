"""Closed-loop tracking of the four-joint arm (`replication.studies.arm4_control`, `lagbench control --system
four_joint_arm`): the declared gains keep the true inverse dynamics at the integrator's floor (the hold over a
control period) and PD alone finite; a tiny run fits both models, writes the two-link study's table for 4
joints, its traces, settings and fits inside RESULTS/control_four_joint_arm/ only, reuses its fits on a
rerun and reaches the report; the two-link arm's study is what it was; a bad --system is one line."""
import json

import numpy as np
import pandas as pd
import pytest

from lagbench import systems
from lagbench.cli import main
from lagbench.replication.studies import arm4_control as A
from lagbench.replication.studies import control as C

ARM4 = systems.get("four_joint_arm")
TINY = {"n_train": 2, "n_points": 40, "duration": 4.0}


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("control4")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(A, "SIZES", TINY)
        assert main(["control", "--system", "four_joint_arm", "--out", str(out), "--references", "1",
                     "--duration", "0.1", "--steps", "3", "--quiet"]) == 0
    return out


def test_the_gains_keep_the_true_inverse_dynamics_at_the_floor_and_pd_alone_finite():
    refs = C.references("test", n=1, duration=0.1, system="four_joint_arm")
    assert refs["q"].shape == (1, 51, 4)
    kp, kd = C.gains(4)
    assert np.array_equal(kp, np.full(4, 20.0)) and np.allclose(kd, 2 * np.sqrt(20.0))
    exact = C.scores(C.track(ARM4.inverse_dynamics, refs, system="four_joint_arm"), refs)
    pd_alone = C.scores(C.track(None, refs, system="four_joint_arm"), refs)
    assert exact["n_diverged"] == pd_alone["n_diverged"] == 0
    assert exact["track_mse"] < 1e-4 and exact["track_mse"] < 1e-3 * pd_alone["track_mse"]
    assert np.isfinite(pd_alone["track_mse"]) and pd_alone["track_mse"] > 1e-3
    fine = C.references("test", n=1, duration=0.1, rate=2000.0, system="four_joint_arm")
    finer = C.scores(C.track(ARM4.inverse_dynamics, fine, rate=2000.0, system="four_joint_arm"), fine)
    assert finer["track_mse"] < 0.1 * exact["track_mse"]   # what is left is the hold over a control period


def test_a_tiny_run_writes_the_table_traces_settings_and_fits_inside_its_folder(tiny_run):
    assert [p.name for p in tiny_run.iterdir()] == ["control_four_joint_arm"]
    folder = tiny_run / "control_four_joint_arm"
    df = pd.read_csv(folder / "tracking.csv")
    joints = [f"track_mse_joint{j}" for j in range(4)]
    assert list(df.columns) == ["family", "controller", "framework", "seed", "n_refs", "n_diverged", *joints,
                                "track_mse", "torque_effort", "ratio_to_pd"]
    assert set(df["family"]) == {"test", "train_x2"} and len(df) == 2 * 4
    assert set(df["controller"]) == {"exact", "pd", "delan", "ff"}
    learned = df[df["controller"].isin(["delan", "ff"])]
    assert (learned["framework"] == "jax").all() and (learned["seed"].astype(str) == "0").all()
    assert learned["track_mse"].notna().all() and (df["n_diverged"] == 0).all()
    assert (df.loc[df["controller"] == "pd", "ratio_to_pd"] == 1).all()
    assert (df.loc[df["controller"] == "exact", "track_mse"] < 1e-4).all()
    with np.load(folder / "traces.npz") as z:
        assert z["test__q_ref"].shape == z["test__delan__jax__q"].shape == z["test__delan__jax__tau"].shape == (51, 4)
    s = json.loads((folder / "study.json").read_text())
    assert s["system"] == "four_joint_arm" and s["steps"] == 3 and s["seeds"] == [0] and s["training_data"] == TINY
    assert s["kp"] == [20.0] * 4 and s["budget"]["hidden"] == [64, 64]
    assert (folder / "data" / "train.npz").is_file()
    assert len(list((folder / "fits" / "seed0" / "units" / "fit" / "jax").glob("*/seed0/checkpoint.npz"))) == 2


def test_a_rerun_reuses_the_fits(tiny_run):
    folder = tiny_run / "control_four_joint_arm"
    units = sorted((folder / "fits").rglob("result.json")) + [folder / "data" / "train.npz"]
    before = {p: p.stat().st_mtime_ns for p in units}
    table = (folder / "tracking.csv").read_bytes()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(A, "SIZES", TINY)
        assert main(["control", "--system", "four_joint_arm", "--out", str(tiny_run), "--references", "1",
                     "--duration", "0.1", "--steps", "3", "--quiet"]) == 0
    assert {p: p.stat().st_mtime_ns for p in units} == before
    assert (folder / "tracking.csv").read_bytes() == table


def test_the_run_reaches_the_report_as_its_own_section(tiny_run, tmp_path):
    from lagbench.reports.document import Figure, Table
    from lagbench.reports.load import load_results
    from lagbench.reports.sections_control import control_sections

    (section,) = control_sections(load_results(tiny_run), tmp_path)   # no two-link study here: one section
    assert section.title == "Closed-loop tracking control of the four-joint arm (study)"
    table = next(b for b in section.blocks if isinstance(b, Table))
    assert table.sources == ["control_four_joint_arm/tracking.csv"] and len(table.df) == 8
    text = " ".join(getattr(b, "text", "") for b in section.blocks)
    assert "3 optimiser steps" in text and "four_joint_arm" in text
    (figure,) = [b for b in section.blocks if isinstance(b, Figure)]
    assert (tmp_path / figure.path).stat().st_size > 1000 and "four_joint" in figure.path
    assert control_sections(load_results(tmp_path), tmp_path) == []   # no study: no section


def test_the_two_link_study_is_what_it_was():
    from lagbench.systems.arm_data import arm_dataset

    refs = C.references("test", n=1, duration=0.1)
    d = arm_dataset("test", n_traj=1, n_points=51, seed=C.SEED, duration=0.1, cache=False)
    assert refs["q"].shape == (1, 51, 2) and np.array_equal(refs["q"], d["q"])
    assert np.array_equal(C.KP, [20.0, 20.0]) and np.array_equal(C.KD, 2.0 * np.sqrt(C.KP))
    plant = systems.get("two_link_arm")
    default = C.track(plant.inverse_dynamics, refs)
    explicit = C.track(plant.inverse_dynamics, refs, kp=np.array([20.0, 20.0]), kd=2.0 * np.sqrt([20.0, 20.0]),
                       plant=plant)
    assert all(np.array_equal(default[k], explicit[k]) for k in default)


def test_bad_options_are_one_line_errors(tmp_path, capsys):
    for bad, option in ((["--system", "three_link_arm"], "--system"), (["--steps", "5"], "--steps"),
                        (["--system", "four_joint_arm", "--steps", "0"], "--steps"),
                        (["--system", "four_joint_arm", "--frameworks", "tf"], "--frameworks"),
                        (["--system", "four_joint_arm", "--seeds", "a"], "--seeds")):
        assert main(["control", "--out", str(tmp_path), *bad, "--quiet"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("lagbench: error: ") and option in err
    assert not list(tmp_path.iterdir())
