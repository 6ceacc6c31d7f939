"""Hand-written input gradient and tangent-projected Hessian of a scalar MLP (JAX), for the fast LNN.
Mirrors `models.torch.mlp_derivatives` line for line (see its docstring for the formula).

`input_grad_and_tangent_hessian(params, x, tangents, spec, prefix="mlp", rows=None) -> (g (B, n_in), G (B, R, T))`
  f(x) = mlp(params, x, spec, prefix)[..., 0]; x (B, n_in), tangents (B, T, n_in);
  g[b] = df/dx at x[b]; G[b, s, t] = v_s^T (d^2 f/dx^2) v_t with v_s = tangents[b, s], s < R = rows (T when
  None). The Gram term stays an einsum here: XLA runs it, the broadcast product and the full T rows at one
  speed (the full double-pendulum LNN's step, one thread, interleaved: 9.1-9.3 ms each).
  d^2 f/dx^2 = sum_i J_i^T diag(g_i * act''(a_i)) J_i, J_i = da_i/dx: one forward pass carrying the T
  tangents (each layer ONE (B*T, width) @ W^T product) plus the primal reverse pass. Measured against
  XLA's forward-over-reverse (`models.jax.lnn.fast_terms`), which it equals up to rounding.
Activation derivatives (act, act', act'') by nested elementwise jvp (`models.jax.mlp.act_derivs`).
"""
from __future__ import annotations

import jax.numpy as jnp

from lagbench.models.jax.mlp import act_derivs
from lagbench.models.params import n_layers


def input_grad_and_tangent_hessian(params: dict, x, tangents, spec, prefix: str = "mlp", rows=None):
    """(g = df/dx (B, n_in), G (B, R, T), read in the first R = rows tangents, T when None); see the module
    docstring."""
    n = n_layers(spec)
    weights = [params[f"{prefix}.{i}.weight"] for i in range(n)]
    h, dh, saved = x, tangents, []
    for i in range(n - 1):                       # forward: primal (B, w) and tangents (B, T, w)
        a = h @ weights[i].T + params[f"{prefix}.{i}.bias"]
        da = dh @ weights[i].T                   # J_i tangents
        h, s1, s2 = act_derivs(spec.activation, a)
        if i < n - 2:
            dh = s1[:, None, :] * da
        saved.append((s1, s2, da))
    g, gram = weights[n - 1][0], None            # g = df/dh of the last hidden layer
    for i in reversed(range(n - 1)):             # reverse pass; each layer adds da^T diag(g act'') da
        s1, s2, da = saved[i]
        term = jnp.einsum("btw,bsw->bts", da[:, :rows] * (g * s2)[:, None, :], da)
        gram = term if gram is None else gram + term
        g = (g * s1) @ weights[i]
    return g, gram
