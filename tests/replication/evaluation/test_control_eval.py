"""Claim 12's evaluation (`replication.evaluation.control`): the true inverse dynamics as the model tracks at
the zero-order hold's floor, far below PD alone; a null model (zero feed-forward) is PD alone and fails the
competence bar; a diverging model counts its references as diverged and its error as +inf."""
from types import SimpleNamespace

import numpy as np
import pytest

from lagbench import systems
from lagbench.replication.claims import get
from lagbench.replication.claims.bars import competence
from lagbench.replication.evaluation.control import FAMILIES, eval_control
from lagbench.replication.run.splits import DEV, TEST

PLANT = systems.get("two_link_arm")


class Inverse:
    def __init__(self, fn):
        self.fn = fn

    def inverse_dynamics(self, q, qdot, qddot):
        return self.fn(q, qdot, qddot)


def _evaluate(fn, split=DEV):
    ctx = SimpleNamespace(cfg={"n_refs": 2, "duration": 0.4}, model=Inverse(fn), spec=SimpleNamespace(kind="delan"),
                          protocol=SimpleNamespace(task="inverse_dynamics"), split=split, progress=None)
    return eval_control(ctx).metrics


def test_the_true_inverse_dynamics_tracks_at_the_floor_far_below_pd():
    m = _evaluate(lambda q, v, a: PLANT.inverse_dynamics(q, v, a))
    for f in FAMILIES:
        assert m[f"tracking_mse_{f}"] == pytest.approx(m[f"truth_tracking_mse_{f}"], rel=1e-9)
        assert m[f"tracking_mse_{f}"] < 1e-3 * m[f"null_tracking_mse_{f}"]
    assert m["n_diverged"] == 0


def test_a_null_model_is_pd_alone_and_fails_the_bar():
    m = _evaluate(lambda q, v, a: np.zeros_like(q))
    for f in FAMILIES:
        assert m[f"tracking_mse_{f}"] == pytest.approx(m[f"null_tracking_mse_{f}"], rel=1e-12)
    bar = get("delan_tracking").bars[0]
    row = [{"seed": 0, "status": "ok", **m}]
    ok, _, per = competence((bar,), {"delan": row, "ff": row})
    assert not ok and not per["delan"][0]


def test_a_diverging_model_scores_inf_and_counts_its_references():
    m = _evaluate(lambda q, v, a: 1e9 * np.ones_like(q))
    assert m["n_diverged"] > 0 and all(np.isinf(m[f"tracking_mse_{f}"]) for f in FAMILIES)


def test_the_test_split_tracks_other_references():
    a = _evaluate(lambda q, v, a: np.zeros_like(q))
    b = _evaluate(lambda q, v, a: np.zeros_like(q), split=TEST)
    assert a["null_tracking_mse_test"] != b["null_tracking_mse_test"]


def test_tracking_the_families_in_one_batch_gives_each_familys_own_numbers():
    """The three families are simulated side by side; each scores as when tracked on its own."""
    from lagbench.replication.studies import control

    def fn(q, v, a):
        return 0.8 * PLANT.inverse_dynamics(q, v, a)

    m = _evaluate(fn)
    for f in FAMILIES:
        refs = control.references(f, 2, 0.4, seed=control.SEED + DEV.draw_offset)
        alone = control.scores(control.track(fn, refs), refs)
        assert m[f"tracking_mse_{f}"] == alone["track_mse"], f
        assert m[f"torque_effort_{f}"] == alone["torque_effort"], f
