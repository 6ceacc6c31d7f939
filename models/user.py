"""A user's model (`lagbench run --add-model NAME=module:factory`): the factory, called as factory(dof),
returns a torch.nn.Module whose forward(q, qdot) maps (N, dof) tensors to q-double-dot (N, dof), or, if the
module says `returns = "lagrangian"`, to a scalar Lagrangian per sample (`returns`); a factory that takes a
`key`, factory(dof, key), returns an equinox Module called as module(q, qdot) the same way, and trains in
JAX (`framework_of`).

`factory_source(ref)`: the sha256 (16 hex digits) of the file that defines the factory (a spec field, so
an edited module never reuses a cached training). `make_module(spec, seed)`: a fresh module of spec's
factory. `param_shapes(spec)`: {name: shape} of its parameters (the layout `models.params` checks against).
`init_params(spec, seed)`: its initial parameters as NumPy arrays, the factory called under
torch.manual_seed(seed) or with jax.random.PRNGKey(seed) (same seed, same numbers). Every call into the user's
code (the factory; the module, `forward`) goes through the suite's one boundary, `lagbench.files.user_functions`:
an exception, a wrong type or shape is one line naming the user's file and function. Imported only when a
user names a model.
"""
from __future__ import annotations

import hashlib
import inspect

import numpy as np

OPTION = "--add-model"


def _factory(ref: str):
    from lagbench.files.user_functions import import_function  # the one boundary with a user's code

    return import_function(ref, OPTION)


def _boundary():
    from lagbench.files import user_functions

    return user_functions


def files_of(spec, module) -> tuple:
    """The user's files a call into `module` may raise from: the factory's, and its class's unless the class is
    a library's (a torch.nn.Sequential the factory built)."""
    b = _boundary()
    own = type(module).__module__.split(".")[0] not in ("torch", "equinox")
    return tuple(dict.fromkeys(f for f in (b.source_file(_factory(spec.own.factory)), own and b.source_file(module)) if f))


def forward(spec, module, fn, *args):
    """fn(*args), a call of `module` (an equinox module itself, or torch's `functional_call` of it): any exception
    is the boundary's one line naming the module's forward (`lagbench.files.user_functions.call`)."""
    name = f"{type(module).__name__}.{'forward' if hasattr(module, 'forward') else '__call__'}(q, qdot)"
    return _boundary().call(OPTION, spec.own.factory, name, fn, *args, files=lambda: files_of(spec, module))


def factory_source(ref: str) -> str:
    fn = _factory(ref)
    try:
        with open(inspect.getsourcefile(fn), "rb") as f:
            data = f.read()
    except (TypeError, OSError) as e:
        raise ValueError(f"--add-model {ref}: cannot read the file that defines it ({e})") from None
    return hashlib.sha256(data).hexdigest()[:16]


def _framework(fn) -> str:
    return "jax" if "key" in inspect.signature(fn).parameters else "torch"


def framework_of(ref: str) -> str:
    """"jax" for a factory that takes a `key` (an equinox module's PRNG key), else "torch"."""
    return _framework(_factory(ref))


def make_module(spec, seed: int = 0):
    """A fresh module of spec's factory: PyTorch's in spec.dtype (under the caller's torch seed), equinox's
    from jax.random.PRNGKey(seed)."""
    fn = _factory(spec.own.factory)   # imported once: a file named by its path runs on each import
    b, name = _boundary(), getattr(fn, "__name__", "factory")
    if _framework(fn) == "jax":
        import equinox as eqx
        import jax

        module = b.call(OPTION, spec.own.factory, f"the factory {name}(dof, key)", fn, spec.dof, key=jax.random.PRNGKey(seed))
        if not isinstance(module, eqx.Module):
            raise b.wrong(OPTION, spec.own.factory, f"the factory takes a key but returned {type(module).__name__}, not "
                          f"an equinox Module")
        return module
    import torch

    module = b.call(OPTION, spec.own.factory, f"the factory {name}(dof)", fn, spec.dof)
    if not isinstance(module, torch.nn.Module):
        raise b.wrong(OPTION, spec.own.factory, f"the factory returned {type(module).__name__}, not a torch.nn.Module "
                      f"(an equinox factory takes a key: factory(dof, key))")
    return module.to(getattr(torch, spec.dtype))


def _named_arrays(module) -> dict:
    """{name: array} of the module's parameters: PyTorch's named_parameters, equinox's inexact array leaves
    by their tree path."""
    import torch

    if isinstance(module, torch.nn.Module):
        return {k: v.detach() for k, v in module.named_parameters()}
    import equinox as eqx
    import jax

    arrays = eqx.filter(module, eqx.is_inexact_array)
    return {jax.tree_util.keystr(path): leaf for path, leaf in jax.tree_util.tree_flatten_with_path(arrays)[0]}


def param_shapes(spec) -> dict:
    return {k: tuple(v.shape) for k, v in _named_arrays(make_module(spec)).items()}


def init_params(spec, seed: int) -> dict:
    import torch

    with torch.random.fork_rng():   # a torch factory draws under the seed; an equinox one from its key
        torch.manual_seed(seed)
        module = make_module(spec, seed)
    return {k: np.asarray(v.cpu() if hasattr(v, "cpu") else v).astype(spec.dtype)
            for k, v in _named_arrays(module).items()}


RETURNS = ("acceleration", "lagrangian", "hamiltonian")


def returns(module) -> str:
    """What forward(q, qdot) gives: the module's class attribute `returns`, "acceleration" (q-double-dot, the
    default), "lagrangian" (a scalar L per sample, turned into q-double-dot by the suite's Euler-Lagrange) or
    "hamiltonian" (a scalar H(q, p) per sample: Hamilton's equations, trained where the paper's HNN is)."""
    r = getattr(module, "returns", "acceleration")
    if r not in RETURNS:
        raise _boundary().UserCodeError(f"{OPTION}: {type(module).__name__}.returns is {r!r}; valid: "
                                        f"{', '.join(RETURNS)}; {_boundary().NO_RERUN}")
    return r


def returns_of(ref: str) -> str:
    """`returns` of the module the factory `ref` builds (built once, for one coordinate)."""
    from lagbench.models.spec import USER_KIND, ModelSpec

    return returns(make_module(ModelSpec(kind=USER_KIND, dof=1, factory=ref, factory_source="-")))


def scalar(spec, out, like):
    """A Lagrangian's output (N,) or (N, 1) as (N,)."""
    if out.shape[-1:] == (1,) and out.ndim == like.ndim:
        out = out[..., 0]
    if tuple(out.shape) != tuple(like.shape[:-1]):
        raise _boundary().wrong(OPTION, spec.own.factory, f"a scalar module's forward(q, qdot) returned shape "
                                f"{tuple(out.shape)}, expected {tuple(like.shape[:-1])} (one scalar per sample)")
    return out


def check_output(spec, out, like) -> None:
    if tuple(out.shape) != tuple(like.shape):
        raise _boundary().wrong(OPTION, spec.own.factory, f"forward(q, qdot) returned shape {tuple(out.shape)}, "
                                f"expected {tuple(like.shape)} (q-double-dot, one per coordinate)")

