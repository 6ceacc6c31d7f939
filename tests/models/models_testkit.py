"""Shared helpers for the model tests: one dtype-keyed tolerance table, inputs, and the per-kind
prediction and L1 loss evaluated the same way in both frameworks."""
from __future__ import annotations

import equinox as eqx
import jax.numpy as jnp
import numpy as np
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench.models import ModelSpec, init_params

# relative tolerance, max|a - b| / max|b|, keyed by dtype (one table for every model test)
TOL = {"float64": 1e-10, "float32": 2e-4}


def assert_rel(a, b, dtype: str, what: str = "", factor: float = 1.0):
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    assert a.shape == b.shape, (what, a.shape, b.shape)
    assert np.all(np.isfinite(a)) and np.all(np.isfinite(b)), what
    scale = max(np.max(np.abs(b)), 1e-300)
    err = np.max(np.abs(a - b)) / scale
    assert err <= TOL[dtype] * factor, f"{what}: relative error {err:.3e} > {TOL[dtype] * factor:.1e}"


def make_inputs(spec: ModelSpec, batch: int = 16, seed: int = 0, n: int | None = None) -> dict:
    """NumPy inputs in spec.dtype: q, qdot (batch, d), extra (or None), target of the kind's output."""
    rng = np.random.default_rng(seed)
    d = n or spec.dof
    out = {"q": rng.uniform(-2, 2, (batch, d)), "qdot": rng.uniform(-1, 1, (batch, d)), "extra": None}
    if spec.extra_inputs:
        out["extra"] = rng.normal(size=(batch, spec.extra_inputs))
    if spec.kind == "delan":
        out["extra"] = rng.normal(size=(batch, d))          # tau for the forward model, qddot for inverse
    width = {"hnn": 2 * d, "delan": 2 * d, "baseline": spec.mlp_sizes()[-1]}.get(spec.kind, d)
    out["target"] = rng.normal(size=(batch, width))
    return {k: None if v is None else v.astype(spec.dtype) for k, v in out.items()}


def predict(model, kind: str, x: dict, cat):
    q, qdot, extra = x["q"], x["qdot"], x["extra"]
    if kind == "hnn":
        return cat(list(model.time_derivative(q, qdot, extra)), -1)
    if kind == "delan":
        return cat([model.inverse_dynamics(q, qdot, extra), model.acceleration(q, qdot, extra)], -1)
    return model.acceleration(q, qdot, extra)


def to_jax(x: dict) -> dict:
    return {k: None if v is None else jnp.asarray(v) for k, v in x.items()}


def to_torch(x: dict) -> dict:
    return {k: None if v is None else torch.tensor(v) for k, v in x.items()}


def jax_loss_and_grads(spec, params, x):
    """(prediction, {key: dloss/dparam}) with loss = mean over samples of sum |pred - target|."""
    def loss(model, xj):
        pred = predict(model, spec.kind, xj, jnp.concatenate)
        return jnp.mean(jnp.sum(jnp.abs(pred - xj["target"]), axis=-1)), pred

    step = eqx.filter_jit(eqx.filter_value_and_grad(loss, has_aux=True))
    (_, pred), grads = step(lagbench.models.jax.build(spec, params), to_jax(x))
    return np.asarray(pred), {k: np.asarray(v) for k, v in grads.params.items()}


def torch_loss_and_grads(spec, params, x):
    xt = to_torch(x)
    model = lagbench.models.torch.build(spec, params)
    pred = predict(model, spec.kind, xt, torch.cat)
    torch.mean(torch.sum(torch.abs(pred - xt["target"]), dim=-1)).backward()
    return pred.detach().numpy(), {k: np.zeros(tuple(p.shape)) if p.grad is None else p.grad.numpy()
                                  for k, p in model.named_parameters()}


def spec_params(seed: int = 0, **kw):
    kw.setdefault("hidden", (32, 32))
    spec = ModelSpec(**kw)
    return spec, init_params(spec, seed)
