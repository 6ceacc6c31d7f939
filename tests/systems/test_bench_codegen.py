"""Benchmark: generated double-pendulum accelerations (JAX, jit + vmap, float64, batch 100 000)
against the hand-written closed form (``systems.closed_form``). Target: generated / hand-written
<= 1.5 in best-of-rounds time.

Run with ``pytest -m bench --benchmark-only`` (the tox ``bench`` env) for the pytest-benchmark
table; ``pytest -m bench`` alone runs the timeit-based ratio check (pyproject's addopts carry
``--benchmark-skip``, which skips the fixture-based cases unless ``--benchmark-only`` is given).
"""

import timeit

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from lagbench import systems
from lagbench.systems import closed_form

pytestmark = pytest.mark.bench

BATCH = 100_000
TARGET = 1.5


@pytest.fixture(scope="module")
def states():
    st = systems.get("double_pendulum").sample_states(BATCH, 0)
    return jnp.asarray(st["q"]), jnp.asarray(st["qdot"])


@pytest.fixture(scope="module")
def generated():
    s = systems.get("double_pendulum")
    return jax.jit(jax.vmap(lambda q, v: s.acceleration(q, v, backend="jax")))


@pytest.fixture(scope="module")
def hand_written():
    return jax.jit(jax.vmap(lambda q, v: closed_form.double_pendulum_acceleration(q, v, xp=jnp)))


def _best(fn, q, v) -> float:
    fn(q, v).block_until_ready()
    return min(timeit.repeat(lambda: fn(q, v).block_until_ready(), number=5, repeat=7)) / 5


def test_bench_hand_written(benchmark, states, hand_written):
    q, v = states
    hand_written(q, v).block_until_ready()
    benchmark.extra_info["batch"] = BATCH
    benchmark.pedantic(lambda: hand_written(q, v).block_until_ready(), rounds=30, iterations=1, warmup_rounds=3)


def test_bench_generated(benchmark, states, generated, hand_written):
    q, v = states
    generated(q, v).block_until_ready()
    benchmark.extra_info["batch"] = BATCH
    benchmark.pedantic(lambda: generated(q, v).block_until_ready(), rounds=30, iterations=1, warmup_rounds=3)
    ratio = benchmark.stats.stats.min / _best(hand_written, q, v)
    benchmark.extra_info["ratio_to_hand_written"] = ratio
    assert ratio < TARGET, f"generated/hand-written = {ratio:.2f}"


def test_generated_within_target_of_hand_written(states, generated, hand_written):
    q, v = states
    np.testing.assert_allclose(np.asarray(generated(q, v)), np.asarray(hand_written(q, v)),
                               rtol=1e-12, atol=1e-12)
    ratio = _best(generated, q, v) / _best(hand_written, q, v)
    assert ratio < TARGET, f"generated/hand-written = {ratio:.2f}"
