"""MLP pieces in PyTorch: the activation table's translation, the MLP, the input features.

mlp(params, x, spec, prefix="mlp", final_linear=True): x (..., n_in) -> (..., n_out) with the layers
"{prefix}.{i}.weight" (out, in) / ".bias" (out,), activation after every layer but the last (after every
layer too when final_linear=False). Mirrors `models.jax.mlp`.
The MLP's q part (`ModelSpec.periodic`, `angle_wrap`): q_features(spec, q) (..., d) -> (..., spec.q_width()),
each coordinate k in order as q_k (wrapped with angle_wrap) or, for k in spec.periodic, (cos q_k, sin q_k);
for the hand-written chain rules its tangent q_features_jvp(spec, q, v) = (dq_features/dq) v (..., q_width)
and its transpose q_features_vjp(spec, q, g) = (dq_features/dq)^T g (..., d); q and v broadcast.
"""
from __future__ import annotations

import math

import torch

from lagbench.models.params import n_layers
from lagbench.models.torch.export_paths import pick


class _Softplus(torch.autograd.Function):
    """softplus(a) = logaddexp(a, 0) in one op whose derivative is the given s = sigmoid(a), itself part
    of the graph: every higher derivative is sigmoid's, finite everywhere (torch's own logaddexp
    double-backward is NaN for large negative a; JAX's is 0). Reverse, forward (jvp) and vmap all work,
    so the Hessians of `models.torch.lnn` / `lgn` go through it; half the ops of a where-based form."""
    generate_vmap_rule = True

    @staticmethod
    def forward(a, s):
        return torch.logaddexp(a, torch.zeros((), dtype=a.dtype, device=a.device))

    @staticmethod
    def setup_context(ctx, inputs, output):
        ctx.save_for_backward(inputs[1])
        ctx.save_for_forward(inputs[1])

    @staticmethod
    def backward(ctx, grad):
        (s,) = ctx.saved_tensors
        return grad * s, None

    @staticmethod
    def jvp(ctx, a_t, s_t):
        (s,) = ctx.saved_tensors
        return a_t * s


def _plain_softplus(x, s):
    return torch.logaddexp(x, torch.zeros((), dtype=x.dtype, device=x.device))


def softplus_given_sigmoid(x, s):
    """softplus(x), with s = sigmoid(x) already computed (see `_Softplus`). Under torch.compile the plain
    logaddexp (torch 2.13's dynamo cannot capture a Function with a jvp rule; the compiled training losses
    take first derivatives only, and inductor fuses the recomputed sigmoid)."""
    return pick(_Softplus.apply, compiled=_plain_softplus)(x, s)


def softplus(x):
    """log(1 + e^x) with derivatives of every order finite (see `_Softplus`)."""
    return softplus_given_sigmoid(x, torch.sigmoid(x))


ACT = {
    "softplus": softplus,
    # torch.relu, not clamp(x, min=0): its slope at 0 is 0, as jax.nn.relu's (clamp's is 1)
    "relu": torch.relu,
    "relu2": lambda x: torch.relu(x) ** 2,
    "relu3": lambda x: torch.relu(x) ** 3,
    "tanh": torch.tanh,
    "sigmoid": torch.sigmoid,
}


def linear(params: dict, prefix: str, x):
    """x (..., in) -> (..., out); stacked members (weight (K, out, in)): x (K, ..., in) -> (K, ..., out)."""
    w, b = params[f"{prefix}.weight"], params[f"{prefix}.bias"]
    if w.dim() == 2:
        return torch.nn.functional.linear(x, w, b)
    return torch.baddbmm(b.unsqueeze(-2), x.flatten(1, -2), w.mT).view(*x.shape[:-1], w.shape[-2])


def mlp(params: dict, x, spec, prefix: str = "mlp", final_linear: bool = True):
    """The spec's MLP on x (..., n_in) -> (..., n_out)."""
    act, n = ACT[spec.activation], n_layers(spec)
    for i in range(n):
        x = linear(params, f"{prefix}.{i}", x)
        if i < n - 1 or not final_linear:
            x = act(x)
    return x


def wrap_angles(spec, q):
    """q (..., d) -> q wrapped to [-pi, pi) if spec.angle_wrap, else q."""
    if not spec.angle_wrap:
        return q
    return torch.remainder(q + math.pi, 2 * math.pi) - math.pi


def q_features(spec, q):
    """q (..., d) -> the MLP's q part (..., d + len(spec.periodic)); see the module docstring."""
    if not spec.periodic:
        return wrap_angles(spec, q)
    cols = []
    for k in range(q.shape[-1]):
        qk = q[..., k:k + 1]
        cols += [torch.cos(qk), torch.sin(qk)] if k in spec.periodic else [qk]
    return torch.cat(cols, dim=-1)


def q_features_jvp(spec, q, v):
    """(dq_features/dq) v (..., d + len(spec.periodic)) for q, v (..., d) (wrapping has slope 1)."""
    if not spec.periodic:
        return v
    v = v.expand(torch.broadcast_shapes(q.shape, v.shape))
    cols = []
    for k in range(q.shape[-1]):
        qk, vk = q[..., k:k + 1], v[..., k:k + 1]
        cols += [-torch.sin(qk) * vk, torch.cos(qk) * vk] if k in spec.periodic else [vk]
    return torch.cat(cols, dim=-1)


def q_features_vjp(spec, q, g):
    """(dq_features/dq)^T g (..., d) for q (..., d), g (..., d + len(spec.periodic)) on the q part's slots."""
    if not spec.periodic:
        return g
    cols, i = [], 0
    for k in range(q.shape[-1]):
        if k in spec.periodic:
            qk = q[..., k:k + 1]
            cols.append(torch.cos(qk) * g[..., i + 1:i + 2] - torch.sin(qk) * g[..., i:i + 1])
            i += 2
        else:
            cols.append(g[..., i:i + 1])
            i += 1
    return torch.cat(cols, dim=-1)


def input_scale(spec, n: int, dtype, device=None):
    """spec.input_scale as an (n,) tensor, ones when it is None (for the chain rule of hand-written
    derivatives: the MLP sees x = scale * features)."""
    if spec.input_scale is None:
        return torch.ones(n, dtype=dtype, device=device)
    return torch.tensor(spec.input_scale, dtype=dtype, device=device)


def mlp_input(spec, parts: list):
    """Concatenate the feature parts (each (..., k)) and apply spec.input_scale: (..., n_in)."""
    x = torch.cat(parts, dim=-1)
    if spec.input_scale is not None:
        x = x * torch.tensor(spec.input_scale, dtype=x.dtype, device=x.device)
    return x
