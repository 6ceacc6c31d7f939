"""Datasets follow the original protocols and carry exact targets."""

import numpy as np

from lagbench import systems
from lagbench.systems import closed_form
from lagbench.systems.datasets import iid_dataset, trajectory_dataset


def test_double_pendulum_iid_distribution_and_targets():
    d = iid_dataset("double_pendulum", 20000, 0, cache=False)
    assert d["q"].min() >= 0 and d["q"].max() < 2 * np.pi
    assert d["qdot"].min() >= -10 and d["qdot"].max() < 10
    np.testing.assert_allclose(d["qddot"], closed_form.double_pendulum_acceleration(d["q"], d["qdot"]),
                               rtol=1e-12, atol=1e-12)
    assert 40 < np.abs(d["qddot"]).sum(-1).mean() < 55  # the reference computed about 47.4


def test_relativistic_iid_has_per_sample_field():
    d = iid_dataset("relativistic", 1000, 0, cache=False)
    assert d["g"].shape == (1000,)
    np.testing.assert_allclose(d["qddot"][:, 0],
                               closed_form.relativistic_acceleration(d["qdot"][:, 0], d["g"]), rtol=1e-10)


def test_wave_iid_white_noise_on_a_larger_grid():
    d = iid_dataset("wave", 200, 0, n=100, cache=False)
    assert d["q"].shape == d["qddot"].shape == (200, 100)
    assert abs(d["q"].std() - 1) < 0.05 and abs(d["qdot"].mean()) < 0.05


def test_trajectory_dataset_is_seeded_and_consistent():
    t = np.linspace(0.0, 2.0, 21)
    a = trajectory_dataset("pendulum", 3, t, 5, cache=False)
    b = trajectory_dataset("pendulum", 3, t, 5, cache=False)
    np.testing.assert_array_equal(a["q"], b["q"])
    assert a["q"].shape == (3, 21, 1) and a["energy"].shape == (3, 21)
    np.testing.assert_allclose(a["energy"], np.broadcast_to(a["energy"][:, :1], (3, 21)), rtol=1e-10)
    s = systems.get("pendulum")
    np.testing.assert_allclose(a["qddot"], s.acceleration(a["q"], a["qdot"]), rtol=1e-14)
