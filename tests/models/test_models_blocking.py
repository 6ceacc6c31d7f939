"""Cache blocking (`models.jax.blocking`): a batch computed in row blocks equals the one-call result,
padding never leaks into the output or into the fallback count."""
import jax.numpy as jnp
import numpy as np
import pytest
from models_testkit import make_inputs, spec_params, to_jax

import lagbench.models.jax
import lagbench.models.jax.lnn as jlnn
from lagbench.models.jax.blocking import block_size, in_row_blocks


def test_blocks_equal_one_call_with_padding_and_none_arguments():
    rng = np.random.default_rng(0)
    n = 3 * block_size(5) + 7                               # forces blocks and a padded last block
    a, b = jnp.asarray(rng.normal(size=(n, 3))), jnp.asarray(rng.normal(size=(n, 2, 2)))
    fn = lambda x, none, y: (jnp.sin(x) * y[:, 0, :1], x.sum(-1) if none is None else None)  # noqa: E731
    blocked, one = in_row_blocks(fn, (a, None, b), 5), fn(a, None, b)
    for u, v in zip(blocked, one, strict=True):
        assert u.shape == v.shape
        np.testing.assert_array_equal(np.asarray(u), np.asarray(v))


@pytest.mark.parametrize("formulation", ["fast", "paper"])
def test_blocked_lnn_equals_per_block_calls(formulation):
    spec, params = spec_params(kind="lnn", dof=2, dtype="float64", formulation=formulation)
    n = 2 * block_size(spec.dof + 1) + 18                    # 3 blocks, the last padded; halves unblocked
    assert n % 3
    x = to_jax(make_inputs(spec, batch=n, seed=3))
    model = lagbench.models.jax.build(spec, params)
    whole = np.asarray(model.acceleration(x["q"], x["qdot"]))
    half = n // 2
    parts = [np.asarray(model.acceleration(x["q"][s], x["qdot"][s])) for s in (slice(0, half), slice(half, n))]
    np.testing.assert_allclose(whole, np.concatenate(parts), rtol=1e-12, atol=1e-12)
    if formulation == "fast":
        hess = np.asarray(model.velocity_hessian(x["q"], x["qdot"]))
        ref = np.asarray(jlnn.velocity_hessian(model._lagrangian, x["q"][:half], x["qdot"][:half]))
        np.testing.assert_allclose(hess[:half], ref, rtol=1e-10, atol=1e-12)


def test_blocked_fallbacks_count_each_sample_once():
    spec, params = spec_params(kind="lnn", dof=2, dtype="float64", activation="relu")
    n = 3 * block_size(spec.dof + 1) - 23                     # 3 blocks, the last padded
    assert n % 3
    x = to_jax(make_inputs(spec, batch=n))
    qddot, n_bad = lagbench.models.jax.build(spec, params).acceleration_info(x["q"], x["qdot"])
    assert int(n_bad) == n
    assert qddot.shape == (n, 2) and np.all(np.isfinite(np.asarray(qddot)))
