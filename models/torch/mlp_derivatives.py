"""Hand-written input gradient and tangent-projected Hessian of a scalar MLP (PyTorch), for the fast LNN
and the HNN.

`input_grad_and_tangent_hessian(params, x, tangents, spec, prefix="mlp", rows=None) -> (g (B, n_in), G (B, R, T))`
  f(x) = mlp(params, x, spec, prefix)[..., 0] (last layer linear, its first output), x (B, n_in),
  tangents (B, T, n_in). g[b] = df/dx at x[b] (the reverse pass); G[b, s, t] = v_s^T (d^2 f/dx^2) v_t
  with v_s = tangents[b, s]: the Hessian of f in the tangents' span, e.g. the forward-mode derivative of
  g along v_t, read in direction v_s (what forward-over-reverse gives, projected). Only the first R = rows
  tangents are read as v_s (all T when rows is None): the LNN and LGN need the Hessian's columns and
  the mixed term, never the mixed tangent's own row.
  tangents=None gives (g, None): the reverse pass alone (the HNN's dH/dx).
  Stacked members (`models.torch.build.build_stacked`): weights (K, out, in), biases (K, out), x (K, B, n_in),
  tangents (K, B, T, n_in) give g (K, B, n_in), G (K, B, R, T); every product becomes one batched product
  over the K members (`torch.baddbmm` / `torch.bmm`), no torch.func.vmap.
How: with a_i = W_i h_(i-1) + b_i, h_i = act(a_i) and g_i = df/dh_i, the Hessian of an MLP is exactly
  d^2 f/dx^2 = sum_i J_i^T diag(g_i * act''(a_i)) J_i,   J_i = da_i/dx,
so one forward-mode pass (J_i v_t for the T tangents, a leading batch dimension after B: every layer is
ONE (B*T, width) @ W^T product) plus the primal reverse pass (B rows) give G: no reverse-mode pass of the
tangents, half the large products of forward-over-reverse. Each layer's Gram term is an elementwise product summed
over the width, not a batched matrix product: torch.bmm of B tiny (R, w) @ (w, T) blocks runs one small
GEMM per sample (the full double-pendulum LNN's training step, 3 x 128 at batch 256, one thread: 15.5 ms
median with bmm over all T rows, 13.2 ms with this product over R = T - 1; interleaved rounds). Activation derivatives are closed forms
(`ACT_DERIVS`). Everything is ordinary differentiable torch ops: autograd gives the parameter gradients
of anything built on it. Same values as torch.func / jax forward-over-reverse, up to rounding.
"""
from __future__ import annotations

import torch

from lagbench.models.params import n_layers
from lagbench.models.torch.mlp import linear, softplus_given_sigmoid


def _softplus(a):
    s = torch.sigmoid(a)
    return softplus_given_sigmoid(a, s), s, torch.addcmul(s, s, s, value=-1.0)


def _relu(a):
    return torch.relu(a), (a > 0).to(a.dtype), torch.zeros_like(a)


def _relu2(a):
    r = torch.relu(a)
    return r * r, 2.0 * r, 2.0 * (a > 0).to(a.dtype)


def _relu3(a):
    r = torch.relu(a)
    r2 = r * r
    return r2 * r, 3.0 * r2, 6.0 * r


def _tanh(a):
    t = torch.tanh(a)
    s1 = 1.0 - t * t
    return t, s1, -2.0 * t * s1


def _sigmoid(a):
    s = torch.sigmoid(a)
    s1 = s * (1.0 - s)
    return s, s1, s1 * (1.0 - 2.0 * s)


# activation name -> a (...) -> (act(a), act'(a), act''(a)), each shaped like a
ACT_DERIVS = {"softplus": _softplus, "relu": _relu, "relu2": _relu2, "relu3": _relu3,
              "tanh": _tanh, "sigmoid": _sigmoid}


def _tangent_product(dh, w):
    """dh @ w^T for tangents dh (B, T, in) (one (B*T, in) product), or (K, B, T, in) with w (K, out, in)."""
    if w.dim() == 2:
        return dh @ w.T
    return torch.bmm(dh.flatten(1, 2), w.mT).view(*dh.shape[:-1], w.shape[-2])


def input_grad_and_tangent_hessian(params: dict, x, tangents, spec, prefix: str = "mlp", rows=None):
    """(g = df/dx (B, n_in), G (B, R, T) with G[b, s, t] = tangents[b, s] . Hessian(f)(x[b]) tangents[b, t]
    for s < R = rows (T when None)), G None when tangents is None; with stacked members a leading K on every
    shape; see the module docstring."""
    derivs, n = ACT_DERIVS[spec.activation], n_layers(spec)
    weights = [params[f"{prefix}.{i}.weight"] for i in range(n)]
    h, dh, saved = x, tangents, []
    for i in range(n - 1):                       # forward: primal (B, w) and tangents (B, T, w)
        a = linear(params, f"{prefix}.{i}", h)   # one model or stacked members, as the MLP itself
        h, s1, s2 = derivs(a)
        if dh is None:
            saved.append((s1, None, None))
            continue
        da = _tangent_product(dh, weights[i])    # J_i tangents
        if i < n - 2:
            dh = s1.unsqueeze(-2) * da
        saved.append((s1, s2, da))
    g, gram = weights[n - 1][..., :1, :], None   # g = df/dh of the last hidden layer, (1, w) or (K, 1, w)
    for i in reversed(range(n - 1)):             # reverse pass; each layer adds da^T diag(g act'') da
        s1, s2, da = saved[i]
        if da is not None:
            left = da[..., :rows, :] * (g * s2).unsqueeze(-2)
            term = torch.sum(left.unsqueeze(-2) * da.unsqueeze(-3), -1)
            gram = term if gram is None else gram + term
        g = (g * s1) @ weights[i]
    return g, gram
