"""Block cyclic reduction (`models.<fw>.banded.block_tridiagonal_solve`) against a dense solve of the same
block-tridiagonal matrix, for block counts that hit every branch: one block, odd counts (padded), even
counts and several levels."""
import jax.numpy as jnp
import numpy as np
import pytest
import torch

import lagbench.models.jax.banded as jb
import lagbench.models.torch.banded as tb


def _system(m, w=2, k=3, batch=2, seed=0):
    rng = np.random.default_rng(seed)
    diag = rng.normal(size=(batch, m, w, w)) + 4 * np.eye(w)
    lower, upper = rng.normal(size=(2, batch, m, w, w))
    lower[:, 0], upper[:, -1] = 0.0, 0.0
    dense = np.zeros((batch, m * w, m * w))
    for b in range(m):
        s = slice(b * w, (b + 1) * w)
        dense[:, s, s] = diag[:, b]
        if b:
            dense[:, s, slice((b - 1) * w, b * w)] = lower[:, b]
        if b < m - 1:
            dense[:, s, slice((b + 1) * w, (b + 2) * w)] = upper[:, b]
    rhs = rng.normal(size=(batch, m, w, k))
    ref = np.linalg.solve(dense, rhs.reshape(batch, m * w, k)).reshape(rhs.shape)
    return (diag, lower, upper, rhs), ref


@pytest.mark.parametrize("m", [1, 2, 5, 8, 13])
@pytest.mark.parametrize("fw", ["jax", "torch"])
def test_cyclic_reduction_equals_dense_solve(fw, m):
    args, ref = _system(m)
    if fw == "jax":
        x = np.asarray(jb.block_tridiagonal_solve(*(jnp.asarray(a) for a in args)))
    else:
        x = tb.block_tridiagonal_solve(*(torch.tensor(a) for a in args)).numpy()
    np.testing.assert_allclose(x, ref, rtol=1e-10, atol=1e-12)


def test_singular_pivot_block_gives_nan_not_an_exception():
    (diag, lower, upper, rhs), _ = _system(4)
    diag[:, 1] = 0.0
    lower[:, 1], upper[:, 1] = 0.0, 0.0                       # block 1 is singular and decoupled
    x = tb.block_tridiagonal_solve(*(torch.tensor(a) for a in (diag, lower, upper, rhs)))
    assert torch.isnan(x).any()
