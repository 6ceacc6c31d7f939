"""Learning online while tracking (`replication.studies.online`, `lagbench online`): without learning the loop is
`control.track`'s (the true inverse dynamics at the integrator's floor, far below PD alone), an untrained model
that does not learn tracks every repetition of a reference exactly as the first, a null learner (learning rate
0) changes nothing, a DeLaN learning online improves (the positive control), a diverging controller is marked,
and the command writes both tables with their declared columns and refuses bad options with one line naming the option."""
import json

import numpy as np
import pandas as pd
import pytest

from lagbench import systems
from lagbench.cli import main
from lagbench.replication.studies import control as C
from lagbench.replication.studies import online as O
from lagbench.replication.studies.online_learner import ReplayBuffer, learner

PLANT = systems.get("two_link_arm")
TINY = (8, 8)


def tiled(duration: float, times: int) -> dict:
    """One training-family reference played `times` times (each repetition from its own initial state)."""
    r = C.references("train", n=1, duration=duration)
    return {k: v if k == "t" else np.repeat(v, times, 0) for k, v in r.items()}


def mses(windows) -> np.ndarray:
    return np.array([w["track_mse"] for w in windows])


def test_without_learning_the_loop_is_control_track_and_the_true_inverse_is_at_the_floor():
    refs = C.references("test", n=1, duration=0.4)
    for ctrl, inverse in ((None, None), ("exact", PLANT.inverse_dynamics)):
        windows, _ = O.run_online(ctrl, refs, window=0.4)
        q = C.track(inverse, refs)["q"][0, :-1]
        assert len(windows) == 1
        assert windows[0]["track_mse"] == pytest.approx(np.mean(np.sum((q - refs["q"][0, :-1]) ** 2, -1)), rel=1e-12)
    exact, pd_alone = O.run_online("exact", refs, window=0.4)[0][0], O.run_online(None, refs, window=0.4)[0][0]
    assert exact["track_mse"] < 1e-3 * pd_alone["track_mse"] and pd_alone["track_mse"] > 1e-4


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_a_model_that_does_not_learn_repeats_its_first_window_and_a_null_learner_changes_nothing(framework):
    refs = tiled(0.2, 3)
    frozen = O.run_online(learner("ff", framework, 0, hidden=TINY), refs, steps=0, window=0.2)[0]
    assert len(frozen) == 3 and all(w["steps"] == 0 for w in frozen)
    assert np.allclose(mses(frozen), mses(frozen)[0], rtol=1e-12, atol=0)
    null = O.run_online(learner("delan", framework, 0, hidden=TINY, lr=0.0), refs, steps=1, window=0.2)[0]
    still = O.run_online(learner("delan", framework, 0, hidden=TINY), refs, steps=0, window=0.2)[0]
    assert null[-1]["steps"] == 300 and np.array_equal(mses(null), mses(still))


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_a_delan_learning_online_improves_its_tracking(framework):
    refs = tiled(0.25, 4)
    windows = O.run_online(learner("delan", framework, 0, hidden=(16, 16)), refs, window=0.25, seed=0)[0]
    m = mses(windows)
    assert windows[-1]["steps"] == 500 and np.isfinite(m).all()
    assert (np.diff(m) < 0).all() and m[-1] < 0.5 * m[0], m   # seeds 0-3: last / first 0.32-0.44


def test_a_diverging_controller_is_marked_and_each_reference_starts_afresh():
    class Wild:
        def tau(self, q, qdot, qddot):
            return np.full(2, 1e9)

    windows, ticks = O.run_online(Wild(), tiled(0.1, 2), steps=0, window=0.1)
    assert [w["n_diverged"] for w in windows] == [49, 49] and [w["track_mse"] for w in windows] == [0.0, 0.0]
    assert len(ticks["inference_us"]) == 2


def test_the_replay_buffer_keeps_the_last_samples_and_draws_training_batches():
    buf = ReplayBuffer(3, 2, seed=0)
    for k in range(5):
        buf.add(*np.full((4, 2), float(k)))
    b = buf.sample(50)
    assert set(b) == {"q", "qdot", "extra", "target"} and b["q"].shape == (50, 2)
    assert set(np.unique(b["q"])) == {2.0, 3.0, 4.0} and np.array_equal(b["q"], b["target"])


def test_a_tiny_study_writes_both_tables(tmp_path):
    curves, summary = O.write_study(tmp_path, models=("delan", "ff"), frameworks=("jax", "torch"), seconds=0.3,
                                    window=0.1, sustain=0.2, hidden=TINY, n_unseen=1, unseen_duration=0.1)
    c, s = pd.read_csv(tmp_path / "curves.csv"), pd.read_csv(tmp_path / "summary.csv")
    assert list(c.columns) == O.CURVE_COLUMNS and list(s.columns) == O.SUMMARY_COLUMNS
    assert len(c) == 6 * 3 and len(s) == 6 and (tmp_path / "setup.json").is_file()
    assert (c.loc[c["controller"] == "pd", "ratio_to_pd"] == 1).all()
    assert (c.loc[c["controller"].isin(["pd", "exact"]), "learning_us_per_tick"] < 50).all()
    learned = s[s["controller"].isin(["delan", "ff"])]
    assert (learned["steps"] == 150).all() and (learned["learning_us_mean"] > 0).all()
    assert (s["compute_us_p99"] >= s["compute_us_median"]).all() and s["unseen_mse"].notna().all()
    exact = s.set_index("controller").loc["exact"]
    assert exact["t_reach_s"] == pytest.approx(0.1) and exact["t_first_cross_s"] == pytest.approx(0.1)
    assert exact["unseen_ratio_to_pd"] < 1e-2 and (s["sustain"] == 0.2).all()
    assert json.loads((tmp_path / "setup.json").read_text())["sustain"] == 0.2


def test_the_command_runs_and_refuses_bad_options(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(O, "one_thread", lambda: {"test": "threads left as they are"})
    out = tmp_path / "o"
    assert main(["online", "--out", str(out), "--seconds", "0.1", "--window", "0.05", "--models", "ff",
                 "--frameworks", "jax", "--unseen-refs", "0", "--quiet"]) == 0
    s = pd.read_csv(out / "online" / "summary.csv")
    assert list(s["controller"]) == ["pd", "exact", "ff"] and s["unseen_mse"].isna().all()
    capsys.readouterr()
    for bad, option in ((["--every", "0"], "--every"), (["--seconds", "-1"], "--seconds"),
                        (["--frameworks", "tf"], "--frameworks"), (["--seeds", "a"], "--seeds"),
                        (["--threshold", "0"], "--threshold"), (["--models", "lnn"], "--models"),
                        (["--sustain", "-1"], "--sustain")):
        assert main(["online", "--out", str(tmp_path / "bad"), *bad, "--quiet"]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and option in err
    assert not (tmp_path / "bad").exists()
