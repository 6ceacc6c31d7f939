"""The banded LGN path is differentiated implicitly: its float32 parameter gradients match the dense
path's (differentiating through the unpivoted block elimination gave gradients off by over 100 %)."""
import equinox as eqx
import jax.numpy as jnp
import numpy as np
import pytest
import torch

import lagbench.models.jax
import lagbench.models.torch
from lagbench import systems
from lagbench.models import ModelSpec, init_params


@pytest.mark.parametrize("dtype, rtol", [("float64", 1e-10), ("float32", 2e-3)])
def test_banded_gradients_match_dense(dtype, rtol):
    s = systems.get("wave", n=10, variant="code")
    st = s.sample_states(16, np.random.default_rng(0))
    tgt = s.acceleration(st["q"], st["qdot"])
    grads = {}
    for form in ("dense", "banded"):
        spec = ModelSpec(kind="lgn", dof=10, hidden=(32, 32, 32), dtype=dtype, formulation=form)
        m = lagbench.models.jax.build(spec, init_params(spec, 0))
        q, qd, t = (jnp.asarray(x, dtype) for x in (st["q"], st["qdot"], tgt))
        def loss(m, q=q, qd=qd, t=t):
            return jnp.mean(jnp.sum(jnp.abs(m.acceleration(q, qd) - t), -1))

        g = eqx.filter_grad(loss)(m)
        grads[form] = lagbench.models.jax.to_params(g)
        if form == "banded":
            mt = lagbench.models.torch.build(spec, init_params(spec, 0))
            qt, qdt, tt = (torch.as_tensor(x, dtype=getattr(torch, dtype)) for x in (st["q"], st["qdot"], tgt))
            (mt.acceleration(qt, qdt) - tt).abs().sum(-1).mean().backward()
            grads["torch"] = {k: (v.grad if v.grad is not None else torch.zeros_like(v)).numpy()
                              for k, v in mt.named_parameters()}
    for k, ref in grads["dense"].items():
        scale = np.max(np.abs(ref)) + 1e-30
        assert np.max(np.abs(grads["banded"][k] - ref)) <= rtol * scale, k
        assert np.max(np.abs(grads["torch"][k] - ref)) <= rtol * scale, k
