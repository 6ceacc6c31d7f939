"""JAX against PyTorch on identical parameters: outputs and the gradients of the L1 training loss with
respect to every parameter, to TOL[dtype] relative (float64 1e-10, float32 dtype-appropriate); every kind
that takes periodic angle features has a row with them, and the LNN has rows with its q-derivatives in the
scaled q (`Lnn.scale_q_before_grad`) and made even in qdot (`Lnn.even_velocity`)."""
import jax
import jax.numpy as jnp
import pytest
import torch
from models_testkit import (
    assert_rel,
    jax_loss_and_grads,
    make_inputs,
    spec_params,
    to_jax,
    to_torch,
    torch_loss_and_grads,
)

import lagbench.models.jax
import lagbench.models.torch

CASES = [
    ("baseline", {"activation": "relu"}),
    ("baseline", {"extra_inputs": 2, "init": "pytorch_default"}),
    ("lnn", {"formulation": "fast"}),
    ("lnn", {"formulation": "paper"}),
    ("lnn", {"formulation": "fast", "dissipation": True}),
    ("lnn", {"formulation": "fast", "extra_inputs": 1, "angle_wrap": True, "input_scale": (0.5, 2.0, 1.5, 0.1, 2.0)}),
    ("hnn", {"activation": "tanh"}),
    ("hnn", {"extra_inputs": 1, "angle_wrap": True, "input_scale": (0.5, 2.0, 1.5, 0.1, 2.0)}),
    ("delan", {"init": "xavier"}),
    ("delan", {"init": "xavier", "dissipation": True}),
    ("hnn", {"activation": "tanh", "dissipation": True}),
    ("lgn", {"formulation": "banded", "dof": 7}),
    ("lgn", {"formulation": "dense", "dof": 7}),
    # angles as cos and sin (`ModelSpec.periodic`)
    ("lnn", {"formulation": "fast", "periodic": (0,)}),
    ("lnn", {"formulation": "paper", "periodic": (0, 1)}),
    ("lnn", {"formulation": "fast", "periodic": (1,), "extra_inputs": 1, "dissipation": True,
             "input_scale": (0.5, 2.0, 1.5, 0.3, 1.1, 2.0)}),
    ("hnn", {"periodic": (0, 1), "extra_inputs": 1, "input_scale": (0.5, 2.0, 1.5, 0.7, 0.3, 1.1, 2.0)}),
    ("delan", {"init": "xavier", "periodic": (1,)}),
    ("baseline", {"periodic": (0,), "extra_inputs": 2}),
    # q-derivatives in the scaled q, the original code's convention (`Lnn.scale_q_before_grad`)
    ("lnn", {"formulation": "fast", "extra_inputs": 1, "scale_q_before_grad": True,
             "input_scale": (0.1, 0.5, 1.0, 1.0, 0.1)}),
    ("lnn", {"formulation": "paper", "extra_inputs": 1, "scale_q_before_grad": True,
             "input_scale": (0.1, 0.5, 1.0, 1.0, 0.1)}),
    ("lnn", {"formulation": "fast", "periodic": (0,), "dissipation": True, "scale_q_before_grad": True,
             "input_scale": (0.5, 2.0, 0.1, 1.5, 0.3)}),
    # a Lagrangian even in qdot (`Lnn.even_velocity`)
    ("lnn", {"formulation": "fast", "periodic": (0, 1), "dissipation": True, "even_velocity": True}),
    ("lnn", {"formulation": "paper", "extra_inputs": 1, "even_velocity": True}),
]
FLOAT32 = [0, 2, 4, 6, 8, 13, 16, 19, 22]


def _check(kind, kw, dtype):
    kw = {"dof": 2, "init": "cranmer2020"} | kw
    spec, params = spec_params(kind=kind, dtype=dtype, **kw)
    x = make_inputs(spec, batch=12, seed=1)
    pred_j, grads_j = jax_loss_and_grads(spec, params, x)
    pred_t, grads_t = torch_loss_and_grads(spec, params, x)
    assert_rel(pred_j, pred_t, dtype, f"{kind} prediction")
    assert grads_j.keys() == grads_t.keys() == params.keys()
    for k in params:
        assert_rel(grads_j[k], grads_t[k], dtype, f"{kind} dloss/d{k}")


@pytest.mark.parametrize("kind, kw", CASES, ids=[f"{k}-{kw.get('formulation', '')}{i}" for i, (k, kw) in enumerate(CASES)])
def test_float64_outputs_and_loss_gradients_agree(kind, kw):
    _check(kind, kw, "float64")


@pytest.mark.parametrize("kind, kw", [CASES[i] for i in FLOAT32], ids=[CASES[i][0] for i in FLOAT32])
def test_float32_outputs_and_loss_gradients_agree(kind, kw):
    _check(kind, kw, "float32")


def _jax_scalar_and_grads(fn, *args):
    val = fn(*args)
    grads = jax.grad(lambda *a: jnp.sum(fn(*a)), argnums=(0, 1))(*args)
    return [val, *grads]


def _torch_scalar_and_grads(fn, *args):
    args = [a.clone().requires_grad_(True) for a in args]
    val = fn(*args)
    grads = torch.autograd.grad(val.sum(), args)
    return [val.detach(), *grads]


@pytest.mark.parametrize("kind", ["lnn", "hnn", "delan", "lgn"])
def test_float64_energy_function_and_its_gradients_agree(kind):
    spec, params = spec_params(kind=kind, dof=5 if kind == "lgn" else 3, dtype="float64", init="xavier")
    x = make_inputs(spec, batch=6, seed=2)
    mj, mt = lagbench.models.jax.build(spec, params), lagbench.models.torch.build(spec, params)
    name = "hamiltonian" if kind == "hnn" else "lagrangian"
    xj, xt = to_jax(x), to_torch(x)
    got_j = _jax_scalar_and_grads(getattr(mj, name), xj["q"], xj["qdot"])
    got_t = _torch_scalar_and_grads(getattr(mt, name), xt["q"], xt["qdot"])
    for a, b, what in zip(got_j, got_t, ("value", "d/dq", "d/dqdot"), strict=True):
        assert_rel(a, b, "float64", f"{kind} {name} {what}")


def test_float64_velocity_hessian_and_delan_terms_agree():
    spec, params = spec_params(kind="lnn", dof=3, dtype="float64")
    x = make_inputs(spec, batch=6, seed=3)
    xj, xt = to_jax(x), to_torch(x)
    hj = lagbench.models.jax.build(spec, params).velocity_hessian(xj["q"], xj["qdot"])
    ht = lagbench.models.torch.build(spec, params).velocity_hessian(xt["q"], xt["qdot"])
    assert hj.shape == (6, 3, 3)
    assert_rel(hj, ht.detach(), "float64", "velocity Hessian")
    spec, params = spec_params(kind="delan", dof=3, dtype="float64", init="xavier")
    mj, mt = lagbench.models.jax.build(spec, params), lagbench.models.torch.build(spec, params)
    for name, args in [("mass_matrix", ("q",)), ("gravity", ("q",)), ("coriolis", ("q", "qdot")),
                       ("potential", ("q",)), ("lagrangian", ("q", "qdot"))]:
        a = getattr(mj, name)(*[xj[k] for k in args])
        b = getattr(mt, name)(*[xt[k] for k in args])
        assert_rel(a, b.detach(), "float64", f"delan {name}")


def test_float64_lgn_paper_formulation_agrees():
    spec, params = spec_params(kind="lgn", dof=6, dtype="float64", formulation="paper")
    x = make_inputs(spec, batch=4, seed=4)
    xj, xt = to_jax(x), to_torch(x)
    a = lagbench.models.jax.build(spec, params).acceleration(xj["q"], xj["qdot"])
    b = lagbench.models.torch.build(spec, params).acceleration(xt["q"], xt["qdot"])
    assert_rel(a, b.detach(), "float64", "lgn paper qddot")
