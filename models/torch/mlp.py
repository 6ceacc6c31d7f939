"""MLP pieces in PyTorch: the activation table's translation, the MLP, the input features.

mlp(params, x, spec, prefix="mlp", final_linear=True): x (..., n_in) -> (..., n_out) with the layers
"{prefix}.{i}.weight" (out, in) / ".bias" (out,), activation after every layer but the last (after every
layer too when final_linear=False). Mirrors `models.jax.mlp`.
"""
from __future__ import annotations

import math

import torch

from models.params import n_layers


def softplus(x):
    """log(1 + e^x) as logaddexp(x, 0) computes it, but with derivatives of every order finite:
    torch's logaddexp double-backward is NaN for large negative x (JAX's is 0). Each branch only
    sees inputs of the sign it is valid for, so the unselected branch's gradient is 0, not NaN."""
    pos = x > 0
    zero = torch.zeros_like(x)
    return torch.where(pos, x + torch.log1p(torch.exp(-torch.where(pos, x, zero))),
                       torch.log1p(torch.exp(torch.where(pos, zero, x))))


ACT = {
    "softplus": softplus,
    "relu": lambda x: torch.clamp(x, min=0.0),
    "relu2": lambda x: torch.clamp(x, min=0.0) ** 2,
    "relu3": lambda x: torch.clamp(x, min=0.0) ** 3,
    "tanh": torch.tanh,
    "sigmoid": torch.sigmoid,
}


def linear(params: dict, prefix: str, x):
    """x (..., in) -> (..., out)."""
    return x @ params[f"{prefix}.weight"].T + params[f"{prefix}.bias"]


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


def mlp_input(spec, parts: list):
    """Concatenate the feature parts (each (..., k)) and apply spec.input_scale: (..., n_in)."""
    x = torch.cat(parts, dim=-1)
    if spec.input_scale is not None:
        x = x * torch.tensor(spec.input_scale, dtype=x.dtype)
    return x
