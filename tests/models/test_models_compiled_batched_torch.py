"""models.torch.compiled.compile_batched: one AOTInductor library for every batch size gives the eager
numbers (float64) at batch sizes other than the one it was traced with, keeps the Euler-Lagrange
fallback (torch.cond under export: pinv where the velocity Hessian is singular) and refuses inputs of
another width or dtype; the HNN and the banded LGN (hand-written derivatives) export too. Each compile
takes 10-25 s: three in the default run, the model case is slow."""
import numpy as np
import pytest
import torch

import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.models.torch.compiled import compile_batched

RNG = np.random.default_rng(3)


def _lnn(**kw):
    spec = ModelSpec(kind="lnn", dof=2, hidden=(16, 16), dtype="float64", init="xavier", formulation="fast", **kw)
    return spec, init_params(spec, seed=2)


def test_any_batch_size_and_the_singular_fallback():
    """An LNN blind to qdot (first-layer velocity weights zero): its velocity Hessian is 0, every sample
    takes the pinv branch (q'' = pinv(0) rhs = 0); without that branch the guarded solve would return rhs."""
    spec, params = _lnn()
    params["mlp.0.weight"][:, 2:] = 0.0
    m = lagbench.models.torch.build(spec, params)
    f = compile_batched(m.acceleration, n_inputs=2, width=2, dtype="float64", name="acceleration")
    for b in (1, 5, 37):
        q, qdot = (torch.tensor(RNG.uniform(-2, 2, (b, 2))) for _ in range(2))
        with torch.no_grad():
            want, n_bad = m.acceleration_info(q, qdot)
            rhs = m._fast_terms(q, qdot)[1]
        assert int(n_bad) == b and rhs.abs().min() > 0
        got = f(q, qdot)
        np.testing.assert_allclose(got.numpy(), want.numpy(), rtol=0, atol=1e-12)
        np.testing.assert_allclose(got.numpy(), 0.0, atol=1e-12)
    with pytest.raises(ValueError, match=r"input 1: compiled for a \(batch, 2\) torch.float64"):
        f(q, torch.zeros(3, 3, dtype=torch.float64))
    with pytest.raises(ValueError, match="input 0.*float32"):
        f(q.float(), qdot)
    with pytest.raises(ValueError, match="n_inputs >= 1"):
        compile_batched(m.acceleration, n_inputs=0, width=2)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["delan", "lnn"])
def test_model_acceleration_any_batch(kind):
    spec = ModelSpec(kind=kind, dof=2, hidden=(16, 16), dtype="float64", init="xavier")
    m = lagbench.models.torch.build(spec, init_params(spec, seed=2))
    f = compile_batched(m.acceleration, n_inputs=2, width=2, dtype="float64")
    for b in (1, 64):
        q, qdot = (torch.tensor(RNG.uniform(-1, 1, (b, 2))) for _ in range(2))
        with torch.no_grad():
            want = m.acceleration(q, qdot)
        np.testing.assert_allclose(f(q, qdot).numpy(), want.numpy(), rtol=1e-10, atol=1e-12)


@pytest.mark.slow   # slow: 15 s of compiling; what it builds serves the HNN rollouts that compile their step (slow too)
def test_hnn_exports_and_matches_the_autograd_gradient():
    """The HNN's hand-written input gradient goes through torch.export (torch.func.grad did not); the
    compiled (dH/dy, -dH/dx) matches autograd's gradient of the eager Hamiltonian at any batch size."""
    spec = ModelSpec(kind="hnn", dof=2, hidden=(16, 16), dtype="float64", init="xavier", angle_wrap=True,
                     input_scale=(0.5, 2.0, 1.5, 0.1))
    m = lagbench.models.torch.build(spec, init_params(spec, seed=2))
    f = compile_batched(m.time_derivative, n_inputs=2, width=2, dtype="float64", name="time_derivative")
    for b in (1, 9):
        x, y = (torch.tensor(RNG.uniform(-4, 4, (b, 2)), requires_grad=True) for _ in range(2))
        dh_dx, dh_dy = torch.autograd.grad(m.hamiltonian(x, y).sum(), (x, y))
        xdot, ydot = f(x.detach(), y.detach())
        np.testing.assert_allclose(xdot.numpy(), dh_dy.numpy(), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(ydot.numpy(), -dh_dx.numpy(), rtol=1e-12, atol=1e-12)


@pytest.mark.slow   # slow: the speed study's AOT path, 30-50 s of compiling; its lighter siblings stay in the default run
def test_banded_lgn_exports_and_keeps_its_fallback():
    """The banded LGN (hand-written node derivatives, O(n) solve) exports; under export its fallback
    takes pinv on the gathered bad samples only. A batch with one non-finite state: the good samples
    equal eager, the bad one is NaN (as in eager), also at batch 1."""
    spec = ModelSpec(kind="lgn", dof=10, hidden=(16, 16), dtype="float64", init="xavier", formulation="banded")
    m = lagbench.models.torch.build(spec, init_params(spec, seed=2))
    f = compile_batched(m.acceleration, n_inputs=2, width=10, dtype="float64", name="acceleration")
    for b in (1, 6):
        q, qdot = (torch.tensor(RNG.uniform(-1, 1, (b, 10))) for _ in range(2))
        if b > 1:
            q[2, 4] = float("nan")
        with torch.no_grad():
            want, n_bad = m.acceleration_info(q, qdot)
        assert int(n_bad) == (b > 1)
        np.testing.assert_allclose(f(q, qdot).numpy(), want.numpy(), rtol=1e-10, atol=1e-12)  # NaN == NaN
