"""Trajectory input of `lagbench fit` (issue 26, gaps 2 and 3): derivatives estimated from noisy positions
against analytic trajectories, and the splits a researcher controls. No training here."""
import numpy as np
import pandas as pd
import pytest
from scipy.signal import savgol_coeffs

from lagbench.files import user_data
from lagbench.replication.fit import rows as fit_data
from lagbench.replication.fit import trajectories

H = 0.02  # 50 samples per second
W, P = trajectories.WINDOW, trajectories.POLYORDER


def test_exact_for_a_polynomial_of_the_filter_degree():
    t = np.arange(60) * H
    q = (1.0 - 2.0 * t + 0.5 * t**2 - 0.3 * t**3)[:, None]
    qdot = trajectories.derivative(q, H, 1)
    qddot = trajectories.derivative(q, H, 2)
    np.testing.assert_allclose(qdot[:, 0], -2.0 + t - 0.9 * t**2, atol=1e-9)
    np.testing.assert_allclose(qddot[:, 0], 1.0 - 1.8 * t, atol=1e-8)


@pytest.mark.parametrize("order", [1, 2])
def test_noisy_sine_error_is_the_filters_bias_plus_its_noise_gain(order):
    """On q = A sin(w t) + white noise s, the interior error of the k-th derivative is what the linear filter
    predicts: its bias on the clean signal, plus noise of standard deviation s x |coefficients|."""
    rng = np.random.default_rng(0)
    t = np.arange(2000) * H
    a, w, s = 1.5, 2.0, 0.01
    clean = a * np.sin(w * t)[:, None]
    true = [None, a * w * np.cos(w * t), -a * w**2 * np.sin(w * t)][order]
    inner = slice(W, -W)
    bias = trajectories.derivative(clean, H, order)[inner, 0] - true[inner]
    noisy = trajectories.derivative(clean + s * rng.standard_normal(clean.shape), H, order)[inner, 0] - true[inner]
    gain = np.linalg.norm(savgol_coeffs(W, P, deriv=order, delta=H))
    predicted = np.sqrt(np.mean(bias**2) + (s * gain) ** 2)
    assert np.sqrt(np.mean(noisy**2)) == pytest.approx(predicted, rel=0.1)
    # and far better than the plain finite difference of the same noisy samples
    fd = np.gradient(clean[:, 0] + s * rng.standard_normal(t.size), H)
    if order == 2:
        fd = np.gradient(fd, H)
    assert np.sqrt(np.mean(noisy**2)) < np.sqrt(np.mean((fd[inner] - true[inner]) ** 2)) / 3


def _file(path, n_traj=3, n=40, shuffle=True, **cols):
    t = np.tile(np.arange(n) * H, n_traj)
    traj = np.repeat(np.arange(n_traj), n)
    df = pd.DataFrame({"traj": traj, "t": t, "q0": np.sin(t + traj), **cols})
    if shuffle:
        df = df.sample(frac=1.0, random_state=0)
    df.to_csv(path, index=False)
    return path


def test_trajectory_rows_are_sorted_and_given_derivatives_kept(tmp_path):
    path = str(_file(tmp_path / "a.csv"))
    d = trajectories.with_derivatives(user_data.read(path)[1], path)
    assert set(d) == {"traj", "t", "q", "qdot", "qddot"}
    assert len(d["q"]) == 3 * (40 - 2 * (W // 2))  # the ends of each trajectory, without a centred window, dropped
    for k in range(3):
        rows = d["traj"] == k
        assert np.all(np.diff(d["t"][rows]) > 0)
        np.testing.assert_allclose(d["qdot"][rows, 0], np.cos(d["t"][rows] + k), atol=1e-6)
    n = 120
    given = str(_file(tmp_path / "b.csv", shuffle=False, qdot0=np.full(n, 7.0)))
    d = trajectories.with_derivatives(user_data.read(given)[1], given)
    assert np.all(d["qdot"] == 7.0) and np.allclose(d["qddot"], 0.0, atol=1e-9)  # qddot from the given qdot


@pytest.mark.parametrize("change, message", [
    ({"t": lambda t: t**2}, "not uniformly spaced"),
    ({"n": 15}, "needs at least 16"),
    ({"window": 14}, "odd window"),
])
def test_bad_trajectories_name_the_problem(tmp_path, change, message):
    n = change.get("n", 40)
    t = np.arange(n) * H
    t = change.get("t", lambda x: x)(t)
    path = tmp_path / "c.csv"
    pd.DataFrame({"t": t, "q0": np.sin(t)}).to_csv(path, index=False)
    with pytest.raises(ValueError, match=message):
        trajectories.with_derivatives(user_data.read(str(path))[1], str(path), window=change.get("window", W))


def test_splits_hold_out_whole_trajectories_random_rows_or_nothing(tmp_path):
    path = _file(tmp_path / "d.csv", n_traj=10)
    by = fit_data.prepare(tmp_path / "out", path)             # trajectory file: by-trajectory by default
    kept = 40 - 2 * (W // 2)
    assert by.trajectories == {"heldout": 1, "train": 9} and by.counts == {"heldout": kept, "train": 9 * kept}
    rows = {k: user_data.rows(by.reference, k) for k in ("train", "heldout")}
    assert not set(rows["train"]["traj"]) & set(rows["heldout"]["traj"])
    again = fit_data.prepare(tmp_path / "out", path)
    assert again.reference == by.reference                    # same data and options: the same prepared file
    wider = fit_data.prepare(tmp_path / "out", path, window=21)
    assert wider.reference != by.reference                    # another option: another file (and training key)
    assert fit_data.prepare(tmp_path / "out", path, "none").counts == {"train": 10 * kept}
    rnd = fit_data.prepare(tmp_path / "out", path, "random", heldout=0.25)
    assert rnd.counts == {"heldout": round(2.5 * kept), "train": 10 * kept - round(2.5 * kept)}
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["data"]   # writes only under --out/data
    one = _file(tmp_path / "e.csv", n_traj=1)
    with pytest.raises(ValueError, match="one trajectory only"):
        fit_data.prepare(tmp_path / "out", one)
    with pytest.raises(ValueError, match="--holdout-fraction"):
        fit_data.prepare(tmp_path / "out", path, "random", heldout=1.5)
