"""The systems' tests run under JAX's strict numerics (`tests/systems/conftest.py`)."""
import jax
import jax.numpy as jnp
import pytest

from lagbench import systems  # noqa: F401  (float64 on, as every systems test has it)


def test_strict_numerics_are_on():
    with pytest.raises(ValueError, match="rank_promotion"):
        jnp.ones((2, 3)) + jnp.ones(3)
    with pytest.raises(ValueError, match="promot"):
        jnp.ones(3, jnp.float32) + jnp.ones(3, jnp.float64)
    assert jax.config.jax_enable_x64
