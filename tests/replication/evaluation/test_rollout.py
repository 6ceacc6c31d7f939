"""The one fixed-step RK4 integrator (`replication.evaluation.rollout`): its step rules, its dtype, its JAX
scan and its handling of a diverging trajectory."""
import numpy as np
import pytest

from lagbench.replication.evaluation.rollout import lagrangian_field, rk4_scan, rk4_step, rollout


def _oscillator(dtype, seen=None):
    def accel(q, qd):
        if seen is not None:
            seen.add(q.dtype)
        return (-q).astype(dtype)
    return lagrangian_field(accel, 1)


def test_split_rule_meets_the_grid_and_matches_the_exact_solution():
    t = np.linspace(0.0, 1.0, 4)
    z = rollout(_oscillator(np.float64), np.array([[1.0, 0.0]]), t, 0.01)
    assert z.shape == (1, 4, 2) and z.dtype == np.float64
    np.testing.assert_allclose(z[0, :, 0], np.cos(t), atol=1e-9)


def test_dt_rule_steps_by_exactly_dt_in_the_dtype():
    """Step "dt" in float32 is the hand-written loop of `rk4_step` with a float32 state and step."""
    seen: set = set()
    t, dt = np.linspace(0.0, 0.2, 3), 0.01
    z = rollout(_oscillator(np.float32, seen), np.array([[1.0, 0.5]]), t, dt, dtype=np.float32, step="dt")
    y, h, f = np.array([[1.0, 0.5]], np.float32), np.asarray(dt, np.float32), _oscillator(np.float32)
    for _ in range(20):
        y = rk4_step(f, y, h)
    assert seen == {np.dtype(np.float32)} and z.dtype == np.float64
    assert np.array_equal(z[:, -1], y.astype(np.float64))


def test_diverged_trajectory_is_nan_from_then_on_and_others_continue():
    def f(z):
        out = np.stack([z[:, 1], -z[:, 0]], 1)
        out[z[:, 0] > 1.5] = np.inf
        return out
    z = rollout(f, np.array([[1.0, 0.0], [1.6, 0.0]]), np.linspace(0.0, 1.0, 3), 0.1)
    assert np.isfinite(z[0]).all() and np.isnan(z[1, 1:]).all()


def test_unknown_step_rule_is_rejected():
    with pytest.raises(ValueError, match="step rule"):
        rollout(_oscillator(np.float64), np.zeros((1, 2)), [0.0, 1.0], 0.1, step="adaptive")


def test_jax_scan_is_the_numpy_loop():
    import jax.numpy as jnp

    def f(z):
        return jnp.stack([z[1], -jnp.sin(z[0])])
    y0, h = np.array([0.3, -0.2]), 0.05
    got = np.asarray(rk4_scan(f, jnp.asarray(y0), h, 10))
    y = jnp.asarray(y0)
    for _ in range(10):
        y = rk4_step(f, y, h)
    np.testing.assert_allclose(got, np.asarray(y), rtol=1e-14)
