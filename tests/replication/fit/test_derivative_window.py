"""`--window auto` (`replication.fit.derivative_window`, issue 87): the noise read off a recording with known
noise, and the window chosen for q̈ against the true q̈ of a simulated double pendulum with friction at
100 Hz (`lagbench simulate`'s own trajectories) and of slower analytic motion; an integer window as before."""
import numpy as np
import pandas as pd
import pytest

from lagbench import systems
from lagbench.replication.fit import derivative_window as DW
from lagbench.replication.fit import trajectories
from lagbench.replication.fit.simulate import simulate
from lagbench.replication.fit.task import file_derivatives

NOISES = (0.0, 0.001, 0.0087)   # rad; 0.0087 is half a degree, a camera's tracking noise
RATE = 100.0


@pytest.fixture(scope="module")
def pendulum():
    """Clean double-pendulum trajectories with friction (traj, t, q) and their true q̈ per row."""
    df = simulate("double_pendulum", trajectories=4, duration=5.0, rate=RATE, velocities=True,
                  settings=("friction=0.2",))
    q, qdot = df[["q0", "q1"]].to_numpy(), df[["qdot0", "qdot1"]].to_numpy()
    qddot = systems.get("double_pendulum", friction=0.2).acceleration(q, qdot)
    return {"traj": df["traj"].to_numpy(float), "t": df["t"].to_numpy(), "q": q}, qddot


def noisy(d, s, seed=0):
    return {**d, "q": d["q"] + s * np.random.default_rng(seed).standard_normal(d["q"].shape)}


def rms_error(d, true, window):
    """The rms error of the q̈ `with_derivatives` gives at `window`, per row kept, summed over coordinates."""
    out = trajectories.with_derivatives(d, "sim.csv", window=window)
    row = {(k, round(t, 9)): i for i, (k, t) in enumerate(zip(d["traj"], d["t"], strict=True))}
    idx = [row[(k, round(t, 9))] for k, t in zip(out["traj"], out["t"], strict=True)]
    return float(np.sqrt(np.mean(np.sum((out["qddot"] - true[idx]) ** 2, axis=1))))


@pytest.mark.parametrize("s", NOISES)
def test_the_noise_read_off_the_recording_is_the_noise_added(pendulum, s):
    d, _ = pendulum
    est = np.array(trajectories.choose_window(noisy(d, s), "sim.csv").noise)
    if s:
        np.testing.assert_allclose(est, s, rtol=0.25)
    else:   # the motion alone reads as (almost) no noise
        assert est.max() < 0.25 * NOISES[1]


def test_the_window_grows_with_the_noise_and_beats_window_15(pendulum):
    d, true = pendulum
    chosen = [trajectories.choose_window(noisy(d, s), "sim.csv").window for s in NOISES]
    assert chosen == sorted(chosen) and chosen[0] < chosen[-1], chosen
    assert chosen[0] <= DW.smallest(trajectories.POLYORDER) + 2   # no noise: (nearly) the smallest window
    errors = {s: (rms_error(noisy(d, s), true, DW.AUTO), rms_error(noisy(d, s), true, 15)) for s in NOISES}
    for s, (auto, fixed) in errors.items():
        assert auto <= 1.02 * fixed, (s, errors)
    assert errors[0.001][0] < 0.7 * errors[0.001][1], errors   # a fast motion: smaller windows are less biased


def test_camera_noise_on_slower_motion_takes_a_wider_window_and_a_far_smaller_error():
    """Damped oscillations of 1.5 to 4 rad/s at 100 Hz with half a degree of noise: window 15 passes most of the
    noise to q̈, the chosen window averages it away."""
    rng = np.random.default_rng(3)
    t = np.arange(600) / RATE
    a, w, g, p = (rng.uniform(lo, hi, (4, 1)) for lo, hi in ((0.5, 1.5), (1.5, 4.0), (0.05, 0.3), (0, 6)))
    q = a * np.exp(-g * t) * np.cos(w * t + p)
    qddot = a * np.exp(-g * t) * ((g**2 - w**2) * np.cos(w * t + p) + 2 * g * w * np.sin(w * t + p))
    d = {"traj": np.repeat(np.arange(4.0), t.size), "t": np.tile(t, 4), "q": q.reshape(-1, 1)}
    d = noisy(d, NOISES[2])
    choice = trajectories.choose_window(d, "slow.csv")
    assert choice.window > 21 and choice.noise[0] == pytest.approx(NOISES[2], rel=0.25)
    auto, fixed = (rms_error(d, qddot.reshape(-1, 1), w) for w in (DW.AUTO, 15))
    assert auto < 0.35 * fixed, (auto, fixed)
    assert choice.high == DW.highest(t.size, trajectories.POLYORDER) == 199   # a third of the 600 samples


def test_an_exact_polynomial_keeps_the_smallest_window_and_stays_exact():
    t = np.arange(200) * 0.01
    q = (1.0 - 2.0 * t + 0.5 * t**2 - 0.3 * t**3)[:, None]
    d = {"t": t, "q": q}
    assert trajectories.choose_window(d, "cubic.csv").window == DW.smallest(trajectories.POLYORDER)
    out = trajectories.with_derivatives(d, "cubic.csv", window=DW.AUTO)
    np.testing.assert_allclose(out["qddot"][:, 0], 1.0 - 1.8 * out["t"], atol=1e-6)


def test_dropped_frames_filled_by_splines_are_not_read_as_noise_free(pendulum):
    d, _ = pendulum
    rec = noisy(d, NOISES[2])
    inner = (d["t"] > 0) & (d["t"] < d["t"].max())   # never a trajectory's first or last sample
    kept = ~(inner & (np.random.default_rng(1).random(len(d["t"])) < 0.02))
    gapped = {k: v[kept] for k, v in rec.items()}
    np.testing.assert_allclose(trajectories.choose_window(gapped, "sim.csv").noise, NOISES[2], rtol=0.25)


def test_the_record_says_why_and_reads_back_as_the_rule(tmp_path, pendulum):
    d, _ = pendulum
    rec = noisy(d, NOISES[2])
    path = tmp_path / "rec.csv"
    pd.DataFrame({"traj": rec["traj"], "t": rec["t"] * 1000, "q0": rec["q"][:, 0], "q1": rec["q"][:, 1]}).to_csv(
        path, index=False)
    got = file_derivatives(path, DW.AUTO, 3, "interpolate", "ms")   # times in ms: read in seconds first
    choice = trajectories.choose_window(rec, "sim.csv")
    assert got == choice.record() and got["window"] == choice.window and got["rule"] == DW.AUTO
    text = DW.describe(got)
    assert f"window {choice.window}, degree 3" in text and f"{choice.noise[0]:.3g}" in text and "auto" in text
    assert trajectories.rule_of(got) == DW.AUTO and trajectories.rule_of({"window": 21, "polyorder": 3}) == 21
    assert trajectories.rule_of({}) == trajectories.WINDOW
    # an integer window is recorded as it always was, and a state file records the rule it would use
    assert file_derivatives(path, 21, 3, "interpolate", "ms") == {"window": 21, "polyorder": 3}
    assert trajectories.derivative_record({"q": rec["q"]}, "s.csv", DW.AUTO) == {"window": DW.AUTO, "polyorder": 3}


@pytest.mark.parametrize("text, value", [("auto", DW.AUTO), ("31", 31)])
def test_window_text(text, value):
    assert trajectories.window_value(text) == value
    trajectories.check_options(value, 3)


@pytest.mark.parametrize("bad", ["wide", 14, 3])
def test_bad_windows_are_refused(bad):
    with pytest.raises(ValueError, match="--window"):
        trajectories.check_options(trajectories.window_value(bad) if isinstance(bad, str) else bad, 3)
