"""Two-link arm: mass matrix SPD, dM/dt - 2C skew-symmetric, inverse/forward dynamics round-trip."""

import numpy as np
import pytest

from lagbench import systems


@pytest.fixture(scope="module")
def arm():
    return systems.get("two_link_arm")


@pytest.fixture(scope="module")
def states(arm):
    return arm.sample_states(1000, 0)


def test_mass_matrix_symmetric_positive_definite(arm, states):
    m = arm.mass_matrix(states["q"])
    assert m.shape == (1000, 2, 2)
    np.testing.assert_array_equal(m, np.swapaxes(m, -1, -2))
    assert np.linalg.eigvalsh(m).min() > 0


def test_mdot_minus_two_c_is_skew(arm, states):
    q, qdot = states["q"], states["qdot"]
    h = 1e-6
    mdot = (arm.mass_matrix(q + h * qdot) - arm.mass_matrix(q - h * qdot)) / (2 * h)
    c = arm.coriolis_matrix(q, qdot)
    n = mdot - 2 * c
    np.testing.assert_allclose(n + np.swapaxes(n, -1, -2), 0, atol=1e-7)
    np.testing.assert_allclose(np.einsum("...ij,...j->...i", c, qdot), arm.coriolis(q, qdot),
                               rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_inverse_then_forward_round_trip(states, friction):
    arm = systems.get("two_link_arm", friction=friction)
    q, qdot = states["q"], states["qdot"]
    qddot = np.random.default_rng(1).normal(0, 5, q.shape)
    tau = arm.inverse_dynamics(q, qdot, qddot)
    np.testing.assert_allclose(arm.acceleration(q, qdot, tau=tau), qddot, rtol=1e-10, atol=1e-10)
    m, c, g = arm.mass_matrix(q), arm.coriolis(q, qdot), arm.gravity(q)
    rigid = np.einsum("...ij,...j->...i", m, qddot) + c + g + friction * qdot
    np.testing.assert_allclose(tau, rigid, rtol=1e-12, atol=1e-12)


def test_arm_dataset_families_differ_and_torques_are_exact(arm):
    from lagbench.systems.datasets import arm_dataset

    train = arm_dataset("train", 4, 50, 0, cache=False)
    test = arm_dataset("test", 4, 50, 0, cache=False)
    assert train["tau"].shape == test["tau"].shape == (4, 50, 2)
    assert np.abs(test["qddot"]).max() > np.abs(train["qddot"]).max()
    np.testing.assert_allclose(arm.acceleration(train["q"], train["qdot"], tau=train["tau"]),
                               train["qddot"], rtol=1e-9, atol=1e-9)
    # qdot is the time derivative of q (spectral check by central differences)
    t = train["t"]
    fd = (train["q"][:, 2:] - train["q"][:, :-2]) / (t[2:] - t[:-2])[None, :, None]
    np.testing.assert_allclose(fd, train["qdot"][:, 1:-1], atol=5e-2)
