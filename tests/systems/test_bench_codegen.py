"""Benchmark: generated double-pendulum accelerations (JAX, jit + vmap, float64, batch 100 000)
against the hand-written closed form. Run with ``pytest -m bench --benchmark-enable``; the
target is generated / hand-written mean time <= 1.5."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import systems
from systems import closed_form

pytestmark = pytest.mark.bench

BATCH = 100_000


@pytest.fixture(scope="module")
def states():
    st = systems.get("double_pendulum").sample_states(BATCH, 0)
    return jnp.asarray(st["q"]), jnp.asarray(st["qdot"])


def _generated():
    s = systems.get("double_pendulum")
    return jax.jit(jax.vmap(lambda q, v: s.acceleration(q, v, backend="jax")))


def _hand_written():
    return jax.jit(jax.vmap(lambda q, v: closed_form.double_pendulum_acceleration(q, v, xp=jnp)))


@pytest.mark.parametrize("which", ["generated", "hand_written"])
def test_double_pendulum_acceleration_speed(benchmark, states, which):
    fn = _generated() if which == "generated" else _hand_written()
    q, v = states
    out = fn(q, v).block_until_ready()
    assert out.shape == (BATCH, 2) and out.dtype == jnp.float64
    benchmark.extra_info["batch"] = BATCH
    benchmark.pedantic(lambda: fn(q, v).block_until_ready(), rounds=30, iterations=1, warmup_rounds=3)


def test_generated_within_1p5x_of_hand_written(states):
    import timeit

    q, v = states
    gen, ref = _generated(), _hand_written()
    np.testing.assert_allclose(np.asarray(gen(q, v)), np.asarray(ref(q, v)), rtol=1e-12, atol=1e-12)
    t_gen = min(timeit.repeat(lambda: gen(q, v).block_until_ready(), number=5, repeat=7))
    t_ref = min(timeit.repeat(lambda: ref(q, v).block_until_ready(), number=5, repeat=7))
    assert t_gen / t_ref < 1.5, f"generated/hand-written = {t_gen / t_ref:.2f}"
