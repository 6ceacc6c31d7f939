"""Row blocks for PyTorch's compiled calls: the plan shared with JAX (`models.row_blocks`), the blocking
mirror (`models.torch.blocking`), a blocked call (`models.torch.compiled.BlockedMethod`) equal to one
call with the padding sliced off, a fixed-batch library compiled for the block size only, and the traced
inference solve, whose pinv runs only where a sample is bad, compiled and run on batches with none, one
and all samples bad. Four compiles (5-20 s each)."""
import numpy as np
import pytest
import torch

from lagbench.models import ModelSpec
from lagbench.models.row_blocks import block_plan, block_size, rows_per_sample
from lagbench.models.torch.compiled import BlockedMethod, compile_batched
from lagbench.models.torch.lnn import solve_with_fallback

RNG = np.random.default_rng(11)


def test_block_plan_equal_blocks_and_small_batches_in_one_call():
    assert block_plan(2 * block_size(5), 5) is None
    for n in (2 * block_size(5) + 1, 3 * block_size(5) + 7, 10_000):
        n_blocks, block = block_plan(n, 5)
        assert block <= block_size(5) and 0 <= n_blocks * block - n < n_blocks
    assert block_size(10_000) == 8


@pytest.mark.parametrize("kind, form, dof, rows", [
    ("lnn", "fast", 2, 3), ("lnn", "paper", 16, 17), ("lgn", "dense", 32, 33), ("lgn", "paper", 8, 9),
    ("lgn", "banded", 32, None), ("lgn", "banded", 4, 5),  # n < 4r + 1: the banded LGN takes the dense path
    ("hnn", "fast", 2, None), ("delan", "fast", 2, None), ("baseline", "fast", 2, None)])
def test_rows_per_sample_follow_the_jax_models(kind, form, dof, rows):
    spec = ModelSpec(kind=kind, dof=dof, hidden=(8,), formulation=form if kind in ("lnn", "lgn") else "fast")
    assert rows_per_sample(spec) == rows


def test_in_row_blocks_mirrors_jax_with_padding_and_none_arguments():
    """`models.torch.blocking.in_row_blocks`, the mirror of `models.jax.blocking.in_row_blocks`: blocks
    equal one call, padding sliced off, None arguments passed through, small batches in one call."""
    from lagbench.models.torch.blocking import in_row_blocks

    n = 3 * block_size(5) + 7                               # forces blocks and a padded last block
    a, b = torch.tensor(RNG.normal(size=(n, 3))), torch.tensor(RNG.normal(size=(n, 2, 2)))
    calls = []

    def fn(x, none, y):
        calls.append(x.shape[0])
        return torch.sin(x) * y[:, 0, :1], x.sum(-1) if none is None else None
    blocked, one = in_row_blocks(fn, (a, None, b), 5), fn(a, None, b)
    assert len(calls) == 1 + block_plan(n, 5)[0]
    for u, v in zip(blocked, one, strict=True):
        assert u.shape == v.shape
        np.testing.assert_array_equal(u.numpy(), v.numpy())
    calls.clear()
    in_row_blocks(fn, (a[:8], None, b[:8]), 5)
    assert calls == [8]


def _counting(f):
    calls = []
    inner = f.inner

    def run(*xs):
        calls.append(xs[0].shape[0])
        return inner(*xs)
    f.inner = run
    return calls


def _fn(a, b):
    return torch.sin(a) * b, torch.sum(a * b, dim=-1)


@pytest.mark.slow   # slow: the speed study's AOT path, 30-50 s of compiling; its lighter siblings stay in the default run
def test_fixed_batch_is_compiled_for_its_block_and_called_per_block():
    n = 3 * block_size(5) + 7
    n_blocks, block = block_plan(n, 5)
    a, b = (torch.tensor(RNG.normal(size=(n, 3))) for _ in range(2))
    f = compile_batched(_fn, 2, 3, "float64", batch=n, rows_per_sample=5)
    assert isinstance(f, BlockedMethod) and f.inner.in_shape == (block, 3)
    calls = _counting(f)
    got, want = f(a, b), _fn(a, b)
    assert calls == [block] * n_blocks
    for u, v in zip(got, want, strict=True):
        assert u.shape == v.shape
        np.testing.assert_allclose(u.numpy(), v.numpy(), rtol=1e-14, atol=1e-15)  # fused sin: ulps
    with pytest.raises(ValueError, match=rf"input 1: compiled for a \({n}, 3\) torch.float64"):
        f(a, b[:-1])


@pytest.mark.slow   # slow: a speed-study compile path (`lagbench bench`'s quick preset); the paths verdicts use stay in the default run
def test_any_batch_library_blocks_large_batches_only():
    f = compile_batched(_fn, 2, 3, "float64", rows_per_sample=5)
    calls = _counting(f)
    for n in (1, 2 * block_size(5), 2 * block_size(5) + 3):
        a, b = (torch.tensor(RNG.normal(size=(n, 3))) for _ in range(2))
        calls.clear()
        for u, v in zip(f(a, b), _fn(a, b), strict=True):
            np.testing.assert_allclose(u.numpy(), v.numpy(), rtol=1e-14, atol=1e-15)  # fused sin: ulps
        assert len(calls) == (1 if block_plan(n, 5) is None else 3) and sum(calls) >= n


@pytest.mark.slow   # slow: the speed study's AOT path, 30-50 s of compiling; its lighter siblings stay in the default run
def test_traced_solve_compiled_takes_pinv_only_where_bad():
    """The make_fx-traced inference solve (its pinv in a torch.cond), exported and compiled for two batch
    sizes in turn (the second once failed to export: dynamo had made the size dynamic): pinv's answer on
    the singular samples, the inverse's elsewhere, for batches with no bad sample, one, and all."""
    def solve(h_flat, r):
        return solve_with_fallback(h_flat.reshape(-1, 2, 2), r[:, :2])[0]

    singular = torch.tensor([[1.0, 1.0], [1.0, 1.0]], dtype=torch.float64)
    for b in (4, 3):
        good = torch.tensor(RNG.normal(size=(b, 2, 2)))
        good = good @ good.mT + torch.eye(2, dtype=torch.float64)
        rhs = torch.tensor(RNG.normal(size=(b, 4)))
        f = compile_batched(solve, 2, 4, "float64", batch=b, flatten=True)
        for bad in ([], [1], list(range(b))):
            hess = good.clone()
            hess[bad] = singular
            want, n_bad = solve_with_fallback(hess, rhs[:, :2])
            assert int(n_bad) == len(bad)
            got = f(hess.reshape(b, 4), rhs)
            np.testing.assert_allclose(got.numpy(), want.numpy(), rtol=1e-10, atol=1e-12)
            for i in bad:
                np.testing.assert_allclose(got[i].numpy(), np.linalg.pinv(singular.numpy()) @ rhs[i, :2].numpy(),
                                           rtol=1e-10)
