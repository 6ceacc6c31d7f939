"""Real recordings (`replication.fit.trajectories`): times with clock jitter or rounded when written, and
dropped frames interpolated, split at or refused (`--gaps`), against analytic trajectories."""
import numpy as np
import pytest

from lagbench.cli import main
from lagbench.replication.fit import trajectories

W = trajectories.WINDOW


def _sine(t):
    return {"traj": np.zeros(t.size), "t": t, "q": np.sin(2 * t)[:, None]}


def test_times_rounded_to_six_decimals_are_one_grid():
    t = np.round(np.arange(80) / 6, 6)            # steps 0.166666 and 0.166667, as a logger writes them
    d = {"traj": np.zeros(t.size), "t": t, "q": np.sin(0.2 * t)[:, None]}
    out = trajectories.with_derivatives(d, "rec.csv")
    np.testing.assert_allclose(out["qddot"][:, 0], -0.04 * np.sin(0.2 * out["t"]), rtol=0.01, atol=1e-5)


def test_dropped_frames_are_filled_for_the_windows_and_never_trained_on():
    t = np.arange(120) * 0.02
    kept = np.ones(t.size, bool)
    kept[[40, 41, 77]] = False                    # a gap of two frames and one of one
    full = trajectories.with_derivatives(_sine(t), "rec.csv")
    out = trajectories.with_derivatives({k: v[kept] for k, v in _sine(t).items()}, "rec.csv")
    assert set(out["t"]) <= set(t[kept]) and set(out["t"]) == set(full["t"]) - set(t[~kept])
    ref = {round(x, 9): v for x, v in zip(full["t"], full["qddot"][:, 0], strict=True)}
    got = np.array([ref[round(x, 9)] for x in out["t"]])
    np.testing.assert_allclose(out["qddot"][:, 0], got, atol=1e-3)   # the spline's frames as good as the data's


def test_split_cuts_at_each_gap_and_refuse_or_a_long_gap_names_the_option():
    t = np.arange(100) * 0.02
    kept = np.ones(t.size, bool)
    kept[50:55] = False                           # five frames: longer than interpolate fills
    d = {k: v[kept] for k, v in _sine(t).items()}
    out = trajectories.with_derivatives(d, "rec.csv", gaps="split")
    assert set(np.unique(out["traj"])) == {0.0, 0.001}
    assert len(out["t"]) == (50 - 2 * (W // 2)) + (45 - 2 * (W // 2))   # pieces of 50 and 45 samples lose their ends
    with pytest.raises(ValueError, match=r"5 dropped frame\(s\) after t = 0.98; --gaps split"):
        trajectories.with_derivatives(d, "rec.csv")
    with pytest.raises(ValueError, match="--gaps interpolate or split"):
        trajectories.with_derivatives(d, "rec.csv", gaps="refuse")
    with pytest.raises(ValueError, match="not uniformly spaced"):
        trajectories.with_derivatives(_sine(np.cumsum(np.r_[0, np.full(60, 0.02), 0.031, np.full(40, 0.02)])), "x")


def test_simulate_writes_a_recording_that_fit_reads(tmp_path, capsys):
    data = tmp_path / "rec.csv"
    assert main(["simulate", "--system", "pendulum", "--trajectories", "3", "--duration", "4", "--rate", "30",
                 "--dropped", "0.05", "--decimals", "6", "--out", str(data)]) == 0
    assert main(["fit", "--data", str(data), "--model", "baseline", "--steps", "3", "--hidden", "8", "--quiet",
                 "--out", str(tmp_path / "fit")]) == 0
    capsys.readouterr()
    assert main(["fit", "--data", str(data), "--model", "baseline", "--steps", "3", "--hidden", "8", "--quiet",
                 "--gaps", "refuse", "--out", str(tmp_path / "fit2")]) == 2
    assert "dropped frame(s)" in capsys.readouterr().err
