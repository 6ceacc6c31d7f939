"""SymPy helpers for spatial (3D) rigid bodies: rotations, body-frame rates, trigonometric reduction.

- ``rotation(axis, angle) -> Matrix`` (3 x 3): the rotation by ``angle`` (rad, right-handed) about the
  coordinate axis ``axis`` ("x" | "y" | "z");
- ``time_derivative(expr, q, qdot)``: d/dt of a SymPy expression or matrix that depends on time only
  through q (chain rule: sum_i d expr / d q_i * qdot_i);
- ``body_angular_velocity(R, q, qdot) -> [wx, wy, wz]``: the angular velocity of a body with orientation
  R(q) (body axes to world axes) in its own axes, read off the skew matrix R^T dR/dt;
- ``body_velocity(R, p, q, qdot) -> [vx, vy, vz]``: the velocity dp/dt of a point p(q) (world axes)
  expressed in the body axes of R(q), R^T dp/dt;
- ``trig_reduce(expr, q)``: ``expr`` (a polynomial in sin q_i, cos q_i and anything else) in the canonical
  form modulo sin^2 q_i + cos^2 q_i = 1 (the remainder of polynomial division by those relations, which
  already form a Groebner basis), so that R^T R = 1 simplifies without ``sympy.trigsimp``'s cost.

A kinetic energy written as 1/2 m |v_b|^2 + 1/2 w_b^T I_b w_b, with v_b and w_b from these helpers and I_b
the body's inertia tensor about its centre of mass in its own axes, is a sum of squares of short
expressions: compact to differentiate in ``systems.derive``.
"""

from __future__ import annotations

import sympy as sp

_AXES = ("x", "y", "z")


def rotation(axis: str, angle) -> sp.Matrix:
    if axis not in _AXES:
        raise ValueError(f"axis must be one of {_AXES}; got {axis!r}")
    c, s = sp.cos(angle), sp.sin(angle)
    if axis == "x":
        return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def time_derivative(expr, q, qdot):
    if isinstance(expr, sp.MatrixBase):
        return expr.applyfunc(lambda e: time_derivative(e, q, qdot))
    return sum((sp.diff(expr, qi) * vi for qi, vi in zip(q, qdot, strict=True)), sp.Integer(0))


def trig_reduce(expr, q) -> sp.Expr:
    s = [sp.Dummy(f"s_{x}") for x in q]
    c = [sp.Dummy(f"c_{x}") for x in q]
    to_poly = {**{sp.sin(x): si for x, si in zip(q, s, strict=True)},
               **{sp.cos(x): ci for x, ci in zip(q, c, strict=True)}}
    back = {v: k for k, v in to_poly.items()}
    poly = sp.expand(sp.sympify(expr).xreplace(to_poly))
    if poly == 0:
        return sp.Integer(0)
    relations = [ci**2 + si**2 - 1 for si, ci in zip(s, c, strict=True)]
    others = sorted(poly.free_symbols - set(s) - set(c), key=str)
    _, remainder = sp.reduced(poly, relations, *c, *s, *others, order="lex")
    return sp.factor_terms(remainder).xreplace(back)


def body_angular_velocity(rot: sp.Matrix, q, qdot) -> list:
    w = rot.T * time_derivative(rot, q, qdot)  # skew: [[0, -wz, wy], [wz, 0, -wx], [-wy, wx, 0]]
    return [trig_reduce(e, q) for e in (w[2, 1], w[0, 2], w[1, 0])]


def body_velocity(rot: sp.Matrix, point: sp.Matrix, q, qdot) -> list:
    v = rot.T * time_derivative(point, q, qdot)
    return [trig_reduce(e, q) for e in v]
