"""The registry of systems by name.

``names()`` lists every registered name (sorted). ``get(name, **kwargs)`` returns a ``System``:
keyword arguments that are structural options of the family (``n`` and ``variant`` for the wave,
``n`` for the pendulum chain) select the Lagrangian; the rest override numerical parameters
(validated: unknown names and non-physical values raise ValueError). Definitions are built
once per option set and shared by every ``System`` made from them.
"""

from __future__ import annotations

import functools
import inspect

from lagbench.systems.definition import Definition
from lagbench.systems.library import arm, arm4, magnetic, mechanics, relativistic, stiff, wave
from lagbench.systems.system import System

_BUILDERS = {
    "free_fall": mechanics.build_free_fall,
    "pendulum": mechanics.build_pendulum,
    "spring": mechanics.build_spring,
    "double_pendulum": mechanics.build_double_pendulum,
    "pendulum_chain": mechanics.build_pendulum_chain,
    "relativistic": relativistic.build_relativistic,
    "relativistic_standard": relativistic.build_relativistic_standard,
    "charged_magnetic": magnetic.build_charged_magnetic,
    "wave": wave.build_wave,
    "two_link_arm": arm.build_two_link_arm,
    "four_joint_arm": arm4.build_four_joint_arm,
    "stiff_chain": stiff.build_stiff_chain,
}


def names() -> list[str]:
    return sorted(_BUILDERS)


def options_of(name: str) -> dict:
    """Structural options of ``name`` with their defaults (e.g. {"n": 10, "variant": "code"})."""
    sig = inspect.signature(_builder(name))
    return {k: p.default for k, p in sig.parameters.items()}


def _builder(name: str):
    if name not in _BUILDERS:
        raise KeyError(f"unknown system {name!r}; valid names: {', '.join(names())}")
    return _BUILDERS[name]


@functools.lru_cache(maxsize=64)
def _definition(name: str, options: tuple) -> Definition:
    return _builder(name)(**dict(options))


def definition(name: str, **options) -> Definition:
    return _definition(name, tuple(sorted({**options_of(name), **options}.items())))


def get(name: str, **kwargs) -> System:
    """``System`` ``name`` with options and parameter overrides from ``kwargs``."""
    opts = options_of(name)
    chosen = {k: kwargs.pop(k) for k in list(kwargs) if k in opts}
    return System(definition(name, **chosen), **kwargs)
