"""`lagbench fit --periodic`: a pendulum recorded with its angle unwrapped (spinning over several turns) is fitted
by an LNN that sees the angle as cos and sin; the fit runs and learns, `--input-scale auto` scales those features,
and the fit reloads in both frameworks, predicting the same motion at q and q + 2 pi. Bad values are refused before
any work."""
import re

import numpy as np
import pandas as pd
import pytest

from lagbench.cli import main
from lagbench.files import user_data
from lagbench.replication.fit.load import load_fitted
from lagbench.replication.fit.task import fit


def _spinning_pendulum(path, n_traj=4, n=160, dt=0.05):
    """q'' = -sin q from speeds above the separatrix (|qdot(0)| > 2): q runs over several turns, unwrapped."""
    rows = []
    for k in range(n_traj):
        z = np.array([0.3 * k, (2.4 + 0.3 * k) * (-1) ** k])
        qs = []
        for _ in range(n):
            qs.append(z[0])
            for _ in range(4):   # RK4, 4 steps per sample
                f = lambda s: np.array([s[1], -np.sin(s[0])])  # noqa: E731
                h = dt / 4
                a = f(z)
                b = f(z + h / 2 * a)
                c = f(z + h / 2 * b)
                e = f(z + h * c)
                z = z + h / 6 * (a + 2 * b + 2 * c + e)
        rows.append(pd.DataFrame({"traj": k, "t": np.arange(n) * dt, "q0": qs}))
    pd.concat(rows).to_csv(path, index=False)
    return path


def test_an_lnn_fits_unwrapped_angles_as_cos_and_sin(tmp_path):
    data = _spinning_pendulum(tmp_path / "spin.csv")
    q = pd.read_csv(data)["q0"].to_numpy()
    assert np.ptp(q) > 6 * 2 * np.pi   # several turns
    d = fit(data, model="lnn", out=tmp_path / "out", periodic=(0,), input_scale="auto", steps=300, batch=64,
            hidden=(32, 32), activation="softplus", lr=3e-3, schedule="constant", restarts=None)
    assert d["status"] == "ok"
    spec = d["model_spec"]
    assert spec["periodic"] == [0] and len(spec["input_scale"]) == 3   # [cos q, sin q, qdot]
    train = user_data.rows(d["protocol"]["data"]["recipe"], "train")
    feats = np.concatenate([np.cos(train["q"]), np.sin(train["q"]), train["qdot"]], 1)
    np.testing.assert_allclose(spec["input_scale"], 1 / feats.std(0), rtol=1e-5)
    fj = load_fitted(tmp_path / "out")
    ft = load_fitted(tmp_path / "out", framework="torch")
    assert fj.spec.periodic == ft.spec.periodic == (0,)
    rows = user_data.rows(d["protocol"]["data"]["recipe"], "heldout")
    a = fj.acceleration(rows["q"], rows["qdot"])
    assert a.shape == rows["q"].shape and np.all(np.isfinite(a))
    np.testing.assert_allclose(ft.acceleration(rows["q"], rows["qdot"]), a, rtol=1e-4, atol=1e-5)
    # float32: q itself is rounded to ~1e-7 |q| before its cos and sin are taken
    np.testing.assert_allclose(fj.acceleration(rows["q"] - 4 * np.pi, rows["qdot"]), a, rtol=0, atol=1e-4)
    truth = -np.sin(rows["q"])   # it learned the pendulum from the unwrapped record (0.17 x the null error here)
    assert np.abs(a - truth).mean() < 0.5 * np.abs(truth).mean()


@pytest.mark.parametrize("flag, match", [("0,a", "--periodic: .* expected auto, none or comma-separated coordinate indices"),
                                         ("1", r"--periodic: periodic must be indices .*\[0, 1\)")])
def test_bad_periodic_values_are_refused_before_any_work(tmp_path, capsys, flag, match):
    data = _spinning_pendulum(tmp_path / "spin.csv", n_traj=2, n=40)
    assert main(["fit", "--data", str(data), "--model", "lnn", "--periodic", flag, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert re.search(match, err), err
    assert not (tmp_path / "o" / "data").exists()
    with pytest.raises(ValueError, match="periodic and angle_wrap exclude each other"):
        fit(data, model="hnn", out=tmp_path / "o", periodic=(0,), angle_wrap=True)
