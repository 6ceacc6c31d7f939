"""The Lorentz factor as an MLP input feature (`ModelSpec.lorentz_factor`: an own field of the LNN and the HNN),
written once for both frameworks: only arithmetic that JAX arrays and PyTorch tensors share.

`velocity_parts(spec, qdot) -> [qdot]` or `[qdot, gamma(qdot)]`: the velocity's parts of the MLP input.
`lorentz_factor(v)`: gamma = (1 - v^2)^(-1/2) elementwise (c = 1). `lorentz_slopes(v)`: (gamma', gamma'') for
the hand-written chain rules of the LNN (`models.*.lnn`) and the PyTorch HNN.
"""
from __future__ import annotations


def velocity_parts(spec, qdot) -> list:
    """The MLP input parts of the velocity: [qdot], and [gamma(qdot)] after it with spec.lorentz_factor."""
    return [qdot, lorentz_factor(qdot)] if spec.lorentz_factor else [qdot]


def lorentz_factor(v):
    """gamma = (1 - v^2)^(-1/2) elementwise (c = 1)."""
    return (1 - v * v) ** -0.5


def lorentz_slopes(v):
    """(gamma'(v), gamma''(v)) elementwise: v gamma^3 and gamma^3 + 3 v^2 gamma^5."""
    g = lorentz_factor(v)
    g3 = g * g * g
    return v * g3, g3 + 3 * v * v * g3 * g * g
