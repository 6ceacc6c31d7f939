"""Appendix B (claim 5): the exact free-fall Lagrangian through each framework's Euler-Lagrange step.

The SymPy Lagrangian of the system is turned into a per-sample function of (q, qdot) made of plain
arithmetic (so the same function runs on JAX arrays and PyTorch tensors) and handed to
`models.<framework>.lnn.euler_lagrange` in the formulation the model entry names, in float64.
"""
from __future__ import annotations

import numpy as np
import sympy as sp

from lagbench.replication.evaluation.routines import Evaluation, system_of


def lagrangian_callable(s):
    subs = {x: s.params[x.name] for x in s.lagrangian.free_symbols if x.name in s.params}
    f = sp.lambdify([*s.q_symbols, *s.qdot_symbols], s.lagrangian.subs(subs), modules=[{}])
    d = s.dof
    return lambda q, qdot: f(*[q[..., i] for i in range(d)], *[qdot[..., i] for i in range(d)]) + 0 * q[..., 0]


def eval_exact_lagrangian(ctx) -> Evaluation:
    s = system_of(ctx.protocol)
    rng = np.random.default_rng(ctx.split.draw_offset)
    st = s.sample_states(ctx.protocol.data.n_heldout, rng)
    q, qdot = st["q"], st["qdot"]
    L = lagrangian_callable(s)
    form = ctx.spec.own.formulation
    if ctx.framework == "jax":
        import jax.numpy as jnp

        from lagbench.models.jax.lnn import euler_lagrange
        qdd = np.asarray(euler_lagrange(L, jnp.asarray(q), jnp.asarray(qdot), form))
    else:
        import torch

        from lagbench.models.torch.lnn import euler_lagrange
        qdd = euler_lagrange(L, torch.as_tensor(q), torch.as_tensor(qdot), form).detach().cpu().numpy()
    truth = s.acceleration(q, qdot, backend="numpy")
    expected = np.broadcast_to(np.array([-float(s.params["g"]), 0.0]), qdd.shape)
    return Evaluation(metrics={"max_abs_err": float(np.max(np.abs(qdd - expected))),
                               "max_abs_err_vs_sympy": float(np.max(np.abs(qdd - truth)))})
