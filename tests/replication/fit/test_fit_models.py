"""Fitted models loaded back and judged (issue 26, gaps 1, 4, 5 and 7): load_fitted in either framework,
torques refused by an LNN / HNN and used by DeLaN, the options' defaults in --help, tiny trainings only."""
import argparse

import numpy as np
import pandas as pd
import pytest

from lagbench.cli import build_parser, main
from lagbench.files import user_data
from lagbench.replication.fit.load import load_fitted
from lagbench.replication.fit.task import fit

TINY = {"steps": 6, "hidden": (8,), "batch": 32}


def _arm_trajectories(path, n_traj=3, n=40, tau=True):
    """Two-dof trajectories with torques: smooth q, any tau (the fit learns whatever maps them)."""
    t = np.arange(n) * 0.02
    rows = []
    for k in range(n_traj):
        q = np.stack([np.sin(t + k), np.cos(2 * t + k)], 1)
        row = {"traj": k, "t": t, "q0": q[:, 0], "q1": q[:, 1]}
        if tau:
            row.update(tau0=np.cos(t) * (k + 1), tau1=np.sin(t))
        rows.append(pd.DataFrame(row))
    pd.concat(rows).to_csv(path, index=False)
    return path


@pytest.mark.parametrize("model", ["lnn", "hnn"])
def test_an_lnn_or_hnn_given_torques_refuses_before_any_work(tmp_path, capsys, model):
    data = _arm_trajectories(tmp_path / "arm.csv")
    assert main(["fit", "--data", str(data), "--model", model, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "tau" in err and "fit baseline or delan" in err, err
    assert not (tmp_path / "out" / "data").exists() and not (tmp_path / "out" / "trained").exists()


def test_delan_fits_torques_and_loads_in_both_frameworks(tmp_path):
    data = _arm_trajectories(tmp_path / "arm.csv")
    options = {"activation": "tanh", "weight_decay": 1e-5, "schedule": "constant", "delan_eps": 0.1,
               "delan_offset": 1.0, "input_scale": "auto"}
    d = fit(data, model="delan", out=tmp_path / "out", split="none", test=_arm_trajectories(tmp_path / "t.csv", 2),
            **options, **TINY)
    assert d["status"] == "ok" and d["protocol"]["task"] == "inverse_dynamics" and d["metric"] == "test_mse"  # the kind's loss
    p, s = d["protocol"], d["model_spec"]
    assert (s["activation"], p["l2"], p["schedule"]["kind"], s["delan_eps"], s["delan_diag_offset"]) == ("tanh", 1e-5,
                                                                                                 "constant", 0.1, 1.0)
    half = d["eval_config"]["derivatives"]["window"] // 2   # the window chosen from the data (--window auto)
    t = np.arange(40)[half:40 - half] * 0.02  # the samples with a centred derivative window of each trajectory
    q_train = np.concatenate([np.stack([np.sin(t + k), np.cos(2 * t + k)], 1) for k in range(3)])
    np.testing.assert_allclose(s["input_scale"], 1 / q_train.std(0), rtol=1e-5)  # auto: 1 / std of DeLaN's input q
    assert {"test_l1", "test_rollout_gmean_err", "test_mass_matrix_min_eig"} <= set(d["metrics"])
    one = pd.read_csv(tmp_path / "out/units/fit/jax/delan/seed0/one_step.csv")
    assert list(one["quantity"]) == ["tau", "tau"] and list(one["component"]) == [0, 1]
    folder = tmp_path / "out/units/fit/jax/delan/seed0"
    tc = load_fitted(tmp_path / "out", framework="torch")  # trained in JAX, loaded in PyTorch
    rows = user_data.rows(d["eval_config"]["test"], "test")
    saved = np.load(folder / "arrays.npz")  # the JAX model's own predictions on those rows, saved by the fit
    tau = tc.inverse_dynamics(rows["q"], rows["qdot"], rows["qddot"])
    np.testing.assert_allclose(tau, saved["test_pred"], rtol=1e-4, atol=1e-5)
    np.testing.assert_allclose(tc.acceleration(rows["q"], rows["qdot"], tau), rows["qddot"], rtol=1e-3, atol=1e-3)
    assert tc.energy(rows["q"], rows["qdot"]).shape == (len(tau),)


def test_an_inverse_dynamics_baseline_and_a_damaged_fit(tmp_path):
    data = _arm_trajectories(tmp_path / "arm.csv")
    base = fit(data, model="baseline", out=tmp_path / "out", split="none", **TINY)
    assert base["metric"] == "final_train_loss"  # nothing held out, no test file: the training loss only
    folder = tmp_path / "out/units/fit/jax/baseline/seed0"
    z = np.zeros((1, 2))
    assert load_fitted(folder, framework="torch").inverse_dynamics(z, z, z).shape == (1, 2)
    with pytest.raises(ValueError, match="no forward model"):
        load_fitted(folder).acceleration(z, z)
    (folder / "checkpoint.npz").write_bytes(b"x")
    with pytest.raises(ValueError, match="not a usable fit"):
        load_fitted(folder)
    with pytest.raises(ValueError, match="holds no fitted model"):
        load_fitted(tmp_path)


def test_the_metric_is_named_for_the_loss_and_the_rows():
    from lagbench.replication.fit.task import metric_of

    assert metric_of({"train": 9, "heldout": 1}, False, "mse") == ("heldout_mse", "held-out MSE")
    assert metric_of({"train": 9, "heldout": 1}, True, "l1") == ("test_l1", "test L1")
    assert metric_of({"train": 9}, False, "l1")[0] == "final_train_loss"


def test_every_fit_option_shows_its_default():
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    parser = sub.choices["fit"]
    helps = {a.option_strings[-1]: a.help for a in parser._actions   # hidden ones (old spellings) aside
             if a.option_strings and not a.required and a.nargs != 0 and a.help != argparse.SUPPRESS}
    assert {"--activation", "--weight-decay", "--schedule", "--lr-final", "--delan-eps", "--delan-offset",
            "--input-scale", "--holdout", "--holdout-fraction", "--test", "--window", "--polyorder"} <= set(helps)
    missing = [k for k, h in helps.items() if "default" not in h]
    assert not missing, missing


def test_a_users_energy_function_is_imported_and_checked_before_any_work(tmp_path, monkeypatch):
    from lagbench.replication.fit.evaluate import energy_function

    (tmp_path / "my_energy.py").write_text("def pendulum(q, qdot):\n    return 0.5 * (qdot**2).sum(-1) - 3 * __import__('numpy').cos(q).sum(-1)\n"
                                           "def wrong(q, qdot):\n    return q\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    energy = energy_function({"energy": "my_energy:pendulum"}, 1)
    q = np.zeros((4, 5, 1))
    assert energy(q, q + 1.0).shape == (4, 5) and np.allclose(energy(q, q + 1.0), 0.5 - 3.0)
    with pytest.raises(ValueError, match="must map"):
        energy_function({"energy": "my_energy:wrong"}, 2)
    data = _arm_trajectories(tmp_path / "arm.csv", tau=False)
    with pytest.raises(ValueError, match="--energy no_such_module:f: cannot import"):
        fit(data, model="baseline", out=tmp_path / "out", energy="no_such_module:f", **TINY)
    assert not (tmp_path / "out" / "data").exists()
