"""Closed-loop tracking control (`replication.studies.control`, `lagbench control`): the true inverse dynamics
tracks far better than PD alone (the positive control), a model that predicts zero torque is PD alone (the
null), a diverging model is marked and scores no error, and the references are the families no model saw."""
import numpy as np
import pytest

from lagbench import systems
from lagbench.cli import main
from lagbench.replication.studies import control as C

PLANT = systems.get("two_link_arm")


@pytest.fixture(scope="module")
def refs():
    return C.references("test", n=2, duration=0.5)


def test_the_true_inverse_dynamics_tracks_and_pd_alone_does_not(refs):
    exact = C.scores(C.track(lambda q, v, a: PLANT.inverse_dynamics(q, v, a), refs), refs)
    pd_alone = C.scores(C.track(None, refs), refs)
    assert exact["n_diverged"] == pd_alone["n_diverged"] == 0
    assert exact["track_mse"] < 1e-3 * pd_alone["track_mse"] and pd_alone["track_mse"] > 1e-3
    fine = C.references("test", n=2, duration=0.5, rate=2000.0)
    finer = C.scores(C.track(lambda q, v, a: PLANT.inverse_dynamics(q, v, a), fine, rate=2000.0), fine)
    assert finer["track_mse"] < 0.1 * exact["track_mse"]   # what is left is the hold over a control period


def test_a_model_of_zero_torque_is_pd_alone_and_a_diverging_one_is_marked(refs):
    zero = C.track(lambda q, v, a: np.zeros_like(q), refs)
    pd_alone = C.track(None, refs)
    assert np.array_equal(zero["q"], pd_alone["q"])
    wild = C.scores(C.track(lambda q, v, a: np.full_like(q, 1e9), refs), refs)
    assert wild["n_diverged"] == 2 and "track_mse" not in wild


def test_the_references_are_unseen_shapes_and_the_training_family_twice_as_fast():
    from lagbench.systems.arm_data import arm_dataset

    fast = C.references("train_x2", n=2, duration=1.0, rate=100.0)
    slow = arm_dataset("train", n_traj=2, n_points=101, seed=C.SEED, duration=2.0, cache=False)
    assert np.allclose(fast["q"], slow["q"]) and np.allclose(fast["qdot"], 2 * slow["qdot"])
    assert np.allclose(fast["qddot"], 4 * slow["qddot"]) and np.isclose(fast["t"][-1], 1.0)
    assert np.allclose(np.gradient(fast["q"], fast["t"], axis=1)[:, 5:-5], fast["qdot"][:, 5:-5], atol=2e-2)


def test_the_command_writes_the_study_for_a_folder_without_models(tmp_path, capsys):
    assert main(["control", "--out", str(tmp_path), "--references", "1", "--duration", "0.2", "--quiet"]) == 0
    import pandas as pd

    df = pd.read_csv(tmp_path / "control" / "tracking.csv")
    assert set(df["controller"]) == {"exact", "pd"} and set(df["family"]) == {"test", "train_x2"}
    assert (df.loc[df["controller"] == "pd", "ratio_to_pd"] == 1).all()
    assert main(["control", "--out", str(tmp_path), "--references", "0", "--quiet"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_the_report_shows_the_study_and_flags_a_controller_no_better_than_pd(tmp_path):
    import pandas as pd

    from lagbench.reports.sections_control import _table

    df = pd.DataFrame([{"family": "test", "controller": c, "framework": fw, "seed": s, "track_mse": m,
                        "ratio_to_pd": m / 0.3, "torque_effort": 1.0, "n_diverged": 0}
                       for c, fw, s, m in (("pd", "numpy", "-", 0.3), ("delan", "jax", "1000", 0.01),
                                           ("ff", "jax", "1000", 0.4))])
    t = _table(df).set_index("controller")
    assert t.loc["ff", "flag"].startswith("NO BETTER") and t.loc["delan", "flag"] == "-" and t.loc["pd", "flag"] == "-"


@pytest.mark.parametrize("system", ["two_link_arm", "four_joint_arm"])
def test_the_compiled_period_is_the_numpy_hold_to_rounding(system):
    plant = systems.get(system)
    rng = np.random.default_rng(0)
    q, v, tau = (rng.normal(size=(3, plant.dof)) for _ in range(3))
    h = 1.0 / C.RATE / C.SUBSTEPS
    fast = C.period(plant, h, periods=C.COMPILE_FROM)
    assert fast is not C.period(plant, h, periods=C.COMPILE_FROM - 1)
    for _ in range(5):   # the states after five periods
        want = C.hold(plant, q, v, tau, h)
        got = fast(q, v, tau)
        for w, g in zip(want, got, strict=True):
            assert isinstance(g, np.ndarray) and g.dtype == np.float64
            np.testing.assert_allclose(g, w, rtol=1e-12, atol=1e-12)
        q, v = want[0], want[1]
    wild = fast(q, v, np.full_like(tau, 1e30))   # a diverging torque stays visible to `diverged`
    assert C.diverged(wild[0], wild[1]).all()


def test_a_long_track_gives_the_short_tracks_numbers(refs, monkeypatch):
    exact = lambda q, v, a: PLANT.inverse_dynamics(q, v, a)   # noqa: E731
    numpy = C.track(exact, refs)
    monkeypatch.setattr(C, "COMPILE_FROM", 1)   # this track compiled
    compiled = C.track(exact, refs)
    np.testing.assert_allclose(compiled["q"], numpy["q"], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(compiled["tau"], numpy["tau"], rtol=1e-8, atol=1e-9)
