"""A user's model (`lagbench run --add-model NAME=module:factory`): the factory, called as factory(dof),
returns a torch.nn.Module whose forward(q, qdot) maps (N, dof) tensors to q-double-dot (N, dof), or, if the
module says `returns = "lagrangian"`, to a scalar Lagrangian per sample (`returns`).

`factory_source(ref)`: the sha256 (16 hex digits) of the file that defines the factory (a spec field, so
an edited module never reuses a cached training). `make_module(spec)`: a fresh module of spec's factory
in spec.dtype. `param_shapes(spec)`: {name: shape} of its parameters (the layout `models.params` checks
against). `init_params(spec, seed)`: its initial parameters as NumPy arrays, the factory called under
torch.manual_seed(seed) (same seed, same numbers). Imported only when a user names a model.
"""
from __future__ import annotations

import hashlib
import inspect


def _factory(ref: str):
    from replication.user_functions import import_function  # the one importer of a user's code

    return import_function(ref, "--add-model")


def factory_source(ref: str) -> str:
    fn = _factory(ref)
    try:
        with open(inspect.getsourcefile(fn), "rb") as f:
            data = f.read()
    except (TypeError, OSError) as e:
        raise ValueError(f"--add-model {ref}: cannot read the file that defines it ({e})") from None
    return hashlib.sha256(data).hexdigest()[:16]


def make_module(spec):
    import torch

    module = _factory(spec.factory)(spec.dof)
    if not isinstance(module, torch.nn.Module):
        raise ValueError(f"--add-model {spec.factory}: the factory returned {type(module).__name__}, not a "
                         f"torch.nn.Module")
    return module.to(getattr(torch, spec.dtype))


def param_shapes(spec) -> dict:
    return {k: tuple(v.shape) for k, v in make_module(spec).named_parameters()}


def init_params(spec, seed: int) -> dict:
    import torch

    with torch.random.fork_rng():
        torch.manual_seed(seed)
        module = make_module(spec)
    return {k: v.detach().cpu().numpy().astype(spec.dtype) for k, v in module.named_parameters()}


RETURNS = ("acceleration", "lagrangian")


def returns(module) -> str:
    """What forward(q, qdot) gives: the module's class attribute `returns`, "acceleration" (q-double-dot, the
    default) or "lagrangian" (a scalar L per sample, turned into q-double-dot by the suite's Euler-Lagrange)."""
    r = getattr(module, "returns", "acceleration")
    if r not in RETURNS:
        raise ValueError(f"--add-model: {type(module).__name__}.returns is {r!r}; valid: {', '.join(RETURNS)}")
    return r


def scalar(spec, out, like):
    """A Lagrangian's output (N,) or (N, 1) as (N,)."""
    if out.shape[-1:] == (1,) and out.ndim == like.ndim:
        out = out[..., 0]
    if tuple(out.shape) != tuple(like.shape[:-1]):
        raise ValueError(f"--add-model {spec.factory}: a Lagrangian's forward(q, qdot) returned shape "
                         f"{tuple(out.shape)}, expected {tuple(like.shape[:-1])} (one scalar per sample)")
    return out


def check_output(spec, out, like) -> None:
    if tuple(out.shape) != tuple(like.shape):
        raise ValueError(f"--add-model {spec.factory}: forward(q, qdot) returned shape {tuple(out.shape)}, "
                         f"expected {tuple(like.shape)} (q-double-dot, one per coordinate)")


__all__ = ["factory_source", "make_module", "param_shapes", "init_params", "check_output"]
