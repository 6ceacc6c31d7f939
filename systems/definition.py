"""A system's single source: a SymPy Lagrangian plus generalised forces, parameters and samplers.

``Definition`` is immutable and holds only SymPy objects and plain data:

- ``q``, ``qdot``: tuples of ``dof`` SymPy symbols (coordinates and velocities);
- ``lagrangian``: SymPy expression in q, qdot and the parameter symbols;
- ``forces``: optional tuple of ``dof`` expressions, the non-conservative generalised forces
  (e.g. viscous friction ``-b*qdot``); joint torques ``tau`` are always added on top;
- ``params``: mapping parameter name -> (SymPy symbol, default value, constraint), constraint
  one of "positive", "nonnegative", "real";
- ``options``: structural (non-symbolic) choices that built the Lagrangian (e.g. wave ``n``);
- ``local_coupling``, ``actuated``: declared structure (the rest is derived);
- ``max_speed``: if set, every |qdot| must be below it (relativistic particle: 1);
- ``validate``: optional ``validate(params: dict) -> None`` raising ValueError on
  non-physical combinations of bound parameters (e.g. a centre of mass beyond its link);
- ``sampler``: ``sampler(n, rng, params, distribution) -> dict`` of float64 arrays
  ("q", "qdot" of shape (n, dof) and any per-sample parameter of shape (n,)).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
from collections.abc import Callable, Mapping

import sympy as sp

CONSTRAINTS = ("positive", "nonnegative", "real")


@dataclasses.dataclass(frozen=True, eq=False)
class Definition:
    name: str
    q: tuple
    qdot: tuple
    lagrangian: sp.Expr
    params: Mapping[str, tuple]
    sampler: Callable
    forces: tuple | None = None
    options: Mapping[str, object] = dataclasses.field(default_factory=dict)
    local_coupling: bool = False
    actuated: bool = False
    max_speed: float | None = None
    description: str = ""
    validate: Callable | None = None

    @property
    def dof(self) -> int:
        return len(self.q)

    @property
    def param_symbols(self) -> tuple:
        return tuple(sym for sym, _, _ in self.params.values())

    def fingerprint(self) -> str:
        """Hash of everything the derived code depends on (the Lagrangian, forces, symbol order)."""
        return self._fingerprint

    @functools.cached_property
    def _fingerprint(self) -> str:
        text = "|".join(
            [
                sp.srepr(self.lagrangian),
                sp.srepr(tuple(self.forces or ())),
                sp.srepr(tuple(self.q)),
                sp.srepr(tuple(self.qdot)),
                sp.srepr(self.param_symbols),
            ]
        )
        return hashlib.sha256(text.encode()).hexdigest()


def coordinates(names: list[str]) -> tuple[tuple, tuple]:
    """Real symbols for coordinates ``names`` and their velocities ``<name>_dot``."""
    q = tuple(sp.Symbol(n, real=True) for n in names)
    qdot = tuple(sp.Symbol(f"{n}_dot", real=True) for n in names)
    return q, qdot


def param(name: str, default: float, constraint: str = "positive") -> tuple:
    """``name -> (symbol, default, constraint)`` entry for ``Definition.params``."""
    if constraint not in CONSTRAINTS:
        raise ValueError(f"constraint must be one of {CONSTRAINTS}")
    return sp.Symbol(name, real=True), float(default), constraint


def planar_position(terms) -> tuple:
    """(x, y) of a point sum_a length_a * (cos angle_a, sin angle_a); ``terms`` = [(length, angle)]."""
    return sum(r * sp.cos(a) for r, a in terms), sum(r * sp.sin(a) for r, a in terms)


def planar_kinetic(points, masses, q, qdot) -> sp.Expr:
    """T = sum_k m_k/2 |v_k|^2 for planar point masses given as ``[(length, angle), ...]`` sums.

    Uses |sum_a r_a w_a e(angle_a)|^2 = sum_ab r_a r_b w_a w_b cos(angle_a - angle_b) with
    w_a = d angle_a / dt, so the kinetic energy comes out in its compact trigonometric form.
    """
    total = sp.Integer(0)
    for terms, m in zip(points, masses, strict=True):
        rates = [sum(sp.diff(a, qi) * vi for qi, vi in zip(q, qdot, strict=True)) for _, a in terms]
        for (ra, aa), wa in zip(terms, rates, strict=True):
            for (rb, ab), wb in zip(terms, rates, strict=True):
                total += m / 2 * ra * rb * wa * wb * sp.cos(aa - ab)
    return total
