"""Energy conservation of the float64 ground truth (the LNN energy protocol) and of the wave."""

import numpy as np
import pytest

from lagbench import systems
from lagbench.systems.trajectories import integrate


def _max_drift(s, q, qdot, **params):
    e = s.energy(q, qdot, **params)
    return np.abs(e - e[:, :1]).max()


def test_double_pendulum_40_near_rest_starts_to_t100():
    s = systems.get("double_pendulum")
    st = s.sample_states(40, 0, distribution="near_rest")
    assert st["qdot"].min() >= 0 and st["qdot"].max() < 0.1
    t = np.linspace(0.0, 100.0, 1000)
    q, qdot = integrate(s, st["q"], st["qdot"], t)
    assert q.shape == (40, 1000, 2)
    assert _max_drift(s, q, qdot) / 29.4 < 1e-9


@pytest.mark.parametrize("variant", ["code", "textbook"])
def test_wave_variants_conserve_their_energy(variant):
    s = systems.get("wave", variant=variant)
    st = s.sample_states(4, 0)
    q, qdot = integrate(s, st["q"], st["qdot"], np.linspace(0.0, 5.0, 50), rtol=1e-11, atol=1e-11)
    e0 = np.abs(s.energy(st["q"], st["qdot"])).max()
    assert _max_drift(s, q, qdot) / e0 < 1e-8


@pytest.mark.parametrize("variant,k", [("code", 5.0), ("textbook", 100.0)])
def test_wave_accelerations_are_the_stated_second_differences(variant, k):
    s = systems.get("wave", variant=variant)
    st = s.sample_states(100, 1)
    u = st["q"]
    expected = k * (np.roll(u, -1, -1) - 2 * u + np.roll(u, 1, -1))
    np.testing.assert_allclose(s.acceleration(u, st["qdot"]), expected, rtol=1e-12, atol=1e-12)
    e = 0.5 * (st["qdot"] ** 2).sum(-1) + k / 2 * ((np.roll(u, -1, -1) - u) ** 2).sum(-1)
    np.testing.assert_allclose(s.energy(u, st["qdot"]), e, rtol=1e-12)


def test_integrate_validates_inputs():
    s = systems.get("pendulum")
    with pytest.raises(ValueError, match="strictly increasing"):
        integrate(s, [0.1], [0.0], [0.0, 1.0, 0.5])
    with pytest.raises(ValueError, match="shape"):
        integrate(s, [[0.1, 0.2]], [[0.0, 0.0]], [0.0, 1.0])
    with pytest.raises(ValueError, match="solver"):
        integrate(s, [0.1], [0.0], [0.0, 1.0], solver="euler")
