"""models.torch.compiled.compile_batched(..., flatten=True): the models that differentiate with torch.func
(the paper-formulation LNN, the dense LGN), which torch.export refuses, are traced into ATen operators by
make_fx (`trace_flat`) and then export and compile for one batch size, giving the eager numbers (float64);
the traced fast Euler-Lagrange solve keeps its pinv fallback without a Python branch on data. Two compiles
(10-25 s each)."""
import numpy as np
import pytest
import torch

import lagbench.models.torch
from lagbench.models import ModelSpec, init_params
from lagbench.models.graph import periodic_neighbours
from lagbench.models.torch.compiled import compile_batched, trace_flat
from lagbench.models.torch.lgn import _neighbours
from lagbench.models.torch.lnn import solve_with_fallback
from lagbench.speedstudy.evaluators import make_evaluator

RNG = np.random.default_rng(5)


def _states(b, d):
    return (torch.tensor(RNG.uniform(-2, 2, (b, d))) for _ in range(2))


@pytest.mark.slow   # slow: a speed-study compile path (`lagbench bench`'s quick preset); the paths verdicts use stay in the default run
@pytest.mark.parametrize("kind, form, dof", [("lnn", "paper", 2), ("lgn", "dense", 8)])
def test_torch_func_models_compile_once_traced(kind, form, dof):
    spec = ModelSpec(kind=kind, dof=dof, hidden=(16, 16), dtype="float64", init="xavier", formulation=form)
    m = lagbench.models.torch.build(spec, init_params(spec, seed=1))
    with pytest.raises(Exception):  # noqa: B017 - what torch.export raises on torch.func is torch's to name
        compile_batched(m.acceleration, 2, dof, "float64", batch=3)
    f = compile_batched(m.acceleration, 2, dof, "float64", batch=3, flatten=True)
    q, qdot = _states(3, dof)
    with torch.no_grad():
        want = m.acceleration(q, qdot)
    np.testing.assert_allclose(f(q, qdot).numpy(), want.numpy(), rtol=1e-9, atol=1e-9)
    with pytest.raises(ValueError, match=r"compiled for a \(3, " + str(dof)):
        f(*_states(4, dof))


def test_traced_solve_keeps_the_pinv_fallback():
    """One singular Hessian in the batch: the traced graph (no Python branch) gives pinv's answer there
    and the plain solve elsewhere, as eager does; the graph holds no data-dependent branch."""
    hess = torch.tensor(RNG.normal(size=(4, 2, 2)))
    hess = hess @ hess.mT + torch.eye(2)
    hess[1] = torch.tensor([[1.0, 1.0], [1.0, 1.0]])
    rhs = torch.tensor(RNG.normal(size=(4, 2)))
    want, n_bad = solve_with_fallback(hess, rhs)
    assert int(n_bad) == 1
    graph = trace_flat(lambda h, r: solve_with_fallback(h, r)[0], (hess, rhs))
    np.testing.assert_allclose(graph(hess, rhs).numpy(), want.numpy(), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(want[1].numpy(), torch.linalg.pinv(hess[1]).numpy() @ rhs[1].numpy(), rtol=1e-12)


def test_roll_neighbours_are_the_periodic_gather():
    x = torch.tensor(RNG.normal(size=(3, 11)))
    for r in (1, 2, 3):
        assert torch.equal(_neighbours(x, r), x[..., torch.as_tensor(periodic_neighbours(11, r))])


def test_flatten_needs_a_batch_and_traced_mode_is_for_torch_models():
    with pytest.raises(ValueError, match="give batch"):
        compile_batched(lambda q, qd: q, 2, 2, flatten=True)
    spec = ModelSpec(kind="lnn", dof=2, hidden=(8,), dtype="float64", formulation="paper")
    with pytest.raises(ValueError, match="mode 'traced' is for PyTorch models"):
        make_evaluator("jax", spec, init_params(spec, seed=0), kind="lnn", mode="traced")
