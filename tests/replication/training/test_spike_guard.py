"""The gradient-spike guard: its bookkeeping, the protocol fields, and the JAX step's skip."""
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import lagbench.models.jax
from lagbench.models import ModelSpec, init_params
from lagbench.replication.training import train_jax
from lagbench.replication.training.data import BatchStream
from lagbench.replication.training.protocol import Data, Guard, Protocol
from lagbench.replication.training.spike_guard import MIN_HISTORY, WINDOW, SpikeGuard

BASE = Protocol(data=Data("double_pendulum_iid", n_train=32, resample=True), steps=5, batch=8, dtype="float64")


def test_off_by_default():
    guard = SpikeGuard(None)
    assert not guard.active and guard.clip_scale(1e9) == 1.0
    for g in [1.0] * 50 + [1e12]:
        assert guard.record(g, guard.threshold())
    assert guard.skipped == 0


def test_skip_bound_is_factor_times_recent_median():
    guard = SpikeGuard(Guard(skip=10.0))
    for k in range(MIN_HISTORY):
        assert guard.threshold() == math.inf  # warming up
        guard.record(float(k + 1), guard.threshold())
    assert guard.threshold() == pytest.approx(10.0 * np.median(np.arange(1, MIN_HISTORY + 1)))
    bound = guard.threshold()
    assert not guard.record(bound, bound) and guard.record(bound * 0.999, bound)
    assert guard.skipped == 1
    for _ in range(WINDOW):
        guard.record(1000.0, guard.threshold())  # old norms leave the window
    assert guard.threshold() == pytest.approx(1e4)


def test_the_sorted_window_gives_numpy_median_at_every_step_and_after_a_restore():
    """Past the window's length (old norms leaving), with repeated values and non-finite norms left out;
    a guard restored from a window mid-way continues with the same bounds."""
    rng = np.random.default_rng(3)
    norms = np.exp(rng.normal(size=3 * WINDOW + 7)).round(2)   # rounding: ties in the window
    norms[[5, 50, 400]] = [np.inf, np.nan, np.inf]
    guard = SpikeGuard(Guard(skip=3.0))
    seen = []
    for k, g in enumerate(norms):
        if k == WINDOW + 11:
            restored = SpikeGuard(Guard(skip=3.0))
            restored.restore(list(guard.history), guard.skipped)
            guard = restored
        bound = guard.threshold()
        window = seen[-WINDOW:]
        expected = math.inf if len(window) < MIN_HISTORY else 3.0 * float(np.median(window))
        assert bound == expected, k
        guard.record(float(g), bound)
        if np.isfinite(g):
            seen.append(float(g))


def test_non_finite_norm_is_a_skipped_spike_only_when_skipping():
    off, on = SpikeGuard(Guard(clip=5.0)), SpikeGuard(Guard(skip=10.0))
    assert off.fails(1.0, float("inf")) and off.fails(float("nan"), 1.0)
    assert not on.fails(1.0, float("nan")) and not on.fails(1.0, float("inf")) and on.fails(float("inf"), 1.0)
    for g in [2.0] * MIN_HISTORY:
        on.record(g, on.threshold())
    assert not on.record(float("nan"), on.threshold()) and not on.record(float("inf"), on.threshold())
    assert on.skipped == 2 and on.threshold() == pytest.approx(20.0)  # the history holds finite norms only


def test_clip_scale():
    guard = SpikeGuard(Guard(clip=5.0))
    assert guard.clip_scale(4.0) == 1.0 and guard.clip_scale(20.0) == pytest.approx(0.25)


def test_guard_fields_validated_and_keyed():
    for bad in (-1.0, 0.0, float("nan"), float("inf"), "3"):
        with pytest.raises(ValueError, match="guard clip"):
            Guard(clip=bad)
        with pytest.raises(ValueError, match="guard skip"):
            Guard(skip=bad)
    with pytest.raises(ValueError, match="needs clip or skip"):
        Guard()
    with pytest.raises(ValueError, match="protocol guard must be a Guard"):
        BASE.replace(guard={"clip": 1.0})
    assert BASE.to_dict()["guard"] is None
    guarded = BASE.replace(guard=Guard(clip=100.0, skip=10.0))
    assert guarded.key() != BASE.key()
    assert Protocol.from_dict(guarded.to_dict()) == guarded and Protocol.from_dict(BASE.to_dict()) == BASE


def test_jax_step_skip_leaves_model_and_state():
    spec = ModelSpec(kind="lnn", dof=2, hidden=(8, 8), dtype="float64", angle_wrap=True)
    model = lagbench.models.jax.build(spec, init_params(spec, seed=0))
    opt, step = train_jax.make_step(spec, BASE)
    state = opt.init(eqx.filter(model, eqx.is_inexact_array))
    batch = {k: jnp.asarray(v) for k, v in BatchStream(BASE, 0).batch(0).items()}
    lr = jnp.asarray(1e-2)
    m_skip, s_skip, _, gnorm = step(model, state, batch, lr, jnp.asarray(0.0))
    m_take, _, _, _ = step(model, state, batch, lr, jnp.asarray(float(gnorm) * 1.001))
    assert _same(m_skip, model) and _same(s_skip, state)
    assert not _same(m_take, model)


def _same(a, b) -> bool:
    leaves = lambda t: jax.tree_util.tree_leaves(eqx.filter(t, eqx.is_array))  # noqa: E731
    return all(np.array_equal(x, y) for x, y in zip(leaves(a), leaves(b), strict=True))
