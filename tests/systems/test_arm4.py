"""Four-joint arm: M(q) SPD, energy conserved and power balanced along RK4 trajectories, the dynamics
against an independent NumPy model (``arm4_reference``), the planar two-link arm as a special case,
and its torque data family."""

import arm4_reference as ref
import numpy as np
import pytest

from lagbench import systems

FRICTION = {"friction": 0.4, "coulomb": 0.3}


@pytest.fixture(scope="module")
def arm():
    return systems.get("four_joint_arm")


@pytest.fixture(scope="module")
def states(arm):
    return arm.sample_states(500, 0)


def _rk4(s, q, qdot, dt, n_steps, tau=None):
    """Classical RK4 on (q, qdot) with the system's NumPy accelerations; ``tau(t) -> (..., 4)``."""
    def field(t, x):
        q_, v_ = x
        return v_, s.acceleration(q_, v_, tau=None if tau is None else tau(t))

    x, out = (q, qdot), [(q, qdot)]
    for i in range(n_steps):
        t = i * dt
        k1 = field(t, x)
        k2 = field(t + dt / 2, tuple(a + dt / 2 * b for a, b in zip(x, k1, strict=True)))
        k3 = field(t + dt / 2, tuple(a + dt / 2 * b for a, b in zip(x, k2, strict=True)))
        k4 = field(t + dt, tuple(a + dt * b for a, b in zip(x, k3, strict=True)))
        x = tuple(a + dt / 6 * (b1 + 2 * b2 + 2 * b3 + b4)
                  for a, b1, b2, b3, b4 in zip(x, k1, k2, k3, k4, strict=True))
        out.append(x)
    return np.stack([o[0] for o in out], 1), np.stack([o[1] for o in out], 1)


def test_registered_with_its_structure(arm):
    assert "four_joint_arm" in systems.names()
    assert arm.dof == 4
    assert arm.structure == {"quadratic_kinetic": True, "separable": False, "local_coupling": False,
                             "actuated": True}


def test_mass_matrix_symmetric_positive_definite(arm, states):
    m = arm.mass_matrix(states["q"])
    assert m.shape == (500, 4, 4)
    np.testing.assert_allclose(m, np.swapaxes(m, -1, -2), rtol=0, atol=1e-14)
    eig = np.linalg.eigvalsh(m)
    assert eig.min() > 5e-3  # about 0.011 kg m^2 at worst: the roll joint turns only Ia1 + Ia2 = 0.0126 straight


def test_energy_and_yaw_momentum_conserved_without_friction(arm):
    """RK4's energy error falls as dt^4 (no drift of the model's own); the yaw momentum is conserved."""
    st = arm.sample_states(6, 1)
    drift = {}
    for dt in (2e-3, 1e-3):
        q, qdot = _rk4(arm, st["q"], st["qdot"], dt, round(0.5 / dt))
        e = arm.energy(q, qdot)
        drift[dt] = np.abs(e - e[:, :1]).max() / np.abs(e).max()
    assert drift[1e-3] < 1e-6 and drift[2e-3] / drift[1e-3] > 12  # 2^4 = 16 for a fourth-order method
    p_yaw = arm.canonical_momentum(q, qdot)[..., 0]  # q1 is cyclic: gravity is along the yaw axis
    assert np.abs(p_yaw - p_yaw[:, :1]).max() < 1e-6 * max(1.0, np.abs(p_yaw).max())
    assert np.abs(q - q[:, :1]).max() > 0.5  # the arm moved


def test_suite_integrator_conserves_energy(arm):
    from lagbench.systems.trajectories import integrate

    st = arm.sample_states(2, 5)
    q, qdot = integrate(arm, st["q"], st["qdot"], np.linspace(0.0, 0.5, 11), solver="dopri5", rtol=1e-10,
                        atol=1e-10)
    e = arm.energy(q, qdot)
    assert np.abs(e - e[:, :1]).max() / np.abs(e).max() < 1e-8


def test_power_balance_with_viscous_and_coulomb_friction_and_torques():
    s = systems.get("four_joint_arm", **FRICTION)
    st = s.sample_states(4, 2)
    amp = np.array([3.0, 20.0, 1.0, 5.0])

    def tau(t):
        return amp * np.sin(2.0 * t + np.arange(4))

    dt, n = 5e-4, 800
    q, qdot = _rk4(s, st["q"], st["qdot"], dt, n, tau=tau)
    e = s.energy(q, qdot)
    de_dt = (e[:, 2:] - e[:, :-2]) / (2 * dt)
    t = dt * np.arange(n + 1)[1:-1, None]
    v = qdot[:, 1:-1]
    forces = tau(t) - FRICTION["friction"] * v - FRICTION["coulomb"] * np.tanh(v / s.params["coulomb_speed"])
    power = np.sum(v * forces, -1)
    np.testing.assert_allclose(de_dt, power, rtol=0, atol=1e-5 * np.abs(power).max())
    assert np.abs(e[:, -1] - e[:, 0]).max() > 0.1  # friction and torques did change the energy


def test_mass_matrix_and_gravity_match_the_jacobian_assembly(arm, states):
    p = arm.params
    for i in range(25):
        q = states["q"][i]
        np.testing.assert_allclose(arm.mass_matrix(q), ref.mass_matrix(q, p), rtol=1e-12, atol=1e-13)
        np.testing.assert_allclose(arm.gravity(q), ref.gravity(q, p), rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("params", [{}, FRICTION, {"m2": 4.0, "lc2": 0.3, "Ia1": 0.02, "I0": 0.5}])
def test_inverse_dynamics_match_finite_difference_euler_lagrange(states, params):
    s = systems.get("four_joint_arm", **params)
    qddot = np.random.default_rng(3).normal(0, 4, states["q"].shape)
    for i in range(12):
        q, qdot = states["q"][i], states["qdot"][i]
        expected = ref.inverse_dynamics(q, qdot, qddot[i], s.params)
        np.testing.assert_allclose(s.inverse_dynamics(q, qdot, qddot[i]), expected, rtol=1e-7, atol=1e-7)


@pytest.mark.parametrize("params", [{}, FRICTION])
def test_inverse_then_forward_round_trip(states, params):
    s = systems.get("four_joint_arm", **params)
    q, qdot = states["q"], states["qdot"]
    qddot = np.random.default_rng(1).normal(0, 5, q.shape)
    tau = s.inverse_dynamics(q, qdot, qddot)
    np.testing.assert_allclose(s.acceleration(q, qdot, tau=tau), qddot, rtol=1e-9, atol=1e-9)
    v = s.params["coulomb_speed"]
    friction = s.params["friction"] * qdot + s.params["coulomb"] * np.tanh(qdot / v)
    rigid = np.einsum("...ij,...j->...i", s.mass_matrix(q), qddot) + s.coriolis(q, qdot) + s.gravity(q)
    np.testing.assert_allclose(tau, rigid + friction, rtol=1e-11, atol=1e-11)


def test_pitch_joints_alone_are_the_planar_two_link_arm(arm, states):
    """q3 = 0 and the yaw and roll joints at rest: joints 2 and 4 move as two_link_arm's q1, q2."""
    p = arm.params
    planar = systems.get("two_link_arm", m1=p["m1"], l1=p["l1"], lc1=p["lc1"], I1=p["It1"], m2=p["m2"],
                         l2=p["l2"], lc2=p["lc2"], I2=p["It2"], g=p["g"])
    rng = np.random.default_rng(4)
    n = 200
    q = np.stack([rng.uniform(-np.pi, np.pi, n), states["q"][:n, 1], np.zeros(n), states["q"][:n, 3]], -1)
    qdot = np.zeros((n, 4))
    qdot[:, [1, 3]] = states["qdot"][:n, [1, 3]]
    qddot = np.zeros((n, 4))
    qddot[:, [1, 3]] = rng.normal(0, 5, (n, 2))
    pitch = [1, 3]
    np.testing.assert_allclose(arm.mass_matrix(q)[:, pitch][:, :, pitch], planar.mass_matrix(q[:, pitch]),
                               rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(arm.inverse_dynamics(q, qdot, qddot)[:, pitch],
                               planar.inverse_dynamics(q[:, pitch], qdot[:, pitch], qddot[:, pitch]),
                               rtol=1e-11, atol=1e-11)


def test_rod_defaults_and_non_physical_parameters():
    p = systems.get("four_joint_arm").params
    assert p["It1"] == pytest.approx(p["m1"] * (3 * 0.06**2 + p["l1"] ** 2) / 12)
    assert p["Ia2"] == pytest.approx(p["m2"] * 0.04**2 / 2)
    assert p["friction"] == p["coulomb"] == 0.0 and p["coulomb_speed"] == 0.05
    with pytest.raises(ValueError, match="lc1.*must not exceed l1"):
        systems.get("four_joint_arm", lc1=0.6)
    with pytest.raises(ValueError, match="Ia2 must not exceed 2 It2"):
        systems.get("four_joint_arm", Ia2=0.1)
    with pytest.raises(ValueError, match="coulomb.*>= 0"):
        systems.get("four_joint_arm", coulomb=-1.0)


@pytest.mark.parametrize("kind", ["train", "test"])
def test_arm_data_family_for_four_joints(arm, kind):
    from lagbench.systems.datasets import arm_dataset

    d = arm_dataset(kind, 3, 60, 0, system="four_joint_arm", cache=False)
    assert d["q"].shape == d["tau"].shape == (3, 60, 4) and d["energy"].shape == (3, 60)
    assert all(np.all(np.isfinite(v)) for v in d.values())
    np.testing.assert_allclose(arm.acceleration(d["q"], d["qdot"], tau=d["tau"]), d["qddot"],
                               rtol=1e-9, atol=1e-9)
    with pytest.raises(ValueError, match="unknown arm"):
        arm_dataset(kind, 1, 2, 0, system="pendulum", cache=False)
