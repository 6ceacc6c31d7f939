"""MLP pieces in JAX: the activation table's translation, the MLP, the input features.

mlp(params, x, spec, prefix="mlp", final_linear=True): x (..., n_in) -> (..., n_out) with the layers
"{prefix}.{i}.weight" (out, in) / ".bias" (out,), activation after every layer but the last (after every
layer too when final_linear=False). Mirrored by `models.torch.mlp`.
The MLP's q part (`ModelSpec.periodic`, `angle_wrap`): q_features(spec, q) (..., d) -> (..., spec.q_width()),
each coordinate k in order as q_k (wrapped with angle_wrap) or, for k in spec.periodic, (cos q_k, sin q_k);
for the hand-written chain rules its tangent q_features_jvp(spec, q, v) = (dq_features/dq) v (..., q_width)
and its transpose q_features_vjp(spec, q, g) = (dq_features/dq)^T g (..., d); q and v broadcast.
"""
from __future__ import annotations

import math

import jax
import jax.numpy as jnp

from lagbench.models.params import n_layers

ACT = {
    "softplus": lambda x: jnp.logaddexp(x, 0.0),
    # jax.nn.relu, not jnp.maximum(x, 0): its slope at 0 is 0, as torch.relu's (maximum splits a tie, 0.5)
    "relu": jax.nn.relu,
    "relu2": lambda x: jax.nn.relu(x) ** 2,
    "relu3": lambda x: jax.nn.relu(x) ** 3,
    "tanh": jnp.tanh,
    "sigmoid": jax.nn.sigmoid,
}


def act_and_slope(name: str, a):
    """(act(a), act'(a)), each shaped like a: the activation and its elementwise slope (one jvp)."""
    return jax.jvp(ACT[name], (a,), (jnp.ones_like(a),))


def act_derivs(name: str, a):
    """(act(a), act'(a), act''(a)), each shaped like a, by nested elementwise jvp."""
    ones = jnp.ones_like(a)
    (f, s1), (_, s2) = jax.jvp(lambda b: act_and_slope(name, b), (a,), (ones,))
    return f, s1, s2


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
    return jnp.mod(q + math.pi, 2 * math.pi) - math.pi


def q_features(spec, q):
    """q (..., d) -> the MLP's q part (..., d + len(spec.periodic)); see the module docstring."""
    if not spec.periodic:
        return wrap_angles(spec, q)
    cols = []
    for k in range(q.shape[-1]):
        qk = q[..., k:k + 1]
        cols += [jnp.cos(qk), jnp.sin(qk)] if k in spec.periodic else [qk]
    return jnp.concatenate(cols, axis=-1)


def q_features_jvp(spec, q, v):
    """(dq_features/dq) v (..., d + len(spec.periodic)) for q, v (..., d) (wrapping has slope 1)."""
    if not spec.periodic:
        return v
    v = jnp.broadcast_to(v, jnp.broadcast_shapes(q.shape, v.shape))
    cols = []
    for k in range(q.shape[-1]):
        qk, vk = q[..., k:k + 1], v[..., k:k + 1]
        cols += [-jnp.sin(qk) * vk, jnp.cos(qk) * vk] if k in spec.periodic else [vk]
    return jnp.concatenate(cols, axis=-1)


def q_features_vjp(spec, q, g):
    """(dq_features/dq)^T g (..., d) for q (..., d), g (..., d + len(spec.periodic)) on the q part's slots."""
    if not spec.periodic:
        return g
    cols, i = [], 0
    for k in range(q.shape[-1]):
        if k in spec.periodic:
            qk = q[..., k:k + 1]
            cols.append(jnp.cos(qk) * g[..., i + 1:i + 2] - jnp.sin(qk) * g[..., i:i + 1])
            i += 2
        else:
            cols.append(g[..., i:i + 1])
            i += 1
    return jnp.concatenate(cols, axis=-1)


def input_scale(spec, n: int, dtype):
    """spec.input_scale as an (n,) array, ones when it is None (for the chain rule of hand-written
    derivatives: the MLP sees x = scale * features)."""
    return jnp.ones(n, dtype=dtype) if spec.input_scale is None else jnp.asarray(spec.input_scale, dtype=dtype)


def mlp_input(spec, parts: list):
    """Concatenate the feature parts (each (..., k)) and apply spec.input_scale: (..., n_in)."""
    x = jnp.concatenate(parts, axis=-1)
    if spec.input_scale is not None:
        x = x * jnp.asarray(spec.input_scale, dtype=x.dtype)
    return x
