"""Initialisation, in NumPy only: `init_params(spec, seed) -> dict[str, np.ndarray]`.

One generator `np.random.default_rng(seed)` draws the layers in `models.params.layer_table` order
(weight, then bias where the scheme draws one), in float64, then casts to spec.dtype.

Schemes (n_in = fan_in, n_out = fan_out of a weight of shape (n_out, n_in)):
  cranmer2020      the LNN code's `custom_init`: biases 0; W ~ N(0, s^2) with n = max(W.shape) and
                   s = 2.2/sqrt(n) for the first layer, 0.58*i/sqrt(n) for hidden layer i = 1, 2, ...
                   (i = the weight matrix's 0-based index), sqrt(n) (= n/sqrt(n)) for the output layer.
                   DeLaN: the trunk's layers are first/hidden (the trunk has no output layer); each head
                   (lower, diag, potential) is an output layer (s = sqrt(n)), as the formula would treat a
                   final Linear -- far too large for a mass matrix; use "xavier" for DeLaN.
  pytorch_default  torch.nn.Linear: W ~ U(+-1/sqrt(n_in)) (kaiming_uniform, a = sqrt 5), b ~ U(+-1/sqrt(n_in)).
  xavier           W ~ N(0, 2/(n_in + n_out)) (gain 1), biases 0. Heads alike.
  kaiming          W ~ N(0, 2/n_in) (fan_in, ReLU gain), biases 0. Heads alike.
For DeLaN the diagonal is softplus(raw + spec.own.diag_offset), so zero biases give
diag(L) ~ softplus(offset) at init.
"""
from __future__ import annotations

import numpy as np

from lagbench.models.params import layer_table
from lagbench.models.spec import USER_KIND, ModelSpec


def _cranmer_std(role: str, index: int, shape: tuple) -> float:
    n = max(shape)
    if role == "output":
        return n / np.sqrt(n)
    if role == "first":
        return 2.2 / np.sqrt(n)
    return 0.58 * index / np.sqrt(n)


def _draw(rng, scheme: str, role: str, index: int, fan_in: int, fan_out: int):
    shape = (fan_out, fan_in)
    if scheme == "cranmer2020":
        return rng.normal(0.0, _cranmer_std(role, index, shape), shape), np.zeros(fan_out)
    if scheme == "pytorch_default":
        bound = 1.0 / np.sqrt(fan_in)
        w = rng.uniform(-bound, bound, shape)
        return w, rng.uniform(-bound, bound, fan_out)
    if scheme == "xavier":
        return rng.normal(0.0, np.sqrt(2.0 / (fan_in + fan_out)), shape), np.zeros(fan_out)
    if scheme == "kaiming":
        return rng.normal(0.0, np.sqrt(2.0 / fan_in), shape), np.zeros(fan_out)
    raise ValueError(f"unknown init {scheme!r}")


DISSIPATION_INIT = 0.01   # the Rayleigh coefficients' start, b = softplus(raw): small, so training sets them


def init_params(spec: ModelSpec, seed: int = 0) -> dict:
    """Fresh parameters in the `models.params` layout, dtype spec.dtype. Same seed, same numbers."""
    if spec.kind == USER_KIND:
        from lagbench.models import user

        return user.init_params(spec, seed)
    rng = np.random.default_rng(seed)
    out = {}
    for index, (prefix, fan_in, fan_out, role) in enumerate(layer_table(spec)):
        w, b = _draw(rng, spec.init, role, index, fan_in, fan_out)
        out[f"{prefix}.weight"] = w.astype(spec.dtype)
        out[f"{prefix}.bias"] = b.astype(spec.dtype)
    if spec.dissipation:   # not drawn: every coordinate starts at b = DISSIPATION_INIT
        out["dissipation.raw"] = np.full(spec.dof, np.log(np.expm1(DISSIPATION_INIT)), dtype=spec.dtype)
    return out
