"""Evaluation helpers against independent references."""
import numpy as np
import pytest

from lagbench.replication.evaluation.routines import pdot_to_qddot, system_of
from lagbench.replication.training.protocol import Data, Protocol


@pytest.mark.parametrize("data", ["relativistic_iid", "charged_magnetic_iid", "double_pendulum_iid"])
def test_pdot_to_qddot_inverts_the_momentum_rate_along_the_motion(data):
    """pdot = dp/dq qdot + dp/dqdot qdd: feed the pdot of a known qdd (finite differences of p along
    qdd, not the truth's own rate) and get that qdd back."""
    s = system_of(Protocol(data=Data(data, n_train=1), steps=1, batch=1))
    st = s.sample_states(20, np.random.default_rng(0))
    q, qdot = st["q"], st["qdot"]
    qdd = np.random.default_rng(1).normal(size=q.shape)
    h = 1e-6
    pdot = (s.canonical_momentum(q + h * qdot, qdot + h * qdd) - s.canonical_momentum(q - h * qdot, qdot - h * qdd)) / (2 * h)
    np.testing.assert_allclose(pdot_to_qddot(Protocol(data=Data(data, n_train=1), steps=1, batch=1), q, qdot, pdot), qdd,
                               rtol=1e-5, atol=1e-5)
