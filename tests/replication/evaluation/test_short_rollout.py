"""The held-out evaluation's short rollouts (`replication.evaluation.short_rollout`), on the relativistic
particle whose field g is a per-sample input: an exact model retraces the truth, a model that predicts zero
keeps its initial velocity, one that drives the particle past c is marked diverged (no exception), and the
test split draws other initial states than the development split."""
import numpy as np
import pytest

from lagbench.replication.claims import CLAIMS
from lagbench.replication.evaluation.registry import EVALUATIONS
from lagbench.replication.evaluation.routines import Context, system_of
from lagbench.replication.run.runner import plan
from lagbench.replication.run.splits import DEV, TEST

CLAIM = CLAIMS["rel_coords"]
CFG = CLAIM.evaluation_config("smoke")


class Exact:
    """The relativistic particle's true acceleration, reading g from the extra input as the models do."""

    def __init__(self, system, push=0.0):
        self.s, self.push = system, push

    def acceleration(self, q, qdot, extra=None):
        return self.s.acceleration(q, qdot, backend="numpy", g=extra[:, 0]) + self.push

    def acceleration_info(self, q, qdot, extra=None):
        return self.acceleration(q, qdot, extra), 0

    def velocity_hessian(self, q, qdot, extra=None):
        return self.s.velocity_hessian(q, qdot)


def _evaluate(model_of, split=DEV, label="lnn"):
    unit = next(u for u in plan("smoke", claims=["rel_coords"], frameworks=("torch",)) if u.entry.label == label)
    p = unit.protocol()
    ctx = Context(claim=CLAIM, entry=unit.entry, framework="torch", spec=unit.spec(), params=None, protocol=p,
                  profile="smoke", cfg=CFG, model=model_of(system_of(p)), split=split)
    return EVALUATIONS[CLAIM.evaluate](ctx).arrays


def test_an_exact_model_retraces_the_truth_and_the_velocity_moves():
    a = _evaluate(Exact)
    assert a["qdot_true"].shape == (CFG["n_ics"], CFG["n_t"], 1)
    np.testing.assert_allclose(a["qdot_pred"], a["qdot_true"], atol=1e-12)
    np.testing.assert_allclose(a["q_pred"], a["q_true"], atol=1e-12)
    assert np.ptp(a["qdot_true"], axis=1).max() > 0.01   # the field accelerates the particle visibly
    assert np.all(np.abs(a["qdot_true"]) < 1.0)


class _Zero(Exact):
    def __init__(self):
        pass

    def acceleration(self, q, qdot, extra=None):
        return np.zeros_like(q)

    def time_derivative(self, x, y, extra=None):
        return np.zeros_like(y), np.zeros_like(x)

    def velocity_hessian(self, q, qdot, extra=None):
        return np.ones(q.shape + q.shape[-1:])


def test_a_zero_model_keeps_its_initial_velocity():
    a = _evaluate(lambda s: _Zero())
    _constant_velocity(a)
    t = a["t"]
    np.testing.assert_allclose(a["q_pred"][..., 0], a["q_pred"][:, :1, 0] + a["qdot_pred"][:, :1, 0] * t, atol=1e-9)


def test_a_model_that_drives_the_particle_past_c_is_marked_diverged():
    a = _evaluate(lambda s: Exact(s, push=50.0))
    assert np.isnan(a["qdot_pred"][:, -1]).any()
    assert np.all(np.isfinite(a["qdot_true"]))


@pytest.mark.parametrize("label", ["hnn_qp", "hnn_qqdot_slow"])
def test_every_coordinate_kind_of_the_claim_is_rolled_out(label):
    """The canonical HNN runs in (q, p) by its own H (a zero H: dH/dp = 0, so it stays put, and p keeps its
    initial value, so the true velocity at the predicted state keeps the initial velocity); the control, on
    (q, qdot), keeps its initial velocity; it runs on the particle at speeds up to 0.1 c."""
    a = _evaluate(lambda s: _Zero(), label=label)
    assert a["qdot_pred"].shape == a["qdot_true"].shape
    _constant_velocity(a)
    np.testing.assert_allclose(a["qdot_pred"][:, 0], a["qdot_true"][:, 0], rtol=1e-12, atol=1e-14)
    if label == "hnn_qp":
        np.testing.assert_array_equal(a["q_pred"], np.broadcast_to(a["q_true"][:, :1], a["q_pred"].shape))


def _constant_velocity(a):
    np.testing.assert_allclose(a["qdot_pred"], np.broadcast_to(a["qdot_pred"][:, :1], a["qdot_pred"].shape), atol=1e-12)


def test_the_test_split_draws_other_initial_states():
    dev, test = _evaluate(Exact, DEV), _evaluate(Exact, TEST)
    assert not np.allclose(dev["qdot_true"][:, 0], test["qdot_true"][:, 0])
