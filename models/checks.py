"""Input checks shared by the JAX and PyTorch models (framework-neutral: only .shape, .ndim, .dtype).

check_input(spec, name, x, width, like=None): x must be (..., width) (any width if None), of
spec.dtype, and have the batch shape of `like`. check_state(spec, q, qdot, extra, width=None): the
(q, qdot[, extra]) triple of a model call. Shape problems raise ValueError, dtype problems TypeError,
each naming what was expected and what came.
n_required_inputs(fn): required positional arguments of an unbound model method, less `self` (how
many inputs `compile_single` compiles for, in both frameworks).
"""
from __future__ import annotations

import inspect


def _dtype_name(x) -> str:
    return str(x.dtype).removeprefix("torch.")


def check_input(spec, name: str, x, width: int | None, like=None):
    if x is None:
        raise ValueError(f"{spec.kind}: {name} is required (shape (..., {width}))")
    if x.ndim < 1 or (width is not None and x.shape[-1] != width):
        raise ValueError(f"{spec.kind}: expected {name} of shape (..., {width}), got shape {tuple(x.shape)}")
    if like is not None and x.shape[:-1] != like.shape[:-1]:
        raise ValueError(f"{spec.kind}: {name} has batch shape {tuple(x.shape[:-1])}, "
                         f"expected {tuple(like.shape[:-1])} (as q)")
    if _dtype_name(x) != spec.dtype:
        raise TypeError(f"{spec.kind}: {name} has dtype {x.dtype}, the model is {spec.dtype}")


def check_state(spec, q, qdot, extra=None, width=None):
    width = spec.dof if width is None else width
    check_input(spec, "q", q, width)
    check_input(spec, "qdot", qdot, q.shape[-1], like=q)
    if qdot.shape != q.shape:
        raise ValueError(f"{spec.kind}: qdot shape {tuple(qdot.shape)} != q shape {tuple(q.shape)}")
    if spec.extra_inputs:
        check_input(spec, "extra", extra, spec.extra_inputs, like=q)
    elif extra is not None:
        raise ValueError(f"{spec.kind}: got extra inputs but spec.extra_inputs == 0")


def n_required_inputs(fn) -> int:
    """Required positional arguments of an unbound method, less `self`."""
    sig = inspect.signature(inspect.unwrap(fn))
    return -1 + sum(p.default is inspect.Parameter.empty and p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)
               for p in sig.parameters.values())
