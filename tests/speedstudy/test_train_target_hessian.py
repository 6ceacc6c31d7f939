"""`hessian_rel_err`: the learned velocity Hessian against the true mass matrix, up to one scale."""
import numpy as np
import pytest

from lagbench import systems
from lagbench.models import ModelSpec
from lagbench.speedstudy.train_target import hessian_rel_err, protocols


class _FakeLNN:
    """velocity_hessian = c * H_true (+ a perturbation): stands in for a trained LNN."""

    def __init__(self, c, noise=0.0):
        self.c, self.noise, self.sys = c, noise, systems.get("double_pendulum")

    def velocity_hessian(self, q, qdot):
        h = self.c * self.sys.velocity_hessian(np.asarray(q, float), np.asarray(qdot, float))
        return h + self.noise * np.eye(2)


@pytest.fixture(scope="module")
def setup():
    proto = protocols(4096, 256)["variant"][0]
    return ModelSpec(kind="lnn", dof=2, hidden=(8,)), proto


@pytest.mark.parametrize("c", [1.0, -0.37, 250.0])
def test_true_mass_matrix_at_any_scale_is_zero(setup, c):
    spec, proto = setup
    assert hessian_rel_err(_FakeLNN(c), spec, proto) < 1e-5  # float32 held-out states


def test_a_wrong_hessian_is_order_one(setup):
    spec, proto = setup
    err = hessian_rel_err(_FakeLNN(1.0, noise=2.0), spec, proto)
    assert 0.1 < err < 1.0  # |2 I| against |M(q)| ~ 2.6: far from 0, bounded


def test_baseline_has_none(setup):
    _, proto = setup
    assert np.isnan(hessian_rel_err(None, ModelSpec(kind="baseline", dof=2, hidden=(8,)), proto))
