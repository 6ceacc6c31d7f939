"""Hand-written input gradient and tangent-projected Hessian of a scalar MLP (PyTorch), for the fast LNN
and the HNN.

`input_grad_and_tangent_hessian(params, x, tangents, spec, prefix="mlp") -> (g (B, n_in), G (B, T, T))`
  f(x) = mlp(params, x, spec, prefix)[..., 0] (last layer linear, its first output), x (B, n_in),
  tangents (B, T, n_in). g[b] = df/dx at x[b] (the reverse pass); G[b, s, t] = v_s^T (d^2 f/dx^2) v_t
  with v_s = tangents[b, s]: the Hessian of f in the tangents' span, e.g. the forward-mode derivative of
  g along v_t, read in direction v_s (what forward-over-reverse gives, projected).
  tangents=None gives (g, None): the reverse pass alone (the HNN's dH/dx).
How: with a_i = W_i h_(i-1) + b_i, h_i = act(a_i) and g_i = df/dh_i, the Hessian of an MLP is exactly
  d^2 f/dx^2 = sum_i J_i^T diag(g_i * act''(a_i)) J_i,   J_i = da_i/dx,
so one forward-mode pass (J_i v_t for the T tangents, a leading batch dimension after B: every layer is
ONE (B*T, width) @ W^T product) plus the primal reverse pass (B rows) give G: no reverse-mode pass of the
tangents, half the large products of forward-over-reverse. Activation derivatives are closed forms
(`ACT_DERIVS`). Everything is ordinary differentiable torch ops: autograd gives the parameter gradients
of anything built on it. Same values as torch.func / jax forward-over-reverse, up to rounding.
"""
from __future__ import annotations

import torch

from models.params import n_layers
from models.torch.mlp import softplus_given_sigmoid


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


def input_grad_and_tangent_hessian(params: dict, x, tangents, spec, prefix: str = "mlp"):
    """(g = df/dx (B, n_in), G (B, T, T) with G[b, s, t] = tangents[b, s] . Hessian(f)(x[b]) tangents[b, t]),
    G None when tangents is None; see the module docstring."""
    derivs, n = ACT_DERIVS[spec.activation], n_layers(spec)
    weights = [params[f"{prefix}.{i}.weight"] for i in range(n)]
    h, dh, saved = x, tangents, []
    for i in range(n - 1):                       # forward: primal (B, w) and tangents (B, T, w)
        a = torch.addmm(params[f"{prefix}.{i}.bias"], h, weights[i].T)
        h, s1, s2 = derivs(a)
        if dh is None:
            saved.append((s1, None, None))
            continue
        da = dh @ weights[i].T                   # J_i tangents: one (B*T, in) @ (in, w) product
        if i < n - 2:
            dh = s1[:, None, :] * da
        saved.append((s1, s2, da))
    g, gram = weights[n - 1][0], None            # g = df/dh of the last hidden layer
    for i in reversed(range(n - 1)):             # reverse pass; each layer adds da^T diag(g act'') da
        s1, s2, da = saved[i]
        if da is not None:
            term = torch.bmm(da * (g * s2)[:, None, :], da.transpose(1, 2))
            gram = term if gram is None else gram + term
        g = (g * s1) @ weights[i]
    return g, gram
