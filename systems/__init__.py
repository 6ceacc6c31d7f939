"""Ground truth: every benchmark system as one SymPy Lagrangian, derived and code-generated.

    import systems
    systems.names()                        # sorted registered names
    s = systems.get("double_pendulum")     # defaults; systems.get(name, **options_and_params)
    s.acceleration(q, qdot, backend="jax") # (..., dof) -> (..., dof)

See ``systems.system`` for the methods of a ``System`` and their shapes,
``systems.trajectories`` for diffrax integration and ``systems.datasets`` for cached datasets.
Importing this package enables JAX float64 (``jax_enable_x64``).
"""
import os as _os

_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")  # busy-waiting OpenMP threads stall a loaded CPU (CONTRIBUTING)


from systems import backends  # noqa: F401  (enables jax x64)
from systems.derive import NotQuadraticError
from systems.registry import definition, get, names, options_of
from systems.system import System

__all__ = ["names", "get", "definition", "options_of", "System", "NotQuadraticError"]
