"""Double pendulum: generated accelerations equal the hand-written Assencio closed form."""

import numpy as np

from lagbench import systems
from lagbench.systems import closed_form


def test_acceleration_matches_assencio_closed_form():
    s = systems.get("double_pendulum")
    st = s.sample_states(5000, 0)
    ours = s.acceleration(st["q"], st["qdot"])
    ref = closed_form.double_pendulum_acceleration(st["q"], st["qdot"])
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=1e-12)


def test_non_default_parameters_match_closed_form():
    params = {"m1": 1.3, "m2": 0.7, "l1": 0.9, "l2": 1.6, "g": 9.81}
    s = systems.get("double_pendulum", **params)
    st = s.sample_states(2000, 1)
    np.testing.assert_allclose(s.acceleration(st["q"], st["qdot"]),
                               closed_form.double_pendulum_acceleration(st["q"], st["qdot"], **params),
                               rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(s.energy(st["q"], st["qdot"]),
                               closed_form.double_pendulum_energy(st["q"], st["qdot"], **params),
                               rtol=1e-12, atol=1e-12)


def test_structure_and_defaults():
    s = systems.get("double_pendulum")
    assert s.params == {"m1": 1.0, "m2": 1.0, "l1": 1.0, "l2": 1.0, "g": 9.8, "friction": 0.0}
    assert s.structure == {"quadratic_kinetic": True, "separable": False,
                           "local_coupling": False, "actuated": False}
    # the LNN energy scale 29.4 = m1 g l1 + m2 g (l1 + l2) is the potential of the upright state
    top = s.energy(np.array([np.pi, np.pi]), np.zeros(2))
    np.testing.assert_allclose(top, 29.4, rtol=1e-14)


def test_momentum_rate_is_the_time_derivative_of_momentum():
    from lagbench.systems.trajectories import integrate

    s = systems.get("double_pendulum")
    st = s.sample_states(3, 2)
    t = np.array([0.0, 1e-4, 2e-4])
    q, qdot = integrate(s, st["q"], st["qdot"], t)
    p = s.canonical_momentum(q, qdot)
    fd = (p[:, 2] - p[:, 0]) / 2e-4
    np.testing.assert_allclose(fd, s.canonical_momentum_rate(q[:, 1], qdot[:, 1]), rtol=1e-6, atol=1e-6)


def test_friction_is_a_viscous_force_on_each_angle():
    """With friction b: M qddot = (the frictionless right-hand side) - b qdot, against the closed form."""
    b = 0.4
    s = systems.get("double_pendulum", friction=b)
    st = s.sample_states(5, 3)
    q, qd = st["q"], st["qdot"]
    c = np.cos(q[:, 0] - q[:, 1])   # m = l = 1, absolute angles: M = [[2, cos(q1 - q2)], [cos(q1 - q2), 1]]
    m = np.stack([np.stack([2 + 0 * c, c], -1), np.stack([c, 1 + 0 * c], -1)], -2)
    expected = closed_form.double_pendulum_acceleration(q, qd) - np.linalg.solve(m, b * qd[..., None])[..., 0]
    np.testing.assert_allclose(s.acceleration(q, qd, backend="numpy"), expected, rtol=1e-10, atol=1e-12)
