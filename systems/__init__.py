"""Ground truth: every benchmark system as one SymPy Lagrangian, derived and code-generated.

    from lagbench import systems
    systems.names()                        # sorted registered names
    s = systems.get("double_pendulum")     # defaults; systems.get(name, **options_and_params)
    s.acceleration(q, qdot, backend="jax") # (..., dof) -> (..., dof)

See ``systems.system`` for the methods of a ``System`` and their shapes,
``systems.trajectories`` for diffrax integration and ``systems.datasets`` for cached datasets.
Importing this package enables JAX float64 (``jax_enable_x64``).
"""
from lagbench.systems import backends  # noqa: F401  (enables jax x64)
from lagbench.systems.derive import NotQuadraticError
from lagbench.systems.registry import definition, get, names, options_of
from lagbench.systems.system import System

__all__ = ["names", "get", "definition", "options_of", "System", "NotQuadraticError"]
