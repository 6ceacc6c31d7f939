"""Relativistic particle: the paper's and the standard Lagrangian give their known equations."""

import numpy as np
import pytest

from lagbench import systems
from lagbench.systems import closed_form


@pytest.mark.parametrize("name,standard", [("relativistic", False), ("relativistic_standard", True)])
def test_acceleration_and_momentum(name, standard):
    s = systems.get(name)
    st = s.sample_states(4000, 0)
    q, qdot, g = st["q"], st["qdot"], st["g"]
    acc = s.acceleration(q, qdot, g=g)
    np.testing.assert_allclose(acc[:, 0], closed_form.relativistic_acceleration(qdot[:, 0], g, standard),
                               rtol=1e-10, atol=1e-12)
    mom = s.canonical_momentum(q, qdot, g=g)
    np.testing.assert_allclose(mom[:, 0], closed_form.relativistic_momentum(qdot[:, 0], standard),
                               rtol=1e-10, atol=0)
    np.testing.assert_allclose(s.canonical_momentum_rate(q, qdot, g=g)[:, 0], g, rtol=1e-14)


def test_sampler_follows_the_original_protocol():
    st = systems.get("relativistic").sample_states(20000, 3)
    assert st["q"].min() >= -10 and st["q"].max() <= 10
    assert np.abs(st["qdot"]).max() < 1
    assert 9 < st["g"].std() < 11
    assert 0.5 < np.mean(np.abs(st["qdot"]) > 0.8) < 0.65  # the reference measured about 58 %


def test_the_two_lagrangians_differ_in_structure_only_beyond_second_order():
    a, b = systems.get("relativistic", g=2.0), systems.get("relativistic_standard", g=2.0)
    q, slow = np.zeros((1, 1)), np.full((1, 1), 1e-4)
    np.testing.assert_allclose(a.acceleration(q, slow), b.acceleration(q, slow), rtol=1e-7)
    fast = np.full((1, 1), 0.9)
    assert a.acceleration(q, fast)[0, 0] < b.acceleration(q, fast)[0, 0] / 10
    assert not a.structure["quadratic_kinetic"] and a.structure["separable"]
    with pytest.raises(ValueError, match="not quadratic"):
        a.mass_matrix(q)


def test_the_speed_option_draws_slower_particles_under_the_same_lagrangian():
    slow, fast = systems.get("relativistic", speed=0.1), systems.get("relativistic")
    st = slow.sample_states(2000, np.random.default_rng(0))
    assert np.abs(st["qdot"]).max() < 0.1 and np.abs(st["qdot"]).max() > 0.09
    assert slow.definition.fingerprint() == fast.definition.fingerprint()   # the same Lagrangian
    assert slow.options == {"speed": 0.1} and fast.options == {}            # so their datasets key apart
    q, qd = st["q"], st["qdot"]
    p = slow.canonical_momentum(q, qd, backend="numpy", g=st["g"])
    assert np.max(np.abs(p / qd - 1)) < 0.016                               # qdot within 1.5 % of the momentum
    with pytest.raises(ValueError, match="speed"):
        systems.get("relativistic", speed=1.5)
