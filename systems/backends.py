"""Array backends for the generated callables: NumPy, JAX (float64 enabled) and PyTorch.

Contract: ``namespace(backend)`` returns the dict of names the generated source expects
(``sin``, ``cos``, ``sqrt``, ``Abs``, ``pi``, and the helpers ``_stack``, ``_solve``), built once per backend.
``broadcast_shapes(shapes, backend)`` is the common batch shape, ``as_array(x, backend, dtype)`` converts an input to that backend (keeping float32/float64,
promoting anything else to float64); ``is_concrete(x)`` says whether values can be inspected
(False for a JAX tracer inside ``jit``/``vmap``). Importing this module enables JAX x64.
PyTorch is imported lazily, on first use of the "torch" backend.
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

jax.config.update("jax_enable_x64", True)

BACKENDS = ("numpy", "jax", "torch")

_FUNCS = ("sin", "cos", "tan", "exp", "log", "sqrt", "tanh", "sinh", "cosh", "arctan2")


def check_backend(backend: str) -> str:
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; valid backends: {', '.join(BACKENDS)}")
    return backend


@functools.cache
def namespace(backend: str) -> dict:
    """Names used by generated source, bound to ``backend``'s functions."""
    check_backend(backend)
    if backend == "torch":
        import torch

        ns = {f: getattr(torch, "atan2" if f == "arctan2" else f) for f in _FUNCS}
        ns.update(
            Abs=torch.abs,
            sign=torch.sign,
            _stack=lambda xs, axis: torch.stack(xs, dim=axis),
            _solve=lambda a, b: torch.linalg.solve(a, b.unsqueeze(-1)).squeeze(-1),
        )
    else:
        xp = np if backend == "numpy" else jnp
        ns = {f: getattr(xp, f) for f in _FUNCS}
        ns.update(
            Abs=xp.abs,
            sign=xp.sign,
            _stack=lambda xs, axis: xp.stack(xs, axis=axis),
            _solve=lambda a, b: xp.linalg.solve(a, b[..., None])[..., 0],
        )
    ns.update(pi=float(np.pi), E=float(np.e))
    return ns


_FLOAT32 = np.dtype(np.float32)


def result_dtype(*xs):
    """float32 only if every input given (not None) is float32, and there is one; float64 otherwise (an input
    without a dtype, a Python number or list, counts as float64). Called on every evaluation of a system, so
    NumPy's and JAX's dtypes are compared directly and only other libraries' by name."""
    seen = False
    for x in xs:
        if x is None:
            continue
        d = getattr(x, "dtype", None)
        if not (d == _FLOAT32 if isinstance(d, np.dtype) else str(d).replace("torch.", "") == "float32"):
            return "float64"
        seen = True
    return "float32" if seen else "float64"


def as_array(x, backend: str, dtype: str):
    """Convert ``x`` (array, tensor, scalar) to ``backend`` with ``dtype`` ("float32"/"float64")."""
    if backend == "numpy":
        if not isinstance(x, np.ndarray | np.generic | float | int | list | tuple):
            x = np.asarray(_to_numpy(x))
        return np.asarray(x, dtype=dtype)
    if backend == "jax":
        if type(x).__module__.startswith("torch"):
            x = _to_numpy(x)
        return jnp.asarray(x, dtype=dtype)
    import torch

    tdtype = getattr(torch, dtype)
    if isinstance(x, torch.Tensor):
        return x.to(tdtype)
    return torch.as_tensor(np.asarray(x), dtype=tdtype)


def _to_numpy(x):
    if type(x).__module__.startswith("torch"):
        return x.detach().cpu().numpy()
    return np.asarray(x)


def is_concrete(x) -> bool:
    return not isinstance(x, jax.core.Tracer)


def max_abs(x) -> float:
    """Largest |x| as a Python float (x concrete)."""
    return float(np.max(np.abs(_to_numpy(x)))) if np.size(_to_numpy(x)) else 0.0


def broadcast_shapes(shapes, backend: str) -> tuple:
    """The common batch shape (ValueError if none). PyTorch's own rule keeps symbolic sizes symbolic,
    so a function of it exports with a dynamic batch (NumPy's would fix them to the traced example)."""
    if backend != "torch":
        return np.broadcast_shapes(*shapes)
    import torch

    try:
        return tuple(torch.broadcast_shapes(*shapes))
    except RuntimeError as err:
        raise ValueError(str(err)) from err


def zeros(shape, backend: str, dtype: str):
    if backend == "numpy":
        return np.zeros(shape, dtype=dtype)
    if backend == "jax":
        return jnp.zeros(shape, dtype=dtype)
    import torch

    return torch.zeros(shape, dtype=getattr(torch, dtype))
